//! `applesim run SCENARIO --out DIR`.

use applesim::batch::isolate;
use applesim::math::{human, secs, step, step_range};
use applesim::output::plot::{self, PlotOptions};
use applesim::sim::RunResult;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
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
    /// With --plots: time window FROM:TO of the force chart, in ms since first touch; default:
    /// from the touch to the end of the longest impact pulse and a fifth more.
    #[arg(long, value_name = "FROM:TO", requires = "plots")]
    window: Option<String>,
    /// With --plots: time window FROM:TO of the charts against time (slip, speed, angular
    /// speed), in s of simulated time; default: the whole run.
    #[arg(long, value_name = "FROM:TO", requires = "plots")]
    time_window: Option<String>,
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
    let plot_options = PlotOptions {
        force_window_ms: super::plot::windows(a.window.as_deref(), "--window", "ms")?,
        time_window_s: super::plot::windows(a.time_window.as_deref(), "--time-window", "s")?,
        ..PlotOptions::default()
    };
    let (sc, base) = super::load_scenario(&scenario)?;
    if !a.quiet && applesim::scenario::budget::estimate_worth_showing(&sc) {
        eprintln!("{}", estimate_line(&sc));
    }
    // The bar only on a terminal: a pipe or a log file gets no control characters.
    let bar = (std::io::stderr().is_terminal() && !a.quiet).then(|| progress_bar(sc.duration_s));
    // Time left from the recent simulated-time rate (the bar's own estimate misreads a run
    // whose cost changes; super::time_left).
    let mut left = super::time_left::TimeLeft::default();
    let started = std::time::Instant::now();
    let mut progress = |f: f64| {
        if let Some(b) = &bar {
            let eta = left.observe(started.elapsed().as_secs_f64(), f);
            b.set_position((f * 1000.0).round() as u64);
            b.set_message(format!(
                "{} of {} s simulated, {} left",
                human(f * sc.duration_s, 3, 2),
                secs(sc.duration_s),
                eta.map_or_else(|| "?".to_string(), super::time_left::show)
            ));
        }
    };
    // The charts are drawn into the set before it is switched in, so they belong to it; their
    // notes and paths name the temporary folder, shown under the folder's own name.
    let mut plots: Option<(plot::PlotSummary, PathBuf)> = None;
    let mut viewed: Option<applesim::view::ViewStats> = None;
    let mut draw = |dir: &Path, _: &RunResult| -> Result<(), applesim::run::RunError> {
        if a.plots {
            let p = plot::plot_runs(&[dir.to_path_buf()], dir, &plot_options)?;
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
                applesim::run::RunError::Io {
                    path: page.clone(),
                    source: std::io::Error::other(format!("the viewer's page: {e}")),
                }
            })?;
            viewed = Some(stats);
        }
        Ok(())
    };
    let r = super::with_threads(a.threads, || {
        applesim::run::to_dir_with(&sc, &base, &a.out, &mut progress, &mut draw)
    })?
    .map_err(|e| e.to_string());
    if let Some(b) = &bar {
        b.finish_and_clear();
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
        println!("{}", steps_line(&r));
        println!("{} contact events", r.events.len());
        if let Some(e) = r
            .events
            .iter()
            .max_by(|x, y| x.peak_force_n.total_cmp(&y.peak_force_n))
        {
            println!(
                "largest peak force: {:.3} N, '{}' on '{}' at t = {} s",
                e.peak_force_n,
                e.a,
                e.b,
                secs(e.t_peak_s)
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
        println!("{}", fates_line(&r));
        for b in &r.line.throughput {
            if b.apples > 0 {
                println!("{}", bin_line(b));
            }
        }
        for w in &r.warnings {
            println!("warning: {w}");
        }
        // Every file of the folder as it was switched in (the run's set, charts and page
        // included), read back from it.
        println!(
            "wrote {}/{{{}}}",
            a.out.display(),
            written(&a.out).join(", ")
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

/// The entries of a run folder, sorted (folders with a trailing `/`).
fn written(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .map(|rd| {
            rd.filter_map(|e| e.ok())
                .map(|e| {
                    let name = e.file_name().to_string_lossy().to_string();
                    if e.file_type().is_ok_and(|t| t.is_dir()) {
                        format!("{name}/")
                    } else {
                        name
                    }
                })
                .collect()
        })
        .unwrap_or_default();
    names.sort();
    names
}

/// The progress bar of a run on a terminal: elapsed time, the bar, simulated time and the time
/// left (as `applesim batch` shows its runs).
fn progress_bar(duration_s: f64) -> ProgressBar {
    let bar = ProgressBar::with_draw_target(Some(1000), ProgressDrawTarget::stderr());
    bar.set_style(
        ProgressStyle::with_template("{elapsed_precise} [{bar:30}] {msg}")
            .expect("valid template")
            .progress_chars("=> "),
    );
    bar.set_message(format!("0 of {} s simulated, ? left", secs(duration_s)));
    bar
}

/// "200000 steps of 5e-5 s (10 s simulated) in 1.11 s wall time"; an adaptive run gives the
/// range of its steps.
fn steps_line(r: &RunResult) -> String {
    let steps = if r.step_policy == "adaptive" {
        format!(
            "{} adaptive steps of {} s",
            r.steps,
            step_range(r.step_range_s[0], r.step_range_s[1])
        )
    } else {
        format!("{} steps of {} s", r.steps, step(r.time_step_s))
    };
    format!(
        "{steps} ({} s simulated) in {:.2} s wall time",
        secs(r.simulated_time_s),
        r.wall_time_s
    )
}

/// Where the apples ended, counted: "20 apples: 20 in bins, 0 on surfaces, ...".
fn fates_line(r: &RunResult) -> String {
    let f = &r.line.fates;
    let mut parts = vec![
        format!("{} in bins", f.in_bin),
        format!("{} on surfaces", f.on_surface),
    ];
    if f.floating > 0 {
        parts.push(format!("{} at rest touching nothing", f.floating));
    }
    parts.push(format!("{} left the scene", f.left_scene));
    parts.push(format!("{} moving at the end", f.moving));
    if f.never_fed > 0 || !r.line.sources.is_empty() {
        parts.push(format!("{} never fed in", f.never_fed));
    }
    format!(
        "{} apple{}: {} (summary.json apples[].fate)",
        r.apples.len(),
        if r.apples.len() == 1 { "" } else { "s" },
        parts.join(", ")
    )
}

/// One bin's arrivals: "bin 'bin': 20 apples arrived from t = 3.614 to 8.364 s, 4 per second".
fn bin_line(b: &applesim::sim::fate::BinThroughput) -> String {
    let span = match (b.first_entry_s, b.last_entry_s) {
        (Some(f), Some(l)) if l > f => format!(" from t = {} to {} s", secs(f), secs(l)),
        (Some(f), _) => format!(" at t = {} s", secs(f)),
        _ => String::new(),
    };
    let rate = b
        .apples_per_s
        .map(|x| format!(", {} per second", human(x, 4, 0)))
        .unwrap_or_default();
    format!(
        "bin '{}': {} apple{} arrived{span}{rate}",
        b.bin,
        b.apples,
        if b.apples == 1 { "" } else { "s" }
    )
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

/// The line printed before a large run: the estimated output, file by file, and the sampling
/// behind it (the same estimate as the output budget, `scenario::budget::output_estimate`).
fn estimate_line(sc: &applesim::scenario::Scenario) -> String {
    let sampling = sc.sampling();
    format!(
        "estimated output: {}; bodies.csv sampled every {} s ({})",
        applesim::scenario::budget::output_estimate(sc).line(),
        sampling.interval_s,
        if sampling.set_by == "scenario" {
            "output.sample_interval_s"
        } else {
            "the default for the run's length and apples"
        }
    )
}
