//! `applesim audit RUN_A RUN_B ...`: the line audits of several runs side by side (library:
//! `applesim::analysis::audit::compare`).

use applesim::analysis::audit;
use applesim::output::{atomic, audit as files};
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// Run folders written by `applesim run` (or a batch's runs/<id>); the first is the
    /// reference the others are compared with.
    #[arg(required = true)]
    runs: Vec<PathBuf>,
    /// Also write the table to this Markdown file.
    #[arg(long, short)]
    out: Option<PathBuf>,
}

pub fn main(a: Args) -> Result<(), String> {
    let mut runs = Vec::new();
    for dir in &a.runs {
        let p = applesim::output::csv_file::locate(dir, "audit.csv");
        if !p.is_file() {
            return Err(format!(
                "{}: no audit.csv (not a run folder, or written by an applesim before the line audit: run it again)",
                dir.display()
            ));
        }
        let au = files::read_audit(&p).map_err(|e| e.to_string())?;
        runs.push((dir.display().to_string(), au));
    }
    let table = audit::compare(&runs);
    if let Some(out) = &a.out {
        atomic::write_file(out, table.as_bytes()).map_err(|e| format!("{}: {e}", out.display()))?;
    }
    print!("{table}");
    Ok(())
}
