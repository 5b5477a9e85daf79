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

/// A bodies.csv cut at a row boundary inside its last sample (whole rows, the last sample at the
/// run's end time, but only 15 of its 20 apples) is refused naming the file; so is one whose
/// rows of a sample in the middle went missing. The first look accepted the first and showed
/// 15 of 20 apples at the end.
#[test]
fn a_bodies_csv_cut_at_a_row_boundary() {
    let dir = tmp("cut_rows");
    let run = dir.join("run");
    let o = Command::new(exe())
        .args(["run", "scenarios/handling_line.json", "-q", "--out"])
        .arg(&run)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let path = run.join("bodies.csv");
    let text = std::fs::read_to_string(&path).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let last_t = lines[lines.len() - 1].split(',').next().unwrap();
    let in_last = lines
        .iter()
        .filter(|l| l.starts_with(&format!("{last_t},")))
        .count();
    assert_eq!(in_last, 20);
    // The last 5 rows cut off: the last sample keeps its time, with 15 apples.
    let cut = lines[..lines.len() - 5].join("\n") + "\n";
    std::fs::write(&path, cut).unwrap();
    let err = view_fails(&run, &dir.join("view.html"));
    assert!(
        err.contains(&format!(
            "{}: the last sample (t = 10 s) has 15 apples where the one before it has 20: the file is truncated",
            path.display()
        )),
        "{err}"
    );
    // Rows of a sample in the middle missing.
    let mid_t = lines[lines.len() / 2]
        .split(',')
        .next()
        .unwrap()
        .to_string();
    let kept: Vec<&str> = lines
        .iter()
        .enumerate()
        .filter(|(k, l)| !(l.starts_with(&format!("{mid_t},")) && k % 2 == 0))
        .map(|(_, l)| *l)
        .collect();
    std::fs::write(&path, kept.join("\n") + "\n").unwrap();
    let err = view_fails(&run, &dir.join("view.html"));
    assert!(
        err.contains(&format!(
            "{}: the sample at t = {mid_t} s has ",
            path.display()
        )) && err.contains("rows are missing, the file is damaged"),
        "{err}"
    );
    // Whole, it views, and every apple is in the last sample.
    std::fs::write(&path, &text).unwrap();
    let o = Command::new(exe())
        .arg("view")
        .arg(&run)
        .arg("--out")
        .arg(dir.join("view.html"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// A damaged shape column of a run with spheroids (issue 29): an orientation that is no unit
/// quaternion, a height that is not a number. Each is refused naming bodies.csv and the line;
/// whole, the run views.
#[test]
fn a_damaged_orientation_in_bodies_csv() {
    let dir = tmp("damaged_shape");
    let mut sc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string("scenarios/drop_on_steel.json").unwrap())
            .unwrap();
    sc["apples"][0]["height_m"] = 0.07.into();
    sc["apples"][0]["rotation"] = serde_json::json!({ "axis": [1, 0, 0], "angle_deg": 30 });
    sc["output"]["sample_interval_s"] = 1e-3.into();
    let sc_path = dir.join("spheroid.json");
    std::fs::write(&sc_path, sc.to_string()).unwrap();
    let run = dir.join("run");
    let o = Command::new(exe())
        .arg("run")
        .arg(&sc_path)
        .args(["-q", "--out"])
        .arg(&run)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let path = run.join("bodies.csv");
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(
        text.starts_with("time_s,apple,")
            && text
                .lines()
                .next()
                .unwrap()
                .ends_with(",height_m,qw,qx,qy,qz")
    );
    // Line 3 (the second sample): its quaternion (the last four cells) zeroed, then its height.
    let damage = |f: &dyn Fn(&mut Vec<String>)| {
        let mut lines: Vec<String> = text.lines().map(String::from).collect();
        let mut cells: Vec<String> = lines[2].split(',').map(String::from).collect();
        f(&mut cells);
        lines[2] = cells.join(",");
        std::fs::write(&path, lines.join("\n") + "\n").unwrap();
    };
    damage(&|c| {
        let n = c.len();
        c[n - 4..].iter_mut().for_each(|x| *x = "0".into());
    });
    let err = view_fails(&run, &dir.join("view.html"));
    assert!(
        err.contains(&format!(
            "{}: line 3: the orientation (qw, qx, qy, qz) has norm 0, not 1: the file is damaged",
            path.display()
        )),
        "{err}"
    );
    damage(&|c| {
        let n = c.len();
        c[n - 5] = "tall".into();
    });
    let err = view_fails(&run, &dir.join("view.html"));
    assert!(
        err.contains(&format!(
            "{}: line 3: height_m = 'tall' is not a finite number",
            path.display()
        )),
        "{err}"
    );
    std::fs::write(&path, &text).unwrap();
    let o = Command::new(exe())
        .arg("view")
        .arg(&run)
        .arg("--out")
        .arg(dir.join("view.html"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// A run of a free-turning roller (the bearing spin-down of tests/rollers.rs, item 1a) in
/// `dir/run`: it writes rollers.csv.
fn free_roller_run(dir: &Path) -> PathBuf {
    let sc = serde_json::json!({
        "duration_s": 0.2, "time_step_s": 1e-4, "gravity_m_s2": [0, 0, -9.81],
        "output": {"sample_interval_s": 0.02, "force_history": false},
        "materials": {
            "apple": {"youngs_modulus_pa": 3e6, "poisson_ratio": 0.3, "density_kg_m3": 800},
            "steel": {"youngs_modulus_pa": 2e11, "poisson_ratio": 0.28}},
        "contact": {"friction": 0.5, "ke": 0.09, "lambda_s_m": 1000},
        "apples": [{"name": "far", "material": "apple", "diameter_m": 0.075,
            "position_m": [0, 1, -0.5 + 0.0374]}],
        "surfaces": [
            {"name": "r", "type": "roller", "material": "steel", "radius_m": 0.03,
             "length_m": 0.3, "position_m": [0, 0, 0], "axis": [1, 0, 0],
             "angular_velocity_rad_s": 10,
             "free_turning": {"moment_of_inertia_kg_m2": 2e-4, "bearing_torque_n_m": 1e-3}},
            {"name": "floor", "type": "plane", "material": "steel",
             "point_m": [0, 0, -0.5], "normal": [0, 0, 1]}]
    });
    let path = dir.join("free.json");
    std::fs::write(&path, sc.to_string()).unwrap();
    let run = dir.join("run");
    let o = Command::new(exe())
        .arg("run")
        .arg(&path)
        .args(["-q", "--out"])
        .arg(&run)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(run.join("rollers.csv").is_file());
    run
}

/// A truncated or damaged rollers.csv is refused naming it (no HTML written), rather than
/// drawing the free roller at wrong angles; without the file (a run from before it was
/// written) the page is written, the roller drawn without its turn and a note saying why.
#[test]
fn a_truncated_rollers_csv() {
    let dir = tmp("rollers");
    let run = free_roller_run(&dir);
    let path = run.join("rollers.csv");
    let rollers = std::fs::read(&path).unwrap();
    let named = |err: &str| {
        assert!(err.contains(&format!("{}: ", path.display())), "{err}");
    };

    // Cut in the middle of a row (after its second field).
    let last_nl = rollers[..rollers.len() - 1]
        .iter()
        .rposition(|&b| b == b'\n')
        .unwrap();
    let second_comma = last_nl
        + 1
        + rollers[last_nl + 1..]
            .iter()
            .enumerate()
            .filter(|(_, &b)| b == b',')
            .nth(1)
            .unwrap()
            .0;
    std::fs::write(&path, &rollers[..second_comma + 2]).unwrap();
    let err = view_fails(&run, &dir.join("view.html"));
    named(&err);
    assert!(
        err.contains("fields where the header has 5: the file is truncated"),
        "{err}"
    );

    // Cut at the end of a row: whole rows, but the last sample (the run's end) has none.
    std::fs::write(&path, &rollers[..last_nl + 1]).unwrap();
    let err = view_fails(&run, &dir.join("view.html"));
    named(&err);
    assert!(
        err.contains(
            "no row of roller 'r' at t = 0.2 s (a sample of bodies.csv): the file is truncated"
        ),
        "{err}"
    );

    // A number damaged.
    let text = String::from_utf8(rollers.clone()).unwrap();
    std::fs::write(&path, text.replacen(",r,0,10,", ",r,x,10,", 1)).unwrap();
    let err = view_fails(&run, &dir.join("view.html"));
    named(&err);
    assert!(
        err.contains("line 2: angle_rad = 'x' is not a finite number"),
        "{err}"
    );

    // Empty (cut before its header).
    std::fs::write(&path, b"").unwrap();
    let err = view_fails(&run, &dir.join("view.html"));
    assert!(err.contains("rollers.csv: empty file"), "{err}");

    // Without it: viewed, the roller drawn without its turn, and the page says why.
    std::fs::remove_file(&path).unwrap();
    let o = Command::new(exe())
        .arg("view")
        .arg(&run)
        .arg("--out")
        .arg(dir.join("old.html"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        out.contains("roller 'r' turns freely in the run, and the run folder has no rollers.csv"),
        "{out}"
    );
    std::fs::write(&path, &rollers).unwrap();
    let o = Command::new(exe())
        .arg("view")
        .arg(&run)
        .arg("--out")
        .arg(dir.join("new.html"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(
        String::from_utf8_lossy(&o.stdout).contains("free-turning roller(s) 'r' drawn turning"),
        "{}",
        String::from_utf8_lossy(&o.stdout)
    );
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
