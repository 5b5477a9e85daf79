//! Regression (issue 28, defect 1): a roller bed's `count` was range-checked only after the bed
//! had been expanded into its rollers (the output budget counted free rollers by expanding every
//! bed): a count of 4294967295 aborted with "memory allocation of 1271310319320 bytes failed",
//! one of 1e6 took 0.9 GB before the "1 to 10000" refusal. Now it is refused at once naming
//! `surfaces[0].count`, under a 300 MB address-space limit (no allocation of the bed), within a
//! second. And a bed's radius of 1e308 is blamed on `radius_m`, not on `pitch_m`.

use crate::common;
use common::*;
use serde_json::{json, Value};

fn bed(count: u64, radius: f64, free: bool) -> Value {
    let mut bed = json!({"type": "roller_bed", "name": "bed", "material": "steel",
        "radius_m": radius, "length_m": 0.3, "position_m": [0, 0, 0], "axis": [0, 1, 0],
        "pitch_m": 0.08, "pitch_direction": [1, 0, 0], "count": count,
        "angular_velocity_rad_s": 5});
    if free {
        bed["free_turning"] = json!({"moment_of_inertia_kg_m2": 1e-3});
    }
    json!({
        "duration_s": 0.01, "time_step_s": 1e-4, "gravity_m_s2": [0, 0, -9.81],
        "materials": apple_and_steel(),
        "contact": {"friction": 0.5, "ke": 0.09, "lambda_s_m": 1000},
        "apples": [{"name": "a1", "material": "apple", "diameter_m": 0.075, "position_m": [0, 0, 0.2]}],
        "surfaces": [bed]
    })
}

#[test]
fn a_huge_roller_bed_count_is_refused_at_once_without_allocating_the_bed() {
    // 300 MB of address space: far below the 0.9 GB a bed of 1e6 rollers took, and the 1.2 TB
    // of 4294967295 (the binary alone maps about 40 MB).
    let limit = "ulimit -v 300000;";
    for count in [4_294_967_295u64, 1_000_000] {
        for free in [false, true] {
            let line = refused_cli(
                &format!("bed-count-{count}-{free}"),
                &bed(count, 0.03, free),
                limit,
                "surfaces[0].count",
                &[&format!("{count} rollers: a roller bed has 1 to 10000")],
                1.0,
            );
            assert!(!line.contains("memory allocation"), "{line}");
        }
    }
    // In range, the same scene runs under the same limit.
    let (code, err, _, dir) = run_cli("bed-count-ok", &bed(4, 0.03, true), limit);
    assert_eq!(code, Some(0), "{err}");
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn a_roller_bed_radius_out_of_range_is_blamed_on_radius_m() {
    refused_cli(
        "bed-radius",
        &bed(4, 1e308, false),
        "",
        "surfaces[0].radius_m",
        &["1e308 m is outside the range of fruit handling"],
        1.0,
    );
}
