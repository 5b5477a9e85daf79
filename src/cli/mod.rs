//! Argument parsing and plain error reporting; every subcommand lives in its own file.

mod audit;
mod batch;
mod bench;
mod calibrate;
mod calibrate_bruise;
mod merge;
mod plot;
mod report;
mod run;
mod time_left;
mod tradeoff;
mod validate;
mod view;

use applesim::scenario::{self, Scenario};
use clap::{Parser, Subcommand};
use std::path::{Path, PathBuf};

/// applesim: apple contact forces, contact times and slip/roll in fruit-handling lines.
#[derive(Parser)]
#[command(name = "applesim", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run a scenario and write summary.json, contacts.csv and bodies.csv into a folder.
    Run(run::Args),
    /// Find ke for a measured restitution by simulating the impact, or tabulate e over speeds.
    Calibrate(calibrate::Args),
    /// Fit a damage model (energy, pressure-area, peak-force) to a lab's drop tests by simulating
    /// each drop, and write it as a preset file a scenario names (`damage.file`).
    CalibrateBruise(calibrate_bruise::Args),
    /// Draw force-time and velocity-time charts (SVG) of one or several run folders.
    Plot(plot::Args),
    /// Compare two layouts: which is better on apples downgraded, bruise volume and peak g, for
    /// the line and per transfer point, each difference with its 95 % interval ("no change"
    /// inside it); --seeds N reruns both over paired feed seeds.
    Audit(audit::Args),
    /// The line report of a run folder: the scene, the audit per transfer point, the apples over
    /// a bruise threshold, the instrumented spheres, the warnings (Markdown).
    Report(report::Args),
    /// Run a scenario across fidelity levels and step sizes and tabulate error against cost.
    Tradeoff(tradeoff::Args),
    /// Run a batch of scenarios (a sweep spec or a folder) in parallel, resumable, by shards.
    Batch(batch::Args),
    /// Merge the runs of a batch into one table, OUT/merged.csv; report failed or missing runs.
    Merge(merge::Args),
    /// Step a scenario to its end without outputs and report its cost per window of simulated
    /// time (apple-steps per second, awake apples, contacts per apple, memory).
    Bench(bench::Args),
    /// Run the paper's Figs. 1-7, check them against its numbers and closed forms, and write a
    /// Markdown report with SVG charts.
    Validate(validate::Args),
    /// Write one self-contained HTML file showing a run folder in 3-D (opens offline in any
    /// current browser): play, colour apples by force, bruise, speed or motion, inspect contacts.
    View(view::Args),
}

/// Parses the arguments, runs the command, returns the exit code.
pub fn main() -> i32 {
    quiet_on_closed_pipe();
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Run(a) => run::main(a),
        Command::Calibrate(a) => calibrate::main(a),
        Command::CalibrateBruise(a) => calibrate_bruise::main(a),
        Command::Plot(a) => plot::main(a),
        Command::Audit(a) => audit::main(a),
        Command::Report(a) => report::main(a),
        Command::Tradeoff(a) => tradeoff::main(a),
        Command::Batch(a) => batch::main(a),
        Command::Merge(a) => merge::main(a),
        Command::Validate(a) => validate::main(a),
        Command::Bench(a) => bench::main(a),
        Command::View(a) => view::main(a),
    };
    match result {
        Ok(()) => 0,
        Err(msg) => {
            eprintln!("error: {msg}");
            1
        }
    }
}

/// A closed output pipe (`applesim batch --dry-run | head -4`) ends the command quietly, as it
/// does any Unix tool: by SIGPIPE, exit status 141 in the shell. Rust ignores SIGPIPE, which
/// turns the next write into an error and `println!` into a panic with a backtrace; restoring
/// the default disposition is the one place that covers every command's output.
fn quiet_on_closed_pipe() {
    #[cfg(unix)]
    // SAFETY: setting a signal's disposition to its default, before any thread is started.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

/// Loads and validates a scenario file, with the folder its relative paths (meshes, apple files)
/// resolve against.
fn load_scenario(path: &Path) -> Result<(Scenario, PathBuf), String> {
    let sc = scenario::load(path).map_err(|e| e.to_string())?;
    let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
    Ok((sc, base))
}

/// Runs `f` in a pool of `threads` threads (`--threads`), or in rayon's global pool.
fn with_threads<R: Send>(
    threads: Option<usize>,
    f: impl FnOnce() -> R + Send,
) -> Result<R, String> {
    match threads {
        Some(0) => Err("--threads 0: give at least 1".into()),
        Some(n) => Ok(rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .map_err(|e| format!("--threads {n}: {e}"))?
            .install(f)),
        None => Ok(f()),
    }
}
