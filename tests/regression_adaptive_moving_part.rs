//! Regression (issue 28, defect 8): `adaptive` stepping did not see a moving part coming. A wall
//! that starts at 0.5 s and sweeps at 5 m/s over an apple asleep on a floor moved up to 50 mm per
//! 10 ms step and passed through the apple unseen at `preview` and `precise` (no wall contact,
//! exit 0), while `auto` and fixed steps pushed the apple away with a 648 N impact. The adaptive
//! step now keeps every moving part within the pair-finding margin per step (as it keeps every
//! apple): at every accuracy the apple is struck as with `auto` and a fixed step.

use crate::common;
use applesim::scenario;
use common::*;
use serde_json::{json, Value};

fn scene(step: Value, accuracy: &str) -> scenario::Scenario {
    let mut v = json!({
        "duration_s": 1.0, "time_step_s": step, "gravity_m_s2": [0, 0, -9.81],
        "output": {"sample_interval_s": 0.01, "force_history": false},
        "materials": apple_and_steel(),
        "contact": {"friction": 0.5, "ke": 0.09, "lambda_s_m": 1000},
        "apples": [{"name": "a1", "material": "apple", "diameter_m": 0.08, "position_m": [0, 0, 0.0399]}],
        "surfaces": [
            {"name": "floor", "type": "plane", "material": "steel", "point_m": [0, 0, 0], "normal": [0, 0, 1]},
            {"name": "wall", "type": "box", "material": "steel", "size_m": [0.02, 0.3, 0.3],
             "position_m": [-0.5234, 0, 0.2],
             "motion": {"translation": {"keyframes": [[0.5, [0, 0, 0]], [0.6, [0.5, 0, 0]]]}}}]
    });
    if !step.is_number() {
        v["accuracy"] = json!(accuracy);
    }
    scenario::from_json(&v.to_string(), "wall").unwrap()
}

/// The wall's impact: (peak force, start time, the apple's final x).
fn struck(sc: &scenario::Scenario) -> (f64, f64, f64) {
    let (r, _) = run(sc);
    let hits: Vec<_> = r.events.iter().filter(|e| &*e.b == "wall").collect();
    assert_eq!(hits.len(), 1, "wall contacts: {}", hits.len());
    (
        hits[0].peak_force_n,
        hits[0].t_start_s,
        r.apples[0].final_position_m[0],
    )
}

#[test]
fn adaptive_steps_see_a_moving_wall_coming_at_every_accuracy() {
    let (fixed, t_fixed, x_fixed) = struck(&scene(json!(1e-4), ""));
    println!(
        "fixed 1e-4 s: peak {fixed:.1} N at {t_fixed:.4} s, apple pushed to x = {x_fixed:.3} m"
    );
    for accuracy in ["preview", "balanced", "precise"] {
        for step in ["auto", "adaptive"] {
            let (peak, t, x) = struck(&scene(json!(step), accuracy));
            println!("{step} {accuracy}: peak {peak:.1} N at {t:.4} s, x = {x:.3} m");
            // The impact at 5 m/s: within the accuracy's error on peak forces of the fixed
            // step's (preview about 1 %, measured up to 5 % for `auto` at preview: 614 N).
            assert!(
                (peak / fixed - 1.0).abs() < 0.06,
                "{step} {accuracy}: {peak} against {fixed}"
            );
            assert!((t - t_fixed).abs() < 1e-3, "{t}");
            assert!(x > 1.0, "the apple was pushed away: x = {x}");
        }
    }
}
