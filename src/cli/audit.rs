//! `applesim audit A B [--seeds N] [--out DIR] [--jobs N]`: two layouts compared on the fruit's
//! damage, each difference with its 95 % interval, "no change" inside the scatter (library:
//! `applesim::analysis::compare`, `applesim::batch::seeds`; guide: docs/damage.md section 9).

use applesim::analysis::compare;
use applesim::batch::{isolate, runner, seeds, Isolation, Outcome, PlannedRun};
use applesim::output::compare as files;
use std::path::{Path, PathBuf};

#[derive(clap::Args)]
pub struct Args {
    /// Layout A: a run folder written by `applesim run` (or a batch's runs/<id>); with
    /// --seeds, also a scenario file.
    #[arg(value_name = "A")]
    a: PathBuf,
    /// Layout B, the same way.
    #[arg(value_name = "B")]
    b: PathBuf,
    /// Rerun both layouts' scenarios over N feed seeds (run k of each with seed k) and give each
    /// difference with its paired interval over the seeds (the run-to-run scatter). Needs --out.
    #[arg(long, value_name = "N")]
    seeds: Option<usize>,
    /// Folder for compare.md and compare.csv, and with --seeds the runs (DIR/a, DIR/b: batches,
    /// reused by a rerun of the same command).
    #[arg(long, short, value_name = "DIR")]
    out: Option<PathBuf>,
    /// Runs at the same time with --seeds (each run uses one thread) [default: the number of
    /// cores].
    #[arg(long, short)]
    jobs: Option<usize>,
}

/// One line per finished seeded run of layout `.0`, on standard error (standard output is the
/// table).
struct Progress(&'static str);

impl runner::Observer for Progress {
    fn finished(&self, run: &PlannedRun, outcome: &Outcome) {
        let (layout, k) = (self.0, run.index + 1);
        match outcome {
            Outcome::Done { wall_time_s } => {
                eprintln!("ran {layout} seed {k} ({}, {wall_time_s:.2} s)", run.id)
            }
            Outcome::Failed { error } => {
                eprintln!("failed {layout} seed {k} ({}): {error}", run.id)
            }
            Outcome::Skipped(_) => {}
        }
    }
}

pub fn main(a: Args) -> Result<(), String> {
    let (pa, pb) = (&a.a, &a.b);
    if let Some(out) = &a.out {
        if out.extension().is_some_and(|e| e == "md") && !out.is_dir() {
            return Err(format!(
                "--out {}: give a folder (compare.md and compare.csv are written into it)",
                out.display()
            ));
        }
    }
    let (label_a, label_b) = (pa.display().to_string(), pb.display().to_string());
    let cmp = match a.seeds {
        None => {
            if a.jobs.is_some() {
                return Err("--jobs goes with --seeds (the runs it reruns)".into());
            }
            let ra = files::read_run(pa).map_err(|e| e.to_string())?;
            let rb = files::read_run(pb).map_err(|e| e.to_string())?;
            compare::compare_runs(&ra, &rb)
        }
        Some(n) => {
            let Some(out) = &a.out else {
                return Err(format!(
                    "--seeds {n} needs --out DIR: the folder its {} runs are written into (a rerun of the same command reuses them)",
                    2 * n
                ));
            };
            let jobs = match a.jobs {
                Some(0) => return Err("--jobs 0: give at least 1".into()),
                Some(j) => j,
                None => std::thread::available_parallelism()
                    .map(|n| n.get())
                    .unwrap_or(1),
            };
            let la = seeds::layout(pa).map_err(|e| e.to_string())?;
            let lb = seeds::layout(pb).map_err(|e| e.to_string())?;
            let isolation = match isolate::find_executable() {
                Some(exe) if cfg!(unix) => Isolation::Process {
                    exe,
                    memory_limit_bytes: None,
                },
                _ => Isolation::InProcess,
            };
            let opts = runner::Options {
                jobs,
                isolation,
                ..runner::Options::default()
            };
            let [da, db] =
                seeds::run_pair(&la, &lb, n, out, &opts, [&Progress("A"), &Progress("B")])
                    .map_err(|e| e.to_string())?;
            let read = |dirs: &[PathBuf]| -> Result<Vec<_>, String> {
                dirs.iter()
                    .map(|d| files::read_run(d).map_err(|e| e.to_string()))
                    .collect()
            };
            compare::compare_seeds(&read(&da)?, &read(&db)?)
        }
    };
    let suggest = format!(
        "applesim audit {} {} --seeds 5 --out {}",
        shown(pa),
        shown(pb),
        a.out.as_deref().map_or_else(|| "DIR".to_string(), shown)
    );
    let md = cmp.markdown(&label_a, &label_b, &suggest);
    if let Some(out) = &a.out {
        files::write_comparison(out, &md, &cmp).map_err(|e| format!("{}: {e}", out.display()))?;
    }
    print!("{md}");
    Ok(())
}

/// A path as a shell word (quoted where it needs it).
fn shown(p: &Path) -> String {
    let s = p.display().to_string();
    let plain = !s.is_empty()
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || "-_./=:,+%@".contains(c));
    if plain {
        s
    } else {
        format!("'{}'", s.replace('\'', "'\\''"))
    }
}
