//! Hertz normal force (paper eqs. 1 and 3, physics.md section 2).
//!
//! P = k u^(3/2) with k = 4/3 E* sqrt(R*), R* = 1 / (K1 + K2). The paper's eq. 1 written with
//! q1, q2 is exactly this law; its eq. 4 is a factor pi off (erratum 1) and is not used.

/// Effective radius R* = 1 / (K1 + K2) from the curvatures at the contact point.
///
/// K = 1/R for a convex sphere, 0 for a flat, -1/R_s for a concave surface of radius R_s.
/// Returns `None` for a conforming contact (K1 + K2 <= 0), where Hertz theory does not apply.
pub fn effective_radius(k1: f64, k2: f64) -> Option<f64> {
    let sum = k1 + k2;
    if sum > 0.0 && sum.is_finite() {
        Some(1.0 / sum)
    } else {
        None
    }
}

/// Hertz stiffness k = 4/3 E* sqrt(R*) in N/m^(3/2).
pub fn stiffness(e_star_pa: f64, r_star_m: f64) -> f64 {
    4.0 / 3.0 * e_star_pa * r_star_m.sqrt()
}

/// Elastic Hertz force k u^(3/2) for overlap u (m); zero when the bodies do not overlap.
pub fn hertz_force(k: f64, u_m: f64) -> f64 {
    if u_m > 0.0 {
        hertz_force_and_root(k, u_m).0
    } else {
        0.0
    }
}

/// Hertz force k u^(3/2) and sqrt(u) for an overlap u >= 0: the contact law needs the root again
/// for the contact radius sqrt(R*) sqrt(u) and the stored energy, so it is taken once.
#[inline]
pub fn hertz_force_and_root(k: f64, u_m: f64) -> (f64, f64) {
    let sqrt_u = u_m.sqrt();
    (k * u_m * sqrt_u, sqrt_u)
}

/// Contact radius a = sqrt(R* u) (eq. 1 with P eliminated).
pub fn contact_radius(r_star_m: f64, u_m: f64) -> f64 {
    if u_m > 0.0 {
        (r_star_m * u_m).sqrt()
    } else {
        0.0
    }
}

/// Mean contact pressure P / (pi a^2); the peak (centre) pressure is 1.5 times this.
pub fn mean_pressure(force_n: f64, a_m: f64) -> f64 {
    if a_m > 0.0 {
        force_n / (std::f64::consts::PI * a_m * a_m)
    } else {
        0.0
    }
}

/// Elastic energy stored at overlap u: integral of k u^(3/2) du = 2/5 k u^(5/2).
pub fn elastic_energy(k: f64, u_m: f64) -> f64 {
    if u_m > 0.0 {
        0.4 * k * u_m * u_m * u_m.sqrt()
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn radius_rules() {
        assert_eq!(effective_radius(1.0 / 0.04, 0.0), Some(0.04));
        let two = effective_radius(25.0, 25.0).unwrap();
        assert!((two - 0.02).abs() < 1e-15);
        // Apple R = 40 mm inside a cup of R_s = 60 mm: R* = 1/(1/0.04 - 1/0.06) = 0.12 m.
        let cup = effective_radius(25.0, -1.0 / 0.06).unwrap();
        assert!((cup - 0.12).abs() < 1e-12);
        assert_eq!(effective_radius(25.0, -25.0), None);
        assert_eq!(effective_radius(25.0, -30.0), None);
    }

    #[test]
    fn hertz_is_eq1() {
        // Eq. 1: u = (9 pi^2 P^2 (q1+q2)^2 (R1+R2) / (16 R1 R2))^(1/3). Invert it for one case.
        let (e_star, r_star) = (2.6829e6, 0.04);
        let k = stiffness(e_star, r_star);
        let u = 1e-3;
        let p = hertz_force(k, u);
        let q_sum = 1.0 / (std::f64::consts::PI * e_star);
        let u_eq1 = (9.0 * std::f64::consts::PI.powi(2) * p * p * q_sum * q_sum / (16.0 * r_star))
            .powf(1.0 / 3.0);
        assert!((u_eq1 - u).abs() / u < 1e-12);
        let a_eq1 = (3.0 * std::f64::consts::PI * p * q_sum * r_star / 4.0).powf(1.0 / 3.0);
        assert!((a_eq1 - contact_radius(r_star, u)).abs() / a_eq1 < 1e-12);
        assert_eq!(hertz_force(k, -1e-3), 0.0);
        assert_eq!(hertz_force(k, 0.0), 0.0);
    }

    #[test]
    fn energy_is_integral_of_force() {
        let k = 7.1545e5;
        let (n, u_end) = (100_000, 2e-3);
        let du = u_end / n as f64;
        let w: f64 = (0..n)
            .map(|i| hertz_force(k, (i as f64 + 0.5) * du) * du)
            .sum();
        assert!((w - elastic_energy(k, u_end)).abs() / w < 1e-8);
    }
}
