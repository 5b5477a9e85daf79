//! `applesim calibrate-bruise DROPS.csv --materials LAB.json --model energy --out PRESET.json`:
//! a damage model fitted to a lab's drop tests, written as a preset file a scenario names
//! (library: `applesim::analysis::calibrate_bruise`; guide: docs/damage.md section 8).

use applesim::analysis::calibrate_bruise::{self, Options};
use applesim::analysis::damage::fit::FitOptions;
use applesim::output::atomic;
use applesim::scenario::damage::{DamageModelName, DEPTH_RATIO};
use applesim::scenario::lab::LabSetup;
use std::path::{Path, PathBuf};

/// The damage models, as the command line names them.
#[derive(Clone, Copy, clap::ValueEnum)]
enum Model {
    /// Bruise volume BS max(0, E - E_th): fits BS and E_th (E_th only from yes/no data).
    Energy,
    /// The Hertz patch above p_c is bruised: fits p_c (and the depth ratio with
    /// --fit-depth-ratio).
    PressureArea,
    /// Bruised above a peak force: fits F_th (an onset).
    PeakForce,
}

#[derive(clap::Args)]
pub struct Args {
    /// The drops: a CSV, one row per drop (height_m, speed_m_s or peak_force_n; surface;
    /// diameter_m; mass_kg; volume_mm3, diameter_mm and depth_mm, or bruised; id optional).
    drops: PathBuf,
    /// The lab file: the apple's and the surfaces' materials, contact coefficients and pairs as
    /// a scenario writes them, and optional padded test surfaces.
    #[arg(long)]
    materials: PathBuf,
    /// The damage model to fit.
    #[arg(long, value_enum)]
    model: Model,
    /// The preset file to write (a damage entry; the report goes beside it as .report.md).
    #[arg(long)]
    out: PathBuf,
    /// The apple's material in the lab file.
    #[arg(long, default_value = "apple")]
    apple_material: String,
    /// Pressure-area model: bruise depth over the apple's deformation (default 2.5, the
    /// preset's).
    #[arg(long)]
    depth_ratio: Option<f64>,
    /// Pressure-area model with volumes: fit the depth ratio as well as p_c.
    #[arg(long, conflicts_with = "depth_ratio")]
    fit_depth_ratio: bool,
    /// The damage preset the written entry starts from (yes/no data fit the energy model's
    /// E_th only and take BS from it; default generic).
    #[arg(long)]
    preset: Option<String>,
    /// Time steps per elastic contact time of each simulated drop.
    #[arg(long, default_value_t = calibrate_bruise::DEFAULT_STEPS_PER_DROP)]
    steps_per_impact: f64,
    /// The report file (default: the preset's name with .report.md).
    #[arg(long)]
    report: Option<PathBuf>,
}

/// `PRESET.json` -> `PRESET.report.md`.
fn report_path(out: &Path) -> PathBuf {
    let stem = out
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "preset".into());
    out.with_file_name(format!("{stem}.report.md"))
}

pub fn main(a: Args) -> Result<(), String> {
    let model = match a.model {
        Model::Energy => DamageModelName::Energy,
        Model::PressureArea => DamageModelName::PressureArea,
        Model::PeakForce => DamageModelName::PeakForce,
    };
    if let Some(r) = a.depth_ratio {
        if !(r.is_finite() && (0.01..=100.0).contains(&r)) {
            return Err(format!("--depth-ratio: {r} must lie in [0.01, 100]"));
        }
    }
    if (a.depth_ratio.is_some() || a.fit_depth_ratio) && model != DamageModelName::PressureArea {
        return Err("--depth-ratio and --fit-depth-ratio go with --model pressure-area".into());
    }
    let lab_file = a.materials.display().to_string();
    let lab = LabSetup::load(&a.materials).map_err(|e| match e {
        applesim::scenario::ScenarioError::Invalid { .. } => format!("{lab_file}: {e}"),
        e => e.to_string(),
    })?;
    let drops = calibrate_bruise::read_drops(&a.drops, &lab).map_err(|e| e.to_string())?;
    let opts = Options {
        model,
        apple_material: a.apple_material.clone(),
        steps_per_impact: a.steps_per_impact,
        fit: FitOptions {
            depth_ratio: a.depth_ratio.unwrap_or(DEPTH_RATIO.value),
            depth_ratio_given: a.depth_ratio.is_some(),
            fit_depth_ratio: a.fit_depth_ratio,
        },
        preset: a.preset.clone(),
    };
    let cal = calibrate_bruise::calibrate_bruise(&lab, &lab_file, &drops, &opts)
        .map_err(|e| e.to_string())?;
    print!("{}", cal.report_text());
    let json = serde_json::to_string_pretty(&cal.spec).map_err(|e| e.to_string())? + "\n";
    let report = a.report.clone().unwrap_or_else(|| report_path(&a.out));
    let name = a
        .out
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    atomic::write_file(&report, cal.report_markdown(&name).as_bytes())
        .map_err(|e| format!("{}: {e}", report.display()))?;
    atomic::write_file(&a.out, json.as_bytes()).map_err(|e| format!("{}: {e}", a.out.display()))?;
    println!(
        "wrote {} (a scenario names it: \"damage\": {{\"file\": \"{name}\"}}) and {}",
        a.out.display(),
        report.display()
    );
    Ok(())
}
