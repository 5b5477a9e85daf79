//! `applesim report RUN_DIR [--out FILE.md]`: the line report of a run folder (library:
//! `applesim::output::report::line_report`).

use applesim::output::{atomic, report};
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// A run folder written by `applesim run` (or a batch's runs/<id>).
    run: PathBuf,
    /// Write the report to this Markdown file (whole or not at all) instead of printing it.
    #[arg(long, short)]
    out: Option<PathBuf>,
}

pub fn main(a: Args) -> Result<(), String> {
    let mut command = format!("applesim report {}", a.run.display());
    if let Some(out) = &a.out {
        command += &format!(" --out {}", out.display());
    }
    let text = report::line_report(&a.run, &command).map_err(|e| e.to_string())?;
    match &a.out {
        Some(out) => {
            atomic::write_file(out, text.as_bytes())
                .map_err(|e| format!("{}: {e}", out.display()))?;
            eprintln!("wrote {}", out.display());
        }
        None => print!("{text}"),
    }
    Ok(())
}
