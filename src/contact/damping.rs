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

/// The eq. 12 normal force for an elastic Hertz force `hertz_n`, with the rate-dependent part
/// bounded for explicit stepping.
///
/// Eq. 12 splits into a static part H (1 + ke)/2 and a rate part H (1 - ke)/2 tanh(lambda du/dt).
/// Near du/dt = 0 the rate part is a damper of coefficient (1 - ke)/2 lambda H: for an apple at the
/// bottom of a pile (H ~ 150 N, lambda = 1000 s/m) that is ~7e4 N s/m, and c dt / m ~ 30 at
/// dt = 1e-4 s, far beyond the explicit stability limit (~2): the force flips between ke H and H
/// every step and the pile chatters at several cm/s (measured). The rate part is therefore capped
/// at `rate_cap` |du/dt|, the force that would stop the relative normal motion within about one
/// step (the caller passes a share of m_n / dt). The cap only bites at |du/dt| below
/// (1 - ke)/2 H / rate_cap (about 1 mm/s for the paper's apple at 1e-5 s), so impacts, where
/// lambda v0 >> 1, keep the paper's law; a resting contact settles at the static part, smoothly.
/// Never negative: the result lies between ke H and H.
pub fn hysteresis_force(
    hertz_n: f64,
    ke: f64,
    lambda_s_m: f64,
    du_dt_m_s: f64,
    rate_cap: f64,
) -> f64 {
    if ke == 1.0 {
        return hertz_n;
    }
    let static_part = 0.5 * (1.0 + ke) * hertz_n;
    let mut rate_part = 0.5 * (1.0 - ke) * hertz_n * (lambda_s_m * du_dt_m_s).tanh();
    let bound = rate_cap * du_dt_m_s.abs();
    if rate_part.abs() > bound {
        rate_part = bound * du_dt_m_s.signum();
    }
    (static_part + rate_part).max(0.0)
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
    fn capped_rate_part_only_bites_near_rest() {
        // Fast motion: the cap is far above the paper's force, eq. 12 unchanged.
        let h = 100.0;
        let cap = 0.5 * 0.107 / 1e-5;
        for v in [-1.0, -0.1, 0.1, 1.0] {
            let paper = h * hysteresis_factor(0.09, 1000.0, v);
            assert!((hysteresis_force(h, 0.09, 1000.0, v, cap) - paper).abs() < 1e-9);
        }
        // At rest: the static part (1 + ke)/2 H, reached continuously.
        assert!((hysteresis_force(h, 0.09, 1000.0, 0.0, cap) - 54.5).abs() < 1e-12);
        let tiny = hysteresis_force(h, 0.09, 1000.0, 1e-6, cap);
        assert!((tiny - 54.5 - cap * 1e-6).abs() < 1e-9, "{tiny}");
        // Bounded by ke H and H whatever the cap.
        for v in [-10.0, 10.0] {
            let f = hysteresis_force(h, 0.09, 1000.0, v, f64::INFINITY);
            assert!((9.0 - 1e-9..=100.0 + 1e-9).contains(&f));
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
