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
