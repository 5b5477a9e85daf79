//! Rigid surfaces (README, "Surfaces": `"contact_model": "rigid"` is rapier's own contact with
//! friction and restitution sqrt(ke), nothing recorded) and the `rigid` fidelity (rapier's own
//! impulse contacts, restitution sqrt(ke)): an apple dropped square on the surface rebounds at
//! sqrt(ke) times its approach speed, against the closed form e = sqrt(ke) (no gravity: exactly;
//! with gravity the speeds just before and after the impulse), at every step size, and no contact
//! event is recorded.

use crate::common;
use applesim::scenario::{self, Fidelity, Scenario};
use common::*;
use serde_json::json;

/// Fig. 1 apple 5 mm above a rigid steel plane, falling at v0.
fn scene(ke: f64, v0: f64, g: f64, dt: f64) -> Scenario {
    let v = json!({
        "duration_s": 0.05, "time_step_s": dt, "gravity_m_s2": [0, 0, -g],
        "output": {"sample_interval_s": dt, "force_history": false},
        "materials": {
            "apple": {"shear_modulus_pa": 1.1e6, "poisson_ratio": 0.18, "density_kg_m3": 800},
            "steel": {"shear_modulus_pa": 8.1e10, "poisson_ratio": 0.28}},
        "contact": {"friction": 0.3, "ke": ke, "lambda_s_m": 1000},
        "apples": [{"name": "a1", "material": "apple", "diameter_m": 0.08, "mass_kg": 0.107,
                    "position_m": [0, 0, 0.045], "velocity_m_s": [0, 0, -v0]}],
        "surfaces": [{"name": "floor", "type": "plane", "material": "steel", "contact_model": "rigid",
            "point_m": [0, 0, 0], "normal": [0, 0, 1]}]
    });
    scenario::from_json(&v.to_string(), "rigid surface").unwrap()
}

/// (restitution: fastest rise over fastest fall, events recorded).
fn bounce(sc: &Scenario) -> (f64, usize) {
    let (r, s) = run(sc);
    let vz: Vec<f64> = s.of(0).iter().map(|(_, a)| a.velocity.z).collect();
    let down = vz.iter().cloned().fold(f64::MAX, f64::min);
    let up = vz.iter().cloned().fold(f64::MIN, f64::max);
    (up / -down, r.events.len())
}

#[test]
fn rigid_surface_rebounds_at_sqrt_ke() {
    for ke in [0.09, 0.25, 0.64, 1.0] {
        for dt in [1e-5, 1e-4, 1e-3] {
            for v0 in [0.3, 1.0] {
                let (e, n) = bounce(&scene(ke, v0, 0.0, dt));
                println!(
                    "ke {ke}, dt {dt:e}, v0 {v0}: e = {e:.9} (sqrt(ke) {:.9})",
                    ke.sqrt()
                );
                assert_eq!(n, 0, "a rigid surface records nothing");
                // Measured: exact to the last digits; checked at 1e-9.
                assert!((e - ke.sqrt()).abs() < 1e-9, "e = {e}");
            }
        }
        // With gravity: the speeds sampled every step around the impulse, which gravity changes
        // by g dt per step: e within g dt / v0 of sqrt(ke) (measured, the sampling limit).
        let dt = 1e-5;
        let (e, _) = bounce(&scene(ke, 1.0, 9.81, dt));
        println!("ke {ke}, with gravity: e = {e:.6}");
        assert!(
            (e - ke.sqrt()).abs() <= 2.0 * 9.81 * dt / 1.0,
            "with gravity e = {e}"
        );
    }
}

#[test]
fn rigid_fidelity_rebounds_at_sqrt_ke() {
    let mut sc = shipped("scenarios/drop_on_steel.json");
    sc.fidelity = Fidelity::Rigid;
    sc.contact.ke = Some(0.25);
    sc.gravity_m_s2 = [0.0; 3];
    let (e, n) = bounce(&sc);
    println!("fidelity rigid, ke 0.25: e = {e:.9}");
    assert_eq!(n, 0, "no contact forces, no events");
    // docs/transitions.md: the slip/roll detector is off for fidelity rigid.
    let (r, _) = run(&sc);
    assert!(r.transitions.is_empty() && r.transition_summary.is_none());
    assert!((e - 0.5).abs() < 1e-9, "e = {e}");
}
