//! `applesim calibrate SCENARIO --e 0.3 --speed-m-s 1.0`: ke for a target restitution, or with
//! `--ke` the restitution over a range of speeds (library: `applesim::analysis::calibrate`).

use applesim::analysis::calibrate::{self, ImpactSetup};
use applesim::output::atomic;
use applesim::scenario;
use std::path::PathBuf;

#[derive(clap::Args)]
#[command(group(clap::ArgGroup::new("mode").required(true).args(["e", "ke"])))]
pub struct Args {
    /// Scenario file: its materials, apple and surface, lambda and gravity.
    scenario: PathBuf,
    /// Target coefficient of restitution: find ke.
    #[arg(long)]
    e: Option<f64>,
    /// Given ke: print the restitution at each of --speeds.
    #[arg(long)]
    ke: Option<f64>,
    /// Impact speed (m/s) for --e.
    #[arg(long, default_value_t = 1.0)]
    speed_m_s: f64,
    /// Speeds for --ke: a list "0.2,0.5,1" or a range "from:to:step" (m/s).
    #[arg(long, default_value = "0.2:1.4:0.2")]
    speeds: String,
    /// Apple whose material, diameter and mass are used (default: the first).
    #[arg(long)]
    apple: Option<String>,
    /// Surface whose material is hit (default: the first).
    #[arg(long, conflicts_with = "surface_material")]
    surface: Option<String>,
    /// Material hit, by name (instead of a surface).
    #[arg(long)]
    surface_material: Option<String>,
    /// lambda (s/m); default the scenario's for that material pair.
    #[arg(long)]
    lambda_s_m: Option<f64>,
    /// Simulate without gravity (default: the scenario's gravity, pulling the apple onto the surface).
    #[arg(long)]
    no_gravity: bool,
    /// Time steps per elastic contact time.
    #[arg(long, default_value_t = calibrate::DEFAULT_STEPS_PER_IMPACT)]
    steps_per_impact: f64,
    /// Stop when the simulated e is within this of the target.
    #[arg(long, default_value_t = 1e-4)]
    tolerance: f64,
    /// Also write the --ke table as CSV here.
    #[arg(long)]
    csv: Option<PathBuf>,
}

/// Parses "0.2,0.5,1" or "from:to:step".
fn speeds(s: &str) -> Result<Vec<f64>, String> {
    let bad = || format!("--speeds: '{s}' is neither a list 0.2,0.5,1 nor a range from:to:step");
    let parts: Vec<&str> = s.split(':').collect();
    let v: Vec<f64> = if parts.len() == 3 {
        let n: Vec<f64> = parts
            .iter()
            .map(|p| p.trim().parse().map_err(|_| bad()))
            .collect::<Result<_, _>>()?;
        let (from, to, step) = (n[0], n[1], n[2]);
        if !(step > 0.0 && to >= from) {
            return Err(format!(
                "--speeds: range '{s}' needs step > 0 and to >= from"
            ));
        }
        let count = ((to - from) / step + 1e-9).floor() as usize + 1;
        if count > 1000 {
            return Err(format!(
                "--speeds: range '{s}' has {count} speeds (at most 1000)"
            ));
        }
        (0..count).map(|i| from + i as f64 * step).collect()
    } else if parts.len() == 1 {
        s.split(',')
            .map(|p| p.trim().parse().map_err(|_| bad()))
            .collect::<Result<_, _>>()?
    } else {
        return Err(bad());
    };
    if let Some(x) = v.iter().find(|x| !(x.is_finite() && **x > 0.0)) {
        return Err(format!("--speeds: {x} is not a speed > 0"));
    }
    Ok(v)
}

pub fn main(a: Args) -> Result<(), String> {
    let sc = scenario::load(&a.scenario).map_err(|e| e.to_string())?;
    let mut setup = ImpactSetup::from_scenario(
        &sc,
        a.apple.as_deref(),
        a.surface.as_deref(),
        a.surface_material.as_deref(),
    )
    .map_err(|e| e.to_string())?;
    if let Some(l) = a.lambda_s_m {
        setup.lambda_s_m = l;
    }
    if a.no_gravity {
        setup.gravity_m_s2 = 0.0;
    }
    setup.steps_per_impact = a.steps_per_impact;
    let gravity = if setup.gravity_m_s2 > 0.0 {
        format!("gravity {} m/s^2", setup.gravity_m_s2)
    } else {
        "no gravity".into()
    };
    println!(
        "apple D = {} m, m = {} kg on a flat surface, lambda = {} s/m, {gravity}",
        setup.diameter_m, setup.mass_kg, setup.lambda_s_m
    );
    if let Some(target) = a.e {
        let c = calibrate::calibrate(&setup, target, a.speed_m_s, a.tolerance)
            .map_err(|e| e.to_string())?;
        println!(
            "ke = {:.6} gives e = {:.5} (target {}) at v0 = {} m/s, lambda v0 = {} ({} simulated impacts)",
            c.ke, c.restitution, c.target, a.speed_m_s, c.lambda_v0, c.simulations
        );
        println!(
            "closed-form limit sqrt(ke) = {:.5} (no gravity, lambda v0 >> 1){}",
            c.sqrt_ke,
            if (c.sqrt_ke - c.restitution).abs() > 0.005 {
                ": the simulated impact differs, which is why ke is calibrated by simulation"
            } else {
                ""
            }
        );
        if let Some(t) = c.impact.contact_time_s {
            println!(
                "that impact: peak force {:.3} N, contact time {:.3} ms (time step {:.3e} s)",
                c.impact.peak_force_n,
                t * 1e3,
                c.impact.time_step_s
            );
        }
        let [m1, m2] = &setup.material_names;
        println!(
            "scenario: \"pairs\": [{{ \"materials\": [\"{m1}\", \"{m2}\"], \"ke\": {:.6}, \"lambda_s_m\": {} }}]",
            c.ke, setup.lambda_s_m
        );
    } else if let Some(ke) = a.ke {
        let v = speeds(&a.speeds)?;
        let table = calibrate::restitution_table(&setup, ke, &v).map_err(|e| e.to_string())?;
        println!(
            "{:>10} {:>10} {:>9} {:>9} {:>13} {:>16}",
            "v0_m_s", "lambda_v0", "e", "sqrt_ke", "peak_force_n", "contact_time_ms"
        );
        let mut csv =
            String::from("v0_m_s,lambda_v0,restitution,sqrt_ke,peak_force_n,contact_time_s\n");
        for i in &table {
            let e = i
                .restitution
                .map_or("no lift-off".to_string(), |e| format!("{e:.5}"));
            let t = i
                .contact_time_s
                .map_or("-".to_string(), |t| format!("{:.4}", t * 1e3));
            println!(
                "{:>10} {:>10} {:>9} {:>9.5} {:>13.4} {:>16}",
                i.speed_m_s,
                i.speed_m_s * setup.lambda_s_m,
                e,
                ke.sqrt(),
                i.peak_force_n,
                t
            );
            csv.push_str(&format!(
                "{},{},{},{},{},{}\n",
                i.speed_m_s,
                i.speed_m_s * setup.lambda_s_m,
                i.restitution.map(|e| e.to_string()).unwrap_or_default(),
                ke.sqrt(),
                i.peak_force_n,
                i.contact_time_s.map(|t| t.to_string()).unwrap_or_default()
            ));
        }
        if let Some(p) = &a.csv {
            atomic::write_file(p, csv.as_bytes()).map_err(|e| format!("{}: {e}", p.display()))?;
            println!("wrote {}", p.display());
        }
    }
    Ok(())
}
