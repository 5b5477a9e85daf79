//! Each run of a batch in a process of its own, so that nothing a run does can end the batch:
//! an abort (a failed allocation aborts a Rust program; it cannot be caught), a panic, a
//! signal, running out of memory. The batch re-invokes the `applesim` executable as
//! `applesim run --batch-job` with a [`Job`] on its standard input; the child writes the run
//! into `runs/<id>/` through the folder switch ([`crate::output::atomic`]) and answers with one
//! JSON line ([`Answer`]) on its standard output. Whatever ends the child otherwise, its exit
//! code or signal and the end of its standard error go into `runs/<id>.failed.json`, and the
//! batch goes on.
//!
//! The child holds its run's lock with the parent: the parent takes the `flock` of
//! `runs/.<id>.lock` and hands the descriptor down, so the lock lasts until both are gone; on
//! Linux the child is also killed if the parent dies (`PR_SET_PDEATHSIG`), so a killed batch
//! leaves no run writing behind it. An optional memory limit (`RLIMIT_AS`) turns a run that
//! outgrows it into a failed allocation of that run alone, and the child offers itself first
//! to the kernel's out-of-memory killer (`oom_score_adj` 1000), so that the batch survives a
//! machine or a Slurm job running out of memory.

use super::manifest::{self, RunParams};
use crate::output::atomic;
use crate::scenario;
use serde::{Deserialize, Serialize};
use serde_json::Value;
use std::path::{Path, PathBuf};

/// The hidden flag of `applesim run` that makes it a batch run's child process.
pub const CHILD_FLAG: &str = "--batch-job";

/// Environment variable naming the `applesim` executable that runs a batch's runs (for a
/// program that uses the library and is not `applesim` itself).
pub const EXE_ENV: &str = "APPLESIM_EXE";

/// Standard error kept in a failure record: its last lines, up to this many bytes.
const STDERR_KEPT: usize = 8 * 1024;

/// Where a batch's runs run.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Isolation {
    /// Each run in a child process of the `applesim` executable `exe`.
    Process {
        /// The `applesim` executable.
        exe: PathBuf,
        /// Limit of each run's address space (bytes, `RLIMIT_AS`); `None`: no limit.
        memory_limit_bytes: Option<u64>,
    },
    /// In this process, on the batch's threads: a panic is caught and recorded, but an abort
    /// (a failed allocation) or a signal ends the whole batch. For platforms or programs
    /// without the `applesim` executable.
    InProcess,
}

impl Isolation {
    /// A child process per run if the `applesim` executable is found
    /// ([`find_executable`]), else in this process.
    pub fn auto() -> Isolation {
        match find_executable() {
            Some(exe) if cfg!(unix) => Isolation::Process {
                exe,
                memory_limit_bytes: None,
            },
            _ => Isolation::InProcess,
        }
    }
}

impl Default for Isolation {
    fn default() -> Self {
        Isolation::auto()
    }
}

/// The `applesim` executable: `$APPLESIM_EXE`; this program if it is `applesim`; else an
/// `applesim` beside this program or one folder up (a test or example of this crate lives in
/// cargo's `target/<profile>/deps/` or `examples/`, the command in `target/<profile>/`).
pub fn find_executable() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os(EXE_ENV).filter(|p| !p.is_empty()) {
        return Some(PathBuf::from(p));
    }
    let me = std::env::current_exe().ok()?;
    let name = format!("applesim{}", std::env::consts::EXE_SUFFIX);
    if me.file_name().is_some_and(|n| n == name.as_str()) {
        return Some(me);
    }
    me.ancestors()
        .skip(1)
        .take(2)
        .map(|d| d.join(&name))
        .find(|c| c.is_file())
}

/// Parses a memory size: bytes, or a number with K, M, G or T (powers of 1024; `KiB`, `GB`
/// and the like read the same).
pub fn parse_memory_limit(s: &str) -> Result<u64, String> {
    let bad = || format!("memory limit '{s}': give bytes or a size such as 512M, 2G, 1.5G");
    let t = s.trim();
    let split = t
        .find(|c: char| !(c.is_ascii_digit() || c == '.'))
        .unwrap_or(t.len());
    let (num, unit) = t.split_at(split);
    let x: f64 = num.parse().map_err(|_| bad())?;
    let unit = unit.trim().to_ascii_uppercase();
    let scale: f64 = match unit.trim_end_matches("IB").trim_end_matches('B') {
        "" => 1.0,
        "K" => 1024.0,
        "M" => 1024f64.powi(2),
        "G" => 1024f64.powi(3),
        "T" => 1024f64.powi(4),
        _ => return Err(bad()),
    };
    let bytes = x * scale;
    if !(1.0..1.8e19).contains(&bytes) {
        return Err(bad());
    }
    Ok(bytes as u64)
}

/// A size in bytes for messages (`1 GiB`, `512 MiB`).
pub fn show_bytes(b: u64) -> String {
    let units = ["B", "KiB", "MiB", "GiB", "TiB"];
    let mut x = b as f64;
    let mut k = 0;
    while x >= 1024.0 && k + 1 < units.len() {
        x /= 1024.0;
        k += 1;
    }
    if x.fract() == 0.0 {
        format!("{x} {}", units[k])
    } else {
        format!("{x:.1} {}", units[k])
    }
}

/// What the batch hands a run's child process, on its standard input.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Job {
    /// The batch's output folder (holds `runs/`).
    pub out: PathBuf,
    /// The folder relative paths of the scenario resolve against.
    pub base_dir: PathBuf,
    /// The run's label, for the scenario's error messages.
    pub label: String,
    /// The expanded scenario.
    pub scenario: Value,
    /// `params.json` of the run.
    pub params: RunParams,
    /// The descriptor of the run's lock (`runs/.<id>.lock`) the child inherits.
    pub lock_fd: i32,
}

/// The child's answer, one JSON line on its standard output.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct Answer {
    /// Why the run failed (as `applesim run` would say it); `None`: `runs/<id>/` is complete.
    pub error: Option<String>,
}

/// Runs the scenario of a batch run and switches `runs/<id>/` in whole, under the run's lock
/// (held by the caller). Any error is returned as `applesim run` would print it.
pub(crate) fn execute(
    out: &Path,
    base_dir: &Path,
    label: &str,
    scenario_json: &Value,
    params: &RunParams,
    lock: &atomic::FolderLock,
) -> Result<(), String> {
    let text = serde_json::to_string(scenario_json).map_err(|e| e.to_string())?;
    let mut sc = scenario::from_json(&text, label).map_err(|e| e.to_string())?;
    sc.read_files(base_dir).map_err(|e| e.to_string())?;
    scenario::validate(&sc).map_err(|e| e.to_string())?;
    let stage =
        atomic::StagedFolder::begin(lock, crate::run::is_run_file).map_err(|e| e.to_string())?;
    crate::run::into_dir(&sc, base_dir, stage.path(), &mut |_| {}).map_err(|e| match e {
        crate::run::RunError::Io { path, source } => crate::run::RunError::Io {
            path: stage.final_path(&path),
            source,
        }
        .to_string(),
        other => other.to_string(),
    })?;
    let path = stage.path().join(manifest::PARAMS);
    let bytes = manifest::pretty(params).map_err(|e| e.to_string())?;
    atomic::write_file(&path, &bytes)
        .map_err(|e| format!("{}: {e}", stage.final_path(&path).display()))?;
    stage.commit().map_err(|e| e.to_string())?;
    // The run is done: an older failure record of it no longer holds.
    let failed = manifest::failed_path(out, &params.id);
    match std::fs::remove_file(&failed) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
            Err(format!("{}: {e}", failed.display()))
        }
        _ => Ok(()),
    }
}

/// [`execute`] with a panic caught and reported as an internal error.
pub(crate) fn execute_caught(
    out: &Path,
    base_dir: &Path,
    label: &str,
    scenario_json: &Value,
    params: &RunParams,
    lock: &atomic::FolderLock,
) -> Result<(), String> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        execute(out, base_dir, label, scenario_json, params, lock)
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
    })
}

/// The child's side (`applesim run --batch-job`): runs `job` on one thread, under the lock
/// handed down by the parent.
pub fn child_main(job: &Job) -> Answer {
    // The first process the kernel's out-of-memory killer picks, before the batch.
    #[cfg(target_os = "linux")]
    let _ = std::fs::write("/proc/self/oom_score_adj", "1000");
    let error = child_run(job).err();
    Answer { error }
}

#[cfg(unix)]
fn child_run(job: &Job) -> Result<(), String> {
    let dest = manifest::run_dir(&job.out, &job.params.id);
    // SAFETY: the descriptor was handed down by the parent for this process alone; nothing
    // else in this process knows of it.
    let lock =
        unsafe { atomic::FolderLock::inherited(job.lock_fd, &dest) }.map_err(|e| e.to_string())?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .map_err(|e| format!("cannot start the run's thread: {e}"))?;
    pool.install(|| {
        execute_caught(
            &job.out,
            &job.base_dir,
            &job.label,
            &job.scenario,
            &job.params,
            &lock,
        )
    })
}

#[cfg(not(unix))]
fn child_run(_job: &Job) -> Result<(), String> {
    Err("batch runs in child processes need a Unix system".into())
}

/// How a run's child process ended, when it did not answer cleanly.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Crash {
    /// The message for `error` in the failure record and the batch's output.
    pub error: String,
    /// Exit code, when it exited.
    pub exit_code: Option<i32>,
    /// Signal number, when a signal ended it.
    pub signal: Option<i32>,
    /// The end of its standard error.
    pub stderr: String,
}

/// What a run's child process came to.
#[derive(Debug, Clone, PartialEq)]
pub enum ChildEnd {
    /// The run is complete.
    Done,
    /// The run failed cleanly: the scenario's or the run's own error.
    Failed(String),
    /// The process ended otherwise (abort, signal, out of memory, could not start).
    Crashed(Crash),
}

/// Name of a signal number, for messages.
pub fn signal_name(sig: i32) -> String {
    #[cfg(unix)]
    {
        let known = [
            (libc::SIGHUP, "SIGHUP"),
            (libc::SIGINT, "SIGINT"),
            (libc::SIGQUIT, "SIGQUIT"),
            (libc::SIGILL, "SIGILL"),
            (libc::SIGABRT, "SIGABRT"),
            (libc::SIGBUS, "SIGBUS"),
            (libc::SIGFPE, "SIGFPE"),
            (libc::SIGKILL, "SIGKILL"),
            (libc::SIGSEGV, "SIGSEGV"),
            (libc::SIGPIPE, "SIGPIPE"),
            (libc::SIGTERM, "SIGTERM"),
            (libc::SIGXCPU, "SIGXCPU"),
            (libc::SIGUSR1, "SIGUSR1"),
            (libc::SIGUSR2, "SIGUSR2"),
        ];
        if let Some((_, n)) = known.iter().find(|(s, _)| *s == sig) {
            return n.to_string();
        }
    }
    format!("signal {sig}")
}

/// A child's standard error as kept in a failure record: all of it up to [`STDERR_KEPT`]
/// bytes, else its first quarter and its end (the cause comes first, a backtrace after it).
fn stderr_kept(bytes: &[u8]) -> String {
    let text = String::from_utf8_lossy(bytes);
    let text = text.trim_end();
    if text.len() <= STDERR_KEPT {
        return text.to_string();
    }
    let mut head = STDERR_KEPT / 4;
    while !text.is_char_boundary(head) {
        head -= 1;
    }
    let mut tail = text.len() - (STDERR_KEPT - head);
    while !text.is_char_boundary(tail) {
        tail += 1;
    }
    let head = &text[..head];
    let head = head.rfind('\n').map(|k| &head[..k]).unwrap_or(head);
    let tail = &text[tail..];
    let tail = tail.find('\n').map(|k| &tail[k + 1..]).unwrap_or(tail);
    format!("{head}\n[...]\n{tail}")
}

/// The line of a child's standard error that says what happened: an abort's own message
/// (`memory allocation of N bytes failed`), a panic's message, else the first line.
fn cause(stderr: &str) -> String {
    let lines: Vec<&str> = stderr.lines().map(str::trim).collect();
    if let Some(l) = lines.iter().find(|l| l.starts_with("memory allocation of")) {
        return l.to_string();
    }
    if let Some(k) = lines
        .iter()
        .position(|l| l.starts_with("thread '") && l.contains("panicked at"))
    {
        let at = lines[k].trim_end_matches(':');
        return match lines.get(k + 1).filter(|m| !m.is_empty()) {
            Some(m) => format!("{at}: {m}"),
            None => at.to_string(),
        };
    }
    lines
        .iter()
        .find(|l| !l.is_empty())
        .map(|l| l.to_string())
        .unwrap_or_default()
}

/// Describes a child that did not answer: its signal or exit code, what its standard error
/// says happened (an abort's own message, such as `memory allocation of N bytes failed`),
/// and what is likely behind it.
pub fn describe_crash(
    exit_code: Option<i32>,
    signal: Option<i32>,
    stderr: &[u8],
    memory_limit_bytes: Option<u64>,
) -> Crash {
    let stderr = stderr_kept(stderr);
    let last = cause(&stderr);
    let how = match (signal, exit_code) {
        (Some(s), _) => format!(
            "the run's process was killed by signal {s} ({})",
            signal_name(s)
        ),
        (None, Some(c)) => format!("the run's process exited with code {c} without an answer"),
        (None, None) => "the run's process ended without an answer".to_string(),
    };
    let mut error = if last.is_empty() {
        how
    } else {
        format!("{how}: {last}")
    };
    let out_of_memory = last.starts_with("memory allocation of");
    #[cfg(unix)]
    let killed = signal == Some(libc::SIGKILL);
    #[cfg(not(unix))]
    let killed = false;
    if out_of_memory {
        match memory_limit_bytes {
            Some(l) => error.push_str(&format!(
                " (over the per-run memory limit of {}: --memory-limit)",
                show_bytes(l)
            )),
            None => error.push_str(" (out of memory)"),
        }
    } else if killed && last.is_empty() {
        error.push_str(
            " (by a user, a scheduler's time or memory limit, or the kernel's out-of-memory killer)",
        );
    }
    Crash {
        error,
        exit_code,
        signal,
        stderr,
    }
}

/// Runs `job` in a child process of `exe` holding `lock` with this process, and waits for it.
#[cfg(unix)]
pub(crate) fn run_child(
    exe: &Path,
    memory_limit_bytes: Option<u64>,
    job: &Job,
    lock: &atomic::FolderLock,
) -> ChildEnd {
    use std::io::{Seek, Write};
    use std::os::unix::process::{CommandExt, ExitStatusExt};
    use std::process::{Command, Stdio};
    use std::sync::atomic::{AtomicU64, Ordering};
    static SEQ: AtomicU64 = AtomicU64::new(0);
    let start_failed = |what: String| {
        ChildEnd::Crashed(Crash {
            error: what,
            ..Crash::default()
        })
    };

    // The job goes through an unlinked file, not a pipe: writing a pipe to a child that died
    // early would raise SIGPIPE in the batch.
    let runs = job.out.join(manifest::RUNS);
    let job_path = runs.join(format!(
        ".{}.job-{}-{}",
        job.params.id,
        std::process::id(),
        SEQ.fetch_add(1, Ordering::Relaxed)
    ));
    let file = std::fs::OpenOptions::new()
        .read(true)
        .write(true)
        .create_new(true)
        .open(&job_path);
    let _ = std::fs::remove_file(&job_path);
    let mut file = match file {
        Ok(f) => f,
        Err(e) => return start_failed(format!("{}: {e}", job_path.display())),
    };
    let job = Job {
        lock_fd: lock.raw_fd(),
        ..job.clone()
    };
    let written = serde_json::to_vec(&job)
        .map_err(std::io::Error::other)
        .and_then(|b| file.write_all(&b))
        .and_then(|()| file.rewind());
    if let Err(e) = written {
        return start_failed(format!("writing the run's job for its process: {e}"));
    }

    let mut cmd = Command::new(exe);
    cmd.arg("run")
        .arg(CHILD_FLAG)
        .stdin(Stdio::from(file))
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    let lock_fd = job.lock_fd;
    let parent = std::process::id() as libc::pid_t;
    let limit = memory_limit_bytes;
    // SAFETY: the closure runs in the forked child before exec and calls only
    // async-signal-safe functions (prctl, getppid, setrlimit, fcntl), allocating nothing.
    unsafe {
        cmd.pre_exec(move || {
            #[cfg(target_os = "linux")]
            {
                if libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGKILL) != 0 {
                    return Err(std::io::Error::last_os_error());
                }
                // The parent may have died before the prctl: then nobody would kill us.
                if libc::getppid() != parent {
                    return Err(std::io::Error::from_raw_os_error(libc::ESRCH));
                }
            }
            #[cfg(not(target_os = "linux"))]
            let _ = parent;
            if let Some(l) = limit {
                let r = libc::rlimit {
                    rlim_cur: l as libc::rlim_t,
                    rlim_max: l as libc::rlim_t,
                };
                if libc::setrlimit(libc::RLIMIT_AS, &r) != 0 {
                    return Err(std::io::Error::last_os_error());
                }
            }
            // Hand the lock's descriptor down (std opens every file close-on-exec).
            let flags = libc::fcntl(lock_fd, libc::F_GETFD);
            if flags < 0 || libc::fcntl(lock_fd, libc::F_SETFD, flags & !libc::FD_CLOEXEC) < 0 {
                return Err(std::io::Error::last_os_error());
            }
            Ok(())
        });
    }
    let output = match cmd.output() {
        Ok(o) => o,
        Err(e) => return start_failed(format!("cannot start {}: {e}", exe.display())),
    };
    let answer = String::from_utf8_lossy(&output.stdout)
        .lines()
        .rev()
        .find_map(|l| serde_json::from_str::<Answer>(l).ok());
    match (output.status.code(), answer) {
        (Some(0), Some(Answer { error: None })) => ChildEnd::Done,
        (Some(1), Some(Answer { error: Some(e) })) => ChildEnd::Failed(e),
        (code, _) => ChildEnd::Crashed(describe_crash(
            code,
            output.status.signal(),
            &output.stderr,
            memory_limit_bytes,
        )),
    }
}

#[cfg(not(unix))]
pub(crate) fn run_child(
    _exe: &Path,
    _memory_limit_bytes: Option<u64>,
    _job: &Job,
    _lock: &atomic::FolderLock,
) -> ChildEnd {
    ChildEnd::Crashed(Crash {
        error: "batch runs in child processes need a Unix system".into(),
        ..Crash::default()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn memory_sizes() {
        assert_eq!(parse_memory_limit("512M").unwrap(), 512 << 20);
        assert_eq!(parse_memory_limit("2G").unwrap(), 2 << 30);
        assert_eq!(parse_memory_limit("2GiB").unwrap(), 2 << 30);
        assert_eq!(parse_memory_limit("1.5g").unwrap(), 3 << 29);
        assert_eq!(parse_memory_limit("4096").unwrap(), 4096);
        for bad in ["", "G", "-1G", "2X", "0", "nan"] {
            assert!(parse_memory_limit(bad).is_err(), "{bad}");
        }
        assert_eq!(show_bytes(1 << 30), "1 GiB");
        assert_eq!(show_bytes(3 << 29), "1.5 GiB");
    }

    #[cfg(unix)]
    #[test]
    fn crashes_are_described_with_their_cause() {
        let c = describe_crash(
            None,
            Some(libc::SIGABRT),
            b"memory allocation of 152000000000 bytes failed\n",
            Some(1 << 30),
        );
        assert_eq!(
            c.error,
            "the run's process was killed by signal 6 (SIGABRT): memory allocation of \
             152000000000 bytes failed (over the per-run memory limit of 1 GiB: --memory-limit)"
        );
        let c = describe_crash(None, Some(libc::SIGKILL), b"", None);
        assert!(
            c.error.contains("SIGKILL") && c.error.contains("out-of-memory killer"),
            "{}",
            c.error
        );
        let long: String = (0..5000).map(|k| format!("line {k}\n")).collect();
        let c = describe_crash(Some(3), None, long.as_bytes(), None);
        assert!(c.stderr.len() <= STDERR_KEPT + 10, "{}", c.stderr.len());
        assert!(c.stderr.starts_with("line 0\n") && c.stderr.ends_with("\nline 4999"));
        assert!(c.stderr.contains("\n[...]\n"));
        assert!(
            c.error.ends_with("code 3 without an answer: line 0"),
            "{}",
            c.error
        );
        let panic =
            b"thread 'main' panicked at src/x.rs:3:5:\nboom\nnote: run with `RUST_BACKTRACE=1`\n";
        let c = describe_crash(Some(101), None, panic, None);
        assert!(
            c.error.ends_with(
                "code 101 without an answer: thread 'main' panicked at src/x.rs:3:5: boom"
            ),
            "{}",
            c.error
        );
    }
}
