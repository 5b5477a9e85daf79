//! Issue 18: shards of one batch that overlap, one killed and resubmitted by its index while
//! the other runs, end with every run done once and no run's folder deleted under it; a
//! resubmitted Slurm task runs the shard it names or is refused with the commands that would.
#![cfg(unix)] // kill -9, SIGSTOP, flock: Unix processes and locks

use std::collections::{BTreeMap, BTreeSet};
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::sync::{Arc, Mutex};

use crate::procs;

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).to_string()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

const SLURM: [&str; 5] = [
    "SLURM_ARRAY_TASK_ID",
    "SLURM_ARRAY_TASK_MIN",
    "SLURM_ARRAY_TASK_MAX",
    "SLURM_ARRAY_TASK_COUNT",
    "SLURM_ARRAY_TASK_STEP",
];

/// `applesim batch SPEC --out OUT ARGS` as Slurm array task `id` of an array `min..max`.
fn task(spec: &Path, out: &Path, args: &[&str], slurm: Option<[i64; 3]>) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_applesim"));
    c.args(["batch", s(spec), "--out", s(out), "--jobs", "1"])
        .args(args)
        .env_remove("JOB_COMPLETION_INDEX")
        .env_remove("APPLESIM_SHARD_COUNT");
    for v in SLURM {
        c.env_remove(v);
    }
    if let Some([id, min, max]) = slurm {
        c.env("SLURM_ARRAY_TASK_ID", id.to_string())
            .env("SLURM_ARRAY_TASK_MIN", min.to_string())
            .env("SLURM_ARRAY_TASK_MAX", max.to_string())
            .env("SLURM_ARRAY_TASK_COUNT", (max - min + 1).to_string());
    }
    c
}

/// A batch process whose standard output is collected line by line as it comes (so that a
/// killed one's lines are kept).
struct Running {
    child: Child,
    lines: Arc<Mutex<Vec<String>>>,
    reader: std::thread::JoinHandle<()>,
}

fn start(mut c: Command) -> Running {
    let mut child = c
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .unwrap();
    let out = child.stdout.take().unwrap();
    let lines = Arc::new(Mutex::new(vec![]));
    let sink = lines.clone();
    let reader = std::thread::spawn(move || {
        for l in BufReader::new(out).lines() {
            sink.lock().unwrap().push(l.unwrap());
        }
    });
    Running {
        child,
        lines,
        reader,
    }
}

impl Running {
    fn finish(mut self) -> (std::process::ExitStatus, Vec<String>) {
        let st = self.child.wait().unwrap();
        self.reader.join().unwrap();
        let lines = self.lines.lock().unwrap().clone();
        (st, lines)
    }
}

/// Indices of the runs a batch printed as run now (`ok` lines).
fn ran(lines: &[String]) -> Vec<usize> {
    lines
        .iter()
        .filter_map(|l| l.strip_prefix("ok "))
        .map(|l| l.split_whitespace().next().unwrap().parse().unwrap())
        .collect()
}

/// 8 impacts of about half a second each.
fn spec(dir: &Path) -> PathBuf {
    let spec = dir.join("spec.json");
    std::fs::write(
        &spec,
        format!(
            r#"{{ "base": {:?},
                 "set": {{ "/duration_s": 1.2, "/output/sample_interval_s": 0.01,
                           "/output/force_history": false }},
                 "parameters": [{{ "name": "vz_m_s", "path": "/apples/0/velocity_m_s/2",
                                   "range": {{ "start": -0.5, "stop": -1.2, "step": -0.1 }} }}] }}"#,
            procs::repo("scenarios/drop_on_steel.json")
        ),
    )
    .unwrap();
    spec
}

fn index_of(out: &Path) -> BTreeMap<String, usize> {
    let m: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("batch.json")).unwrap()).unwrap();
    m["runs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| {
            (
                r["id"].as_str().unwrap().to_string(),
                r["index"].as_u64().unwrap() as usize,
            )
        })
        .collect()
}

#[test]
fn overlapping_shards_one_killed_and_resubmitted_by_index_run_every_run_once() {
    let dir = procs::scratch("shards", "overlap");
    let spec = spec(&dir);
    let out = dir.join("out");
    let runs = out.join("runs");
    // A: the whole batch (what a resubmit read as `shard 1/1` used to run); B: task 2 of a
    // Slurm array 1-2, shard 2/2 (runs 1, 3, 5, 7).
    let a = start(task(&spec, &out, &["--shard", "1/1"], None));
    let b = start(task(&spec, &out, &["--shard", "auto"], Some([2, 1, 2])));
    let a_pid = a.child.id();
    let b_pid = b.child.id();

    // B is killed in the middle of a run (frozen first, so that it cannot finish it).
    let (b_run, b_run_pid) =
        procs::freeze_a_run(&runs, |_, pid| procs::parent_of(pid) == Some(b_pid));
    let mut b = b;
    b.child.kill().unwrap();
    let (_, b_lines) = b.finish();
    procs::wait_for("B's run to die with it", || {
        procs::gone(b_run_pid).then_some(())
    });
    let index = index_of(&out);
    println!("B killed in run {} ({b_run})", index[&b_run]);

    // A runs on; freeze it in a run of B's shard, and resubmit B's task alone meanwhile, as
    // `sbatch --array=2`: Slurm says task 2 of 2..2.
    let (a_run, a_run_pid) = procs::freeze_a_run(&runs, |id, pid| {
        procs::parent_of(pid) == Some(a_pid) && index.get(id).is_some_and(|k| k % 2 == 1)
    });
    println!("A frozen in run {} ({a_run})", index[&a_run]);
    let b2: Output = task(
        &spec,
        &out,
        &["--shard", "auto", "--shard-count", "2"],
        Some([2, 2, 2]),
    )
    .output()
    .unwrap();
    let b2_out = text(&b2.stdout);
    println!("resubmitted task:\n{b2_out}");
    assert!(b2.status.success(), "{b2_out}\n{}", text(&b2.stderr));
    assert!(b2_out.contains("shard 2/2"), "{b2_out}");
    // A's run in flight was left to A: skipped, its staged folder untouched.
    assert!(
        b2_out.contains(&format!(
            "skip   {:>5} {a_run} (another process is running it)",
            index[&a_run]
        )),
        "{b2_out}"
    );
    assert!(
        procs::staged(&runs)
            .iter()
            .any(|(n, p)| *n == a_run && *p == a_run_pid),
        "A's run in flight lost its folder"
    );
    assert!(procs::signal(a_run_pid, libc::SIGCONT));
    let (a_status, a_lines) = a.finish();
    assert!(a_status.success(), "{a_lines:?}");

    // Every run ran exactly once, none failed; nothing is left behind.
    let b2_lines: Vec<String> = b2_out.lines().map(String::from).collect();
    let mut all = vec![];
    for (who, lines) in [("A", &a_lines), ("B", &b_lines), ("B again", &b2_lines)] {
        println!("{who} ran {:?}", ran(lines));
        all.extend(ran(lines));
        assert!(
            !lines.iter().any(|l| l.starts_with("failed")),
            "{who}: {lines:?}"
        );
    }
    all.sort();
    assert_eq!(all, (0..8).collect::<Vec<_>>(), "each run done once");
    assert!(ran(&a_lines).contains(&index[&a_run]));
    assert!(ran(&b2_lines).iter().all(|k| k % 2 == 1));
    let m = Command::new(env!("CARGO_BIN_EXE_applesim"))
        .args(["merge", s(&out)])
        .output()
        .unwrap();
    assert!(m.status.success(), "{}", text(&m.stderr));
    let left: BTreeSet<String> = std::fs::read_dir(&runs)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .filter(|n| n.starts_with('.') || n.ends_with(".failed.json"))
        .collect();
    assert!(left.is_empty(), "{left:?}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_resubmitted_slurm_task_runs_its_shard_or_is_refused_with_the_commands_that_would() {
    let dir = procs::scratch("shards", "resubmit");
    let spec = spec(&dir);
    let out = dir.join("out");
    let dry = |args: &[&str], slurm: [i64; 3]| {
        let mut a = vec!["--dry-run"];
        a.extend(args);
        task(&spec, &out, &a, Some(slurm)).output().unwrap()
    };
    // `sbatch --array=2` of an array 1-3, read by --shard auto alone: refused, not shard 1/1.
    let o = dry(&["--shard", "auto"], [2, 2, 2]);
    assert_eq!(o.status.code(), Some(1));
    let e = text(&o.stderr);
    assert!(
        e.contains("resubmit") && e.contains("--shard-count N"),
        "{e}"
    );
    // With --shard-count 3 the id cannot tell 2/3 (array 1-3) from 3/3 (array 0-2): refused
    // with both commands, whole.
    let o = dry(&["--shard", "auto", "--shard-count", "3"], [2, 2, 2]);
    assert_eq!(o.status.code(), Some(1));
    let e = text(&o.stderr);
    let cmd = format!(
        "applesim batch {} --out {} --jobs 1 --dry-run",
        s(&spec),
        s(&out)
    );
    assert!(
        e.contains(&format!(
            "if the array counts from 1 (--array=1-3):\n    {cmd} --shard 2/3"
        )) && e.contains(&format!(
            "if it counts from 0 (--array=0-2):\n    {cmd} --shard 3/3"
        )),
        "{e}"
    );
    // Task 3 of 3 can only be shard 3/3; the recipe's `--shard $SLURM_ARRAY_TASK_ID/3` is
    // never ambiguous.
    let o = dry(&["--shard", "auto", "--shard-count", "3"], [3, 3, 3]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(text(&o.stdout).contains("8 runs in the batch, 2 in shard 3/3"));
    let o = dry(&["--shard", "2/3"], [2, 2, 2]);
    assert!(text(&o.stdout).contains("8 runs in the batch, 3 in shard 2/3"));
    let _ = std::fs::remove_dir_all(&dir);
}
