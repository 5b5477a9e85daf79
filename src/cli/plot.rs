//! `applesim plot RUN_DIR [RUN_DIR...] --out DIR`: SVG charts of saved runs, several runs on one
//! chart (library: `applesim::output::plot`).

use applesim::output::plot::{self, ChartWindow, PlotOptions};
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// Run folders written by `applesim run` (or a batch).
    #[arg(required = true)]
    runs: Vec<PathBuf>,
    /// Folder for the charts (created if missing).
    #[arg(long, short, default_value = "plots")]
    out: PathBuf,
    /// Most curves per chart, shared between the runs (largest peak forces first).
    #[arg(long, default_value_t = 10)]
    max_series: usize,
    /// Only this apple (repeatable).
    #[arg(long)]
    apple: Vec<String>,
    /// Time window FROM:TO of the force chart, in ms since first touch (either end may be left
    /// out); default: from the touch to the end of the longest impact pulse and a fifth more.
    #[arg(long, value_name = "FROM:TO")]
    window: Option<String>,
    /// Time window FROM:TO of the charts against time (slip, speed, angular speed), in s of
    /// simulated time; default: the whole run.
    #[arg(long, value_name = "FROM:TO")]
    time_window: Option<String>,
    /// Bin width of the histogram of where apples start rolling (m).
    #[arg(long, default_value_t = 0.05)]
    bin_m: f64,
}

pub fn main(a: Args) -> Result<(), String> {
    if !(a.bin_m.is_finite() && a.bin_m > 0.0) {
        return Err(format!("--bin-m {}: give a width > 0", a.bin_m));
    }
    let opts = PlotOptions {
        max_series: a.max_series,
        apples: a.apple,
        force_window_ms: windows(a.window.as_deref(), "--window", "ms")?,
        time_window_s: windows(a.time_window.as_deref(), "--time-window", "s")?,
        histogram_bin_m: a.bin_m,
    };
    let s = plot::plot_runs(&a.runs, &a.out, &opts).map_err(|e| e.to_string())?;
    for n in &s.notes {
        println!("note: {n}");
    }
    for w in &s.written {
        println!("wrote {}", w.display());
    }
    Ok(())
}

/// A window option parsed (`None` when not given).
pub(super) fn windows(
    text: Option<&str>,
    flag: &str,
    unit: &str,
) -> Result<Option<ChartWindow>, String> {
    text.map(|t| ChartWindow::parse(flag, t, unit).map_err(|e| e.to_string()))
        .transpose()
}
