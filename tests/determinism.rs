//! The same scenario gives byte-identical outputs (every file; in summary.json every field but
//! `wall_time_s`, a measurement of the machine).

use std::path::Path;
use std::process::Command;

fn run_cli(scenario: &str, out: &Path) {
    let s = Path::new(env!("CARGO_MANIFEST_DIR")).join(scenario);
    let o = Command::new(env!("CARGO_BIN_EXE_applesim"))
        .args([
            "run",
            s.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--quiet",
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

fn without_wall_time(p: &Path) -> serde_json::Value {
    let mut v: serde_json::Value = serde_json::from_slice(&std::fs::read(p).unwrap()).unwrap();
    v.as_object_mut().unwrap().remove("wall_time_s");
    v
}

#[test]
fn two_runs_write_identical_files() {
    for sc in [
        "scenarios/slip_to_roll.json",
        "scenarios/two_apples_head_on.json",
    ] {
        let base = std::env::temp_dir().join(format!("applesim-det-{}", std::process::id()));
        let (a, b) = (base.join("a"), base.join("b"));
        run_cli(sc, &a);
        run_cli(sc, &b);
        for f in ["contacts.csv", "bodies.csv", "scenario.json"] {
            let (x, y) = (
                std::fs::read(a.join(f)).unwrap(),
                std::fs::read(b.join(f)).unwrap(),
            );
            assert!(!x.is_empty());
            assert!(x == y, "{sc}: {f} differs between two runs");
        }
        assert_eq!(
            without_wall_time(&a.join("summary.json")),
            without_wall_time(&b.join("summary.json"))
        );
        let _ = std::fs::remove_dir_all(&base);
    }
}

/// The force pass runs in parallel once a step has enough contacts (a pile); its sums are taken
/// in a fixed order, so one thread and two give the same bytes.
#[test]
fn one_thread_and_two_write_identical_files() {
    let base = std::env::temp_dir().join(format!("applesim-threads-{}", std::process::id()));
    std::fs::create_dir_all(&base).unwrap();
    // 288 apples dropped into a bin: about 600 contacts per step at the end, above the
    // parallel threshold.
    let sc = serde_json::json!({
        "description": "pile for the thread-count determinism test",
        "duration_s": 0.25,
        "time_step_s": 1e-4,
        "gravity_m_s2": [0, 0, -9.81],
        "output": { "sample_interval_s": 0.05 },
        "materials": {
            "apple": { "youngs_modulus_pa": 2.6e6, "poisson_ratio": 0.18, "density_kg_m3": 800 },
            "steel": { "youngs_modulus_pa": 2.0e11, "poisson_ratio": 0.3 }
        },
        "contact": { "friction": 0.5, "ke": 0.3, "lambda_s_m": 1000 },
        "generators": [ { "type": "grid", "name": "a", "material": "apple",
            "diameter_m": { "mean_m": 0.08, "spread_m": 0.008 },
            "count": [6, 6, 8], "spacing_m": [0.095, 0.095, 0.095],
            "origin_m": [-0.2375, -0.2375, 0.05], "jitter_m": 0.004, "seed": 3 } ],
        "surfaces": [ { "name": "bin", "type": "bin", "material": "steel",
            "inner_size_m": [0.6, 0.6, 0.5], "position_m": [0, 0, 0] } ]
    });
    let path = base.join("pile.json");
    std::fs::write(&path, serde_json::to_vec_pretty(&sc).unwrap()).unwrap();
    let run = |threads: &str, out: &Path| {
        let o = Command::new(env!("CARGO_BIN_EXE_applesim"))
            .args(["run", path.to_str().unwrap(), "--out"])
            .arg(out)
            .args(["--quiet", "--threads", threads])
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    };
    let (a, b) = (base.join("t1"), base.join("t2"));
    run("1", &a);
    run("2", &b);
    let contacts = std::fs::read_to_string(a.join("contacts.csv")).unwrap();
    assert!(
        contacts.lines().count() > 300,
        "the pile should produce many contacts"
    );
    for f in ["contacts.csv", "bodies.csv"] {
        let (x, y) = (
            std::fs::read(a.join(f)).unwrap(),
            std::fs::read(b.join(f)).unwrap(),
        );
        assert!(x == y, "{f} differs between --threads 1 and --threads 2");
    }
    assert_eq!(
        without_wall_time(&a.join("summary.json")),
        without_wall_time(&b.join("summary.json"))
    );
    let _ = std::fs::remove_dir_all(&base);
}
