//! `applesim view RUN_DIR [--out FILE.html] [--max-frames N] [--assets DIR]`.

use applesim::view::{self, ViewOptions, ViewStats};
use std::path::{Path, PathBuf};

#[derive(clap::Args)]
pub struct Args {
    /// A run folder (what `applesim run --out` wrote).
    run_dir: PathBuf,
    /// The HTML file to write (default: RUN_DIR/view.html). Written whole or not at all.
    #[arg(long, short)]
    out: Option<PathBuf>,
    /// Largest number of frames embedded; the samples of bodies.csv are thinned evenly to it
    /// (first and last kept). Fewer frames, smaller file.
    #[arg(long, default_value_t = view::DEFAULT_MAX_FRAMES)]
    max_frames: usize,
    /// Folder that the scenario's mesh files resolve against (the scenario's own folder);
    /// default the run folder.
    #[arg(long)]
    assets: Option<PathBuf>,
    /// Print nothing but errors.
    #[arg(long, short)]
    quiet: bool,
}

pub fn main(a: Args) -> Result<(), String> {
    let out = a.out.clone().unwrap_or_else(|| a.run_dir.join(VIEW_FILE));
    let opts = ViewOptions {
        max_frames: a.max_frames,
        asset_dir: a.assets.clone(),
        label: None,
    };
    let stats = view::write_view(&a.run_dir, &out, &opts).map_err(|e| e.to_string())?;
    if !a.quiet {
        report(&out, &stats);
    }
    Ok(())
}

/// Name of the page inside a run folder.
pub const VIEW_FILE: &str = "view.html";

/// Prints what a page holds (also for `applesim run --view`).
pub fn report(out: &Path, s: &ViewStats) {
    println!(
        "wrote {} ({:.1} MB): {} apples, {} surface parts, {} of {} samples as frames, {} contacts",
        out.display(),
        s.bytes as f64 / 1e6,
        s.apples,
        s.surfaces,
        s.frames,
        s.samples,
        s.contacts
    );
    for n in &s.notes {
        println!("note: {n}");
    }
}
