//! Helpers of the kill and concurrency tests (tests/batch.rs, run_folder.rs, shards.rs):
//! finding a run in flight by its staged folder, freezing it, killing, waiting for processes.
//! Every wait is for a condition (with a generous bound that only fails a hung test), never a
//! sleep whose length decides the outcome.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// The bound of every wait: reached only if something hangs.
pub const PATIENCE: Duration = Duration::from_secs(120);

/// Path of a file under the repository root.
pub fn repo(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)
}

/// A fresh folder for one test.
pub fn scratch(test: &str, name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("applesim-{test}-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A folder being written: `.NAME.tmp-<pid>-<n>` in `dir`, as (NAME, pid of its writer).
pub fn staged(dir: &Path) -> Vec<(String, u32)> {
    let mut v = vec![];
    let Ok(rd) = std::fs::read_dir(dir) else {
        return v;
    };
    for e in rd.flatten() {
        let n = e.file_name().to_string_lossy().to_string();
        let Some(rest) = n.strip_prefix('.') else {
            continue;
        };
        let Some(k) = rest.find(".tmp-") else {
            continue;
        };
        let (name, tail) = (&rest[..k], &rest[k + 5..]);
        let Some(pid) = tail.split('-').next().and_then(|p| p.parse().ok()) else {
            continue;
        };
        if e.path().is_dir() {
            v.push((name.to_string(), pid));
        }
    }
    v.sort();
    v
}

/// Sends `sig` to `pid`; false if there is no such process.
pub fn signal(pid: u32, sig: i32) -> bool {
    // SAFETY: kill(2) with a plain pid and signal number.
    unsafe { libc::kill(pid as libc::pid_t, sig) == 0 }
}

/// Whether process `pid` is gone (or a zombie: dead, not yet reaped).
pub fn gone(pid: u32) -> bool {
    match std::fs::read_to_string(format!("/proc/{pid}/stat")) {
        Err(_) => true,
        Ok(stat) => stat
            .rsplit_once(')')
            .map(|(_, rest)| rest.trim_start().starts_with('Z'))
            .unwrap_or(true),
    }
}

/// State letter of process `pid` (`R`, `S`, `T` stopped, `Z` zombie, ...).
pub fn state(pid: u32) -> Option<char> {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    stat.rsplit_once(')')?.1.trim_start().chars().next()
}

/// Parent pid of `pid`.
pub fn parent_of(pid: u32) -> Option<u32> {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    let (_, rest) = stat.rsplit_once(')')?;
    rest.split_whitespace().nth(1)?.parse().ok()
}

/// Waits until `cond` holds; panics with `what` after [`PATIENCE`].
#[track_caller]
pub fn wait_for<T>(what: &str, mut cond: impl FnMut() -> Option<T>) -> T {
    let start = Instant::now();
    loop {
        if let Some(t) = cond() {
            return t;
        }
        assert!(start.elapsed() < PATIENCE, "waited {PATIENCE:?} for {what}");
        std::thread::sleep(Duration::from_millis(2));
    }
}

/// Waits for a run in flight in `dir` whose writer passes `pick` and freezes its writer with
/// SIGSTOP, so that it can neither finish nor change anything until it is killed; returns
/// (NAME, pid). A run that finishes between being seen and being stopped is passed over.
#[track_caller]
pub fn freeze_a_run(dir: &Path, mut pick: impl FnMut(&str, u32) -> bool) -> (String, u32) {
    wait_for("a run in flight to freeze", || {
        for (name, pid) in staged(dir) {
            if !pick(&name, pid) || !signal(pid, libc::SIGSTOP) {
                continue;
            }
            // SIGSTOP takes effect asynchronously: wait until the kernel shows it stopped (or
            // dead), then, if its staged folder is still there, it is frozen in flight.
            wait_for("the stop to take effect", || {
                (state(pid).is_none_or(|s| s == 'T' || s == 't' || s == 'Z')).then_some(())
            });
            if staged(dir).iter().any(|(n, p)| *n == name && *p == pid) {
                return Some((name, pid));
            }
            signal(pid, libc::SIGCONT);
        }
        None
    })
}
