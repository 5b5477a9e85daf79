//! `applesim view` on bad input (issue 21): a folder that is not a run, a run without
//! bodies.csv, truncated CSV files. Each is a clear one-line error naming the file, exit 1, and
//! no HTML written. Also: the page is written whole into a run folder and the next run into that
//! folder replaces it (view.html belongs to the run's set).

use std::path::{Path, PathBuf};
use std::process::Command;

fn exe() -> &'static str {
    env!("CARGO_BIN_EXE_applesim")
}

fn tmp(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("view_errors")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A finished run of the Fig. 1 drop (one apple, a floor) in `dir/run`.
fn small_run(dir: &Path) -> PathBuf {
    let run = dir.join("run");
    let o = Command::new(exe())
        .args(["run", "scenarios/drop_on_steel.json", "-q", "--out"])
        .arg(&run)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    run
}

/// Runs `applesim view RUN --out OUT` expecting a failure; returns its message.
fn view_fails(run: &Path, out: &Path) -> String {
    let o = Command::new(exe())
        .arg("view")
        .arg(run)
        .arg("--out")
        .arg(out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1), "expected a failure");
    assert!(!out.exists(), "{} was written", out.display());
    let leftovers: Vec<_> = std::fs::read_dir(out.parent().unwrap())
        .into_iter()
        .flatten()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().contains(".tmp-"))
        .collect();
    assert!(leftovers.is_empty(), "temporaries left: {leftovers:?}");
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert_eq!(err.lines().count(), 1, "one line: {err}");
    assert!(err.starts_with("error: "), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    err
}

#[test]
fn a_folder_that_is_not_a_run() {
    let dir = tmp("not_a_run");
    let folder = dir.join("photos");
    std::fs::create_dir_all(&folder).unwrap();
    std::fs::write(folder.join("apple.txt"), "not a run").unwrap();
    let err = view_fails(&folder, &dir.join("view.html"));
    assert!(
        err.contains(&format!(
            "{}: not a run folder (no summary.json",
            folder.display()
        )),
        "{err}"
    );
    let err = view_fails(&dir.join("missing"), &dir.join("view.html"));
    assert!(
        err.contains("missing: not a run folder (no such folder)"),
        "{err}"
    );
    // A file given as the folder.
    let err = view_fails(&folder.join("apple.txt"), &dir.join("view.html"));
    assert!(
        err.contains("apple.txt: not a run folder (a file, not a folder)"),
        "{err}"
    );
}

#[test]
fn a_run_without_bodies_csv() {
    let dir = tmp("no_bodies");
    let run = small_run(&dir);
    std::fs::remove_file(run.join("bodies.csv")).unwrap();
    let err = view_fails(&run, &dir.join("view.html"));
    assert!(
        err.contains(&format!(
            "{}: missing: the apples' positions over time",
            run.join("bodies.csv").display()
        )),
        "{err}"
    );
}

#[test]
fn truncated_csv_files() {
    let dir = tmp("truncated");
    let run = small_run(&dir);
    let bodies = std::fs::read(run.join("bodies.csv")).unwrap();

    // Cut in the middle of a row.
    let cut = bodies.len() / 2;
    let mid_row = bodies[..cut]
        .iter()
        .rposition(|&b| b == b'\n')
        .map(|k| k + 20)
        .unwrap();
    std::fs::write(run.join("bodies.csv"), &bodies[..mid_row]).unwrap();
    let err = view_fails(&run, &dir.join("view.html"));
    assert!(
        err.contains(&format!("{}: line ", run.join("bodies.csv").display())),
        "{err}"
    );
    assert!(err.contains("truncated"), "{err}");

    // Cut at the end of a row: whole rows, but the samples stop before the run's end.
    let at_row = bodies[..cut].iter().rposition(|&b| b == b'\n').unwrap() + 1;
    std::fs::write(run.join("bodies.csv"), &bodies[..at_row]).unwrap();
    let err = view_fails(&run, &dir.join("view.html"));
    assert!(
        err.contains(&format!(
            "{}: the last sample is at t = ",
            run.join("bodies.csv").display()
        )),
        "{err}"
    );
    assert!(err.contains("the file is truncated"), "{err}");

    // Empty (cut before its header).
    std::fs::write(run.join("bodies.csv"), b"").unwrap();
    let err = view_fails(&run, &dir.join("view.html"));
    assert!(err.contains("bodies.csv: empty file"), "{err}");
    std::fs::write(run.join("bodies.csv"), &bodies).unwrap();

    // contacts.csv cut in the middle of its row.
    let contacts = std::fs::read(run.join("contacts.csv")).unwrap();
    let first_row = contacts.iter().position(|&b| b == b'\n').unwrap() + 1;
    std::fs::write(run.join("contacts.csv"), &contacts[..first_row + 30]).unwrap();
    let err = view_fails(&run, &dir.join("view.html"));
    assert!(
        err.contains(&format!("{}: line 2", run.join("contacts.csv").display())),
        "{err}"
    );
    std::fs::write(run.join("contacts.csv"), &contacts).unwrap();

    // summary.json cut short.
    let summary = std::fs::read(run.join("summary.json")).unwrap();
    std::fs::write(run.join("summary.json"), &summary[..summary.len() / 2]).unwrap();
    let err = view_fails(&run, &dir.join("view.html"));
    assert!(
        err.contains(&format!("{}: ", run.join("summary.json").display())),
        "{err}"
    );
    std::fs::write(run.join("summary.json"), &summary).unwrap();

    // Restored, it views.
    let o = Command::new(exe())
        .arg("view")
        .arg(&run)
        .arg("--out")
        .arg(dir.join("view.html"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(dir.join("view.html").is_file());
}

#[test]
fn bad_options() {
    let dir = tmp("options");
    let run = small_run(&dir);
    let o = Command::new(exe())
        .arg("view")
        .arg(&run)
        .args(["--max-frames", "1"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--max-frames 1: give at least 2"));
    assert!(!run.join("view.html").exists());
    // Into a folder that does not exist.
    let err = view_fails(&run, &dir.join("nowhere").join("view.html"));
    assert!(err.contains("nowhere: no such folder"), "{err}");
}

/// The page is part of the run's set: `run --view` writes it inside the folder, a later
/// `applesim view` replaces it, and the next run into the folder replaces the whole set (a
/// folder holding view.html is still a run folder).
#[test]
fn the_page_belongs_to_the_run_folder() {
    let dir = tmp("set");
    let run = dir.join("run");
    for _ in 0..2 {
        let o = Command::new(exe())
            .args([
                "run",
                "scenarios/drop_on_steel.json",
                "--view",
                "--max-frames",
                "50",
                "--out",
            ])
            .arg(&run)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        assert!(String::from_utf8_lossy(&o.stdout).contains("view.html"));
    }
    let first = std::fs::read(run.join("view.html")).unwrap();
    let o = Command::new(exe())
        .arg("view")
        .arg(&run)
        .args(["-q", "--max-frames", "50"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(o.stdout.is_empty());
    // The same run folder and options give the same bytes.
    let again = std::fs::read(run.join("view.html")).unwrap();
    assert!(first == again, "view.html differs from run --view's");
    let o = Command::new(exe())
        .arg("view")
        .arg(&run)
        .arg("--out")
        .arg(dir.join("copy.html"))
        .args(["-q", "--max-frames", "50"])
        .output()
        .unwrap();
    assert!(o.status.success());
    assert!(
        again == std::fs::read(dir.join("copy.html")).unwrap(),
        "not the same bytes"
    );
    // The page is one file with nothing to fetch: no http(s) source or link in it.
    let text = String::from_utf8(again).unwrap();
    for bad in ["src=\"http", "href=\"http", "<script src", "<link "] {
        assert!(
            !text.contains(bad),
            "the page refers to something outside: {bad}"
        );
    }
    assert!(
        text.contains("Copyright © 2010-2026 three.js authors")
            || text.contains("three.js authors")
    );
}
