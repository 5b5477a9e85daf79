//! Spheroidal apples: the geometry of an apple whose height (stem to calyx, along its own z
//! axis) differs from its diameter, and the two-curvature Hertz contact it makes (issue 29,
//! docs/shape.md).
//!
//! A spheroid of equatorial radius a and polar half-height c (x^2/a^2 + y^2/a^2 + z^2/c^2 = 1 in
//! its own frame; oblate c < a, elongated c > a). Everything the contact needs follows from its
//! support function h(l) = |S l|, S = diag(a, a, c), for a unit direction l in its frame:
//!
//! - the surface point whose outward normal is l: s(l) = S^2 l / h (the support point);
//! - the principal radii of curvature there (a surface of revolution; the meridian's radius of an
//!   ellipse with its normal at angle phi to the axis, and the parallel's, the distance along the
//!   normal to the axis):
//!
//! ```text
//! R_m = a^2 c^2 / h^3,   R_p = a^2 / h,   h = sqrt(a^2 sin^2 phi + c^2 cos^2 phi)
//! ```
//!
//!   so the pole (phi = 0) has R_m = R_p = a^2 / c, the cheek (phi = pi/2) R_m = c^2 / a, R_p = a
//!   (do Carmo, *Differential Geometry of Curves and Surfaces*, section 3-3, surfaces of
//!   revolution);
//! - two bodies touching at a common normal: their curvature tensors in the tangent plane add up
//!   to the relative curvature, whose eigenvalues are 1/R' and 1/R'' (Johnson, *Contact
//!   Mechanics*, section 4.2: A = 1/(2 R'), B = 1/(2 R'')); the elliptic Hertz law
//!   ([`super::elliptic`]) turns them into the stiffness radius R_k and the area radius R_a.
//!
//! The overlap of two convex bodies along a unit direction n (from body 2 to body 1) is
//! u(n) = h1(-n) + h2(n) - n . (x1 - x2); the minimal-translation overlap, and so the common
//! normal, is the n that minimises it (the separating-axis distance when apart). [`pair`] finds it
//! by Newton's method on the tangent plane, with the bodies' radius-of-curvature tensors as the
//! Hessian: it converges quadratically, in one or two iterations from the last step's normal.

use super::elliptic;
use crate::math::Vec3;
use rapier3d_f64::math::{Matrix, Rotation};
use std::f64::consts::PI;
use std::sync::OnceLock;

/// The shape of a spheroidal apple.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spheroid {
    /// Equatorial radius a (m): half the diameter.
    pub a: f64,
    /// Polar half-height c (m): half the extent along the apple's own z axis (stem to calyx).
    pub c: f64,
}

/// A surface point of a spheroid and its curvature there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfacePoint {
    /// Offset of the point from the centre (world, m).
    pub offset: Vec3,
    /// Support distance h = offset . l (m).
    pub support_m: f64,
    /// Radius of curvature of the meridian (m).
    pub r_meridian_m: f64,
    /// Radius of curvature of the parallel (m).
    pub r_parallel_m: f64,
    /// Unit tangent of the meridian (world); any tangent at a pole.
    pub meridian: Vec3,
}

impl Spheroid {
    /// A spheroid of equatorial radius `a_m` and polar half-height `c_m` (both > 0).
    pub fn new(a_m: f64, c_m: f64) -> Self {
        Self { a: a_m, c: c_m }
    }

    /// True for a sphere (a = c): the layer then keeps the sphere's exact code.
    pub fn is_sphere(&self) -> bool {
        self.a == self.c
    }

    /// Height over diameter, c / a.
    pub fn aspect(&self) -> f64 {
        self.c / self.a
    }

    /// The largest radius, max(a, c): the bounding sphere (pair finding).
    pub fn bounding_radius(&self) -> f64 {
        self.a.max(self.c)
    }

    /// The largest principal radius of curvature on its surface (m): a^2/c at the pole of an
    /// oblate apple, c^2/a along the meridian of an elongated one's cheek, R for a sphere. The
    /// stiffest contact it can make has an R_k no larger (step planning uses it).
    pub fn stiffest_radius(&self) -> f64 {
        (self.a * self.a / self.c).max(self.c * self.c / self.a)
    }

    /// [`Self::stiffest_radius`] over the equatorial radius, for an aspect c/a: the most of
    /// 1/aspect and aspect^2.
    pub fn stiffest_radius_ratio(aspect: f64) -> f64 {
        (1.0 / aspect).max(aspect * aspect)
    }

    /// Volume 4/3 pi a^2 c (m^3).
    pub fn volume_m3(&self) -> f64 {
        4.0 / 3.0 * PI * self.a * self.a * self.c
    }

    /// Principal moments of inertia of a uniform spheroid of mass `m`: about an equatorial axis
    /// m (a^2 + c^2) / 5, about its own axis 2 m a^2 / 5 (kg m^2).
    pub fn principal_inertia(&self, mass_kg: f64) -> (f64, f64) {
        (
            0.2 * mass_kg * (self.a * self.a + self.c * self.c),
            0.4 * mass_kg * self.a * self.a,
        )
    }

    /// The surface point whose outward normal is the world direction `l` (unit), for the apple
    /// turned by `rot` (its frame to the world's), with its principal curvatures.
    pub fn point_with_normal(&self, rot: &Rotation, l: Vec3) -> SurfacePoint {
        self.point_with_normal_in(&Matrix::from_quat(*rot), l)
    }

    /// [`Self::point_with_normal`] with the orientation as a rotation matrix (three products of
    /// a matrix and a vector instead of three of a quaternion: the pair search evaluates points
    /// several times per contact and step).
    pub fn point_with_normal_in(&self, m: &Matrix, l: Vec3) -> SurfacePoint {
        let b = m.transpose() * l;
        let (a2, c2) = (self.a * self.a, self.c * self.c);
        let h = (a2 * (b.x * b.x + b.y * b.y) + c2 * b.z * b.z).sqrt();
        let offset = Vec3::new(a2 * b.x, a2 * b.y, c2 * b.z) / h;
        // The meridian's tangent: the axis less its normal part (any tangent at a pole).
        let axis = m.z_axis;
        let t = axis - l * axis.dot(l);
        let t_len = t.length();
        let meridian = if t_len > 1e-9 {
            t / t_len
        } else {
            l.any_orthonormal_vector()
        };
        SurfacePoint {
            offset: *m * offset,
            support_m: h,
            r_meridian_m: a2 * c2 / (h * h * h),
            r_parallel_m: a2 / h,
            meridian,
        }
    }
}

/// A symmetric 2x2 tensor in the tangent plane of a contact, in a fixed basis (e1, e2) of it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tangent2 {
    /// (e1, e1) component.
    pub xx: f64,
    /// (e1, e2) component.
    pub xy: f64,
    /// (e2, e2) component.
    pub yy: f64,
}

impl Tangent2 {
    /// Zero.
    pub const ZERO: Self = Self {
        xx: 0.0,
        xy: 0.0,
        yy: 0.0,
    };

    /// k1 d d^T + k2 (I - d d^T): principal value `k1` along the unit tangent `d`, `k2` across,
    /// in the basis (e1, e2).
    pub fn principal(k1: f64, d: Vec3, k2: f64, e1: Vec3, e2: Vec3) -> Self {
        let (c, s) = (d.dot(e1), d.dot(e2));
        let norm2 = c * c + s * s;
        // A unit tangent (the spheroid's meridian) needs no normalising; a direction off the
        // plane (a cylinder's axis) is projected.
        let (c2, cs, s2) = if (norm2 - 1.0).abs() < 1e-12 {
            (c * c, c * s, s * s)
        } else if norm2 > 0.0 {
            (c * c / norm2, c * s / norm2, s * s / norm2)
        } else {
            (1.0, 0.0, 0.0)
        };
        let dk = k1 - k2;
        Self {
            xx: k2 + dk * c2,
            xy: dk * cs,
            yy: k2 + dk * s2,
        }
    }

    /// An isotropic tensor k I.
    pub fn iso(k: f64) -> Self {
        Self {
            xx: k,
            xy: 0.0,
            yy: k,
        }
    }

    /// The eigenvalues, smaller first.
    pub fn eigen(&self) -> (f64, f64) {
        let mean = 0.5 * (self.xx + self.yy);
        let half = 0.5 * (self.xx - self.yy);
        let r = (half * half + self.xy * self.xy).sqrt();
        (mean - r, mean + r)
    }

    /// Solves T x = g for x (2-vectors as (x, y)); `None` when singular.
    pub fn solve(&self, g: (f64, f64)) -> Option<(f64, f64)> {
        let det = self.xx * self.yy - self.xy * self.xy;
        if det.abs() <= 1e-300 {
            return None;
        }
        Some((
            (self.yy * g.0 - self.xy * g.1) / det,
            (self.xx * g.1 - self.xy * g.0) / det,
        ))
    }
}

impl std::ops::Add for Tangent2 {
    type Output = Self;

    /// The sum of two tensors.
    fn add(self, o: Self) -> Self {
        Self {
            xx: self.xx + o.xx,
            xy: self.xy + o.xy,
            yy: self.yy + o.yy,
        }
    }
}

impl SurfacePoint {
    /// The curvature tensor (1/m) in the basis (e1, e2).
    pub fn curvature(&self, e1: Vec3, e2: Vec3) -> Tangent2 {
        Tangent2::principal(
            1.0 / self.r_meridian_m,
            self.meridian,
            1.0 / self.r_parallel_m,
            e1,
            e2,
        )
    }

    /// The radius-of-curvature tensor (m) in the basis (e1, e2): how far the point moves along
    /// the surface per radian the normal turns.
    pub fn radii(&self, e1: Vec3, e2: Vec3) -> Tangent2 {
        Tangent2::principal(self.r_meridian_m, self.meridian, self.r_parallel_m, e1, e2)
    }
}

/// An orthonormal basis (e1, e2) of the plane normal to `n`.
pub fn tangent_basis(n: Vec3) -> (Vec3, Vec3) {
    let e1 = n.any_orthonormal_vector();
    (e1, n.cross(e1))
}

/// The Hertz radii of a contact whose relative curvature tensor is `k` (1/m): the stiffness
/// radius R_k and the area radius R_a of the elliptic law ([`elliptic`]); `None` when the
/// contact conforms (an eigenvalue <= 0: Hertz does not apply).
pub fn hertz_radii(k: &Tangent2) -> Option<(f64, f64)> {
    let (lo, hi) = k.eigen();
    if !(lo > 0.0 && hi.is_finite()) {
        return None;
    }
    Some(elliptic_radii(1.0 / lo, 1.0 / hi))
}

/// The elliptic law's (R_k, R_a) for the principal relative radii R' >= R'' (m), from a table
/// of the exact solution ([`elliptic::elliptic_hertz`]) in t = ln(R'/R''), interpolated by cubic
/// Lagrange polynomials: the exact solve takes some sixty evaluations of the elliptic integrals,
/// too many for every step of every spheroid contact. The tables hold R_k / sqrt(R' R'') and
/// R_a / sqrt(R' R''): up to R'/R'' = 5 in q = 1 - R''/R' at steps of 1/1024 (no logarithm),
/// beyond that in t = ln(R'/R''), even functions of t, at steps of 1/128 up to R'/R'' = e^8
/// (2981); the interpolation error is below 1e-10 (tested). Beyond the tables: the exact
/// solve.
pub fn elliptic_radii(r_prime: f64, r_double_prime: f64) -> (f64, f64) {
    let (r1, r2) = if r_prime >= r_double_prime {
        (r_prime, r_double_prime)
    } else {
        (r_double_prime, r_prime)
    };
    if r1 == r2 {
        return (r1, r1);
    }
    let geo = (r1 * r2).sqrt();
    let q = 1.0 - r2 / r1;
    if q < NEAR_SPAN {
        return near_radii(q, geo);
    }
    let t = (r1 / r2).ln();
    let table = radii_table();
    let x = t * TABLE_PER_UNIT;
    let k = x.floor() as usize;
    if k + 2 >= table.len() {
        let h = elliptic::elliptic_hertz(r1, r2);
        return (h.stiffness_radius_m, h.area_radius_m);
    }
    // Nodes k-1 .. k+2 (node -1 mirrors node 1: the functions are even in t).
    let node = |i: isize| table[i.unsigned_abs()];
    let ki = k as isize;
    let nodes = [node(ki - 1), node(ki), node(ki + 1), node(ki + 2)];
    cubic(nodes, x - k as f64, geo)
}

/// Cubic Lagrange interpolation of the table's pairs at nodes -1, 0, 1, 2 to the fraction `f`
/// in [0, 1) of the interval (0, 1), times `geo`.
fn cubic(p: [(f64, f64); 4], f: f64, geo: f64) -> (f64, f64) {
    let w = [
        -f * (f - 1.0) * (f - 2.0) / 6.0,
        (f + 1.0) * (f - 1.0) * (f - 2.0) / 2.0,
        -(f + 1.0) * f * (f - 2.0) / 2.0,
        (f + 1.0) * f * (f - 1.0) / 6.0,
    ];
    let rk = w[0] * p[0].0 + w[1] * p[1].0 + w[2] * p[2].0 + w[3] * p[3].0;
    let ra = w[0] * p[0].1 + w[1] * p[1].1 + w[2] * p[2].1 + w[3] * p[3].1;
    (rk * geo, ra * geo)
}

/// The near-circular table's reach in q = 1 - R''/R' (R'/R'' up to 5: apples on apples and flats,
/// and on rollers down to 20 mm radius). The functions are analytic in q at 0 (even in
/// t = -ln(1 - q)), so no logarithm is needed there: one less per contact and step.
const NEAR_SPAN: f64 = 0.8;
/// Near-table nodes per unit of q.
const NEAR_PER_UNIT: f64 = 1024.0;

/// [`elliptic_radii`] for q = 1 - R''/R' < [`NEAR_SPAN`] (cubic Lagrange in q; node -1 by the
/// table's own extrapolation is not needed: the first interval uses nodes 0-3).
fn near_radii(q: f64, geo: f64) -> (f64, f64) {
    let table = near_table();
    let x = q * NEAR_PER_UNIT;
    let k = (x.floor() as usize).clamp(1, table.len() - 3);
    cubic(
        [table[k - 1], table[k], table[k + 1], table[k + 2]],
        x - k as f64,
        geo,
    )
}

fn near_table() -> &'static [(f64, f64)] {
    static TABLE: OnceLock<Vec<(f64, f64)>> = OnceLock::new();
    // Three nodes past the reach, for the last intervals' stencils.
    let n = (NEAR_SPAN * NEAR_PER_UNIT) as usize + 3;
    TABLE.get_or_init(|| tabulate(n, |i| 1.0 / (1.0 - i as f64 / NEAR_PER_UNIT)))
}

/// R_k / sqrt(R' R'') and R_a / sqrt(R' R'') by the exact solve at R'/R'' = `rho(i)`, i < n.
fn tabulate(n: usize, rho: impl Fn(usize) -> f64) -> Vec<(f64, f64)> {
    (0..n)
        .map(|i| {
            let rho = rho(i);
            let h = elliptic::elliptic_hertz(rho, 1.0);
            let geo = rho.sqrt();
            (h.stiffness_radius_m / geo, h.area_radius_m / geo)
        })
        .collect()
}

/// Table nodes per unit of t = ln(R'/R'').
const TABLE_PER_UNIT: f64 = 128.0;
/// The table's reach in t.
const TABLE_SPAN: f64 = 8.0;

fn radii_table() -> &'static [(f64, f64)] {
    static TABLE: OnceLock<Vec<(f64, f64)>> = OnceLock::new();
    let n = (TABLE_SPAN * TABLE_PER_UNIT) as usize + 1;
    TABLE.get_or_init(|| tabulate(n, |i| (i as f64 / TABLE_PER_UNIT).exp()))
}

/// The common normal of two touching (or near) convex bodies, each a spheroid (a sphere is one
/// with a = c), found from a starting normal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PairGeometry {
    /// Unit normal from body 2 towards body 1 (the direction of the force on body 1).
    pub normal: Vec3,
    /// Overlap along it (m); <= 0 when apart.
    pub overlap_m: f64,
    /// Body 1's surface point deepest into body 2, from body 1's centre (m, world).
    pub arm1: Vec3,
    /// Body 2's surface point deepest into body 1, from body 2's centre (m, world).
    pub arm2: Vec3,
    /// Relative curvature tensor at the contact, in [`tangent_basis`] of `normal` (1/m).
    pub curvature: Tangent2,
    /// Newton iterations taken.
    pub iterations: u32,
}

/// Convergence of [`pair`] (the size of the Newton step, the normal's error) and of
/// `layer::surface::spheroid_hits` (the normal's change in the last iteration), in rad. The
/// overlap is stationary in the normal, so its error is of order R delta^2 (4e-20 m); the contact
/// point's is R delta (4e-11 m).
pub const NORMAL_TOLERANCE: f64 = 1e-9;
/// Iterations after which [`pair`] stops (the last estimate is used; never reached in the tests).
pub const MAX_ITERATIONS: u32 = 32;

/// The common normal and overlap of spheroid 1 (centre `x1`, orientation `r1`) and spheroid 2,
/// from the starting normal `n0` (from 2 to 1; the last step's, or the line of centres).
///
/// Newton's method on u(n) = h1(-n) + h2(n) - n . (x1 - x2) over the unit sphere: with
/// w = (x1 + s1(-n)) - (x2 + s2(n)), the gradient is w's tangential part w_t and the Hessian
/// Rc1 + Rc2 + (w . n) I (the radius-of-curvature tensors; section 4.2 of docs/shape.md), so the
/// step is delta = (Rc1 + Rc2 + (w . n) I)^-1 w_t.
pub fn pair(
    x1: Vec3,
    r1: &Rotation,
    s1: &Spheroid,
    x2: Vec3,
    r2: &Rotation,
    s2: &Spheroid,
    n0: Vec3,
) -> PairGeometry {
    let (m1, m2) = (Matrix::from_quat(*r1), Matrix::from_quat(*r2));
    let d = x1 - x2;
    let mut n = n0;
    let mut iterations = 0;
    loop {
        let p1 = s1.point_with_normal_in(&m1, -n);
        let p2 = s2.point_with_normal_in(&m2, n);
        let w = d + p1.offset - p2.offset;
        let wn = w.dot(n);
        let (e1, e2) = tangent_basis(n);
        let g = (w.dot(e1), w.dot(e2));
        let step = if iterations < MAX_ITERATIONS {
            let hess = p1.radii(e1, e2) + p2.radii(e1, e2) + Tangent2::iso(wn);
            hess.solve(g).filter(|s| s.0.is_finite() && s.1.is_finite())
        } else {
            None
        };
        // Newton's step is the normal's error: below the tolerance, the points at n are the
        // contact's (the overlap is stationary in n: its error is of order R delta^2).
        if let Some((a, b)) = step.filter(|s| s.0.abs().max(s.1.abs()) > NORMAL_TOLERANCE) {
            let delta = e1 * a + e2 * b;
            // Never turn by more than 0.5 rad in one step (a far start).
            let len = delta.length();
            let delta = if len > 0.5 {
                delta * (0.5 / len)
            } else {
                delta
            };
            n = (n + delta).normalize();
            iterations += 1;
            continue;
        }
        return PairGeometry {
            normal: n,
            overlap_m: -wn,
            arm1: p1.offset,
            arm2: p2.offset,
            curvature: p1.curvature(e1, e2) + p2.curvature(e1, e2),
            iterations,
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol * b.abs().max(1e-300)
    }

    #[test]
    fn pole_and_cheek_radii() {
        // 80 mm x 72 mm apple: a = 40 mm, c = 36 mm. Pole: a^2/c = 44.44 mm both ways; cheek:
        // c^2/a = 32.4 mm along the meridian, a = 40 mm along the equator.
        let s = Spheroid::new(0.040, 0.036);
        let id = Rotation::IDENTITY;
        let pole = s.point_with_normal(&id, Vec3::Z);
        assert!(close(pole.r_meridian_m, 0.04 * 0.04 / 0.036, 1e-14));
        assert!(close(pole.r_parallel_m, 0.04 * 0.04 / 0.036, 1e-14));
        assert!(close(pole.offset.z, 0.036, 1e-14));
        let cheek = s.point_with_normal(&id, Vec3::X);
        assert!(close(cheek.r_meridian_m, 0.036 * 0.036 / 0.04, 1e-14));
        assert!(close(cheek.r_parallel_m, 0.04, 1e-14));
        assert!(close(cheek.offset.x, 0.04, 1e-14));
        assert!(cheek.meridian.dot(Vec3::Z).abs() > 1.0 - 1e-14);
    }

    #[test]
    fn the_point_lies_on_the_surface_with_that_normal() {
        let s = Spheroid::new(0.04, 0.03);
        let rot = Rotation::from_scaled_axis(Vec3::new(0.3, -0.7, 0.2));
        let l = Vec3::new(0.2, 0.5, -0.8).normalize();
        let p = s.point_with_normal(&rot, l);
        let b = rot.inverse() * p.offset;
        let on = b.x * b.x / 0.0016 + b.y * b.y / 0.0016 + b.z * b.z / 0.0009;
        assert!((on - 1.0).abs() < 1e-14);
        // The implicit function's gradient is along l.
        let grad = rot * Vec3::new(b.x / 0.0016, b.y / 0.0016, b.z / 0.0009);
        assert!((grad.normalize() - l).length() < 1e-14);
        assert!(close(p.support_m, p.offset.dot(l), 1e-14));
    }

    #[test]
    fn meridian_curvature_matches_a_finite_difference() {
        // The meridian's radius of curvature: ds/dphi along the ellipse x = a sin t, z = c cos t.
        let (a, c) = (0.04, 0.03);
        let s = Spheroid::new(a, c);
        let id = Rotation::IDENTITY;
        for phi in [0.2_f64, 0.7, 1.2] {
            let l = |p: f64| Vec3::new(p.sin(), 0.0, p.cos());
            let h = 1e-6;
            let ds = (s.point_with_normal(&id, l(phi + h)).offset
                - s.point_with_normal(&id, l(phi - h)).offset)
                .length()
                / (2.0 * h);
            let p = s.point_with_normal(&id, l(phi));
            assert!(
                close(p.r_meridian_m, ds, 1e-8),
                "{phi}: {} {ds}",
                p.r_meridian_m
            );
            // The parallel's: distance along the normal to the axis.
            let x = p.offset.x;
            assert!(close(p.r_parallel_m, x / phi.sin(), 1e-12));
        }
    }

    #[test]
    fn table_matches_the_exact_solve() {
        let mut worst: f64 = 0.0;
        for i in 0..400 {
            let rho = 1.0 + 0.0137 * i as f64 * (1.0 + 0.05 * i as f64);
            let (rk, ra) = elliptic_radii(0.04 * rho, 0.04);
            let h = elliptic::elliptic_hertz(0.04 * rho, 0.04);
            let e = (rk / h.stiffness_radius_m - 1.0)
                .abs()
                .max((ra / h.area_radius_m - 1.0).abs());
            worst = worst.max(e);
        }
        assert!(worst < 1e-10, "worst {worst:e}");
        assert_eq!(elliptic_radii(0.04, 0.04), (0.04, 0.04));
    }

    #[test]
    fn two_spheres_are_the_line_of_centres() {
        let s = Spheroid::new(0.04, 0.04);
        let id = Rotation::IDENTITY;
        let x1 = Vec3::new(0.01, 0.02, 0.075);
        let g = pair(x1, &id, &s, Vec3::ZERO, &id, &s, Vec3::Z);
        assert!((g.normal - x1.normalize()).length() < 1e-14);
        assert!(close(g.overlap_m, 0.08 - x1.length(), 1e-12));
        let (lo, hi) = g.curvature.eigen();
        assert!(close(lo, 50.0, 1e-12) && close(hi, 50.0, 1e-12));
    }

    #[test]
    fn tilted_spheroids_meet_on_a_common_normal() {
        let s1 = Spheroid::new(0.04, 0.033);
        let s2 = Spheroid::new(0.038, 0.045);
        let r1 = Rotation::from_scaled_axis(Vec3::new(0.4, 0.1, -0.3));
        let r2 = Rotation::from_scaled_axis(Vec3::new(-0.2, 0.9, 0.5));
        let x1 = Vec3::new(0.012, -0.005, 0.074);
        let g = pair(x1, &r1, &s1, Vec3::ZERO, &r2, &s2, x1.normalize());
        assert!(g.iterations < 10, "{} iterations", g.iterations);
        // Both points have normal +-n, and the segment between them is along n.
        let w = (x1 + g.arm1) - g.arm2;
        // To the search's tolerance: its last Newton step, below NORMAL_TOLERANCE rad, times
        // the radii of curvature (< 0.1 m).
        let off = w.cross(g.normal).length();
        assert!(off < NORMAL_TOLERANCE * 0.1, "{off:e}");
        // The overlap is the minimum of u(n): nearby normals give more.
        let u = |n: Vec3| {
            s1.point_with_normal(&r1, -n).support_m + s2.point_with_normal(&r2, n).support_m
                - n.dot(x1)
        };
        assert!(close(u(g.normal), g.overlap_m, 1e-12));
        for dn in [Vec3::X, Vec3::Y, Vec3::Z, -Vec3::X] {
            let m = (g.normal + dn * 1e-3).normalize();
            assert!(u(m) > g.overlap_m);
        }
        assert!(g.overlap_m.abs() < 0.01, "{}", g.overlap_m);
    }
}
