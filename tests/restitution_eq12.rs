//! Eq. 12 with the dissipative sign (physics.md section 3): restitution never exceeds 1, depends
//! only on ke and lambda v0 without gravity, and matches the integrated table of physics.md.

use crate::common;
use common::*;

fn restitution(ke: f64, lambda: f64, v0: f64, dt: f64) -> f64 {
    let mut sc = shipped("scenarios/drop_on_steel.json");
    sc.gravity_m_s2 = [0.0, 0.0, 0.0];
    sc.apples[0].velocity_m_s = [0.0, 0.0, -v0];
    sc.contact.ke = Some(ke);
    sc.contact.lambda_s_m = Some(lambda);
    sc.time_step_s = dt.into();
    // Unloading lasts up to 1/sqrt(ke) times the loading (physics.md section 3): run long enough.
    let t_h = 0.0083 * (0.2 / v0).powf(0.2);
    sc.duration_s = (1.5 * t_h * (1.0 + 1.0 / ke.sqrt())).max(0.03);
    sc.output.sample_interval_s = Some(0.01);
    // With ke -> 0 the apple backs out of the contact at a few mm/s: below the sleep threshold.
    sc.model.sleep.enabled = false;
    let (r, _) = run(&sc);
    let e = &r.events[0];
    assert!(
        e.t_end_s.is_some(),
        "apple left the plate (ke {ke}, lambda {lambda}, v0 {v0})"
    );
    e.restitution.unwrap()
}

#[test]
fn restitution_never_exceeds_one() {
    let mut worst: f64 = 0.0;
    for &ke in &[1e-4, 0.01, 0.09, 0.25, 0.5, 0.9, 1.0] {
        for &lambda in &[0.1, 1.0, 10.0, 100.0, 1e3, 1e4] {
            for &v0 in &[0.2, 1.4] {
                let e = restitution(ke, lambda, v0, 5e-5);
                worst = worst.max(e);
                // ke = 1 is elastic: e = 1 up to the integration error of the rebound, about 1e-6
                // at 165 steps per contact (symplectic Euler, physics.md section 10).
                assert!(
                    e <= 1.0 + 1e-5,
                    "e = {e} > 1 at ke {ke}, lambda {lambda}, v0 {v0}"
                );
                if ke < 1.0 {
                    assert!(e < 1.0, "dissipative ke {ke} gave e = {e}");
                }
            }
        }
    }
    println!("largest restitution over 84 cases: {worst}");
}

#[test]
fn matches_physics_md_table() {
    // (lambda v0, ke, e) from physics.md section 3; the table has three digits.
    let table = [
        (1.0, 1e-6, 0.620),
        (2.0, 1e-6, 0.477),
        (5.0, 1e-6, 0.308),
        (10.0, 1e-6, 0.206),
        (20.0, 1e-6, 0.131),
        (100.0, 1e-6, 0.040),
        (1.0, 0.09, 0.664),
        (2.0, 0.09, 0.534),
        (5.0, 0.09, 0.394),
        (10.0, 0.09, 0.332),
        (20.0, 0.09, 0.309),
        (100.0, 0.09, 0.300),
        (1.0, 0.25, 0.738),
        (2.0, 0.25, 0.631),
        (5.0, 0.25, 0.536),
        (10.0, 0.25, 0.510),
        (20.0, 0.25, 0.502),
        (100.0, 0.25, 0.500),
    ];
    // Each entry's runs are independent: computed on rayon's pool (two cores halve this test's
    // 25 s), then checked in the table's order.
    use rayon::prelude::*;
    let results: Vec<([f64; 2], f64)> = table
        .par_iter()
        .map(|&(lv, ke, _)| {
            // Same lambda v0 at two speeds: scale-free.
            let sim = [0.5, 1.0].map(|v0| restitution(ke, lv / v0, v0, 1e-5));
            // The table itself against the independent RK4 (tests/common/ode.rs, 50 000 steps
            // per elastic contact time, no gravity).
            let s = common::ode::Setup {
                mass_kg: 0.107,
                k: common::ode::fig1_k(),
                r_star_m: 0.04,
                ke,
                lambda_s_m: lv,
                g_n: 0.0,
            };
            (sim, s.impact_with(1.0, 5.0e4, 10.0).rebound_m_s.unwrap())
        })
        .collect();
    let mut worst: f64 = 0.0;
    for (&(lv, ke, want), (sim, rk4)) in table.iter().zip(&results) {
        for (v0, e) in [0.5, 1.0].into_iter().zip(*sim) {
            println!("lambda v0 = {lv}, ke = {ke}, v0 = {v0}: e = {e:.4} (table {want})");
            worst = worst.max((e - want).abs());
            // docs/design.md: the simulator meets the table to 0.0015 (measured 0.0011, the
            // ke -> 0 column at lambda v0 = 20 and 100).
            assert!((e - want).abs() <= 0.0015, "e = {e}, table {want}");
        }
        // The RK4 within twice the table's rounding (0.001): the integral rounds to every entry
        // but one, lambda v0 = 2, ke -> 0: 0.4765, printed 0.477.
        assert!((rk4 - want).abs() <= 0.001, "RK4 e = {rk4}, table {want}");
    }
    println!("largest difference of the simulator from the table: {worst:.5}");
}

#[test]
fn tends_to_sqrt_ke() {
    // README, Choosing ke: e = 0.25-0.35 is ke = 0.0625-0.1225 with lambda v0 >> 1; physics.md
    // section 8: ke 0.8-0.95 gives e = 0.89-0.97.
    for &ke in &[0.0625, 0.09, 0.1225, 0.25, 0.64, 0.8, 0.95] {
        let e = restitution(ke, 1e4, 1.0, 1e-5);
        println!("ke = {ke}: e = {e:.5}, sqrt(ke) = {:.5}", ke.sqrt());
        assert!((e - ke.sqrt()).abs() < 0.002, "e = {e}");
    }
}
