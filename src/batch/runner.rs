//! Running a batch: a local rayon pool of `jobs` threads, each taking the next run in expansion
//! order; every run is single-threaded and writes only its own folder, so its results cannot
//! depend on the number of threads, the shard or the order of execution.
//!
//! Nothing is lost, mixed or run twice:
//! - each run runs in a process of its own ([`super::isolate`]): an abort, a panic, a signal
//!   or running out of memory is that run's failure, recorded in `runs/<id>.failed.json` with
//!   its cause, and the batch goes on;
//! - a run holds the lock `runs/.<id>.lock` (an `flock`, dropped by the kernel when its
//!   holders die, on this node or another over NFS v4) while it runs; another process of the
//!   same batch (an overlapping shard, a resubmitted task) skips a run whose lock is held,
//!   and after taking a lock checks again whether the run was done or failed meanwhile;
//! - a run's set is written beside `runs/<id>/` and switched in whole
//!   ([`crate::output::atomic::StagedFolder`]); temporaries are removed only by the holder of
//!   their run's lock, so never while their writer lives.
//!
//! A rerun skips runs that are done, and runs that failed unless `retry_failed` (a failure is
//! deterministic: it fails again), removes what killed runs of its share left behind, and
//! runs the rest; `force` reruns everything.

use super::isolate::{self, ChildEnd, Isolation, Job};
use super::manifest::{self, FailedRun, Manifest, RunParams};
use super::spec::{Batch, PlannedRun};
use super::{BatchError, Shard};
use crate::output::atomic::{self, FolderLock};
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Instant;

/// How to run a batch.
#[derive(Debug, Clone)]
pub struct Options {
    /// Runs at the same time (threads of the local pool), >= 1.
    pub jobs: usize,
    /// The share of the batch to run.
    pub shard: Shard,
    /// Rerun runs that are already done (and failed ones).
    pub force: bool,
    /// Rerun runs that failed before (they are skipped otherwise).
    pub retry_failed: bool,
    /// Where runs run: a child process each (the default when the `applesim` executable is
    /// found: see [`isolate::find_executable`]) or this process.
    pub isolation: Isolation,
}

impl Default for Options {
    /// One job, the whole batch, nothing rerun, runs isolated when the executable is found.
    fn default() -> Self {
        Options {
            jobs: 1,
            shard: Shard::ALL,
            force: false,
            retry_failed: false,
            isolation: Isolation::auto(),
        }
    }
}

/// What happened to one run.
#[derive(Debug, Clone, PartialEq)]
pub enum Outcome {
    /// Ran and its folder is complete.
    Done {
        /// Wall-clock time of the run (s).
        wall_time_s: f64,
    },
    /// Failed; `runs/<id>.failed.json` holds the error.
    Failed {
        /// The error message.
        error: String,
    },
    /// Not run by this process: another one has it.
    Skipped(Skip),
}

/// Why a run of the share was not run by this process.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Skip {
    /// Another process holds the run's lock: it is running it now.
    Busy,
    /// Another process finished it while this one was getting to it.
    DoneElsewhere,
    /// Another process recorded its failure while this one was getting to it.
    FailedElsewhere,
}

/// Receives the progress of a batch (the command line draws a bar and prints a line per run).
/// Called from the worker threads.
pub trait Observer: Sync {
    /// Before the first run: how many runs of the shard will run and how many are done already.
    fn start(&self, _to_run: usize, _already_done: usize) {}
    /// Before the first run: how many runs of the shard failed before and are not retried.
    fn not_retried(&self, _failed_before: usize) {}
    /// A run finished (or failed, or was left to another process).
    fn finished(&self, _run: &PlannedRun, _outcome: &Outcome) {}
}

/// An observer that ignores everything.
pub struct Silent;
impl Observer for Silent {}

/// What a batch did.
#[derive(Debug, Clone, Default)]
pub struct Report {
    /// Runs of the whole batch.
    pub total: usize,
    /// Runs in this shard.
    pub selected: usize,
    /// Runs that ran and succeeded now.
    pub done: usize,
    /// Runs skipped because they were done before.
    pub skipped: usize,
    /// Runs that failed in this invocation: (index, id, error), in expansion order.
    pub failed: Vec<(usize, String, String)>,
    /// Runs skipped because they had failed before (without `retry_failed`): (index, id,
    /// error), in expansion order.
    pub failed_before: Vec<(usize, String, String)>,
    /// Runs left to another process that held their lock: (index, id).
    pub busy: Vec<(usize, String)>,
    /// Runs another process finished or failed while this one was getting to them.
    pub done_elsewhere: usize,
    /// Temporary folders and files of killed runs that were removed.
    pub stale_removed: usize,
    /// `batch.json` described a different expansion and was replaced.
    pub manifest_replaced: bool,
    /// Whether each run ran in a process of its own.
    pub isolated: bool,
}

/// The runs of `batch` in `shard`, in expansion order.
pub fn select<'a>(batch: &'a Batch, shard: &Shard) -> Vec<&'a PlannedRun> {
    batch
        .runs
        .iter()
        .filter(|r| shard.contains(r.index))
        .collect()
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> BatchError + '_ {
    move |source| BatchError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// The error of a run's failure record, if it has a readable one.
fn recorded_failure(out: &Path, id: &str) -> Option<String> {
    let path = manifest::failed_path(out, id);
    let bytes = std::fs::read(&path).ok()?;
    Some(
        serde_json::from_slice::<FailedRun>(&bytes)
            .map(|f| f.error)
            .unwrap_or_else(|_| format!("(unreadable failure record {})", path.display())),
    )
}

/// Runs (this shard of) a batch into `out`.
pub fn run(
    batch: &Batch,
    out: &Path,
    opts: &Options,
    observer: &dyn Observer,
) -> Result<Report, BatchError> {
    let runs_dir = out.join(manifest::RUNS);
    std::fs::create_dir_all(&runs_dir).map_err(io(&runs_dir))?;
    let manifest_replaced = Manifest::of(batch).write(out)?;
    let share = select(batch, &opts.shard);
    let stale_removed = remove_stale(&runs_dir, &share)?;
    let mut todo: Vec<&PlannedRun> = Vec::new();
    let mut skipped = 0;
    let mut failed_before = Vec::new();
    for &r in &share {
        if opts.force {
            todo.push(r);
        } else if manifest::is_done(out, &r.id) {
            skipped += 1;
        } else if let Some(error) = recorded_failure(out, &r.id).filter(|_| !opts.retry_failed) {
            failed_before.push((r.index, r.id.clone(), error));
        } else {
            todo.push(r);
        }
    }
    observer.start(todo.len(), skipped);
    observer.not_retried(failed_before.len());

    let outcomes: Mutex<Vec<(usize, Outcome)>> = Mutex::new(Vec::with_capacity(todo.len()));
    let jobs = opts.jobs.max(1).min(todo.len().max(1));
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(jobs)
        .thread_name(|k| format!("applesim-batch-{k}"))
        .build()
        .map_err(|e| BatchError::Output {
            path: out.to_path_buf(),
            message: format!("cannot start {jobs} threads: {e}"),
        })?;
    // Each worker takes the next run in expansion order: runs start in order (a killed batch
    // has done a prefix of the list) and a slow run never holds up a queue behind it. The
    // workers live until the last run ends: a run's process is killed with the thread that
    // started it (PR_SET_PDEATHSIG).
    let next = AtomicUsize::new(0);
    pool.scope(|s| {
        for _ in 0..jobs {
            s.spawn(|_| loop {
                let k = next.fetch_add(1, Ordering::Relaxed);
                let Some(run) = todo.get(k) else { break };
                let outcome = run_one(batch, run, out, opts);
                observer.finished(run, &outcome);
                outcomes
                    .lock()
                    .expect("no panic holds this lock")
                    .push((run.index, outcome));
            });
        }
    });
    let mut outcomes = outcomes.into_inner().expect("no panic holds this lock");
    outcomes.sort_by_key(|(k, _)| *k);
    let mut report = Report {
        total: batch.runs.len(),
        selected: share.len(),
        skipped,
        failed_before,
        stale_removed,
        manifest_replaced,
        isolated: matches!(opts.isolation, Isolation::Process { .. }),
        ..Report::default()
    };
    for (index, o) in outcomes {
        let id = batch.runs[index].id.clone();
        match o {
            Outcome::Done { .. } => report.done += 1,
            Outcome::Failed { error } => report.failed.push((index, id, error)),
            Outcome::Skipped(Skip::Busy) => report.busy.push((index, id)),
            Outcome::Skipped(_) => report.done_elsewhere += 1,
        }
    }
    Ok(report)
}

/// The run id a leftover entry of `runs/` belongs to: `.<id>.tmp-<pid>-<n>` (a run's set
/// being written, or an old set being removed), `.<id>.old-<pid>-<n>` (an old set moved
/// aside), `.<id>.job-<pid>-<n>`, `.<id>.failed.json.tmp-<pid>`, `.<id>.lock`; and those of
/// earlier versions, `.tmp-<id>-<pid>` and `.old-<id>-<pid>`.
fn stale_id(name: &str) -> Option<&str> {
    let rest = name
        .strip_prefix(".tmp-")
        .or_else(|| name.strip_prefix(".old-"))
        .or_else(|| name.strip_prefix('.'))?;
    let id = rest.get(..super::id::ID_HEX_DIGITS)?;
    let sep = rest[super::id::ID_HEX_DIGITS..].chars().next();
    (super::id::is_id(id) && matches!(sep, Some('.' | '-'))).then_some(id)
}

/// Removes what killed runs of this share left in `runs/`, run by run under the run's lock
/// (a run whose lock another process holds is being written: its temporaries stay), and puts
/// back a complete run that a killed `--force` rerun of an earlier version had moved aside.
fn remove_stale(runs_dir: &Path, share: &[&PlannedRun]) -> Result<usize, BatchError> {
    let ids: BTreeSet<&str> = share.iter().map(|r| r.id.as_str()).collect();
    let mut by_id: BTreeMap<String, Vec<(String, PathBuf)>> = BTreeMap::new();
    for e in std::fs::read_dir(runs_dir).map_err(io(runs_dir))? {
        let Ok(e) = e else { continue };
        let name = e.file_name().to_string_lossy().to_string();
        if let Some(id) = stale_id(&name).filter(|id| ids.contains(id)) {
            by_id
                .entry(id.to_string())
                .or_default()
                .push((name, e.path()));
        }
    }
    let mut n = 0;
    for (id, mut entries) in by_id {
        let dest = runs_dir.join(&id);
        let to_batch = |e: atomic::FolderError| BatchError::Output {
            path: dest.clone(),
            message: e.to_string(),
        };
        // Dropping the lock at the end of the iteration also removes a killed run's lock file.
        let Some(lock) = FolderLock::try_acquire(&dest).map_err(to_batch)? else {
            continue;
        };
        n += lock.remove_stale().map_err(to_batch)?;
        entries.sort();
        for (name, p) in entries {
            if !(name.starts_with(".tmp-") || name.starts_with(".old-")) {
                continue;
            }
            if name.starts_with(".old-") && !dest.exists() && p.join("summary.json").is_file() {
                std::fs::rename(&p, &dest).map_err(io(&p))?;
                continue;
            }
            let r = if p.is_dir() {
                std::fs::remove_dir_all(&p)
            } else {
                std::fs::remove_file(&p)
            };
            r.map_err(io(&p))?;
            n += 1;
        }
    }
    Ok(n)
}

/// Runs one scenario under its run's lock, in a child process or in this one; any failure
/// is recorded in `runs/<id>.failed.json` (while the lock is held: so that no other process
/// can have finished the run meanwhile and be contradicted by a stale record).
fn run_one(batch: &Batch, run: &PlannedRun, out: &Path, opts: &Options) -> Outcome {
    let dest = manifest::run_dir(out, &run.id);
    let lock = match FolderLock::try_acquire(&dest) {
        Ok(Some(lock)) => lock,
        Ok(None) => return Outcome::Skipped(Skip::Busy),
        Err(e) => {
            return Outcome::Failed {
                error: format!("cannot lock the run: {e}"),
            }
        }
    };
    if !opts.force {
        if manifest::is_done(out, &run.id) {
            return Outcome::Skipped(Skip::DoneElsewhere);
        }
        if !opts.retry_failed && manifest::failed_path(out, &run.id).is_file() {
            return Outcome::Skipped(Skip::FailedElsewhere);
        }
    }
    let start = Instant::now();
    let params = RunParams {
        index: run.index,
        id: run.id.clone(),
        params: run.params(&batch.parameters),
    };
    let end = match &run.scenario {
        Err(e) => ChildEnd::Failed(e.clone()),
        Ok(value) => match &opts.isolation {
            Isolation::Process {
                exe,
                memory_limit_bytes,
            } => {
                let job = Job {
                    out: out.to_path_buf(),
                    base_dir: batch.base_dir.clone(),
                    label: run.label.clone(),
                    scenario: value.clone(),
                    params: params.clone(),
                    lock_fd: -1,
                };
                isolate::run_child(exe, *memory_limit_bytes, &job, &lock)
            }
            Isolation::InProcess => {
                match isolate::execute_caught(
                    out,
                    &batch.base_dir,
                    &run.label,
                    value,
                    &params,
                    &lock,
                ) {
                    Ok(()) => ChildEnd::Done,
                    Err(e) => ChildEnd::Failed(e),
                }
            }
        },
    };
    let crash = match end {
        ChildEnd::Done if manifest::is_done(out, &run.id) => {
            return Outcome::Done {
                wall_time_s: start.elapsed().as_secs_f64(),
            }
        }
        ChildEnd::Done => isolate::Crash {
            error: format!(
                "the run's process reported success but {} holds no summary.json",
                dest.display()
            ),
            ..isolate::Crash::default()
        },
        ChildEnd::Failed(error) => isolate::Crash {
            error,
            ..isolate::Crash::default()
        },
        ChildEnd::Crashed(c) => c,
    };
    // A crashed run leaves its temporaries: its lock is ours alone now.
    let _ = lock.remove_stale();
    let record = FailedRun {
        index: run.index,
        id: run.id.clone(),
        params: params.params,
        error: crash.error.clone(),
        exit_code: crash.exit_code,
        signal: crash.signal,
        signal_name: crash.signal.map(isolate::signal_name),
        stderr: crash.stderr,
    };
    let path = manifest::failed_path(out, &run.id);
    let written = manifest::pretty(&record)
        .map_err(|e| e.to_string())
        .and_then(|b| atomic::write_file(&path, &b).map_err(|e| e.to_string()));
    let error = match written {
        Ok(()) => crash.error,
        Err(e) => format!("{} (and writing {}: {e})", crash.error, path.display()),
    };
    drop(lock);
    Outcome::Failed { error }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn planned(id: &str) -> PlannedRun {
        PlannedRun {
            index: 0,
            id: id.into(),
            values: vec![],
            scenario: Err("unused".into()),
            label: "test".into(),
        }
    }

    #[test]
    fn stale_leftovers_of_this_share_go_unless_locked_and_a_moved_aside_run_comes_back() {
        let runs = std::env::temp_dir().join(format!("applesim-stale-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&runs);
        let (mine, other, forced, live) = (
            "0123456789abcdef",
            "fedcba9876543210",
            "00000000000000aa",
            "00000000000000bb",
        );
        for d in [
            format!(".{mine}.tmp-11-0"),
            format!(".tmp-{mine}-10"),
            format!(".{other}.tmp-12-0"),
            format!(".old-{forced}-13"),
            format!(".{live}.tmp-14-0"),
        ] {
            std::fs::create_dir_all(runs.join(d)).unwrap();
        }
        std::fs::write(runs.join(format!(".old-{forced}-13/summary.json")), "{}").unwrap();
        std::fs::write(runs.join(format!(".{mine}.failed.json.tmp-11")), "{").unwrap();
        std::fs::write(runs.join(format!(".{mine}.lock")), "").unwrap();
        // Another process is writing `live`: its temporaries stay.
        let held = FolderLock::acquire(&runs.join(live)).unwrap();
        let share = [planned(mine), planned(forced), planned(live)];
        let refs: Vec<&PlannedRun> = share.iter().collect();
        assert_eq!(remove_stale(&runs, &refs).unwrap(), 3);
        let mut left: Vec<String> = std::fs::read_dir(&runs)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
            .collect();
        left.sort();
        assert_eq!(
            left,
            [
                format!(".{live}.lock"),
                format!(".{live}.tmp-14-0"),
                format!(".{other}.tmp-12-0"),
                forced.to_string()
            ]
        );
        assert!(runs.join(forced).join("summary.json").is_file());
        drop(held);
        std::fs::remove_dir_all(&runs).unwrap();
    }

    #[test]
    fn stale_names_map_to_their_run() {
        let id = Some("0123456789abcdef");
        assert_eq!(stale_id(".tmp-0123456789abcdef-4242"), id);
        assert_eq!(stale_id(".old-0123456789abcdef-7"), id);
        assert_eq!(stale_id(".0123456789abcdef.failed.json.tmp-9"), id);
        assert_eq!(stale_id(".0123456789abcdef.tmp-9-0"), id);
        assert_eq!(stale_id(".0123456789abcdef.job-9-0"), id);
        assert_eq!(stale_id(".0123456789abcdef.lock"), id);
        assert_eq!(stale_id("0123456789abcdef"), None);
        assert_eq!(stale_id(".0123456789abcdef0"), None);
        assert_eq!(stale_id(".tmp-xyz"), None);
        assert_eq!(stale_id(".DS_Store"), None);
    }
}
