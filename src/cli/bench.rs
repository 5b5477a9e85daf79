//! `applesim bench SCENARIO [--threads N] [--window A:B ...] [--json]`: steps a scenario to its
//! end without outputs and reports the cost per window of simulated time (library:
//! `applesim::bench`).

use applesim::bench::{self, BenchReport, Window};
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// Scenario file (JSON).
    scenario: PathBuf,
    /// Threads of the contact force pass (default: every core), as for `applesim run`.
    #[arg(long)]
    threads: Option<usize>,
    /// A window FROM:TO of simulated seconds to measure, repeatable (default: the LIGGGHTS
    /// phases 0:0.5, 0.5:1 and 3:5 for a run of at least 5 s, else the whole run).
    #[arg(long = "window", value_name = "FROM:TO")]
    windows: Vec<String>,
    /// Print the figures as one JSON object.
    #[arg(long)]
    json: bool,
}

pub fn main(a: Args) -> Result<(), String> {
    let windows: Vec<Window> = a
        .windows
        .iter()
        .map(|w| Window::parse(w))
        .collect::<Result<_, _>>()
        .map_err(|e| e.to_string())?;
    let (sc, base) = super::load_scenario(&a.scenario)?;
    let r = super::with_threads(a.threads, || bench::run(&sc, &base, &windows))?
        .map_err(|e| e.to_string())?;
    if a.json {
        let mut v = serde_json::to_value(&r).map_err(|e| e.to_string())?;
        v["scenario"] = serde_json::Value::String(a.scenario.display().to_string());
        println!("{v}");
    } else {
        print_table(&a.scenario.display().to_string(), &r);
    }
    Ok(())
}

fn opt(x: Option<f64>, f: impl Fn(f64) -> String) -> String {
    x.map(f).unwrap_or_else(|| "-".into())
}

fn print_table(name: &str, r: &BenchReport) {
    println!(
        "{name}: {} apples, {} steps of {} s ({} s simulated), {} thread(s), {} rapier body set(s)",
        r.apples,
        r.steps,
        r.time_step_s,
        // The sum of the steps, without the last digits of its rounding (0.030000000000000002).
        (r.simulated_time_s * 1e9).round() / 1e9,
        r.threads,
        r.body_sets
    );
    println!(
        "{:<22} {:>8} {:>10} {:>14} {:>11} {:>7} {:>15} {:>18} {:>12}  steps set by",
        "window (s)",
        "steps",
        "wall s",
        "apple-steps/s",
        "mean awake",
        "riding",
        "contacts/apple",
        "apple-apple/apple",
        "mean step s"
    );
    for w in &r.windows {
        println!(
            "{:<22} {:>8} {:>10.3} {:>14} {:>11} {:>7} {:>15.3} {:>18.3} {:>12}  {}",
            format!("{} {}-{}", w.window.label, w.window.from_s, w.window.to_s),
            w.steps,
            w.wall_s,
            opt(w.apple_steps_per_s, |x| format!("{x:.3e}")),
            opt(w.mean_awake_apples, |x| format!("{x:.1}")),
            opt(w.mean_riding_apples, |x| format!("{x:.1}")),
            w.contacts_per_apple,
            w.apple_apple_contacts_per_apple,
            opt(w.mean_step_s, |x| format!("{x:.3e}")),
            w.steps_set_by.describe(w.steps)
        );
    }
    println!(
        "whole run: {} steps in {:.3} s wall (time loop; setup {:.3} s), {:.3e} apple-steps/s",
        r.steps, r.wall_s, r.setup_wall_s, r.apple_steps_per_s
    );
    println!(
        "settled pile height (largest apple-centre z at the end): {:.4} m",
        r.pile_height_m
    );
    println!(
        "peak resident memory: {}",
        opt(r.peak_rss_mib, |x| format!("{x:.1} MiB"))
    );
}
