//! Elliptic Hertz contact of a sphere on a cylinder (docs/physics.md 12.3; Johnson, Contact
//! Mechanics, 1985, section 4.2), written here from the formulas and computed another way than
//! the crate's `contact::elliptic` (whose integrals are AGM iterations): the complete elliptic
//! integrals by the trapezoidal rule, which converges geometrically for these smooth periodic
//! integrands. A reference for the tests, calling nothing of the crate.

use std::f64::consts::PI;

/// Complete elliptic integrals K(m) and E(m) of the parameter m = e^2 < 1:
/// K = int_0^{pi/2} (1 - m sin^2 t)^(-1/2) dt, E = int_0^{pi/2} (1 - m sin^2 t)^(1/2) dt, by the
/// trapezoidal rule on 2000 intervals (the integrands are even and pi-periodic in t: the rule
/// is exact to rounding for m up to 0.9).
pub fn k_e(m: f64) -> (f64, f64) {
    assert!((0.0..0.9).contains(&m), "m = {m}");
    let n = 2000;
    let h = 0.5 * PI / n as f64;
    let (mut k, mut e) = (0.0, 0.0);
    for i in 0..=n {
        let w = if i == 0 || i == n { 0.5 } else { 1.0 };
        let s = (i as f64 * h).sin();
        let q = 1.0 - m * s * s;
        k += w / q.sqrt();
        e += w * q.sqrt();
    }
    (k * h, e * h)
}

/// The contact of principal relative radii R' >= R'' (relative curvatures A = 1/(2R'),
/// B = 1/(2R'')).
#[derive(Debug, Clone, Copy)]
pub struct Ellipse {
    /// Axis ratio b/a of the contact ellipse.
    pub axis_ratio: f64,
    /// R_k: the radius of the equivalent sphere, P = 4/3 E* sqrt(R_k) delta^(3/2).
    pub stiffness_radius_m: f64,
    /// R_a: the true area pi a b = pi R_a delta.
    pub area_radius_m: f64,
}

/// Solves Johnson's R'/R'' = ((a/b)^2 E(e) - K(e)) / (K(e) - E(e)) for b/a by bisection (the
/// right side falls as b/a grows), then g = A e^2 / ((K - E) sqrt(1 - e^2)),
/// R_k = pi^2 / (4 g sqrt(1 - e^2) K^3), R_a = 1 / (g K) (docs/physics.md 12.3).
pub fn ellipse(r1: f64, r2: f64) -> Ellipse {
    assert!(r1 > r2 && r2 > 0.0);
    let ratio = |x: f64| {
        let (k, e) = k_e(1.0 - x * x);
        (e / (x * x) - k) / (k - e)
    };
    let (mut lo, mut hi) = (0.35, 1.0 - 1e-9);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if ratio(mid) > r1 / r2 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let x = 0.5 * (lo + hi);
    let m = 1.0 - x * x;
    let (k, e) = k_e(m);
    let g = (0.5 / r1) * m / ((k - e) * x);
    Ellipse {
        axis_ratio: x,
        stiffness_radius_m: PI * PI / (4.0 * g * x * k.powi(3)),
        area_radius_m: 1.0 / (g * k),
    }
}

/// A sphere of radius R on the side of a cylinder of radius R_c: R' = R (along the axis),
/// R'' = R R_c / (R + R_c).
pub fn sphere_on_cylinder(r: f64, r_c: f64) -> Ellipse {
    ellipse(r, r * r_c / (r + r_c))
}

/// The semi-axes a >= b of the contact ellipse under the load P (Johnson 4.2):
/// A = 1/(2R') = 3 P (K - E) / (2 pi E* e^2 a^3), b = (b/a) a.
pub fn semi_axes(r1: f64, r2: f64, e_star: f64, p: f64) -> (f64, f64) {
    let x = ellipse(r1, r2).axis_ratio;
    let m = 1.0 - x * x;
    let (k, e) = k_e(m);
    let a = (3.0 * p * (k - e) / (2.0 * PI * e_star * m * (0.5 / r1))).cbrt();
    (a, x * a)
}

/// Johnson's equivalent radius sqrt(R' R'') (without his correction factors).
pub fn equivalent_radius(r1: f64, r2: f64) -> f64 {
    (r1 * r2).sqrt()
}
