//! Regression: eq. 12's rate part is a very stiff damper near du/dt = 0 ((1 - ke)/2 lambda H);
//! at the bottom of a loaded column, explicit stepping made the force flip between ke H and H
//! every step and resting apples chattered at centimetres per second (a settled 1000-apple pile
//! never fell asleep, and the chatter compacted it). The rate part is now bounded by a share of
//! m / dt (contact::damping::hysteresis_force).

use crate::common;
use applesim::scenario;
use common::*;
use serde_json::json;

#[test]
fn a_loaded_column_comes_to_rest() {
    // Ten apples stacked on steel at dt = 1e-4 s: the bottom contact carries ~19 N, whose eq. 12
    // damper (0.455 * 1000 s/m * 35 N) gives c dt / m ~ 7.6 without the bound (stable needs < 2).
    let v = json!({
        "duration_s": 1.0, "time_step_s": 1e-4, "gravity_m_s2": [0, 0, -9.81],
        "output": {"sample_interval_s": 0.01, "force_history": false},
        "materials": {
            "apple": {"youngs_modulus_pa": 2.6e6, "poisson_ratio": 0.18, "density_kg_m3": 800},
            "steel": {"youngs_modulus_pa": 2.0e11, "poisson_ratio": 0.3}},
        "contact": {"friction": 0.5, "ke": 0.09, "lambda_s_m": 1000},
        "model": {"sleep": {"enabled": false}},
        "generators": [{"type": "grid", "name": "c", "material": "apple", "diameter_m": 0.08,
            "count": [1, 1, 10], "spacing_m": [0.1, 0.1, 0.0801], "origin_m": [0, 0, 0.0401]}],
        "surfaces": [{"name": "floor", "type": "plane", "material": "steel",
            "point_m": [0, 0, 0], "normal": [0, 0, 1]}]
    });
    let sc = scenario::from_json(&v.to_string(), "column").unwrap();
    let (_, series) = run(&sc);
    let mut worst: f64 = 0.0;
    for (t, states) in &series.samples {
        if *t >= 0.6 {
            for a in states {
                worst = worst.max(a.velocity.length());
            }
        }
    }
    println!("largest apple speed after 0.6 s: {worst:.3e} m/s");
    assert!(worst < 1e-3, "the column still moves at {worst} m/s");
}
