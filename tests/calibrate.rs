//! `applesim calibrate` (issue 4 acceptance): ke for a target restitution, found by simulating
//! the impact, checked here against an independent full run of the simulator; and the refusal,
//! with its reason, of a target no ke can reach.

use crate::common;
use applesim::analysis::calibrate::{self, CalibrateError, ImpactSetup, KE_MIN};
use common::*;

/// The Fig. 1 apple (D 80 mm, 0.107 kg) on steel, from the shipped scenario, with gravity.
fn setup(lambda: f64) -> ImpactSetup {
    let sc = shipped("scenarios/drop_on_steel.json");
    let mut s = ImpactSetup::from_scenario(&sc, None, None, None).unwrap();
    s.lambda_s_m = lambda;
    s
}

/// Restitution of one impact at v0 in a full run of the shipped scenario with `ke`, started
/// touching the plate (approach speed v0), at the shipped time step 1e-5 s.
fn full_run_restitution(ke: f64, lambda: f64, v0: f64, gravity: bool) -> f64 {
    let mut sc = shipped("scenarios/drop_on_steel.json");
    sc.contact.ke = Some(ke);
    sc.contact.lambda_s_m = Some(lambda);
    sc.apples[0].position_m = [0.0, 0.0, 0.04];
    sc.apples[0].velocity_m_s = [0.0, 0.0, -v0];
    if !gravity {
        sc.gravity_m_s2 = [0.0; 3];
    }
    sc.duration_s = 0.05;
    sc.output.force_history = Some(false.into());
    let (r, _) = run(&sc);
    r.events[0].restitution.expect("the apple lifts off")
}

#[test]
fn finds_ke_for_e_0_3_at_1_m_s_with_lambda_1000() {
    let s = setup(1000.0);
    let c = calibrate::calibrate(&s, 0.3, 1.0, 1e-4).unwrap();
    println!(
        "ke = {:.6}, e = {:.6}, sqrt(ke) = {:.4}, {} simulated impacts, contact {:.3} ms",
        c.ke,
        c.restitution,
        c.sqrt_ke,
        c.simulations,
        c.impact.contact_time_s.unwrap() * 1e3
    );
    assert!((c.restitution - 0.3).abs() <= 1e-4);
    // Gravity acting through the long unloading takes speed off the rebound: ke is well above
    // the closed-form 0.09 (measured 0.1255).
    assert!(c.sqrt_ke > 0.33, "sqrt(ke) = {}", c.sqrt_ke);
    // Independent check: the ordinary simulator at its own time step.
    let e = full_run_restitution(c.ke, 1000.0, 1.0, true);
    println!("full run with ke = {:.6}: e = {e:.5}", c.ke);
    // docs/analysis.md: under gravity a restitution at dt = 1e-5 s is defined to g dt / v0
    // (1e-4 at 1 m/s); checked at twice that. The full run gives 0.30005 (golden, as printed).
    assert!((e - 0.3).abs() <= 2.0 * 9.81 * 1e-5 / 1.0, "e = {e}");
    assert!((e - 0.30005).abs() <= 1e-5, "e = {e}");
}

#[test]
fn refuses_e_0_3_at_lambda_v0_2_without_gravity_with_the_reason() {
    let mut s = setup(10.0);
    s.gravity_m_s2 = 0.0;
    let err = calibrate::calibrate(&s, 0.3, 0.2, 1e-4).unwrap_err();
    let msg = err.to_string();
    println!("{msg}");
    assert!(matches!(err, CalibrateError::Unreachable { .. }));
    assert!(msg.contains("lambda v0 = 2.000"), "{msg}");
    assert!(msg.contains("Raise lambda"), "{msg}");
    // The bound it quotes is the ke -> 0 restitution of physics.md section 3 (0.477).
    let lo = calibrate::simulate_impact(&s, KE_MIN, 0.2).unwrap();
    let e_lo = lo.restitution.unwrap();
    assert!((e_lo - 0.477).abs() < 0.003, "e(ke = 1e-4) = {e_lo}");
    // Against the independent RK4 (ke = 1e-4, lambda v0 = 2, no gravity): docs/analysis.md
    // states 0.2 % below it; checked at twice that.
    let rk4 = common::ode::Setup {
        mass_kg: 0.107,
        k: common::ode::fig1_k(),
        r_star_m: 0.04,
        ke: KE_MIN,
        lambda_s_m: 10.0,
        g_n: 0.0,
    }
    .impact(0.2, 10.0)
    .rebound_m_s
    .unwrap()
        / 0.2;
    assert_rel("e(ke = 1e-4) against RK4", e_lo, rk4, 2.0 * 0.2e-2);
    assert!(msg.contains(&format!("{e_lo:.4}")), "{msg}");
}

#[test]
fn under_gravity_e_0_3_at_lambda_v0_2_is_reachable() {
    // With gravity (the default) the same target is reached: at 0.2 m/s the 14 ms contact lets
    // gravity take 0.14 m/s, 70 % of v0, so even small ke rebound slower than without gravity
    // (e = 0.16 at ke = 0.01). Measured: ke = 0.1041.
    let s = setup(10.0);
    let c = calibrate::calibrate(&s, 0.3, 0.2, 1e-4).unwrap();
    println!("ke = {:.6}, e = {:.6}", c.ke, c.restitution);
    assert!((c.restitution - 0.3).abs() <= 1e-4);
    let e = full_run_restitution(c.ke, 10.0, 0.2, true);
    println!("full run: e = {e:.5}");
    // The full run's time step (1e-5 s) resolves e only to g dt / v0 = 5e-4 (docs/analysis.md);
    // checked at twice that.
    assert!((e - 0.3).abs() <= 2.0 * 9.81 * 1e-5 / 0.2, "e = {e}");
}

#[test]
fn without_gravity_and_large_lambda_ke_is_e_squared() {
    // physics.md section 3: e -> sqrt(ke) for lambda v0 >> 1 without gravity (table: 0.300 at
    // ke = 0.09, lambda v0 = 100; 1e4 here).
    let mut s = setup(1e4);
    s.gravity_m_s2 = 0.0;
    let c = calibrate::calibrate(&s, 0.3, 1.0, 1e-4).unwrap();
    println!("ke = {:.6}", c.ke);
    assert!((c.ke - 0.09).abs() < 0.002, "ke = {}", c.ke);
}

#[test]
fn refuses_targets_outside_0_1_and_above_the_elastic_rebound() {
    let s = setup(1000.0);
    for bad in [0.0, 1.0, 1.2, f64::NAN] {
        let err = calibrate::calibrate(&s, bad, 1.0, 1e-4).unwrap_err();
        assert!(matches!(err, CalibrateError::Input { .. }), "{err}");
    }
}

#[test]
fn table_rises_with_speed_and_matches_the_lead_measurement() {
    // ke = 0.09, lambda = 1000 s/m, with gravity: e = 0.23 at 1 m/s (README), no lift-off at
    // 0.05 m/s (the unloading lasts ~20 ms, gravity takes 0.2 m/s).
    let s = setup(1000.0);
    let t = calibrate::restitution_table(&s, 0.09, &[0.05, 0.5, 1.0, 1.4]).unwrap();
    for i in &t {
        println!("v0 {}: e {:?}", i.speed_m_s, i.restitution);
    }
    assert_eq!(t[0].restitution, None);
    let e: Vec<f64> = t[1..].iter().map(|i| i.restitution.unwrap()).collect();
    assert!(e.windows(2).all(|w| w[0] < w[1]), "{e:?}");
    assert!((e[1] - 0.23).abs() < 0.01, "e(1 m/s) = {}", e[1]);
    assert!(e.iter().all(|&x| x < 0.3));
}

#[test]
fn cli_reports_ke_and_refuses_with_exit_code_1() {
    let bin = env!("CARGO_BIN_EXE_applesim");
    let scen = repo("scenarios/drop_on_steel.json");
    let ok = std::process::Command::new(bin)
        .args(["calibrate"])
        .arg(&scen)
        .args(["--e", "0.3", "--speed-m-s", "1", "--lambda-s-m", "1000"])
        .output()
        .unwrap();
    let out = String::from_utf8_lossy(&ok.stdout);
    println!("{out}");
    assert!(ok.status.success());
    assert!(
        out.contains("ke = 0.12") && out.contains("sqrt(ke)"),
        "{out}"
    );
    let bad = std::process::Command::new(bin)
        .args(["calibrate"])
        .arg(&scen)
        .args([
            "--e",
            "0.3",
            "--speed-m-s",
            "0.2",
            "--lambda-s-m",
            "10",
            "--no-gravity",
        ])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&bad.stderr);
    println!("{err}");
    assert_eq!(bad.status.code(), Some(1));
    assert!(err.starts_with("error: e = 0.3 cannot be reached"), "{err}");
}
