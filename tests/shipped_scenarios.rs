//! Every shipped scenario under scenarios/ (and its sub-folders, but `batches/`, which holds
//! batch specs) runs through the CLI and writes its files.

use std::path::Path;
use std::process::Command;

#[test]
fn every_shipped_scenario_runs() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios");
    let mut n = 0;
    let mut entries: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .collect();
    entries.sort();
    for p in entries {
        if p.extension().and_then(|e| e.to_str()) != Some("json") {
            continue;
        }
        let out = std::env::temp_dir().join(format!(
            "applesim-shipped-{}-{}",
            std::process::id(),
            p.strip_prefix(&dir)
                .unwrap()
                .to_string_lossy()
                .replace('/', "_")
        ));
        let o = Command::new(env!("CARGO_BIN_EXE_applesim"))
            .args(["run", p.to_str().unwrap(), "--out", out.to_str().unwrap()])
            .output()
            .unwrap();
        assert!(
            o.status.success(),
            "{}: {}",
            p.display(),
            String::from_utf8_lossy(&o.stderr)
        );
        for f in [
            "summary.json",
            "contacts.csv",
            "bodies.csv",
            "scenario.json",
        ] {
            assert!(out.join(f).exists(), "{}: no {f}", p.display());
        }
        let summary: serde_json::Value =
            serde_json::from_slice(&std::fs::read(out.join("summary.json")).unwrap()).unwrap();
        for key in [
            "steps",
            "simulated_time_s",
            "wall_time_s",
            "contacts",
            "apples",
        ] {
            assert!(
                summary.get(key).is_some(),
                "{}: summary lacks {key}",
                p.display()
            );
        }
        assert!(
            !summary["contacts"].as_array().unwrap().is_empty(),
            "{}: no contact",
            p.display()
        );
        let _ = std::fs::remove_dir_all(&out);
        n += 1;
    }
    assert!(n >= 3, "only {n} scenarios found");
}
