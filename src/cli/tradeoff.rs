//! `applesim tradeoff SCENARIO --out DIR`: the scenario across fidelity levels and step sizes.

use applesim::analysis::tradeoff;
use applesim::output::atomic;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// Scenario file (JSON).
    scenario: PathBuf,
    /// Output folder for tradeoff.csv, tradeoff.md and tradeoff.svg (created if missing).
    #[arg(long, short, default_value = "tradeoff")]
    out: PathBuf,
}

pub fn main(a: Args) -> Result<(), String> {
    let (sc, base) = super::load_scenario(&a.scenario)?;
    let (reference, rungs) = tradeoff::default_ladder(&sc);
    let table = tradeoff::tradeoff(&sc, &base, &reference, &rungs, &mut |label| {
        eprintln!("running {label}");
    })
    .map_err(|e| e.to_string())?;
    std::fs::create_dir_all(&a.out).map_err(|e| format!("{}: {e}", a.out.display()))?;
    let io = |e: std::io::Error| format!("{}: {e}", a.out.display());
    atomic::write_file(&a.out.join("tradeoff.csv"), table.to_csv().as_bytes()).map_err(io)?;
    let md = table.to_markdown();
    atomic::write_file(&a.out.join("tradeoff.md"), md.as_bytes()).map_err(io)?;
    let title = format!("Speed against accuracy: {}", a.scenario.display());
    table
        .chart(&title)
        .write_svg(&a.out.join("tradeoff.svg"))
        .map_err(|e| e.to_string())?;
    println!("{md}");
    println!(
        "wrote {}/{{tradeoff.csv, tradeoff.md, tradeoff.svg}}",
        a.out.display()
    );
    Ok(())
}
