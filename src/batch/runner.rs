//! Running a batch: a local rayon pool of `jobs` threads, each taking the next run in expansion
//! order; every run is single-threaded and writes only its own folder, so its results cannot
//! depend on the number of threads, the shard or the order of execution.
//!
//! Nothing is lost or half-written: a run writes into `runs/.tmp-<id>-<pid>/` and the folder is
//! renamed to `runs/<id>/` only when every file is complete; a failed run leaves
//! `runs/<id>.failed.json` (error and parameters) and the batch goes on. A rerun skips runs
//! whose folder is there, removes the temporary folders a killed batch left behind (of this
//! shard's runs only: other shards may be writing theirs), and reruns failed runs.

use super::manifest::{self, FailedRun, Manifest, RunParams};
use super::spec::{Batch, PlannedRun};
use super::{BatchError, Shard};
use crate::output::{self, atomic};
use crate::scenario;
use std::collections::BTreeSet;
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
    /// Rerun runs that are already done.
    pub force: bool,
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
}

/// Receives the progress of a batch (the command line draws a bar and prints a line per run).
/// Called from the worker threads.
pub trait Observer: Sync {
    /// Before the first run: how many runs of the shard will run and how many are done already.
    fn start(&self, _to_run: usize, _already_done: usize) {}
    /// A run finished (or failed).
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
    /// Failed runs: (index, id, error), in expansion order.
    pub failed: Vec<(usize, String, String)>,
    /// Temporary folders of killed runs that were removed.
    pub stale_removed: usize,
    /// `batch.json` described a different expansion and was replaced.
    pub manifest_replaced: bool,
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
    let (todo, skipped): (Vec<&PlannedRun>, Vec<&PlannedRun>) = share
        .iter()
        .partition(|r| opts.force || !manifest::is_done(out, &r.id));
    observer.start(todo.len(), skipped.len());

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
    // has done a prefix of the list) and a slow run never holds up a queue behind it.
    let next = AtomicUsize::new(0);
    pool.scope(|s| {
        for _ in 0..jobs {
            s.spawn(|_| loop {
                let k = next.fetch_add(1, Ordering::Relaxed);
                let Some(run) = todo.get(k) else { break };
                let outcome = run_one(batch, run, out);
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
        skipped: skipped.len(),
        stale_removed,
        manifest_replaced,
        ..Report::default()
    };
    for (index, o) in outcomes {
        match o {
            Outcome::Done { .. } => report.done += 1,
            Outcome::Failed { error } => {
                report
                    .failed
                    .push((index, batch.runs[index].id.clone(), error))
            }
        }
    }
    Ok(report)
}

/// The run id a leftover entry of `runs/` belongs to: `.tmp-<id>-<pid>` (a run folder being
/// written), `.old-<id>-<pid>` (a folder being replaced under --force), `.<id>.failed.json.tmp-<pid>`.
fn stale_id(name: &str) -> Option<&str> {
    let rest = name
        .strip_prefix(".tmp-")
        .or_else(|| name.strip_prefix(".old-"))
        .or_else(|| name.strip_prefix('.'))?;
    let id = rest.get(..super::id::ID_HEX_DIGITS)?;
    super::id::is_id(id).then_some(id)
}

/// Removes what killed runs of this share left in `runs/` (and restores a complete run that a
/// killed `--force` rerun had moved aside).
fn remove_stale(runs_dir: &Path, share: &[&PlannedRun]) -> Result<usize, BatchError> {
    let ids: BTreeSet<&str> = share.iter().map(|r| r.id.as_str()).collect();
    let mut n = 0;
    let mut entries: Vec<PathBuf> = std::fs::read_dir(runs_dir)
        .map_err(io(runs_dir))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .collect();
    entries.sort();
    for p in entries {
        let name = p
            .file_name()
            .map(|n| n.to_string_lossy().to_string())
            .unwrap_or_default();
        let Some(id) = stale_id(&name).filter(|id| ids.contains(id)) else {
            continue;
        };
        // A --force rerun killed between its two renames left the old, complete run aside
        // and no `runs/<id>`: put it back rather than lose it.
        let dest = runs_dir.join(id);
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
    Ok(n)
}

/// Runs one scenario into its temporary folder and renames it into place; any failure,
/// including a panic (a bug, never a user's fault, but it must not take the batch down), is
/// recorded in `runs/<id>.failed.json`.
fn run_one(batch: &Batch, run: &PlannedRun, out: &Path) -> Outcome {
    let runs_dir = out.join(manifest::RUNS);
    let tmp = runs_dir.join(format!(".tmp-{}-{}", run.id, std::process::id()));
    let start = Instant::now();
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        execute(batch, run, out, &tmp)
    }))
    .unwrap_or_else(|panic| {
        let msg = panic
            .downcast_ref::<String>()
            .cloned()
            .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
            .unwrap_or_else(|| "unknown".into());
        Err(format!(
            "internal error (applesim panicked: {msg}); please report it"
        ))
    });
    match result {
        Ok(()) => Outcome::Done {
            wall_time_s: start.elapsed().as_secs_f64(),
        },
        Err(error) => {
            let _ = std::fs::remove_dir_all(&tmp);
            let record = FailedRun {
                index: run.index,
                id: run.id.clone(),
                params: run.params(&batch.parameters),
                error: error.clone(),
            };
            let path = manifest::failed_path(out, &run.id);
            let written = manifest::pretty(&record)
                .map_err(|e| e.to_string())
                .and_then(|b| atomic::write_file(&path, &b).map_err(|e| e.to_string()));
            let error = match written {
                Ok(()) => error,
                Err(e) => format!("{error} (and writing {}: {e})", path.display()),
            };
            Outcome::Failed { error }
        }
    }
}

fn execute(batch: &Batch, run: &PlannedRun, out: &Path, tmp: &Path) -> Result<(), String> {
    let value = run.scenario.as_ref().map_err(Clone::clone)?;
    let text = serde_json::to_string(value).map_err(|e| e.to_string())?;
    let mut sc = scenario::from_json(&text, &run.label).map_err(|e| e.to_string())?;
    sc.read_files(&batch.base_dir).map_err(|e| e.to_string())?;
    scenario::validate(&sc).map_err(|e| e.to_string())?;
    if tmp.exists() {
        std::fs::remove_dir_all(tmp).map_err(|e| format!("{}: {e}", tmp.display()))?;
    }
    output::run_to_dir(&sc, &batch.base_dir, tmp, &mut |_| {}).map_err(|e| e.to_string())?;
    let params = RunParams {
        index: run.index,
        id: run.id.clone(),
        params: run.params(&batch.parameters),
    };
    let bytes = manifest::pretty(&params).map_err(|e| e.to_string())?;
    atomic::write_file(&tmp.join(manifest::PARAMS), &bytes)
        .map_err(|e| format!("{}: {e}", tmp.join(manifest::PARAMS).display()))?;
    commit(out, &run.id, tmp).map_err(|e| format!("moving {} into place: {e}", tmp.display()))
}

/// Renames the finished temporary folder to `runs/<id>`; an older folder of the same run
/// (`--force`) is moved aside first and removed after, so `runs/<id>` is at every instant
/// either the old complete run or the new one.
fn commit(out: &Path, id: &str, tmp: &Path) -> std::io::Result<()> {
    let runs_dir = out.join(manifest::RUNS);
    let dest = manifest::run_dir(out, id);
    let old = runs_dir.join(format!(".old-{id}-{}", std::process::id()));
    let had_old = dest.exists();
    if had_old {
        std::fs::rename(&dest, &old)?;
    }
    std::fs::rename(tmp, &dest)?;
    // Make the rename durable before the failure record (if any) goes.
    if let Ok(d) = std::fs::File::open(&runs_dir) {
        let _ = d.sync_all();
    }
    let failed = manifest::failed_path(out, id);
    if failed.exists() {
        std::fs::remove_file(&failed)?;
    }
    if had_old {
        std::fs::remove_dir_all(&old)?;
    }
    Ok(())
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
    fn stale_leftovers_of_this_share_go_and_a_moved_aside_run_comes_back() {
        let runs = std::env::temp_dir().join(format!("applesim-stale-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&runs);
        let (mine, other, forced) = ("0123456789abcdef", "fedcba9876543210", "00000000000000aa");
        for d in [
            format!(".tmp-{mine}-11"),
            format!(".tmp-{other}-12"),
            format!(".old-{forced}-13"),
        ] {
            std::fs::create_dir_all(runs.join(d)).unwrap();
        }
        std::fs::write(runs.join(format!(".old-{forced}-13/summary.json")), "{}").unwrap();
        std::fs::write(runs.join(format!(".{mine}.failed.json.tmp-11")), "{").unwrap();
        let share = [planned(mine), planned(forced)];
        let refs: Vec<&PlannedRun> = share.iter().collect();
        assert_eq!(remove_stale(&runs, &refs).unwrap(), 2);
        let mut left: Vec<String> = std::fs::read_dir(&runs)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
            .collect();
        left.sort();
        assert_eq!(left, [format!(".tmp-{other}-12"), forced.to_string()]);
        assert!(runs.join(forced).join("summary.json").is_file());
        std::fs::remove_dir_all(&runs).unwrap();
    }

    #[test]
    fn stale_names_map_to_their_run() {
        assert_eq!(
            stale_id(".tmp-0123456789abcdef-4242"),
            Some("0123456789abcdef")
        );
        assert_eq!(
            stale_id(".old-0123456789abcdef-7"),
            Some("0123456789abcdef")
        );
        assert_eq!(
            stale_id(".0123456789abcdef.failed.json.tmp-9"),
            Some("0123456789abcdef")
        );
        assert_eq!(stale_id("0123456789abcdef"), None);
        assert_eq!(stale_id(".tmp-xyz"), None);
        assert_eq!(stale_id(".DS_Store"), None);
    }
}
