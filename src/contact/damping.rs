//! Hysteretic energy loss, paper eq. 12 with the dissipative sign (physics.md section 3).
//!
//! P(u, du/dt) = P_hertz(u) [1 + ke + (1 - ke) tanh(lambda du/dt)] / 2, du/dt > 0 approaching.
//! Loading follows the elastic curve, unloading the curve scaled by ke, so the stored energy comes
//! back multiplied by ke and e -> sqrt(ke) when lambda v0 >> 1. The paper prints tanh(-lambda du/dt),
//! which creates energy (e = 1/sqrt(ke), erratum 4); never use it.

/// The eq. 12 factor multiplying the Hertz force. Lies in [min(ke,1), max(ke,1)], never negative.
///
/// `du_dt_m_s` is the rate of overlap (> 0 while the bodies approach). `ke = 1` is elastic.
pub fn hysteresis_factor(ke: f64, lambda_s_m: f64, du_dt_m_s: f64) -> f64 {
    if ke == 1.0 {
        return 1.0;
    }
    let f = 0.5 * (1.0 + ke + (1.0 - ke) * (lambda_s_m * du_dt_m_s).tanh());
    f.max(0.0)
}

/// Restitution in the limit lambda v0 >> 1: e = sqrt(ke).
pub fn restitution_limit(ke: f64) -> f64 {
    ke.sqrt()
}

/// Contact time with hysteresis in the limit lambda v0 >> 1: t_c = t_H / 2 (1 + 1/sqrt(ke)).
pub fn contact_time_limit(t_hertz_s: f64, ke: f64) -> f64 {
    0.5 * t_hertz_s * (1.0 + 1.0 / ke.sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn factor_limits() {
        assert_eq!(hysteresis_factor(1.0, 100.0, -5.0), 1.0);
        // Fast loading: plain Hertz; fast unloading: ke times Hertz.
        assert!((hysteresis_factor(0.09, 1000.0, 1.0) - 1.0).abs() < 1e-12);
        assert!((hysteresis_factor(0.09, 1000.0, -1.0) - 0.09).abs() < 1e-12);
        // At the turning point (du/dt = 0) the factor is (1 + ke) / 2.
        assert!((hysteresis_factor(0.25, 10.0, 0.0) - 0.625).abs() < 1e-15);
        for &v in &[-10.0, -0.1, 0.0, 0.1, 10.0] {
            let f = hysteresis_factor(0.0, 50.0, v);
            assert!((0.0..=1.0).contains(&f));
        }
    }

    #[test]
    fn dissipative_sign() {
        // Unloading (du/dt < 0) must give less force than loading at the same overlap.
        let load = hysteresis_factor(0.3, 20.0, 0.2);
        let unload = hysteresis_factor(0.3, 20.0, -0.2);
        assert!(unload < load);
    }
}
