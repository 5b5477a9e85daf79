//! `applesim batch SPEC --out DIR [--jobs N] [--shard i/n|auto] [--force] [--retry-failed]
//! [--memory-limit SIZE] [--dry-run]`.

use applesim::batch::{self, isolate, runner, Isolation, Outcome, PlannedRun, Shard, Skip};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::OnceLock;

#[derive(clap::Args)]
pub struct Args {
    /// Batch spec (JSON), or a folder whose *.json scenario files are the runs.
    spec: PathBuf,
    /// Output folder: batch.json, runs/<id>/, and merged.csv once every run of the batch has
    /// ended [default: out/<spec name>].
    #[arg(long, short)]
    out: Option<PathBuf>,
    /// Runs at the same time (each run uses one thread) [default: the number of cores].
    #[arg(long, short)]
    jobs: Option<usize>,
    /// Run only shard i of n (1-based): runs whose index is i-1 modulo n. `auto` reads a Slurm
    /// job array (SLURM_ARRAY_TASK_ID...) or a Kubernetes indexed Job (JOB_COMPLETION_INDEX).
    #[arg(long)]
    shard: Option<String>,
    /// Number of shards for --shard auto where the scheduler does not say it (Kubernetes);
    /// the environment variable APPLESIM_SHARD_COUNT does the same.
    #[arg(long)]
    shard_count: Option<usize>,
    /// Rerun every run of the shard: done, failed or not run yet.
    #[arg(long)]
    force: bool,
    /// Rerun the runs that failed before (a rerun skips them otherwise: a failure is
    /// deterministic, it would fail again).
    #[arg(long)]
    retry_failed: bool,
    /// Limit of each run's memory (address space), e.g. 4G: a run that outgrows it fails
    /// alone, recorded with its cause, and the batch goes on [default: no limit].
    #[arg(long, value_name = "SIZE")]
    memory_limit: Option<String>,
    /// Print the expanded runs (index, id, state, parameters) and run nothing.
    #[arg(long)]
    dry_run: bool,
    /// Print nothing but errors and failed runs.
    #[arg(long, short)]
    quiet: bool,
}

fn params_text(batch: &batch::Batch, run: &PlannedRun) -> String {
    batch
        .parameters
        .iter()
        .zip(&run.values)
        .map(|(p, v)| format!("{}={}", p.name, batch::merge::cell(v)))
        .collect::<Vec<_>>()
        .join(" ")
}

/// Draws the bar and prints one line per run above it (to stdout, so that logs keep them when
/// stderr, and with it the bar, is not a terminal).
struct Progress<'a> {
    batch: &'a batch::Batch,
    bar: OnceLock<ProgressBar>,
    show_bar: bool,
    quiet: bool,
    failed: AtomicUsize,
}

impl Progress<'_> {
    fn println(&self, line: String) {
        match self.bar.get() {
            Some(bar) => bar.suspend(|| println!("{line}")),
            None => println!("{line}"),
        }
    }
}

impl runner::Observer for Progress<'_> {
    fn not_retried(&self, failed_before: usize) {
        if failed_before > 0 {
            self.println(format!(
                "{failed_before} run(s) failed before: skipped (--retry-failed retries them)"
            ));
        }
    }

    fn start(&self, to_run: usize, already_done: usize) {
        if already_done > 0 && !self.quiet {
            self.println(format!(
                "{already_done} run(s) done before: skipped (--force reruns them)"
            ));
        }
        let target = if self.show_bar {
            ProgressDrawTarget::stderr()
        } else {
            ProgressDrawTarget::hidden()
        };
        let bar = ProgressBar::with_draw_target(Some(to_run as u64), target);
        bar.set_style(
            ProgressStyle::with_template(
                "{elapsed_precise} [{bar:30}] {pos}/{len} runs, {msg}, {eta} left",
            )
            .expect("valid template")
            .progress_chars("=> "),
        );
        bar.set_message("0 failed");
        let _ = self.bar.set(bar);
    }

    fn finished(&self, run: &PlannedRun, outcome: &Outcome) {
        match outcome {
            Outcome::Done { wall_time_s } => {
                if !self.quiet {
                    self.println(format!(
                        "ok     {:>5} {} ({wall_time_s:.2} s) {}",
                        run.index,
                        run.id,
                        params_text(self.batch, run)
                    ));
                }
            }
            Outcome::Failed { error } => {
                let n = self.failed.fetch_add(1, Ordering::Relaxed) + 1;
                if let Some(bar) = self.bar.get() {
                    bar.set_message(format!("{n} failed"));
                }
                self.println(format!(
                    "failed {:>5} {} {}\n       error: {error}",
                    run.index,
                    run.id,
                    params_text(self.batch, run)
                ));
            }
            Outcome::Skipped(why) => {
                if !self.quiet {
                    let why = match why {
                        Skip::Busy => "another process is running it",
                        Skip::DoneElsewhere => "another process has just done it",
                        Skip::FailedElsewhere => "another process has just recorded its failure",
                    };
                    self.println(format!("skip   {:>5} {} ({why})", run.index, run.id));
                }
            }
        }
        if let Some(bar) = self.bar.get() {
            bar.inc(1);
        }
    }
}

fn default_out(spec: &Path) -> PathBuf {
    let stem = spec
        .file_stem()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_else(|| "batch".into());
    Path::new("out").join(stem)
}

pub fn main(a: Args) -> Result<(), String> {
    let b = batch::load(&a.spec).map_err(|e| e.to_string())?;
    let shard = match a.shard.as_deref() {
        None => {
            if a.shard_count.is_some() {
                return Err("--shard-count goes with --shard auto".into());
            }
            Shard::ALL
        }
        Some("auto") => {
            let (s, from) = Shard::from_env(|k| std::env::var(k).ok(), a.shard_count)
                .map_err(|e| auto_shard_refused(&e))?;
            if !a.quiet {
                println!("shard {s} ({from})");
            }
            s
        }
        Some(s) => {
            if a.shard_count.is_some() {
                return Err("--shard-count goes with --shard auto, not with --shard i/n".into());
            }
            Shard::parse(s)?
        }
    };
    let out = a.out.clone().unwrap_or_else(|| default_out(&a.spec));
    let jobs = match a.jobs {
        Some(0) => return Err("--jobs 0: give at least 1".into()),
        Some(j) => j,
        None => std::thread::available_parallelism()
            .map(|n| n.get())
            .unwrap_or(1),
    };
    let share = runner::select(&b, &shard);

    if a.dry_run {
        println!(
            "{} runs in the batch, {} in shard {shard}; parameters: {}",
            b.runs.len(),
            share.len(),
            b.parameters
                .iter()
                .map(|p| p.name.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        );
        for run in share {
            let state = if batch::manifest::is_done(&out, &run.id) {
                "done"
            } else if batch::manifest::failed_path(&out, &run.id).is_file() {
                "failed"
            } else {
                "todo"
            };
            println!(
                "{:>5} {} {state:<6} {}",
                run.index,
                run.id,
                params_text(&b, run)
            );
        }
        return Ok(());
    }

    let progress = Progress {
        batch: &b,
        bar: OnceLock::new(),
        show_bar: std::io::stderr().is_terminal() && !a.quiet,
        quiet: a.quiet,
        failed: AtomicUsize::new(0),
    };
    let memory_limit_bytes = a
        .memory_limit
        .as_deref()
        .map(isolate::parse_memory_limit)
        .transpose()
        .map_err(|e| format!("--memory-limit: {e}"))?;
    let isolation = match isolate::find_executable() {
        Some(exe) if cfg!(unix) => Isolation::Process {
            exe,
            memory_limit_bytes,
        },
        _ => {
            if memory_limit_bytes.is_some() {
                return Err("--memory-limit needs runs in processes of their own (Unix)".into());
            }
            Isolation::InProcess
        }
    };
    let opts = runner::Options {
        jobs,
        shard,
        force: a.force,
        retry_failed: a.retry_failed,
        isolation,
    };
    let report = runner::run(&b, &out, &opts, &progress).map_err(|e| e.to_string())?;
    if let Some(bar) = progress.bar.get() {
        bar.finish_and_clear();
    }
    if !a.quiet {
        if report.manifest_replaced {
            println!(
                "note: {} described another expansion (the spec changed); replaced, runs with unchanged scenarios reused",
                out.join(batch::manifest::MANIFEST).display()
            );
        }
        if report.stale_removed > 0 {
            println!(
                "removed {} temporary folder(s) left by an interrupted batch",
                report.stale_removed
            );
        }
        let mut others = String::new();
        if !report.busy.is_empty() {
            others += &format!(
                ", {} left to another process running them",
                report.busy.len()
            );
        }
        if report.done_elsewhere > 0 {
            others += &format!(", {} done by another process", report.done_elsewhere);
        }
        if !report.failed_before.is_empty() {
            others += &format!(
                ", {} failed before (not retried)",
                report.failed_before.len()
            );
        }
        println!(
            "{} runs in shard {shard} of {}: {} ran, {} skipped (done before), {} failed{others}; results in {}",
            report.selected,
            report.total,
            report.done,
            report.skipped,
            report.failed.len(),
            out.join(batch::manifest::RUNS).display()
        );
    }
    // The batch's table, as soon as every run of the whole batch has ended (done or failed):
    // the last shard to finish writes it; `applesim merge OUT` rewrites it at any time.
    let ended = b.runs.iter().all(|r| {
        batch::manifest::is_done(&out, &r.id) || batch::manifest::failed_path(&out, &r.id).is_file()
    });
    if ended {
        let m = batch::merge(&out).map_err(|e| e.to_string())?;
        if !a.quiet {
            println!(
                "wrote {}: {} rows, {} ok, {} failed",
                m.csv.display(),
                m.rows,
                m.ok,
                m.failed.len()
            );
        }
    } else if !a.quiet {
        let left = b
            .runs
            .iter()
            .filter(|r| {
                !batch::manifest::is_done(&out, &r.id)
                    && !batch::manifest::failed_path(&out, &r.id).is_file()
            })
            .count();
        println!(
            "{left} runs of the batch have not ended (other shards): merged.csv is written when the last of them ends, or now, with rows for the missing runs, by `applesim merge {}`",
            out.display()
        );
    }
    let runs = out.join(batch::manifest::RUNS);
    match (report.failed.len(), report.failed_before.len()) {
        (0, 0) => Ok(()),
        (now, 0) => Err(format!(
            "{now} of {} runs failed (errors in {}/<id>.failed.json; --retry-failed retries them)",
            report.selected,
            runs.display()
        )),
        (now, before) => Err(format!(
            "{} of {} runs failed ({now} now, {before} before and not retried; errors in \
             {}/<id>.failed.json; --retry-failed retries them)",
            now + before,
            report.selected,
            runs.display()
        )),
    }
}

/// The refusal of `--shard auto`, with each command line that would run the right shard (this
/// one, with `--shard auto` and `--shard-count` replaced by `--shard i/n`).
fn auto_shard_refused(e: &batch::shard::AutoShardError) -> String {
    if e.instead.is_empty() {
        return e.message.clone();
    }
    let mut args: Vec<String> = vec!["applesim".into()];
    let mut it = std::env::args().skip(1);
    while let Some(arg) = it.next() {
        match arg.as_str() {
            "--shard" | "--shard-count" => {
                it.next();
            }
            a if a.starts_with("--shard=") || a.starts_with("--shard-count=") => {}
            _ => args.push(arg),
        }
    }
    let quoted: Vec<String> = args.iter().map(|a| shell_word(a)).collect();
    let mut msg = format!("{}; run instead:", e.message);
    for (when, s) in &e.instead {
        msg += &format!("\n  {when}:\n    {} --shard {s}", quoted.join(" "));
    }
    msg
}

/// `a` quoted for a POSIX shell where it needs it.
fn shell_word(a: &str) -> String {
    let plain = !a.is_empty()
        && a.chars()
            .all(|c| c.is_ascii_alphanumeric() || "-_./=:,+%@".contains(c));
    if plain {
        a.to_string()
    } else {
        format!("'{}'", a.replace('\'', "'\\''"))
    }
}
