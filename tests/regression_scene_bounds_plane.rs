//! Regression (issue 28, defect 2): with `model.scene_bounds`, an apple that left the bounds was
//! parked 1e5 m below the origin, which lies inside every upward plane's half-space: the run
//! then failed with "time_step_s: unstable ... overlap 100000040 mm", while the same scene with a
//! box floor passed. An apple taken out of the run now touches nothing in the layer, wherever it
//! is parked. An apple rolling off the bounds at 2 m/s leaves the scene the same way on a plane
//! floor as on a box floor: same fate, same time and place of leaving.

use crate::common;
use applesim::scenario;
use applesim::sim::fate::Fate;
use common::*;
use serde_json::json;

fn scene(floor: serde_json::Value) -> scenario::Scenario {
    let v = json!({
        "duration_s": 1.0, "time_step_s": 1e-4, "gravity_m_s2": [0, 0, -9.81],
        "output": {"sample_interval_s": 0.01, "force_history": false},
        "materials": apple_and_steel(),
        "contact": {"friction": 0.5, "ke": 0.09, "lambda_s_m": 1000},
        "model": {"scene_bounds": {"min_m": [-1, -1, -1], "max_m": [0.5, 1, 1]}},
        "apples": [
            {"name": "a1", "material": "apple", "diameter_m": 0.08, "position_m": [0, 0, 0.0401],
             "velocity_m_s": [2, 0, 0]},
            {"name": "a2", "material": "apple", "diameter_m": 0.08, "position_m": [-0.5, 0.3, 0.0401]}],
        "surfaces": [floor]
    });
    scenario::from_json(&v.to_string(), "bounds").unwrap()
}

#[test]
fn an_apple_leaving_the_bounds_over_a_plane_floor_leaves_as_over_a_box_floor() {
    let plane = scene(
        json!({"name": "floor", "type": "plane", "material": "steel",
        "point_m": [0, 0, 0], "normal": [0, 0, 1]}),
    );
    let boxed = scene(json!({"name": "floor", "type": "box", "material": "steel",
        "size_m": [10, 10, 0.1], "position_m": [0, 0, -0.05]}));
    let (rp, _) = run(&plane);
    let (rb, _) = run(&boxed);
    let left = |r: &applesim::sim::RunResult| match &r.apples[0].fate {
        Fate::LeftScene {
            time_s, position_m, ..
        } => (*time_s, *position_m),
        other => panic!("a1 did not leave the scene: {other:?}"),
    };
    let (tp, pp) = left(&rp);
    let (tb, pb) = left(&rb);
    println!("plane floor: left at t = {tp} s at {pp:?}; box floor: t = {tb} s at {pb:?}");
    assert_eq!(tp, tb);
    for i in 0..3 {
        assert!((pp[i] - pb[i]).abs() < 1e-9, "{pp:?} against {pb:?}");
    }
    // The other apple stays on the floor, untouched by the parked one.
    for r in [&rp, &rb] {
        assert!(
            matches!(r.apples[1].fate, Fate::OnSurface { .. }),
            "{:?}",
            r.apples[1].fate
        );
        assert!(
            r.warnings.iter().any(|w| w.contains("'a1' left the scene")),
            "{:?}",
            r.warnings
        );
    }
}
