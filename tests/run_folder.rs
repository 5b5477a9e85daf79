//! Issue 18: a result folder holds one run's complete set or the previous complete set, never
//! a mix. `applesim run --out DIR` killed with SIGKILL at 100 points of its run (drawn from a
//! seeded generator over the measured length of a run), two runs into one folder at once,
//! folders that are not a run's, and a run that fails.
#![cfg(unix)] // kill -9, SIGSTOP, flock: Unix processes and locks

use rand::{Rng, SeedableRng};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use crate::procs;

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).to_string()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// drop_on_steel.json at impact speed `vz_m_s`, 0.1 s with ParaView frames every 5 ms: about
/// 0.35 s of a run of which a good part writes files (22 VTK files, CSVs, charts).
fn scenario(dir: &Path, name: &str, vz_m_s: f64) -> PathBuf {
    let mut v: serde_json::Value = serde_json::from_slice(
        &std::fs::read(procs::repo("scenarios/drop_on_steel.json")).unwrap(),
    )
    .unwrap();
    v["duration_s"] = 0.1.into();
    v["output"]["vtk"] = serde_json::json!({ "interval_s": 0.005 });
    v["apples"][0]["velocity_m_s"][2] = vz_m_s.into();
    let p = dir.join(name);
    std::fs::write(&p, serde_json::to_vec_pretty(&v).unwrap()).unwrap();
    p
}

fn run_cmd(sc: &Path, out: &Path) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_applesim"));
    c.args(["run", s(sc), "--out", s(out), "--plots", "--quiet"]);
    c
}

#[track_caller]
fn run_ok(sc: &Path, out: &Path) {
    let o = run_cmd(sc, out).output().unwrap();
    assert!(o.status.success(), "{}", text(&o.stderr));
}

/// Every file of a result folder by relative path; `summary.json` without its `wall_time_s`
/// (a measurement of the machine, the one field that differs between two runs).
fn set_of(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    fn walk(root: &Path, dir: &Path, out: &mut BTreeMap<String, Vec<u8>>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk(root, &p, out);
                continue;
            }
            let rel = p.strip_prefix(root).unwrap().to_string_lossy().to_string();
            let mut bytes = std::fs::read(&p).unwrap();
            if rel == "summary.json" {
                bytes = text(&bytes)
                    .lines()
                    .filter(|l| !l.contains("\"wall_time_s\""))
                    .collect::<Vec<_>>()
                    .join("\n")
                    .into_bytes();
            }
            out.insert(rel, bytes);
        }
    }
    let mut out = BTreeMap::new();
    walk(dir, dir, &mut out);
    out
}

/// Which reference set `dir` holds, byte for byte: `Some(k)`, or `None` for anything else.
fn which(dir: &Path, refs: &[BTreeMap<String, Vec<u8>>]) -> Option<usize> {
    let here = set_of(dir);
    refs.iter().position(|r| *r == here)
}

/// Entries of `parent` other than `keep`.
fn beside(parent: &Path, keep: &str) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(parent)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .filter(|n| n != keep && !n.ends_with(".json"))
        .collect();
    v.sort();
    v
}

#[test]
fn a_run_killed_at_100_points_leaves_the_old_set_or_the_new_one() {
    let dir = procs::scratch("run-folder", "kill");
    let scs = [
        scenario(&dir, "a.json", -1.4),
        scenario(&dir, "b.json", -0.9),
    ];
    let refs: Vec<BTreeMap<String, Vec<u8>>> = scs
        .iter()
        .enumerate()
        .map(|(k, sc)| {
            let r = dir.join(format!("ref{k}"));
            run_ok(sc, &r);
            set_of(&r)
        })
        .collect();
    assert_ne!(refs[0], refs[1]);
    assert!(
        refs[0].contains_key("vtk/apples_000020.vtp") && refs[0].contains_key("force_time.svg")
    );

    // The length of a whole run replacing a set, start to exit, on this machine now: the
    // median of five (fsync's latency on a shared disk varies from run to run).
    let out = dir.join("out");
    let mut lengths: Vec<Duration> = [0, 1, 0, 1, 0]
        .iter()
        .map(|&k| {
            let t0 = Instant::now();
            run_ok(&scs[k], &out);
            t0.elapsed()
        })
        .collect();
    lengths.sort();
    let whole = lengths[2];
    let mut holds = 0;
    assert_eq!(which(&out, &refs), Some(holds));

    // Each kill replaces the set the folder holds by the other one.
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(18);
    let (mut kept, mut switched, mut finished) = (0, 0, 0);
    for k in 0..100 {
        let next = 1 - holds;
        let at = whole.mul_f64(rng.random_range(0.0..1.0));
        let mut child = run_cmd(&scs[next], &out)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        let start = Instant::now();
        while start.elapsed() < at {
            if child.try_wait().unwrap().is_some() {
                break;
            }
            std::thread::sleep(Duration::from_millis(1));
        }
        let status = match child.try_wait().unwrap() {
            Some(st) => {
                finished += 1;
                assert!(st.success(), "kill {k}: the run failed on its own");
                st
            }
            None => {
                child.kill().unwrap();
                child.wait().unwrap()
            }
        };
        match which(&out, &refs) {
            Some(h) if h == holds => kept += 1,
            Some(_) => {
                switched += 1;
                holds = next;
            }
            None => panic!(
                "kill {k} at {at:?} ({status}): {} holds neither the old set nor the new one: {:?}",
                out.display(),
                set_of(&out).keys().collect::<Vec<_>>()
            ),
        }
    }
    println!(
        "a run takes {whole:?}; 100 kills: {kept} left the old set, {switched} the new one \
         ({finished} runs had finished before their kill point)"
    );
    assert_eq!(kept + switched, 100);
    assert!(kept > 0, "no kill landed before the switch");

    // The next run into the folder removes what the killed ones left beside it.
    run_ok(&scs[1 - holds], &out);
    assert_eq!(which(&out, &refs), Some(1 - holds));
    assert_eq!(beside(&dir, "out"), ["ref0", "ref1"]);
    let _ = std::fs::remove_dir_all(&dir);
}

fn spawn_run(sc: &Path, out: &Path) -> std::process::Child {
    run_cmd(sc, out)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

#[test]
fn two_runs_into_one_folder_never_both_succeed_with_a_mixed_set() {
    let dir = procs::scratch("run-folder", "concurrent");
    // Longer runs (1 s simulated) so that the second run starts while the first one writes.
    let long = |name: &str, vz: f64| {
        let p = scenario(&dir, name, vz);
        let mut v: serde_json::Value = serde_json::from_slice(&std::fs::read(&p).unwrap()).unwrap();
        v["duration_s"] = 1.0.into();
        v["output"]["vtk"] = serde_json::json!({ "interval_s": 0.05 });
        std::fs::write(&p, serde_json::to_vec_pretty(&v).unwrap()).unwrap();
        p
    };
    let scs = [long("a.json", -1.4), long("b.json", -0.9)];
    let refs: Vec<BTreeMap<String, Vec<u8>>> = scs
        .iter()
        .enumerate()
        .map(|(k, sc)| {
            let r = dir.join(format!("ref{k}"));
            run_ok(sc, &r);
            set_of(&r)
        })
        .collect();
    let out = dir.join("out");
    run_ok(&scs[0], &out);

    // The second run starts while the first one is in flight (frozen with its staged folder
    // there, so that it cannot finish meanwhile): it is refused at once, and the first one's
    // set is switched in whole once it goes on.
    for (first, second) in [(1, 0), (0, 1)] {
        let a = spawn_run(&scs[first], &out);
        let a_pid = a.id();
        procs::freeze_a_run(&dir, |_, pid| pid == a_pid);
        let b: Output = run_cmd(&scs[second], &out).output().unwrap();
        assert!(procs::signal(a_pid, libc::SIGCONT));
        let a = a.wait_with_output().unwrap();
        assert!(a.status.success(), "{}", text(&a.stderr));
        assert_eq!(b.status.code(), Some(1));
        assert!(
            text(&b.stderr).contains("another applesim process is writing this folder now"),
            "{}",
            text(&b.stderr)
        );
        assert_eq!(which(&out, &refs), Some(first));
    }

    // Started together, in either order: never both succeed with a mix; the folder holds the
    // set of one that succeeded.
    let mut outcomes = BTreeMap::new();
    for round in 0..6 {
        let (x, y) = (round % 2, 1 - round % 2);
        let a = spawn_run(&scs[x], &out);
        let b = spawn_run(&scs[y], &out);
        let (a, b) = (a.wait_with_output().unwrap(), b.wait_with_output().unwrap());
        let holds = which(&out, &refs).expect("a complete set of one run");
        let ok = [(x, &a), (y, &b)]
            .iter()
            .filter(|(_, o)| o.status.success())
            .map(|(k, _)| *k)
            .collect::<Vec<_>>();
        assert!(!ok.is_empty(), "both refused");
        assert!(ok.contains(&holds), "the folder holds a run that failed");
        for o in [&a, &b] {
            if !o.status.success() {
                assert!(
                    text(&o.stderr).contains("another applesim process is writing"),
                    "{}",
                    text(&o.stderr)
                );
            }
        }
        *outcomes.entry(ok.len()).or_insert(0) += 1;
    }
    println!("started together: {outcomes:?} (succeeded: rounds)");
    assert_eq!(beside(&dir, "out"), ["ref0", "ref1"]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn folders_that_are_not_a_run_are_refused_and_a_failed_run_keeps_the_old_set() {
    let dir = procs::scratch("run-folder", "refuse");
    let sc = scenario(&dir, "a.json", -1.4);
    // A folder of the user's own files.
    let mine = dir.join("thesis");
    std::fs::create_dir_all(&mine).unwrap();
    std::fs::write(mine.join("chapter1.tex"), "x").unwrap();
    let o = run_cmd(&sc, &mine).output().unwrap();
    assert_eq!(o.status.code(), Some(1));
    let e = text(&o.stderr);
    assert!(
        e.contains("'chapter1.tex'") && e.contains("not an applesim result folder"),
        "{e}"
    );
    assert_eq!(
        std::fs::read_dir(&mine).unwrap().count(),
        1,
        "the folder was changed"
    );
    // A file.
    let file = dir.join("file.txt");
    std::fs::write(&file, "x").unwrap();
    let o = run_cmd(&sc, &file).output().unwrap();
    assert!(
        text(&o.stderr).contains("this is a file"),
        "{}",
        text(&o.stderr)
    );
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "x");

    // A run that fails (an impact resolved in too few steps) leaves the old set as it was.
    let out = dir.join("out");
    run_ok(&sc, &out);
    let before = set_of(&out);
    let mut v: serde_json::Value = serde_json::from_slice(&std::fs::read(&sc).unwrap()).unwrap();
    v["time_step_s"] = 1e-3.into();
    let bad = dir.join("bad.json");
    std::fs::write(&bad, serde_json::to_vec(&v).unwrap()).unwrap();
    let o = run_cmd(&bad, &out).output().unwrap();
    assert_eq!(o.status.code(), Some(1));
    assert!(text(&o.stderr).contains("unstable"), "{}", text(&o.stderr));
    assert_eq!(set_of(&out), before);
    let mut left = beside(&dir, "out");
    left.retain(|n| !n.starts_with("thesis") && n != "file.txt");
    assert!(left.is_empty(), "{left:?}");
    let _ = std::fs::remove_dir_all(&dir);
}
