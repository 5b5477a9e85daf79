//! `applesim merge OUT`: all runs of a batch in one table, `OUT/merged.csv`.

use applesim::batch;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// Output folder of `applesim batch` (holds batch.json and runs/).
    out: PathBuf,
    /// Print nothing but errors, failed and missing runs.
    #[arg(long, short)]
    quiet: bool,
}

pub fn main(a: Args) -> Result<(), String> {
    let r = batch::merge(&a.out).map_err(|e| e.to_string())?;
    for (index, id, error) in &r.failed {
        eprintln!("failed  run {index} ({id}): {error}");
    }
    for (index, id) in &r.missing {
        eprintln!("missing run {index} ({id})");
    }
    if !a.quiet {
        println!(
            "wrote {}: {} rows, {} ok, {} failed, {} missing",
            r.csv.display(),
            r.rows,
            r.ok,
            r.failed.len(),
            r.missing.len()
        );
    }
    if r.failed.is_empty() && r.missing.is_empty() {
        Ok(())
    } else {
        Err(format!(
            "{} failed and {} missing of {} runs (rows with status failed/missing in {})",
            r.failed.len(),
            r.missing.len(),
            r.rows,
            r.csv.display()
        ))
    }
}
