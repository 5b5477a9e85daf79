//! Regression (issue 28, defect 6): a probe's accelerometer trace was not counted in the memory
//! and output budgets (`model.max_memory_mb`, `model.max_output_mb`): at 10 MHz with a 1 s window
//! on a 30 s line the run aborted on an 8 GiB allocation, and two seconds of the same line wrote
//! 573 MB. The trace can keep every sampling instant (30 s x 1e7 = 3e8 samples, 64 bytes each in
//! memory at most, 40 bytes a row): refused before the run, naming the probe's
//! `sample_rate_hz` with the estimate, within a second and under a 300 MB address-space limit.

use crate::common;
use common::*;
use serde_json::Value;

fn line(duration: f64, rate: f64, window: f64) -> Value {
    let mut v: Value = serde_json::from_str(
        &std::fs::read_to_string(repo("scenarios/handling_line_probe.json")).unwrap(),
    )
    .unwrap();
    v["duration_s"] = duration.into();
    v["apples"][0]["probe"]["sample_rate_hz"] = rate.into();
    v["apples"][0]["probe"]["window_s"] = window.into();
    // The probe's mesh-free line: meshes resolve from the scenario's folder, none here.
    v
}

#[test]
fn a_probe_trace_beyond_the_budgets_is_refused_up_front_with_the_estimate() {
    let mut v = line(30.0, 1e7, 1.0);
    refused_cli(
        "probe-memory",
        &v,
        "ulimit -v 300000;",
        "apples[0].probe.sample_rate_hz",
        &[
            "the probe 'is' sampled at 1e7 Hz over 30 s can keep 3.000e8 samples in its trace",
            "about 17.9 GiB of memory (64 bytes per sample",
            "more than model.max_memory_mb = 8192 MiB",
        ],
        1.0,
    );
    // With memory to spare, the output budget refuses it: 3e8 rows of 40 bytes.
    v["model"] = serde_json::json!({"max_memory_mb": 1e6});
    refused_cli(
        "probe-output",
        &v,
        "ulimit -v 300000;",
        "apples[0].probe.sample_rate_hz",
        &[
            "about 11.2 GiB of its trace file (40 bytes per row; the run's output 11.2 GiB in all)",
            "more than model.max_output_mb = 4096 MiB",
        ],
        1.0,
    );
}
