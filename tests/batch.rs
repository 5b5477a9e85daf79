//! Batches through the real binary (issue 5 acceptance): the 7 x 3 impact sweep and its
//! trends, a batch with an invalid run, kill and resume, and byte-identical merged tables
//! whatever the number of jobs or shards.

use std::collections::{BTreeMap, BTreeSet};
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

#[cfg(unix)]
use crate::procs;

const SWEEP: &str = "scenarios/batches/impact_sweep.json";

fn repo(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)
}

/// A fresh folder for one test.
fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("applesim-batch-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn applesim(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_applesim"))
        .args(args)
        .env_remove("SLURM_ARRAY_TASK_ID")
        .env_remove("JOB_COMPLETION_INDEX")
        .output()
        .unwrap()
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).to_string()
}

#[track_caller]
fn ok(o: &Output) -> String {
    assert!(
        o.status.success(),
        "exit {:?}\nstdout:\n{}\nstderr:\n{}",
        o.status,
        text(&o.stdout),
        text(&o.stderr)
    );
    text(&o.stdout)
}

/// (header, rows) of a CSV file.
fn read_csv(path: &Path) -> (Vec<String>, Vec<BTreeMap<String, String>>) {
    let mut r = csv::Reader::from_path(path).unwrap();
    let header: Vec<String> = r.headers().unwrap().iter().map(String::from).collect();
    let rows = r
        .records()
        .map(|rec| {
            header
                .iter()
                .cloned()
                .zip(rec.unwrap().iter().map(String::from))
                .collect()
        })
        .collect();
    (header, rows)
}

/// Indices of the runs a batch printed as run now (`ok` lines).
fn ran(stdout: &str) -> BTreeSet<usize> {
    stdout
        .lines()
        .filter_map(|l| l.strip_prefix("ok "))
        .map(|l| l.split_whitespace().next().unwrap().parse().unwrap())
        .collect()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn impact_sweep_gives_21_rows_with_peak_force_rising_with_speed_and_size() {
    let out = scratch("sweep");
    let spec = repo(SWEEP);
    let stdout = ok(&applesim(&[
        "batch",
        s(&spec),
        "--out",
        s(&out),
        "--jobs",
        "2",
    ]));
    assert_eq!(ran(&stdout).len(), 21, "{stdout}");
    ok(&applesim(&["merge", s(&out)]));
    let (header, rows) = read_csv(&out.join("merged.csv"));
    assert_eq!(
        &header[..6],
        ["index", "id", "status", "vz_m_s", "diameter_m", "z0_m"]
    );
    assert_eq!(header.last().unwrap(), "error");
    assert!(!header.iter().any(|h| h == "wall_time_s"));
    assert_eq!(rows.len(), 21);
    // peak[speed][size]
    let speeds = [-0.2, -0.4, -0.6, -0.8, -1.0, -1.2, -1.4];
    let sizes = [0.06, 0.08, 0.1];
    let mut peak = [[f64::NAN; 3]; 7];
    for (k, row) in rows.iter().enumerate() {
        assert_eq!(row["index"], k.to_string());
        assert_eq!(row["status"], "ok", "{row:?}");
        assert_eq!(row["error"], "");
        let v: f64 = row["vz_m_s"].parse().unwrap();
        let d: f64 = row["diameter_m"].parse().unwrap();
        let z: f64 = row["z0_m"].parse().unwrap();
        assert_eq!(
            (v, d),
            (speeds[k / 3], sizes[k % 3]),
            "expansion order: speed slowest"
        );
        assert!(
            (z - (d / 2.0 + 1e-4)).abs() < 1e-12,
            "the grouped start height moves with the size"
        );
        peak[k / 3][k % 3] = row["max_peak_force_n"].parse().unwrap();
    }
    // Issue 20: per-surface columns (the line audit's transfer points), and no velocity change
    // above the largest impact speed times (1 + e): the fastest apple touches at
    // sqrt(1.4^2 + 2 g 0.1 mm) and eq. 12 with ke = 0.09 rebounds with at most e = sqrt(ke)
    // (physics.md section 3; gravity only lowers it).
    for col in [
        "floor.impacts",
        "floor.max_peak_force_n",
        "floor.max_peak_g",
        "floor.p95_peak_g",
        "floor.max_velocity_change_m_s",
        "floor.apples_bruised",
        "floor.bruise_volume_mm3",
        "floor.apples_downgraded",
    ] {
        assert!(header.iter().any(|h| h == col), "no {col}: {header:?}");
    }
    let v_max = (1.4f64 * 1.4 + 2.0 * 9.81 * 1e-4).sqrt();
    let bound = (1.0 + 0.09f64.sqrt()) * v_max;
    let dv_cols: Vec<&String> = header
        .iter()
        .filter(|h| h.ends_with("velocity_change_m_s"))
        .collect();
    assert!(dv_cols.len() >= 2, "{dv_cols:?}");
    let mut largest = 0.0f64;
    for row in &rows {
        assert!(
            row["floor.impacts"].parse::<f64>().unwrap() >= 1.0,
            "{row:?}"
        );
        for c in &dv_cols {
            let dv: f64 = row[c.as_str()].parse().unwrap();
            largest = largest.max(dv);
            assert!(dv <= bound, "{c} = {dv} > {bound}: {row:?}");
        }
    }
    println!("largest velocity change {largest:.4} m/s, bound (1 + sqrt(ke)) v = {bound:.4} m/s");
    for (i, row) in peak.iter().enumerate() {
        println!(
            "v {:>4} m/s: peak force {:8.3} {:8.3} {:8.3} N (D 60, 80, 100 mm)",
            -speeds[i], row[0], row[1], row[2]
        );
    }
    for i in 0..7 {
        for j in 0..3 {
            assert!(peak[i][j].is_finite() && peak[i][j] > 0.0);
            if i > 0 {
                assert!(
                    peak[i][j] > peak[i - 1][j],
                    "speed {} -> {}, D {}: {} !> {}",
                    speeds[i - 1],
                    speeds[i],
                    sizes[j],
                    peak[i][j],
                    peak[i - 1][j]
                );
            }
            if j > 0 {
                assert!(
                    peak[i][j] > peak[i][j - 1],
                    "speed {}, D {} -> {}: {} !> {}",
                    speeds[i],
                    sizes[j - 1],
                    sizes[j],
                    peak[i][j],
                    peak[i][j - 1]
                );
            }
        }
    }
    // Every run folder is complete and records its parameters beside its results.
    for row in &rows {
        let dir = out.join("runs").join(&row["id"]);
        for f in [
            "summary.json",
            "contacts.csv",
            "bodies.csv",
            "scenario.json",
            "params.json",
        ] {
            assert!(dir.join(f).is_file(), "{}: no {f}", dir.display());
        }
        let p: serde_json::Value =
            serde_json::from_slice(&std::fs::read(dir.join("params.json")).unwrap()).unwrap();
        assert_eq!(p["id"], row["id"].as_str());
        assert_eq!(p["params"]["diameter_m"].to_string(), row["diameter_m"]);
    }
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn jobs_and_shards_give_byte_identical_merged_tables() {
    let root = scratch("determinism");
    let spec = repo(SWEEP);
    let merged = |name: &str, runs: &[Vec<&str>]| -> (Vec<u8>, Vec<BTreeSet<usize>>) {
        let out = root.join(name);
        let mut sets = vec![];
        for extra in runs {
            let mut args = vec!["batch", s(&spec), "--out", s(&out)];
            args.extend(extra.iter().copied());
            sets.push(ran(&ok(&applesim(&args))));
        }
        ok(&applesim(&["merge", s(&out)]));
        (std::fs::read(out.join("merged.csv")).unwrap(), sets)
    };
    let (one, _) = merged("jobs1", &[vec!["--jobs", "1"]]);
    let (two, _) = merged("jobs2", &[vec!["--jobs", "2"]]);
    let (shards, sets) = merged(
        "shards",
        &[
            vec!["--shard", "1/3"],
            vec!["--shard", "2/3", "--jobs", "2"],
            vec!["--shard", "3/3", "--jobs", "1"],
        ],
    );
    assert_eq!(text(&one), text(&two), "--jobs 1 and --jobs 2 differ");
    assert_eq!(
        text(&one),
        text(&shards),
        "--jobs 1 and shards 1/3+2/3+3/3 differ"
    );
    // The shards are disjoint and their union is the whole batch.
    let mut all = BTreeSet::new();
    for (k, set) in sets.iter().enumerate() {
        assert_eq!(set.len(), 7, "shard {}/3 ran {set:?}", k + 1);
        assert!(
            set.iter().all(|i| i % 3 == k),
            "shard {}/3 ran {set:?}",
            k + 1
        );
        assert!(all.is_disjoint(set));
        all.extend(set);
    }
    assert_eq!(all, (0..21).collect());
    // The runs' own files are identical too (summary.json only differs by wall_time_s).
    let (_, rows) = read_csv(&root.join("jobs1").join("merged.csv"));
    for row in &rows {
        for f in ["contacts.csv", "bodies.csv", "scenario.json", "params.json"] {
            let a = std::fs::read(root.join("jobs1/runs").join(&row["id"]).join(f)).unwrap();
            let b = std::fs::read(root.join("shards/runs").join(&row["id"]).join(f)).unwrap();
            assert!(
                a == b,
                "run {} {f} differs between --jobs 1 and the shards",
                row["id"]
            );
        }
    }

    // --shard auto: a Kubernetes indexed Job of 3 pods gives the same shards.
    let out = root.join("k8s");
    for (k, set) in sets.iter().enumerate() {
        let o = Command::new(env!("CARGO_BIN_EXE_applesim"))
            .args(["batch", s(&spec), "--out", s(&out), "--shard", "auto"])
            .env_remove("SLURM_ARRAY_TASK_ID")
            .env("JOB_COMPLETION_INDEX", k.to_string())
            .env("APPLESIM_SHARD_COUNT", "3")
            .output()
            .unwrap();
        let stdout = ok(&o);
        assert_eq!(&ran(&stdout), set, "pod {k}");
    }
    ok(&applesim(&["merge", s(&out)]));
    assert_eq!(
        text(&one),
        text(&std::fs::read(out.join("merged.csv")).unwrap())
    );
    let _ = std::fs::remove_dir_all(&root);
}

/// A spec in `dir` over drop_on_steel.json with short runs.
fn write_spec(dir: &Path, name: &str, set_extra: &str, parameters: &str) -> PathBuf {
    let spec = dir.join(name);
    let base = repo("scenarios/drop_on_steel.json");
    std::fs::write(
        &spec,
        format!(
            r#"{{ "base": {base:?},
                 "set": {{ "/duration_s": 0.015, "/output/force_history": false {set_extra} }},
                 "parameters": {parameters} }}"#
        ),
    )
    .unwrap();
    spec
}

#[test]
fn an_invalid_run_fails_alone_and_the_batch_exits_non_zero() {
    let dir = scratch("failure");
    let out = dir.join("out");
    let spec = write_spec(
        &dir,
        "friction.json",
        "",
        r#"[{ "name": "mu", "path": "/contact/friction", "values": [0.2, -1.0, 0.4] }]"#,
    );
    let o = applesim(&["batch", s(&spec), "--out", s(&out), "--jobs", "2"]);
    let stdout = text(&o.stdout);
    let stderr = text(&o.stderr);
    assert_eq!(
        o.status.code(),
        Some(1),
        "stdout:\n{stdout}\nstderr:\n{stderr}"
    );
    assert_eq!(ran(&stdout), BTreeSet::from([0, 2]), "{stdout}");
    assert!(
        stdout.contains("failed     1 ") && stdout.contains("error: contact.friction: -1"),
        "{stdout}"
    );
    assert!(stderr.contains("error: 1 of 3 runs failed"), "{stderr}");
    // The failure is recorded with its parameters; the others are complete.
    let failed: Vec<PathBuf> = std::fs::read_dir(out.join("runs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.to_string_lossy().ends_with(".failed.json"))
        .collect();
    assert_eq!(failed.len(), 1);
    let rec: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&failed[0]).unwrap()).unwrap();
    assert_eq!(rec["index"], 1);
    assert_eq!(rec["params"]["mu"], -1.0);
    assert!(
        rec["error"]
            .as_str()
            .unwrap()
            .starts_with("contact.friction: -1"),
        "{rec}"
    );
    // merge lists it, writes the table anyway and exits non-zero.
    let m = applesim(&["merge", s(&out)]);
    assert_eq!(m.status.code(), Some(1));
    assert!(
        text(&m.stderr).contains("failed  run 1 ("),
        "{}",
        text(&m.stderr)
    );
    let (_, rows) = read_csv(&out.join("merged.csv"));
    let status: Vec<&str> = rows.iter().map(|r| r["status"].as_str()).collect();
    assert_eq!(status, ["ok", "failed", "ok"]);
    assert!(rows[1]["error"].starts_with("contact.friction: -1"));
    assert_eq!(rows[1]["max_peak_force_n"], "");
    assert!(rows[0]["max_peak_force_n"].parse::<f64>().unwrap() > 0.0);
    // A rerun skips the failed run (it would fail again) and still exits 1: the shard has a
    // failed run.
    let o = applesim(&["batch", s(&spec), "--out", s(&out)]);
    assert_eq!(o.status.code(), Some(1));
    let stdout = text(&o.stdout);
    assert!(
        stdout.contains("2 run(s) done before: skipped")
            && stdout.contains("1 run(s) failed before: skipped (--retry-failed retries them)")
            && !stdout.contains("failed     1"),
        "{stdout}"
    );
    assert!(
        text(&o.stderr).contains("1 of 3 runs failed (0 now, 1 before and not retried"),
        "{}",
        text(&o.stderr)
    );
    assert!(ran(&stdout).is_empty());
    // --retry-failed retries it only.
    let o = applesim(&["batch", s(&spec), "--out", s(&out), "--retry-failed"]);
    assert_eq!(o.status.code(), Some(1));
    let stdout = text(&o.stdout);
    assert!(
        stdout.contains("2 run(s) done before: skipped") && stdout.contains("failed     1 "),
        "{stdout}"
    );
    assert!(ran(&stdout).is_empty());

    // A run that fails while running (an impact resolved in too few steps) is recorded too.
    let out2 = dir.join("out2");
    let spec2 = write_spec(
        &dir,
        "dt.json",
        "",
        r#"[{ "name": "dt_s", "path": "/time_step_s", "values": [1e-5, 1e-3] }]"#,
    );
    let o = applesim(&["batch", s(&spec2), "--out", s(&out2)]);
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(ran(&text(&o.stdout)), BTreeSet::from([0]));
    assert!(
        text(&o.stdout).contains("error: time_step_s: unstable"),
        "{}",
        text(&o.stdout)
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[cfg(unix)]
#[test]
fn a_killed_batch_resumes_with_the_remaining_runs_only() {
    let dir = scratch("resume");
    let out = dir.join("out");
    // 8 runs of about 0.3 s each (80 000 steps), one at a time.
    let spec = write_spec(
        &dir,
        "long.json",
        r#", "/duration_s": 0.8, "/output/sample_interval_s": 0.01"#,
        r#"[{ "name": "vz_m_s", "path": "/apples/0/velocity_m_s/2", "range": { "start": -0.5, "stop": -1.2, "step": -0.1 } }]"#,
    );
    let spec_text = std::fs::read_to_string(&spec)
        .unwrap()
        .replace(r#""/duration_s": 0.015, "#, "");
    std::fs::write(&spec, spec_text).unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_applesim"))
        .args(["batch", s(&spec), "--out", s(&out), "--jobs", "1"])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let mut lines = BufReader::new(child.stdout.take().unwrap()).lines();
    let mut first = 0;
    while first < 3 {
        let l = lines.next().expect("batch ended before 3 runs").unwrap();
        if l.starts_with("ok ") {
            first += 1;
        }
    }
    // Freeze the next run in flight (its process, found by its staged folder), then kill the
    // batch (SIGKILL: no chance to clean up); the run's process dies with it.
    let runs = out.join("runs");
    let (killed_id, run_pid) =
        procs::freeze_a_run(&runs, |_, pid| procs::parent_of(pid) == Some(child.id()));
    child.kill().unwrap();
    child.wait().unwrap();
    procs::wait_for("the run's process to die with its batch", || {
        procs::gone(run_pid).then_some(())
    });

    let manifest: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("batch.json")).unwrap()).unwrap();
    let id_of: BTreeMap<usize, String> = manifest["runs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| {
            (
                r["index"].as_u64().unwrap() as usize,
                r["id"].as_str().unwrap().to_string(),
            )
        })
        .collect();
    let killed = *id_of.iter().find(|(_, id)| **id == killed_id).unwrap().0;
    println!("killed in run {killed} ({killed_id})");
    assert!(killed >= 3, "runs 0-2 were reported done");

    // Exactly the runs before the killed one are complete, and nothing else is visible: the
    // killed run is there only as its staged folder and its lock file.
    let mut done: BTreeMap<String, std::time::SystemTime> = BTreeMap::new();
    let mut hidden = vec![];
    for e in std::fs::read_dir(&runs).unwrap() {
        let p = e.unwrap().path();
        let name = p.file_name().unwrap().to_string_lossy().to_string();
        if name.starts_with('.') {
            hidden.push(name);
            continue;
        }
        assert!(p.is_dir(), "{name}");
        for f in [
            "summary.json",
            "contacts.csv",
            "bodies.csv",
            "scenario.json",
            "params.json",
        ] {
            assert!(p.join(f).is_file(), "{name} lacks {f}: half-written");
        }
        done.insert(
            name,
            std::fs::metadata(p.join("summary.json"))
                .unwrap()
                .modified()
                .unwrap(),
        );
    }
    let expected_done: BTreeSet<String> = (0..killed).map(|k| id_of[&k].clone()).collect();
    assert_eq!(done.keys().cloned().collect::<BTreeSet<_>>(), expected_done);
    hidden.sort();
    assert_eq!(
        hidden,
        [
            format!(".{killed_id}.lock"),
            format!(".{killed_id}.tmp-{run_pid}-0")
        ]
    );
    let m = applesim(&["merge", s(&out)]);
    assert_eq!(m.status.code(), Some(1), "runs are missing");
    assert_eq!(text(&m.stderr).matches("missing run").count(), 8 - killed);

    // The rerun runs exactly the others and removes the killed run's staged folder.
    let stdout = ok(&applesim(&[
        "batch",
        s(&spec),
        "--out",
        s(&out),
        "--jobs",
        "1",
    ]));
    assert_eq!(ran(&stdout), (killed..8).collect(), "{stdout}");
    assert!(
        stdout.contains(&format!("{killed} run(s) done before: skipped")),
        "{stdout}"
    );
    assert!(stdout.contains("removed 1 temporary folder(s)"), "{stdout}");
    for (id, t) in &done {
        let now = std::fs::metadata(runs.join(id).join("summary.json"))
            .unwrap()
            .modified()
            .unwrap();
        assert_eq!(*t, now, "run {id} was rewritten");
    }
    let leftovers: Vec<_> = std::fs::read_dir(&runs)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .filter(|n| n.starts_with('.'))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
    ok(&applesim(&["merge", s(&out)]));
    let (_, rows) = read_csv(&out.join("merged.csv"));
    assert!(rows.iter().all(|r| r["status"] == "ok") && rows.len() == 8);

    // --force reruns everything, replacing each folder whole.
    let stdout = ok(&applesim(&[
        "batch",
        s(&spec),
        "--out",
        s(&out),
        "--jobs",
        "2",
        "--force",
    ]));
    assert_eq!(ran(&stdout).len(), 8);
    let leftovers: Vec<_> = std::fs::read_dir(&runs)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .filter(|n| n.starts_with('.'))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn dry_run_folder_batches_and_clear_errors() {
    let dir = scratch("cli");
    let spec = repo(SWEEP);
    let out = dir.join("out");
    let stdout = ok(&applesim(&[
        "batch",
        s(&spec),
        "--out",
        s(&out),
        "--dry-run",
        "--shard",
        "2/3",
    ]));
    assert!(
        stdout.starts_with("21 runs in the batch, 7 in shard 2/3"),
        "{stdout}"
    );
    let lines: Vec<&str> = stdout.lines().skip(1).collect();
    assert_eq!(lines.len(), 7);
    assert!(
        lines[0].trim_start().starts_with("1 ")
            && lines[0].contains(" todo ")
            && lines[0].contains("vz_m_s=-0.2 diameter_m=0.08 z0_m=0.0401"),
        "{}",
        lines[0]
    );
    assert!(!out.exists(), "--dry-run wrote {}", out.display());

    let e = applesim(&["batch", s(&spec), "--out", s(&out), "--shard", "auto"]);
    assert_eq!(e.status.code(), Some(1));
    assert!(
        text(&e.stderr).contains("neither SLURM_ARRAY_TASK_ID"),
        "{}",
        text(&e.stderr)
    );
    let e = applesim(&["batch", s(&spec), "--shard", "4/3"]);
    assert!(
        text(&e.stderr).contains("1 <= i <= n"),
        "{}",
        text(&e.stderr)
    );
    let bad = write_spec(
        &dir,
        "bad.json",
        "",
        r#"[{ "path": "/apples/1/diameter_m", "values": [0.07] }]"#,
    );
    let e = applesim(&["batch", s(&bad), "--out", s(&out)]);
    assert_eq!(e.status.code(), Some(1));
    assert!(text(&e.stderr).contains("bad.json: parameters[0].path: '/apples/1/diameter_m': '/apples' has 1 element(s), no index 1"), "{}", text(&e.stderr));
    let e = applesim(&["merge", s(&dir)]);
    assert_eq!(e.status.code(), Some(1));
    assert!(
        text(&e.stderr).contains("batch.json"),
        "{}",
        text(&e.stderr)
    );

    // A folder of scenario files: one run each, named by file; a broken file fails alone.
    let folder = dir.join("scenarios");
    std::fs::create_dir_all(&folder).unwrap();
    let base = std::fs::read_to_string(repo("scenarios/drop_on_steel.json")).unwrap();
    let short = base.replace("\"duration_s\": 0.03", "\"duration_s\": 0.01");
    std::fs::write(folder.join("a.json"), &short).unwrap();
    std::fs::write(folder.join("b.json"), short.replace("-1.4]", "-0.7]")).unwrap();
    std::fs::write(folder.join("c.json"), "{ not json").unwrap();
    std::fs::write(folder.join("notes.txt"), "ignored").unwrap();
    let out = dir.join("folder_out");
    let o = applesim(&["batch", s(&folder), "--out", s(&out)]);
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(ran(&text(&o.stdout)), BTreeSet::from([0, 1]));
    let m = applesim(&["merge", s(&out)]);
    assert_eq!(m.status.code(), Some(1));
    let (header, rows) = read_csv(&out.join("merged.csv"));
    assert_eq!(header[3], "file");
    let files: Vec<(&str, &str)> = rows
        .iter()
        .map(|r| (r["file"].as_str(), r["status"].as_str()))
        .collect();
    assert_eq!(
        files,
        [("a.json", "ok"), ("b.json", "ok"), ("c.json", "failed")]
    );
    assert!(
        rows[2]["error"].contains("not valid JSON"),
        "{}",
        rows[2]["error"]
    );
    let fa: f64 = rows[0]["max_peak_force_n"].parse().unwrap();
    let fb: f64 = rows[1]["max_peak_force_n"].parse().unwrap();
    assert!(fa > fb, "1.4 m/s hits harder than 0.7 m/s: {fa} vs {fb}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Issue 18: a run that aborts (a failed allocation of 152 GB for 1e9 apples) or is killed
/// fails alone, recorded with its cause; the batch goes on and a resume skips it.
#[cfg(unix)]
#[test]
fn a_run_that_aborts_or_is_killed_fails_alone_with_its_cause() {
    let dir = scratch("abort");
    let out = dir.join("out");
    let spec = dir.join("count.json");
    std::fs::write(
        &spec,
        format!(
            r#"{{"base": {:?}, "set": {{"/duration_s": 0.5}},
                "parameters": [{{"name": "count", "path": "/sources/0/count",
                                 "values": [5, 1000000000, 6, 7]}}]}}"#,
            repo("scenarios/handling_line.json")
        ),
    )
    .unwrap();
    // A small limit per run: whatever the 1e9 run tries, it fails fast and the machine keeps
    // its memory.
    let o = applesim(&[
        "batch",
        s(&spec),
        "--out",
        s(&out),
        "--jobs",
        "1",
        "--memory-limit",
        "256M",
    ]);
    let stdout = text(&o.stdout);
    assert_eq!(o.status.code(), Some(1), "{stdout}\n{}", text(&o.stderr));
    assert_eq!(ran(&stdout), BTreeSet::from([0, 2, 3]), "{stdout}");
    let failed: Vec<PathBuf> = std::fs::read_dir(out.join("runs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.to_string_lossy().ends_with(".failed.json"))
        .collect();
    assert_eq!(failed.len(), 1);
    let rec: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&failed[0]).unwrap()).unwrap();
    println!("{}", rec["error"]);
    assert_eq!(rec["index"], 1);
    assert_eq!(rec["params"]["count"], 1000000000);
    let error = rec["error"].as_str().unwrap();
    // Today the allocation aborts the run's process; once scenarios this large are refused
    // up front (issue 18 item 3), the refusal is the cause. Either way it names it.
    if rec.get("signal").is_some() {
        assert_eq!(rec["signal"], 6, "{rec}");
        assert_eq!(rec["signal_name"], "SIGABRT");
        assert!(
            error.contains("killed by signal 6 (SIGABRT): memory allocation of")
                && error.contains("over the per-run memory limit of 256 MiB"),
            "{error}"
        );
        assert!(rec["stderr"]
            .as_str()
            .unwrap()
            .contains("memory allocation of"));
    } else {
        assert!(
            error.contains("count") || error.contains("memory"),
            "{error}"
        );
    }
    assert!(stdout.contains(&format!("error: {error}")), "{stdout}");
    // Nothing of the failed run is left but its record.
    let hidden: Vec<String> = std::fs::read_dir(out.join("runs"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .filter(|n| n.starts_with('.'))
        .collect();
    assert!(hidden.is_empty(), "{hidden:?}");
    // A resume skips it; merge lists it with its cause.
    let o = applesim(&["batch", s(&spec), "--out", s(&out), "--jobs", "1"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(ran(&text(&o.stdout)).is_empty());
    assert!(text(&o.stdout).contains("1 run(s) failed before: skipped"));
    let m = applesim(&["merge", s(&out)]);
    assert_eq!(m.status.code(), Some(1));
    let (_, rows) = read_csv(&out.join("merged.csv"));
    let status: Vec<&str> = rows.iter().map(|r| r["status"].as_str()).collect();
    assert_eq!(status, ["ok", "failed", "ok", "ok"]);
    assert_eq!(rows[1]["error"], error);

    // A run's process killed by a signal (as by the out-of-memory killer or a user) is that
    // run's failure too: the next run of the batch still runs.
    let out2 = dir.join("out2");
    let spec2 = write_spec(
        &dir,
        "speeds.json",
        r#", "/duration_s": 0.5"#,
        r#"[{ "name": "vz_m_s", "path": "/apples/0/velocity_m_s/2", "values": [-0.5, -0.6, -0.7] }]"#,
    );
    let spec_text = std::fs::read_to_string(&spec2)
        .unwrap()
        .replace(r#""/duration_s": 0.015, "#, "");
    std::fs::write(&spec2, spec_text).unwrap();
    let batch = Command::new(env!("CARGO_BIN_EXE_applesim"))
        .args(["batch", s(&spec2), "--out", s(&out2), "--jobs", "1"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let (victim, pid) = procs::freeze_a_run(&out2.join("runs"), |_, pid| {
        procs::parent_of(pid) == Some(batch.id())
    });
    assert!(procs::signal(pid, libc::SIGKILL));
    let o = batch.wait_with_output().unwrap();
    let stdout = text(&o.stdout);
    assert_eq!(o.status.code(), Some(1), "{stdout}");
    assert_eq!(ran(&stdout), BTreeSet::from([1, 2]), "{stdout}");
    let rec: serde_json::Value = serde_json::from_slice(
        &std::fs::read(out2.join("runs").join(format!("{victim}.failed.json"))).unwrap(),
    )
    .unwrap();
    assert_eq!(rec["index"], 0);
    assert_eq!(rec["signal"], 9);
    assert!(
        rec["error"]
            .as_str()
            .unwrap()
            .starts_with("the run's process was killed by signal 9 (SIGKILL)"),
        "{rec}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Issue 18: `applesim batch --dry-run | head -4` panicked on the closed pipe with a
/// backtrace. A closed output pipe ends the command quietly (SIGPIPE, 141 in a shell).
#[cfg(unix)]
#[test]
fn a_closed_output_pipe_ends_the_command_quietly() {
    use std::os::unix::process::ExitStatusExt;
    let dir = scratch("pipe");
    // 3000 runs: the listing (some 200 kB) outgrows the pipe's buffer, so the command is still
    // writing when the pipe closes.
    let spec = write_spec(
        &dir,
        "many.json",
        "",
        r#"[{ "name": "vz_m_s", "path": "/apples/0/velocity_m_s/2", "range": { "start": -0.1, "stop": -3.0, "count": 3000 } }]"#,
    );
    let mut child = Command::new(env!("CARGO_BIN_EXE_applesim"))
        .args(["batch", s(&spec), "--dry-run"])
        .env("RUST_BACKTRACE", "1")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Read one line as `head -1` would, then close the pipe: every later write finds it closed.
    let mut out = BufReader::new(child.stdout.take().unwrap());
    let mut first = String::new();
    out.read_line(&mut first).unwrap();
    assert!(first.starts_with("3000 runs in the batch"), "{first}");
    drop(out);
    let o = child.wait_with_output().unwrap();
    assert_eq!(o.status.signal(), Some(13), "{:?}", o.status);
    assert_eq!(text(&o.stderr), "");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Issue 31 item 4: `applesim batch` writes merged.csv once every run of the batch has ended,
/// as the README says: a shard that ends while others have not says so and writes none; the
/// last shard writes it, the same bytes as `applesim merge`.
#[test]
fn the_batch_writes_its_table_when_every_run_has_ended() {
    let out = scratch("auto_merge");
    let spec = repo(SWEEP);
    let first = ok(&applesim(&[
        "batch",
        s(&spec),
        "--out",
        s(&out),
        "--shard",
        "1/2",
    ]));
    assert!(
        !out.join("merged.csv").exists(),
        "written before the batch ended"
    );
    assert!(
        first.contains("runs of the batch have not ended (other shards)"),
        "{first}"
    );
    let last = ok(&applesim(&[
        "batch",
        s(&spec),
        "--out",
        s(&out),
        "--shard",
        "2/2",
    ]));
    assert!(
        last.contains("merged.csv: 21 rows, 21 ok, 0 failed"),
        "{last}"
    );
    let by_batch = std::fs::read(out.join("merged.csv")).unwrap();
    ok(&applesim(&["merge", s(&out)]));
    assert_eq!(
        text(&by_batch),
        text(&std::fs::read(out.join("merged.csv")).unwrap())
    );
    let _ = std::fs::remove_dir_all(out);
}
