//! Elliptical Hertz contact: a sphere on a convex cylinder (an apple on a roller), where the
//! relative curvature differs in the two principal directions and the contact patch is an
//! ellipse.
//!
//! Johnson, *Contact Mechanics* (1985), section 4.2. With the principal relative curvatures
//! A <= B (A + B = (1/R1' + 1/R1'' + 1/R2' + 1/R2'') / 2; for a sphere of radius R1 on a cylinder
//! of radius R2, A = 1/(2 R1) along the cylinder's axis and B = 1/(2 R1) + 1/(2 R2) across it) and
//! R' = 1/(2A) >= R'' = 1/(2B), the semi-axes a >= b of the ellipse, e^2 = 1 - b^2/a^2 and the
//! complete elliptic integrals K(e), E(e) satisfy (Johnson eqs. 4.36-4.39, the pressure
//! p = p0 sqrt(1 - x^2/a^2 - y^2/b^2)):
//!
//! ```text
//! B/A = R'/R'' = ((a/b)^2 E - K) / (K - E)        (fixes e from the geometry alone)
//! A = p0 b (K - E) / (E* e^2 a^2)
//! delta = p0 b K / E*,      P = 2/3 pi a b p0
//! ```
//!
//! e does not depend on the load, so the force is still P = k delta^(3/2) with a constant k:
//! eliminating a, b and p0,
//!
//! ```text
//! k = 4/3 E* sqrt(R_k),   R_k = pi^2 / (4 g sqrt(1 - e^2) K^3),   g = A e^2 / ((K - E) sqrt(1 - e^2))
//! ```
//!
//! and the contact area pi a b = pi R_a delta with R_a = 1 / (g K). Both reduce to R* = R' = R''
//! for a circle (e -> 0). The layer uses R_k as the contact's R*: force, impact time and energy are
//! exact. The law's contact radius sqrt(R_k u) (the Mindlin spring's) is sqrt(R_k/R_a) times the
//! exact sqrt(a b) (1.0064-1.0303 for an apple of 37 mm on rollers of 60-20 mm); the area and
//! pressure the layer reports use R_a ([`EllipticHertz::area_radius_m`],
//! `ContactConstants::area_scale`), so they are the true ellipse's (docs/physics.md section 12).
//!
//! Johnson's shortcut, the equivalent radius R_e = sqrt(R' R'') with correction factors read off
//! his Fig. 4.4, is not used: [`johnson_equivalent_radius`] is kept to state its error (used bare,
//! it makes the stiffness 0.5-2.2 % low for the same apple and rollers).

use std::f64::consts::PI;

/// Complete elliptic integrals of the first and second kind, K(m) and E(m), of parameter
/// m = e^2 in [0, 1), by the arithmetic-geometric mean (Abramowitz and Stegun 17.6): exact to
/// rounding after a handful of iterations.
pub fn elliptic_k_e(m: f64) -> (f64, f64) {
    debug_assert!((0.0..1.0).contains(&m));
    let mut a = 1.0f64;
    let mut b = (1.0 - m).sqrt();
    let mut c = m.sqrt();
    // Sum of 2^(n-1) c_n^2, from n = 0.
    let mut sum = 0.5 * c * c;
    let mut pow = 0.5;
    for _ in 0..40 {
        if c <= 1e-17 * a {
            break;
        }
        let an = 0.5 * (a + b);
        let bn = (a * b).sqrt();
        c = 0.5 * (a - b);
        a = an;
        b = bn;
        pow *= 2.0;
        sum += pow * c * c;
    }
    let k = PI / (2.0 * a);
    (k, k * (1.0 - sum))
}

/// The geometry of one elliptical Hertz contact (independent of the load).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EllipticHertz {
    /// e^2 = 1 - (b/a)^2 of the contact ellipse.
    pub eccentricity_sq: f64,
    /// b/a, the ratio of the semi-axes (<= 1; 1 for a circle).
    pub axis_ratio: f64,
    /// R_k: the radius whose circular Hertz law k = 4/3 E* sqrt(R_k) gives the exact force
    /// P = k delta^(3/2) (m).
    pub stiffness_radius_m: f64,
    /// R_a: the exact contact area is pi a b = pi R_a delta (m).
    pub area_radius_m: f64,
}

/// B/A as a function of the axis ratio x = b/a (m = 1 - x^2).
fn curvature_ratio(x: f64) -> f64 {
    let m = 1.0 - x * x;
    if m <= 0.0 {
        return 1.0;
    }
    let (k, e) = elliptic_k_e(m);
    (e / (x * x) - k) / (k - e)
}

/// The elliptical contact of two bodies whose principal relative radii of curvature are
/// `r_prime` = 1/(2A) and `r_double_prime` = 1/(2B) (any order; both > 0 and finite).
pub fn elliptic_hertz(r_prime: f64, r_double_prime: f64) -> EllipticHertz {
    let (r1, r2) = if r_prime >= r_double_prime {
        (r_prime, r_double_prime)
    } else {
        (r_double_prime, r_prime)
    };
    let rho = r1 / r2;
    if rho <= 1.0 + 1e-14 {
        return EllipticHertz {
            eccentricity_sq: 0.0,
            axis_ratio: 1.0,
            stiffness_radius_m: r1,
            area_radius_m: r1,
        };
    }
    // Solve curvature_ratio(x) = rho for x = b/a in (0, 1): the ratio falls monotonically from
    // infinity (x -> 0) to 1 (x = 1). Bisection on ln x, started from the Brewe-Hamrock estimate
    // a/b ~ rho^(2/pi) (within a few per cent), bracketed by halving/doubling, then refined to
    // rounding: about 60 evaluations of a few AGM steps, only when a contact's geometry changes.
    let guess = rho.powf(-2.0 / PI).min(1.0 - 1e-9);
    let (mut lo, mut hi) = (guess, guess);
    // lo: ratio above rho; hi: ratio below rho.
    while curvature_ratio(lo) <= rho && lo > 1e-12 {
        lo *= 0.5;
    }
    while curvature_ratio(hi) > rho && hi < 1.0 {
        hi = (hi * 2.0).min(1.0);
    }
    for _ in 0..200 {
        let mid = (lo * hi).sqrt();
        if mid <= lo || mid >= hi {
            break;
        }
        if curvature_ratio(mid) > rho {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let x = (lo * hi).sqrt();
    let m = 1.0 - x * x;
    let (k, e) = elliptic_k_e(m);
    let a_curv = 0.5 / r1;
    let g = a_curv * m / ((k - e) * x);
    EllipticHertz {
        eccentricity_sq: m,
        axis_ratio: x,
        stiffness_radius_m: PI * PI / (4.0 * g * x * k * k * k),
        area_radius_m: 1.0 / (g * k),
    }
}

/// A sphere of radius `r_sphere` on the outside of a cylinder of radius `r_cylinder` (axes
/// crossing at right angles to the normal): R' = r_sphere along the axis,
/// R'' = r_sphere r_cylinder / (r_sphere + r_cylinder) across.
///
/// Remembered per thread for each pair of radii (the same bits as solving again): the layer asks
/// for it at every query of an apple near a roller's side, and each solve is a bisection of some
/// 60 evaluations of the elliptic integrals. Solved at every query, it took 87 % of a line with a
/// 35-roller singulator bed (docs/performance.md, "A singulator in the line").
pub fn sphere_on_cylinder(r_sphere: f64, r_cylinder: f64) -> EllipticHertz {
    SOLVED.with(|solved| {
        let key = (r_sphere.to_bits(), r_cylinder.to_bits());
        let mut solved = solved.borrow_mut();
        // The last pair asked first: one apple meets rollers of one radius, query after query,
        // and the map's hashing cost 2 % of a line's busy steps (docs/performance.md).
        if let Some((k, h)) = solved.last {
            if k == key {
                return h;
            }
        }
        if let Some(h) = solved.map.get(&key) {
            let h = *h;
            solved.last = Some((key, h));
            return h;
        }
        if solved.map.len() >= SOLVED_MAX {
            // Many runs in one process (a batch): start again rather than grow without end.
            solved.map.clear();
        }
        let h = elliptic_hertz(r_sphere, r_sphere * r_cylinder / (r_sphere + r_cylinder));
        solved.map.insert(key, h);
        solved.last = Some((key, h));
        h
    })
}

/// Pairs of radii [`sphere_on_cylinder`] remembers per thread (an apple's radius each, times the
/// rollers' few radii).
const SOLVED_MAX: usize = 1 << 16;

/// The ellipses solved on one thread, keyed by the bits of (sphere radius, cylinder radius), and
/// the last one asked for.
#[derive(Default)]
struct Solved {
    last: Option<((u64, u64), EllipticHertz)>,
    map: std::collections::HashMap<(u64, u64), EllipticHertz, BitsHash>,
}

/// A multiply-rotate hash of the keys' bits (the scheme of rustc's FxHash) instead of the
/// standard SipHash, which guards maps against chosen keys: these keys are radii, and on a line
/// every apple of its own radius meets the rollers, so that most queries miss `Solved::last` and
/// hash (SipHash: 1.6 % of the 1000-apple line's late steps, docs/performance.md).
#[derive(Default, Clone, Copy)]
struct BitsHash;

impl std::hash::BuildHasher for BitsHash {
    type Hasher = BitsHasher;
    fn build_hasher(&self) -> BitsHasher {
        BitsHasher(0)
    }
}

/// See [`BitsHash`].
struct BitsHasher(u64);

impl std::hash::Hasher for BitsHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(u64::from(b));
        }
    }
    fn write_u64(&mut self, x: u64) {
        self.0 = (self.0.rotate_left(5) ^ x).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
}

thread_local! {
    static SOLVED: std::cell::RefCell<Solved> = std::cell::RefCell::new(Solved::default());
}

/// Johnson's equivalent radius R_e = sqrt(R' R'') (section 4.2), before his correction factors:
/// kept to state the error of using it bare (docs/physics.md section 12).
pub fn johnson_equivalent_radius(r_prime: f64, r_double_prime: f64) -> f64 {
    (r_prime * r_double_prime).sqrt()
}

/// The curvature K2 the layer gives a sphere-on-cylinder contact, so that its effective radius
/// 1/(1/R + K2) ([`super::normal::effective_radius`]) is the elliptic law's R_k (1/m).
pub fn cylinder_equivalent_curvature(r_sphere: f64, r_cylinder: f64) -> f64 {
    1.0 / sphere_on_cylinder(r_sphere, r_cylinder).stiffness_radius_m - 1.0 / r_sphere
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_remembered_ellipse_is_the_solved_one() {
        // Regression (docs/performance.md, "A singulator in the line"): the ellipse of an apple
        // on a roller was solved again at every query. Remembered, it is the same, bit for bit,
        // at the first call and after, for each pair of radii.
        for (r, rr) in [(0.0375, 0.03), (0.04, 0.03), (0.0375, 0.02)] {
            let solved = elliptic_hertz(r, r * rr / (r + rr));
            assert_eq!(sphere_on_cylinder(r, rr), solved);
            assert_eq!(sphere_on_cylinder(r, rr), solved);
            SOLVED.with(|s| assert!(s.borrow().map.contains_key(&(r.to_bits(), rr.to_bits()))));
        }
    }

    #[test]
    fn elliptic_integrals_match_tables() {
        // Abramowitz and Stegun table 17.1 (m = sin^2 alpha): K(0.5) = 1.8540746773013719,
        // E(0.5) = 1.3506438810476755; K(0) = E(0) = pi/2; K(0.9) = 2.5780921133481733,
        // E(0.9) = 1.1047747327040733.
        let (k, e) = elliptic_k_e(0.5);
        assert!((k - 1.854_074_677_301_371_9).abs() < 1e-15);
        assert!((e - 1.350_643_881_047_675_5).abs() < 1e-15);
        let (k, e) = elliptic_k_e(0.0);
        assert_eq!((k, e), (PI / 2.0, PI / 2.0));
        let (k, e) = elliptic_k_e(0.9);
        assert!((k - 2.578_092_113_348_173_3).abs() < 1e-14);
        assert!((e - 1.104_774_732_704_073_3).abs() < 1e-14);
    }

    #[test]
    fn circle_is_the_sphere_law() {
        let h = elliptic_hertz(0.04, 0.04);
        assert_eq!(h.stiffness_radius_m, 0.04);
        // Nearly circular: continuous with it.
        let h = elliptic_hertz(0.04, 0.04 * (1.0 - 1e-6));
        assert!((h.stiffness_radius_m / 0.04 - 1.0).abs() < 1e-6);
        assert!((h.area_radius_m / 0.04 - 1.0).abs() < 1e-6);
        assert!(h.axis_ratio > 0.999_999);
    }

    #[test]
    fn the_ellipse_satisfies_hertz() {
        // Rebuild a, b, p0 at a load and check Johnson's three equations.
        let (r1, r2) = (0.037, 0.02);
        let h = sphere_on_cylinder(r1, r2);
        let (ca, cb) = (0.5 / r1, 0.5 / r1 + 0.5 / r2);
        let e_star = 2.0e6;
        let delta: f64 = 1e-3;
        let p = 4.0 / 3.0 * e_star * h.stiffness_radius_m.sqrt() * delta.powf(1.5);
        let m = h.eccentricity_sq;
        let (k, e) = elliptic_k_e(m);
        // pi a b = pi R_a delta, b = x a.
        let a = (h.area_radius_m * delta / h.axis_ratio).sqrt();
        let b = h.axis_ratio * a;
        let p0 = 1.5 * p / (PI * a * b);
        assert!((p0 * b * k / e_star - delta).abs() / delta < 1e-12);
        let a_back = p0 * b * (k - e) / (e_star * m * a * a);
        assert!((a_back - ca).abs() / ca < 1e-12);
        let b_back = p0 * b * (a * a / (b * b) * e - k) / (e_star * m * a * a);
        assert!((b_back - cb).abs() / cb < 1e-12);
    }

    #[test]
    fn johnson_equivalent_radius_error_for_apples_on_rollers() {
        // Apple 37 mm on rollers 20-60 mm: R_k against sqrt(R' R''), and the area radius.
        for (r2, k_ratio, a_ratio) in [
            (0.020, 1.022771, 1.030253),
            (0.030, 1.013421, 1.017856),
            (0.040, 1.008923, 1.011880),
            (0.060, 1.004804, 1.006400),
        ] {
            let h = sphere_on_cylinder(0.037, r2);
            let re = johnson_equivalent_radius(0.037, 0.037 * r2 / (0.037 + r2));
            let got = (h.stiffness_radius_m / re).sqrt();
            assert!((got - k_ratio).abs() < 1e-5, "{r2}: k ratio {got}");
            let got_a = (h.stiffness_radius_m / h.area_radius_m).sqrt();
            assert!((got_a - a_ratio).abs() < 1e-5, "{r2}: a ratio {got_a}");
        }
    }
}
