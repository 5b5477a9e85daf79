//! `applesim run SCENARIO --out DIR`.

use applesim::batch::isolate;
use applesim::output;
use applesim::output::plot::{self, PlotOptions};
use applesim::sim::RunResult;
use std::io::{IsTerminal, Read};
use std::path::{Path, PathBuf};

#[derive(clap::Args)]
pub struct Args {
    /// Scenario file (JSON).
    #[arg(required_unless_present = "batch_job")]
    scenario: Option<PathBuf>,
    /// Output folder (created if missing). Its files are replaced as one set, at once: it holds
    /// either the previous run's files or this run's, never a mix; a folder that is not a
    /// run's is refused, and so is a folder another run is writing.
    #[arg(long, short, default_value = "out")]
    out: PathBuf,
    /// Print nothing but errors.
    #[arg(long, short)]
    quiet: bool,
    /// Also draw the charts (force_time.svg, linear_velocity.svg, angular_velocity.svg) into the
    /// output folder.
    #[arg(long)]
    plots: bool,
    /// Also write the viewer's page, view.html, into the output folder (one HTML file that
    /// opens offline in a browser; see `applesim view`).
    #[arg(long)]
    view: bool,
    /// With --view: the largest number of frames in the page.
    #[arg(long, default_value_t = applesim::view::DEFAULT_MAX_FRAMES, requires = "view")]
    max_frames: usize,
    /// Threads for the contact force pass (default: every core). The outputs do not depend on
    /// it, byte for byte.
    #[arg(long)]
    threads: Option<usize>,
    /// A batch run's child process: reads its job (JSON) on standard input, answers on
    /// standard output (applesim batch starts it; see batch::isolate).
    #[arg(long = "batch-job", hide = true, conflicts_with_all = ["scenario", "plots", "view"])]
    batch_job: bool,
}

pub fn main(a: Args) -> Result<(), String> {
    if a.batch_job {
        return batch_job();
    }
    let scenario = a
        .scenario
        .clone()
        .expect("clap requires it without --batch-job");
    let (sc, base) = super::load_scenario(&scenario)?;
    let tty = std::io::stderr().is_terminal() && !a.quiet;
    let mut last = -1i64;
    let mut progress = |f: f64| {
        let pct = (f * 100.0) as i64;
        if tty && pct != last {
            last = pct;
            eprint!("\r{pct:3} %");
        }
    };
    // The charts are drawn into the set before it is switched in, so they belong to it; their
    // notes and paths name the temporary folder, shown under the folder's own name.
    let mut plots: Option<(plot::PlotSummary, PathBuf)> = None;
    let mut viewed: Option<applesim::view::ViewStats> = None;
    let mut draw = |dir: &Path, _: &RunResult| -> Result<(), output::RunError> {
        if a.plots {
            let p = plot::plot_runs(&[dir.to_path_buf()], dir, &PlotOptions::default())?;
            plots = Some((p, dir.to_path_buf()));
        }
        if a.view {
            // Into the set before it is switched in, like the charts: a failed page fails
            // the run's set as a whole.
            let opts = applesim::view::ViewOptions {
                max_frames: a.max_frames,
                asset_dir: Some(base.clone()),
                label: Some(a.out.display().to_string()),
            };
            let page = dir.join(super::view::VIEW_FILE);
            let stats = applesim::view::write_view(dir, &page, &opts).map_err(|e| {
                output::RunError::Io {
                    path: page.clone(),
                    source: std::io::Error::other(format!("the viewer's page: {e}")),
                }
            })?;
            viewed = Some(stats);
        }
        Ok(())
    };
    let r = super::with_threads(a.threads, || {
        output::run_to_dir_with(&sc, &base, &a.out, &mut progress, &mut draw)
    })?
    .map_err(|e| e.to_string());
    if tty {
        eprint!("\r      \r");
    }
    let r = r?;
    let plots = plots.map(|(mut p, staged)| {
        let (from, to) = (staged.display().to_string(), a.out.display().to_string());
        for n in &mut p.notes {
            *n = n.replace(&from, &to);
        }
        for w in &mut p.written {
            if let Ok(rel) = w.strip_prefix(&staged) {
                *w = a.out.join(rel);
            }
        }
        p
    });
    if !a.quiet {
        println!(
            "{} steps of {} s ({} s simulated) in {:.2} s wall time",
            r.steps, r.time_step_s, r.simulated_time_s, r.wall_time_s
        );
        println!("{} contact events", r.events.len());
        if let Some(e) = r
            .events
            .iter()
            .max_by(|x, y| x.peak_force_n.total_cmp(&y.peak_force_n))
        {
            println!(
                "largest peak force: {:.3} N, '{}' on '{}' at t = {:.6} s",
                e.peak_force_n, e.a, e.b, e.t_peak_s
            );
        }
        if let Some(n) = r.metrics.get("bruised_apples") {
            println!("{n} apple(s) over a bruise threshold (bruise.csv)");
        }
        if let Some(t) = &r.transition_summary {
            let rolling = r
                .metrics
                .get("apples_rolling_at_end")
                .copied()
                .unwrap_or(0.0);
            println!(
                "{} slip/roll transitions; {rolling} of {} apple(s) rolling at the end (transitions.csv)",
                t.transitions,
                t.apples.len()
            );
        }
        for w in &r.warnings {
            println!("warning: {w}");
        }
        println!(
            "wrote {}/{{summary.json, contacts.csv, bodies.csv, bruise.csv, scenario.json{}{}{}}}",
            a.out.display(),
            if r.transition_summary.is_some() {
                ", transitions.csv"
            } else {
                ""
            },
            if sc.output.force_history {
                ", forces.csv, pulse_fits.csv"
            } else {
                ""
            },
            if sc.output.vtk.is_some() {
                ", scene.pvd, vtk/"
            } else {
                ""
            }
        );
        if let Some(s) = &viewed {
            super::view::report(&a.out.join(super::view::VIEW_FILE), s);
        }
        if let Some(p) = &plots {
            for n in &p.notes {
                println!("note: {n}");
            }
            for w in &p.written {
                println!("wrote {}", w.display());
            }
        }
    }
    Ok(())
}

/// `applesim run --batch-job`: one run of a batch, in a process of its own. The answer goes to
/// standard output as one JSON line; the exit code is 0 when the run is complete, 1 when it
/// failed (anything else, a signal included, is a crash the batch records as such).
fn batch_job() -> Result<(), String> {
    let mut text = String::new();
    std::io::stdin()
        .read_to_string(&mut text)
        .map_err(|e| format!("reading the batch job on standard input: {e}"))?;
    let job: isolate::Job =
        serde_json::from_str(&text).map_err(|e| format!("not a batch job: {e}"))?;
    let answer = isolate::child_main(&job);
    println!(
        "{}",
        serde_json::to_string(&answer).expect("an answer serialises")
    );
    match answer.error {
        None => Ok(()),
        Some(e) => Err(e),
    }
}
