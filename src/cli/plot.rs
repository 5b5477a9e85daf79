//! `applesim plot RUN_DIR [RUN_DIR...] --out DIR`: SVG charts of saved runs, several runs on one
//! chart (library: `applesim::output::plot`).

use applesim::output::plot::{self, PlotOptions};
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
    /// Time window of the force chart (ms from first touch); default: five times the longest
    /// impact pulse.
    #[arg(long)]
    window_ms: Option<f64>,
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
        window_ms: a.window_ms,
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
