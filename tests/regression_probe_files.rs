//! Regression (issue 28, defects 4 and 5): a probe apple's files are named after it
//! (`probe_NAME_trace.csv`, every character but letters, digits, `-` and `_` made `_`). Two
//! probes named "a 1" and "a_1" wrote the same files, one probe's record lost (exit 0); a probe
//! with a 256-character name simulated the whole run, then failed writing with "File name too
//! long", naming the file and not the field. Both are refused before the run, naming the second
//! apple's `apples[k].name`; the limit is 200 characters, and a probe of 200 writes its files.

use crate::common;
use common::*;
use serde_json::{json, Value};

fn probes(names: &[&str]) -> Value {
    let apples: Vec<Value> = names
        .iter()
        .enumerate()
        .map(|(k, n)| {
            json!({"name": n, "material": "apple", "diameter_m": 0.08,
                   "position_m": [0.2 * k as f64, 0, 0.0401 + 0.02], "probe": {}})
        })
        .collect();
    json!({
        "duration_s": 0.05, "time_step_s": 1e-5, "gravity_m_s2": [0, 0, -9.81],
        "output": {"sample_interval_s": 1e-3},
        "materials": apple_and_steel(),
        "contact": {"friction": 0.5, "ke": 0.09, "lambda_s_m": 1000},
        "apples": apples,
        "surfaces": [{"name": "floor", "type": "plane", "material": "steel",
            "point_m": [0, 0, 0], "normal": [0, 0, 1]}]
    })
}

#[test]
fn two_probes_writing_the_same_files_are_refused_naming_the_second() {
    refused_cli(
        "probe-stems",
        &probes(&["a 1", "a_1"]),
        "",
        "apples[1].name",
        &[
            "the probe 'a_1' would write the same files as the probe 'a 1' (apples[0])",
            "probe_a_1_trace.csv",
        ],
        2.0,
    );
    // Distinct stems run, each probe with its own two files.
    let (code, err, _, dir) = run_cli("probe-stems-ok", &probes(&["a 1", "a-1"]), "");
    assert_eq!(code, Some(0), "{err}");
    for f in [
        "probe_a_1_trace.csv",
        "probe_a_1_impacts.csv",
        "probe_a-1_trace.csv",
        "probe_a-1_impacts.csv",
    ] {
        assert!(dir.join("out").join(f).exists(), "{f} missing");
    }
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn a_probe_name_too_long_for_its_files_is_refused_before_the_run() {
    let long = "p".repeat(256);
    let line = refused_cli(
        "probe-long",
        &probes(&["ok", &long]),
        "",
        "apples[1].name",
        &["a probe's name of 256 characters", "give at most 200"],
        2.0,
    );
    assert!(!line.contains("File name too long"), "{line}");
    // 200 characters: the longest file name, .probe_NAME_impacts.csv.tmp-PID, fits in 255 bytes.
    let edge = "q".repeat(200);
    let (code, err, _, dir) = run_cli("probe-200", &probes(&[&edge]), "");
    assert_eq!(code, Some(0), "{err}");
    assert!(dir
        .join("out")
        .join(format!("probe_{edge}_trace.csv"))
        .exists());
    let _ = std::fs::remove_dir_all(dir);
}
