//! `applesim bench` through the real binary (issue 11): the JSON figures of a tiny pile with
//! two windows are present and consistent. Timings are never asserted, only that they exist.

use serde_json::{json, Value};
use std::path::PathBuf;
use std::process::{Command, Output};

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("applesim-bench-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn applesim(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_applesim"))
        .args(args)
        .output()
        .unwrap()
}

/// Five apples in a steel box 160.2 mm wide: four on the floor (5 mm above it at the start,
/// 0.1 mm apart, touching the walls), one on top of them (8.5 mm above its seat). Read from a
/// pile file, as the reference scenarios are.
fn tiny_pile(dir: &std::path::Path) -> PathBuf {
    let s = 0.04005;
    let pile = json!([
        {"name": "a", "diameter_m": 0.08, "position_m": [-s, -s, 0.045]},
        {"name": "b", "diameter_m": 0.08, "position_m": [s, -s, 0.045]},
        {"name": "c", "diameter_m": 0.08, "position_m": [-s, s, 0.045]},
        {"name": "d", "diameter_m": 0.08, "position_m": [s, s, 0.045]},
        {"name": "top", "diameter_m": 0.08, "position_m": [0, 0, 0.11]}
    ]);
    std::fs::write(dir.join("pile.json"), pile.to_string()).unwrap();
    let w = 0.0801;
    let plane = |name: &str, p: [f64; 3], n: [f64; 3]| json!({"name": name, "type": "plane", "material": "steel", "point_m": p, "normal": n});
    let sc = json!({
        "duration_s": 0.3, "time_step_s": 1e-4, "gravity_m_s2": [0, 0, -9.81],
        "output": {"sample_interval_s": 0.1, "force_history": false, "transitions": {"enabled": false}},
        "materials": {
            "apple": {"youngs_modulus_pa": 2.6e6, "poisson_ratio": 0.18, "density_kg_m3": 800},
            "steel": {"youngs_modulus_pa": 2.0e11, "poisson_ratio": 0.3}},
        "contact": {"friction": 0.5, "ke": 0.09, "lambda_s_m": 1000},
        "generators": [{"type": "file", "name": "p", "material": "apple", "file": "pile.json"}],
        "surfaces": [
            plane("floor", [0.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
            plane("x_min", [-w, 0.0, 0.0], [1.0, 0.0, 0.0]),
            plane("x_max", [w, 0.0, 0.0], [-1.0, 0.0, 0.0]),
            plane("y_min", [0.0, -w, 0.0], [0.0, 1.0, 0.0]),
            plane("y_max", [0.0, w, 0.0], [0.0, -1.0, 0.0])
        ]
    });
    let path = dir.join("tiny.json");
    std::fs::write(&path, sc.to_string()).unwrap();
    path
}

fn num(v: &Value, key: &str) -> f64 {
    v[key]
        .as_f64()
        .unwrap_or_else(|| panic!("'{key}' missing or not a number in {v}"))
}

#[test]
fn bench_json_has_every_figure_per_window() {
    let dir = scratch("json");
    let sc = tiny_pile(&dir);
    let o = applesim(&[
        "bench",
        sc.to_str().unwrap(),
        "--threads",
        "1",
        "--window",
        "0:0.002",
        "--window",
        "0.1:0.3",
        "--json",
    ]);
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: Value = serde_json::from_str(stdout.trim()).unwrap_or_else(|e| panic!("{e}: {stdout}"));
    println!("{v:#}");
    assert_eq!(v["scenario"].as_str(), sc.to_str());
    assert_eq!(v["threads"], 1);
    assert_eq!(v["apples"], 5);
    assert_eq!(v["steps"], 3000);
    assert_eq!(num(&v, "time_step_s"), 1e-4);
    assert!((num(&v, "simulated_time_s") - 0.3).abs() < 1e-9);
    // Timing figures exist and are positive numbers; their values are never asserted.
    for key in ["wall_s", "apple_steps_per_s", "setup_wall_s"] {
        let x = num(&v, key);
        assert!(x.is_finite() && x >= 0.0, "{key} = {x}");
    }
    assert!(num(&v, "apple_steps_per_s") > 0.0);
    if std::path::Path::new("/proc/self/status").exists() {
        assert!(num(&v, "peak_rss_mib") > 0.0);
    }
    // The top apple rests on the four below it: its centre is 56.5 mm above theirs (40 mm up).
    let h = num(&v, "pile_height_m");
    assert!((0.09..0.1).contains(&h), "pile height {h}");

    let w = v["windows"].as_array().unwrap();
    assert_eq!(w.len(), 2);
    assert_eq!((num(&w[0], "from_s"), num(&w[0], "to_s")), (0.0, 0.002));
    assert_eq!((num(&w[1], "from_s"), num(&w[1], "to_s")), (0.1, 0.3));
    assert_eq!(w[0]["label"], "0:0.002");
    assert_eq!(w[0]["steps"], 20);
    assert_eq!(w[1]["steps"], 2000);
    for x in w {
        assert_eq!(x["apples_at_end"], 5);
        let (wall, rate) = (num(x, "wall_s"), num(x, "apple_steps_per_s"));
        assert!(wall > 0.0 && rate > 0.0, "{x}");
        let awake = num(x, "mean_awake_apples");
        assert!((0.0..=5.0).contains(&awake), "{x}");
        // No belt: nobody rides.
        assert_eq!(num(x, "mean_riding_apples"), 0.0, "{x}");
        // A fixed step: every step is the driver's, of 1e-4 s.
        assert_eq!(x["steps_set_by"]["driver"], x["steps"], "{x}");
        assert!((num(x, "mean_step_s") - 1e-4).abs() < 1e-12, "{x}");
    }
    // Nobody sleeps in the first 2 ms, and nothing touches yet (apples fall 0.02 mm of 5 mm).
    assert_eq!(num(&w[0], "mean_awake_apples"), 5.0);
    assert_eq!(num(&w[0], "contacts_per_apple"), 0.0);
    assert_eq!(num(&w[0], "apple_apple_contacts_per_apple"), 0.0);
    // At 0.3 s: each bottom apple touches the floor and two walls, the top one the four below:
    // at least 12 + 4 contacts, 4 of them (at least) apple-apple, over 5 apples.
    let (all, aa) = (
        num(&w[1], "contacts_per_apple"),
        num(&w[1], "apple_apple_contacts_per_apple"),
    );
    assert!(all >= 16.0 / 5.0 && aa >= 4.0 / 5.0 && aa < all, "{}", w[1]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bench_text_report_and_default_window() {
    let dir = scratch("text");
    let sc = tiny_pile(&dir);
    let o = applesim(&["bench", sc.to_str().unwrap(), "--threads", "2"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let out = String::from_utf8_lossy(&o.stdout);
    println!("{out}");
    // A run shorter than 5 s is measured as one window, the whole run.
    assert!(out.contains("whole run 0-0.3"), "{out}");
    assert!(out.contains("5 apples, 3000 steps"), "{out}");
    for s in [
        "apple-steps/s",
        "settled pile height",
        "peak resident memory",
        "2 thread(s)",
        // Five apples, fewer than APPLE_SETS_MIN_APPLES: all in rapier's own set.
        "2 thread(s), 1 rapier body set(s)",
        "steps set by",
        "driver 100 %",
    ] {
        assert!(out.contains(s), "lacks '{s}': {out}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bench_refuses_plainly() {
    let dir = scratch("bad");
    let sc = tiny_pile(&dir);
    let sc = sc.to_str().unwrap();
    let missing = dir.join("none.json");
    let cases: [(&[&str], &str); 5] = [
        (&["bench", sc, "--window", "0:0.5"], "ends after the run"),
        (&["bench", sc, "--window", "0.2:0.1"], "FROM < TO"),
        (
            &["bench", sc, "--window", "0:0.00001"],
            "shorter than one time step",
        ),
        (&["bench", sc, "--threads", "0"], "--threads 0"),
        (&["bench", missing.to_str().unwrap()], "none.json"),
    ];
    for (args, needle) in cases {
        let o = applesim(args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
        assert!(
            err.starts_with("error: ") && err.contains(needle),
            "{args:?}: {err}"
        );
        assert!(o.stdout.is_empty(), "{args:?}");
    }
    // An unstable run is an error too: a step far too long for the apples' impacts.
    let mut v: Value = serde_json::from_slice(&std::fs::read(sc).unwrap()).unwrap();
    v["time_step_s"] = json!(2e-3);
    let unstable = dir.join("unstable.json");
    std::fs::write(&unstable, v.to_string()).unwrap();
    let o = applesim(&["bench", unstable.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("time_step_s"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}
