//! `applesim validate [--out DIR] [--runs DIR] [--specs DIR] [--jobs N]`: the paper's Figs. 1-7
//! run, checked and written up as a Markdown report with SVG charts (docs/validation/).

use applesim::validate::{self, Options};
use std::path::PathBuf;
use std::time::Instant;

#[derive(clap::Args)]
pub struct Args {
    /// Folder of the report (report.md) and its charts (figN_*.svg), created if missing.
    #[arg(long, short, default_value = "out/validation")]
    out: PathBuf,
    /// Folder of the runs, one batch folder per figure [default: OUT/runs].
    #[arg(long)]
    runs: Option<PathBuf>,
    /// Folder of the figure specs (fig1.json ... fig7.json, eq12_restitution.json).
    #[arg(long, default_value = "scenarios/paper")]
    specs: PathBuf,
    /// Runs at the same time within a figure [default: the number of cores].
    #[arg(long, short)]
    jobs: Option<usize>,
}

pub fn main(a: Args) -> Result<(), String> {
    let jobs = match a.jobs {
        Some(0) => return Err("--jobs 0: give at least 1".into()),
        Some(n) => n,
        None => std::thread::available_parallelism().map_or(1, |n| n.get()),
    };
    if !a.specs.is_dir() {
        return Err(format!(
            "--specs {}: no such folder (run from the repository root, or give the folder of the paper's specs)",
            a.specs.display()
        ));
    }
    let opts = Options {
        runs_dir: a.runs.unwrap_or_else(|| a.out.join("runs")),
        specs_dir: a.specs,
        out_dir: a.out,
        jobs,
    };
    let start = Instant::now();
    let v = validate::run(&opts, &mut |line| println!("{line}")).map_err(|e| e.to_string())?;
    let total = v.checks().count();
    let failed = v.failed();
    println!(
        "{} of {total} checks pass ({:.1} s); report: {}",
        total - failed.len(),
        start.elapsed().as_secs_f64(),
        v.report.display()
    );
    if failed.is_empty() {
        Ok(())
    } else {
        for c in &failed {
            eprintln!(
                "FAIL {}: {} = {} ({}; tolerance {})",
                c.key,
                c.what,
                c.unit.show(c.ours),
                c.source,
                c.tolerance_text()
            );
        }
        Err(format!(
            "{} of {total} checks failed (see {})",
            failed.len(),
            v.report.display()
        ))
    }
}
