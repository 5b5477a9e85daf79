//! Eq. 13 pulse fit (physics.md section 7, issue 4 acceptance): the fit of an elastic Hertz
//! impact gives k_P within 0.5 % of 0.5436, tau within 0.02 of 0.5 and eps in [1.8, 2.1].
//!
//! Measured (dt = 1e-5 s, no gravity, Fig. 1 apple on steel): eps = 1.9027, tau = 0.4931 and
//! k_P = 0.54141 (-0.41 %) at both 0.2 and 1.4 m/s. eq. 13 is not the Hertz curve (which rises as
//! t^1.5 at touch), so the least-squares optimum is slightly asymmetric: (eps, tau) and its mirror
//! image (eps (1 - tau) / tau, 1 - tau) fit a symmetric pulse equally well.

use crate::common;
use applesim::analysis::{self, pulse};
use applesim::contact::theory::ELASTIC_PULSE_COEFFICIENT;
use common::*;

fn elastic_fit(v0: f64) -> pulse::PulseFit {
    let mut sc = shipped("scenarios/drop_on_steel.json");
    sc.gravity_m_s2 = [0.0, 0.0, 0.0];
    sc.apples[0].velocity_m_s = [0.0, 0.0, -v0];
    sc.output.force_history = Some(true.into());
    let (r, _) = run(&sc);
    let a = analysis::analyse(&sc, &r);
    assert_eq!(a.pulse_fits.len(), 1, "one impact fitted");
    a.pulse_fits[0].clone()
}

fn check_elastic(v0: f64) {
    let f = elastic_fit(v0);
    println!(
        "v0 = {v0}: P_max {:.4} N (measured {:.4}), t_k {:.4} ms (measured {:.4}), eps {:.4}, tau {:.4}, k_P {:.5} (shape {:.5}), rms {:.4} N, {} samples",
        f.fit_peak_force_n,
        f.peak_force_n,
        f.fit_contact_time_s * 1e3,
        f.contact_time_s * 1e3,
        f.fit_eps,
        f.fit_tau,
        f.k_p,
        f.k_p_shape,
        f.rms_residual_n,
        f.samples
    );
    assert!(f.converged);
    assert_rel("k_P", f.k_p, ELASTIC_PULSE_COEFFICIENT, 0.005);
    assert!((f.fit_tau - 0.5).abs() <= 0.02, "tau = {}", f.fit_tau);
    assert!((1.8..=2.1).contains(&f.fit_eps), "eps = {}", f.fit_eps);
    // docs/analysis.md's table (golden values of the fit at their printed digits): eps 1.903,
    // tau 0.493, k_P 0.5414 (-0.41 % from the closed form 0.5436, checked at twice that), k_P
    // measured 0.5436, rms 0.64 % of the peak, eq. 15 error 0.0 %.
    assert!((f.fit_eps - 1.903).abs() <= 1e-3, "eps {}", f.fit_eps);
    assert!((f.fit_tau - 0.493).abs() <= 1e-3, "tau {}", f.fit_tau);
    assert!((f.k_p - 0.5414).abs() <= 1e-4, "k_P {}", f.k_p);
    assert_rel(
        "k_P against 0.5436121",
        f.k_p,
        ELASTIC_PULSE_COEFFICIENT,
        2.0 * 0.41e-2,
    );
    assert!(
        (f.k_p_measured - 0.5436).abs() <= 1e-4,
        "k_P measured {}",
        f.k_p_measured
    );
    assert!((100.0 * f.rms_residual_n / f.peak_force_n - 0.64).abs() <= 0.01);
    assert!((100.0 * (f.eq15_peak_force_n / f.peak_force_n - 1.0)).abs() <= 0.1);
    // The fitted curve stays within 1 % of the peak force everywhere on average.
    assert!(
        f.rms_residual_n < 0.01 * f.peak_force_n,
        "rms {}",
        f.rms_residual_n
    );
    // Eq. 15 with the elastic k_P and the measured contact time and restitution gives back the
    // measured peak force (k_P is defined from this very impact: physics.md section 4).
    assert_rel(
        "eq. 15 peak force",
        f.eq15_peak_force_n,
        f.peak_force_n,
        0.005,
    );
}

#[test]
fn elastic_impact_at_1_4_m_s() {
    check_elastic(1.4);
}

#[test]
fn elastic_impact_at_0_2_m_s() {
    check_elastic(0.2);
}

#[test]
fn dissipative_impacts_are_skewed_and_eq15_needs_their_own_k_p() {
    // ke = 0.09 at lambda v0 = 2 and 5: the unloading is slower than the loading, so the pulse
    // peaks early (tau < 0.5; 1 / (1 + 1/sqrt(ke)) = 0.23 in the lambda v0 >> 1 limit,
    // physics.md section 3) and its area is a smaller share of P_max t_c than an elastic one's.
    // Measured: tau 0.221 and 0.179, k_P (measured) 0.369 and 0.255; eq. 15 with the elastic
    // 0.5436 then underestimates the peak force by 32 % and 53 %. eq. 13 describes these pulses
    // only roughly (rms residual 4 % and 6 % of the peak; t_k ends on its bound, 1.25 times the
    // contact time), which is why the analysis reports k_P measured beside the fit.
    for lambda in [2.0, 5.0] {
        let mut sc = shipped("scenarios/drop_on_steel.json");
        sc.gravity_m_s2 = [0.0, 0.0, 0.0];
        sc.apples[0].velocity_m_s = [0.0, 0.0, -1.0];
        sc.contact.ke = Some(0.09);
        sc.contact.lambda_s_m = Some(lambda);
        let (r, _) = run(&sc);
        let a = analysis::analyse(&sc, &r);
        let f = &a.pulse_fits[0];
        println!(
            "lambda v0 = {lambda}: eps {:.3}, tau {:.3}, t_k {:.3} ms (contact {:.3} ms), rms {:.2} N of {:.2} N, k_P fit {:.4}, measured {:.4}, eq. 15 {:.2} N",
            f.fit_eps,
            f.fit_tau,
            f.fit_contact_time_s * 1e3,
            f.contact_time_s * 1e3,
            f.rms_residual_n,
            f.peak_force_n,
            f.k_p,
            f.k_p_measured,
            f.eq15_peak_force_n
        );
        assert!(f.fit_tau < 0.35, "tau {}", f.fit_tau);
        // No gravity: the impulse is exactly m v0 (1 + e), so k_P measured makes eq. 14 exact.
        let impulse = f.effective_mass_kg * 1.0 * (1.0 + f.restitution);
        assert_rel(
            "eq. 14 with k_P measured",
            f.k_p_measured * f.peak_force_n * f.contact_time_s,
            impulse,
            1e-3,
        );
        assert!(f.k_p_measured < 0.45, "k_P measured {}", f.k_p_measured);
        assert!(f.eq15_peak_force_n < 0.8 * f.peak_force_n);
        // docs/analysis.md's table (golden values at their printed digits): eps, tau, k_P (fit),
        // k_P measured, rms / peak (%), eq. 15 error (%).
        let (eps, tau, kp, kpm, rms, eq15) = if lambda == 2.0 {
            (2.33, 0.221, 0.315, 0.369, 4.1, -32.0)
        } else {
            (3.90, 0.179, 0.220, 0.255, 5.8, -53.0)
        };
        assert!((f.fit_eps - eps).abs() <= 0.01, "eps {}", f.fit_eps);
        assert!((f.fit_tau - tau).abs() <= 1e-3, "tau {}", f.fit_tau);
        assert!((f.k_p - kp).abs() <= 1e-3, "k_P {}", f.k_p);
        assert!(
            (f.k_p_measured - kpm).abs() <= 1e-3,
            "k_P measured {}",
            f.k_p_measured
        );
        assert!((100.0 * f.rms_residual_n / f.peak_force_n - rms).abs() <= 0.1);
        assert!((100.0 * (f.eq15_peak_force_n / f.peak_force_n - 1.0) - eq15).abs() <= 1.0);
    }
}

#[test]
fn contacts_that_start_at_rest_are_not_fitted() {
    // slip_to_roll: the apple rests on the plate from t = 0: no impact, no pulse.
    let sc = shipped("scenarios/slip_to_roll.json");
    let (r, _) = run(&sc);
    assert!(!r.events.is_empty());
    let a = analysis::analyse(&sc, &r);
    assert!(a.pulse_fits.is_empty());
}
