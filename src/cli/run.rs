//! `applesim run SCENARIO --out DIR`.

use applesim::output;
use applesim::output::plot::{self, PlotOptions};
use std::io::IsTerminal;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// Scenario file (JSON).
    scenario: PathBuf,
    /// Output folder (created if missing).
    #[arg(long, short, default_value = "out")]
    out: PathBuf,
    /// Print nothing but errors.
    #[arg(long, short)]
    quiet: bool,
    /// Also draw the charts (force_time.svg, linear_velocity.svg, angular_velocity.svg) into the
    /// output folder.
    #[arg(long)]
    plots: bool,
    /// Threads for the contact force pass (default: every core). The outputs do not depend on
    /// it, byte for byte.
    #[arg(long)]
    threads: Option<usize>,
}

pub fn main(a: Args) -> Result<(), String> {
    let (sc, base) = super::load_scenario(&a.scenario)?;
    let tty = std::io::stderr().is_terminal() && !a.quiet;
    let mut last = -1i64;
    let mut progress = |f: f64| {
        let pct = (f * 100.0) as i64;
        if tty && pct != last {
            last = pct;
            eprint!("\r{pct:3} %");
        }
    };
    let r = super::with_threads(a.threads, || {
        output::run_to_dir(&sc, &base, &a.out, &mut progress)
    })?
    .map_err(|e| e.to_string());
    if tty {
        eprint!("\r      \r");
    }
    let r = r?;
    let plots = if a.plots {
        Some(
            plot::plot_runs(
                std::slice::from_ref(&a.out),
                &a.out,
                &PlotOptions::default(),
            )
            .map_err(|e| e.to_string())?,
        )
    } else {
        None
    };
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
