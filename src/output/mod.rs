//! Outputs of a run: `summary.json`, `contacts.csv`, `bodies.csv`, `transitions.csv` (and the
//! scenario as run); with free-turning rollers `rollers.csv` ([`rollers`]);
//! with force histories `forces.csv` and `pulse_fits.csv`; always `bruise.csv`; on request the
//! ParaView files ([`vtk`]) and the charts ([`plot`]).
//!
//! Every file is written whole or not at all, and a run's folder is switched in as a whole set
//! ([`atomic`], [`run_to_dir`]). Numbers are printed in Rust's
//! shortest round-trip form, so the same run gives byte-identical files; the one exception is
//! `wall_time_s` in `summary.json`, a measurement of the machine.

pub mod atomic;
pub mod audit;
pub mod plot;
pub mod probe;
pub mod report;
pub mod rollers;
pub mod vtk;

use crate::analysis::bruise::{AppleAssessment, ContactAssessment};
use crate::analysis::pulse::PulseFit;
use crate::analysis::Analysis;
use crate::record::events::ContactEvent;
use crate::record::series::{AppleState, SampleSink};
use crate::record::transitions::{Transition, TransitionSummary};
use crate::scenario::Scenario;
use crate::sim::{AppleFinal, RunResult};
use atomic::AtomicCsv;
pub use rollers::{RollersCsv, ROLLERS_CSV};
use serde::Serialize;
use std::path::Path;

/// The `summary.json` document.
#[derive(Debug, Serialize)]
pub struct Summary<'a> {
    /// applesim version that wrote it.
    pub applesim_version: &'static str,
    /// The scenario's description.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub description: Option<&'a str>,
    /// Steps taken.
    pub steps: u64,
    /// Simulated time (s).
    pub simulated_time_s: f64,
    /// Time step (s): the fixed step, or the mean step of an adaptive run.
    pub time_step_s: f64,
    /// `fixed`, `auto` or `adaptive`.
    pub step_policy: &'a str,
    /// Shortest and longest step taken (s).
    pub step_range_s: [f64; 2],
    /// The stiffest contact the scene can produce (behind `auto`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stiffest_contact: Option<&'a crate::sim::timestep::StiffestContact>,
    /// The fidelity level and what it cannot tell.
    pub fidelity: &'a str,
    /// Wall-clock time of the stepping loop (s).
    pub wall_time_s: f64,
    /// Contact events.
    pub contacts: &'a [ContactEvent],
    /// Final state and peak force per apple.
    pub apples: &'a [AppleFinal],
    /// Warnings.
    pub warnings: &'a [String],
    /// Apples per fate, throughput per bin, what each source fed (`fates`, `throughput`,
    /// `sources`).
    #[serde(flatten)]
    pub line: &'a crate::sim::fate::LineEnd,
    /// Key results as flat, unit-suffixed numbers (what `applesim merge` tabulates).
    pub metrics: &'a std::collections::BTreeMap<String, f64>,
    /// Bruise assessment: per apple, and the contacts over a threshold (all contacts in
    /// `bruise.csv`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bruise: Option<BruiseSummary<'a>>,
    /// Eq. 13 fits of the impacts (also `pulse_fits.csv`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pulse_fits: Option<&'a [PulseFit]>,
    /// Slip/roll transitions: per apple and per surface (every transition in
    /// `transitions.csv`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub transitions: Option<&'a TransitionSummary>,
    /// The line audit: impacts per transfer point, hardest first (also `audit.csv`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub audit: Option<&'a [crate::analysis::audit::TransferPoint]>,
    /// The virtual instrumented spheres: per probe its settings and impacts (also
    /// `probe_NAME_impacts.csv`; the trace in `probe_NAME_trace.csv`).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub probes: Vec<ProbeSummary<'a>>,
}

/// One probe in `summary.json`.
#[derive(Debug, Serialize)]
pub struct ProbeSummary<'a> {
    /// The probe apple.
    pub apple: &'a str,
    /// Its mass (kg).
    pub mass_kg: f64,
    /// How it sampled.
    pub settings: &'a crate::record::probe::ProbeSpec,
    /// The files it wrote.
    pub files: [String; 2],
    /// Its impacts, as in the impacts file.
    pub impacts: &'a [crate::record::probe::ProbeImpact],
}

/// The bruise section of `summary.json`.
#[derive(Debug, Serialize)]
pub struct BruiseSummary<'a> {
    /// Apples at risk (over a threshold in at least one contact).
    pub apples_at_risk: Vec<&'a str>,
    /// Every apple's assessment.
    pub apples: &'a [AppleAssessment],
    /// The contacts over a threshold, per apple.
    pub contacts_at_risk: Vec<&'a ContactAssessment>,
}

/// Header of `contacts.csv`.
pub const CONTACT_HEADER: [&str; 37] = [
    "a",
    "b",
    "t_start_s",
    "t_end_s",
    "duration_s",
    "peak_force_n",
    "t_peak_s",
    "impulse_n_s",
    "max_overlap_m",
    "max_contact_radius_m",
    "max_pressure_pa",
    "approach_speed_m_s",
    "separation_speed_m_s",
    "restitution",
    "absorbed_energy_j",
    "steps",
    "contact_point_m",
    "a_diameter_m",
    "a_mass_kg",
    "b_diameter_m",
    "b_mass_kg",
    "impact_peak_force_n",
    "impact_t_peak_s",
    "impact_duration_s",
    "impact_impulse_n_s",
    "impact_absorbed_energy_j",
    "impact_max_pressure_pa",
    "a_velocity_change_m_s",
    "a_peak_g",
    "b_velocity_change_m_s",
    "b_peak_g",
    "resting_s",
    "resting_mean_force_n",
    "resting_max_force_n",
    "resting_mean_pressure_pa",
    "resting_max_pressure_pa",
    "transfer_point",
];

fn opt(v: Option<f64>) -> String {
    v.map(|x| x.to_string()).unwrap_or_default()
}

/// Writes `contacts.csv`.
pub fn write_contacts(
    path: &Path,
    events: &[ContactEvent],
    points: &[String],
    roster: &crate::world::Roster,
) -> std::io::Result<()> {
    let mut w = AtomicCsv::create(path, &CONTACT_HEADER)?;
    let by_name = roster.by_name();
    let size = |name: &str| by_name.get(name).map(|a| (2.0 * a.radius_m, a.mass_kg));
    for (e, point) in events.iter().zip(points) {
        let a = size(&e.a);
        let b = match e.b_party {
            crate::record::events::Party::Apple(_) => size(&e.b),
            crate::record::events::Party::Surface(_) => None,
        };
        let side = |s: Option<(f64, f64)>, towards: bool| match (e.impact.as_ref(), s) {
            (Some(p), Some((_, m))) => {
                let x = crate::analysis::impacts::for_apple(p, m, towards);
                (x.velocity_change_m_s.to_string(), x.peak_g.to_string())
            }
            _ => (String::new(), String::new()),
        };
        let (a_dv, a_g) = side(a, true);
        let (b_dv, b_g) = side(b, false);
        let i = e.impact.as_ref();
        let r = e.resting.as_ref();
        let num = |x: Option<f64>| opt(x);
        w.write_record([
            e.a.to_string(),
            e.b.to_string(),
            e.t_start_s.to_string(),
            opt(e.t_end_s),
            opt(e.duration_s),
            e.peak_force_n.to_string(),
            e.t_peak_s.to_string(),
            e.impulse_n_s.to_string(),
            e.max_overlap_m.to_string(),
            e.max_contact_radius_m.to_string(),
            e.max_pressure_pa.to_string(),
            e.approach_speed_m_s.to_string(),
            opt(e.separation_speed_m_s),
            opt(e.restitution),
            e.absorbed_energy_j.to_string(),
            e.steps.to_string(),
            format!(
                "{} {} {}",
                e.contact_point_m[0], e.contact_point_m[1], e.contact_point_m[2]
            ),
            num(a.map(|x| x.0)),
            num(a.map(|x| x.1)),
            num(b.map(|x| x.0)),
            num(b.map(|x| x.1)),
            num(i.map(|p| p.peak_force_n)),
            num(i.map(|p| p.t_peak_s)),
            num(i.map(|p| p.duration_s)),
            num(i.map(|p| p.impulse_n_s)),
            num(i.map(|p| p.absorbed_energy_j)),
            num(i.map(|p| p.max_pressure_pa)),
            a_dv,
            a_g,
            b_dv,
            b_g,
            num(r.map(|x| x.duration_s)),
            num(r.map(|x| x.mean_force_n)),
            num(r.map(|x| x.max_force_n)),
            num(r.map(|x| x.mean_pressure_pa)),
            num(r.map(|x| x.max_pressure_pa)),
            point.clone(),
        ])?;
    }
    w.commit()
}

/// Header of `transitions.csv`.
pub const TRANSITION_HEADER: [&str; 16] = [
    "apple",
    "from",
    "to",
    "from_surface",
    "surface",
    "time_s",
    "x_m",
    "y_m",
    "z_m",
    "along_m",
    "speed_m_s",
    "spin_rad_s",
    "slip_m_s",
    "slid_m",
    "sliding_time_s",
    "since_previous_s",
];

/// Writes `transitions.csv`: one row per slip/roll transition ([`TRANSITION_HEADER`]).
pub fn write_transitions(path: &Path, rows: &[Transition]) -> std::io::Result<()> {
    let mut w = AtomicCsv::create(path, &TRANSITION_HEADER)?;
    for e in rows {
        let name = |s: &Option<std::sync::Arc<str>>| s.as_deref().unwrap_or("").to_string();
        w.write_record([
            e.apple.to_string(),
            e.from.as_str().to_string(),
            e.to.as_str().to_string(),
            name(&e.from_surface),
            name(&e.surface),
            e.time_s.to_string(),
            e.position_m[0].to_string(),
            e.position_m[1].to_string(),
            e.position_m[2].to_string(),
            opt(e.along_m),
            e.speed_m_s.to_string(),
            e.spin_rad_s.to_string(),
            e.slip_m_s.to_string(),
            e.slid_m.to_string(),
            e.sliding_time_s.to_string(),
            e.since_previous_s.to_string(),
        ])?;
    }
    w.commit()
}

/// Writes `summary.json`.
pub fn write_summary(path: &Path, sc: &Scenario, r: &RunResult) -> std::io::Result<()> {
    write_summary_with(path, sc, r, None)
}

/// Writes `summary.json` with the analysis sections (bruise, pulse fits) when given.
pub fn write_summary_with(
    path: &Path,
    sc: &Scenario,
    r: &RunResult,
    analysis: Option<&Analysis>,
) -> std::io::Result<()> {
    let s = Summary {
        applesim_version: env!("CARGO_PKG_VERSION"),
        description: sc.description.as_deref(),
        steps: r.steps,
        simulated_time_s: r.simulated_time_s,
        time_step_s: r.time_step_s,
        step_policy: r.step_policy,
        step_range_s: r.step_range_s,
        stiffest_contact: r.stiffest_contact.as_ref(),
        fidelity: r.fidelity_limits,
        wall_time_s: r.wall_time_s,
        contacts: &r.events,
        apples: &r.apples,
        warnings: &r.warnings,
        line: &r.line,
        metrics: &r.metrics,
        bruise: analysis.map(|a| BruiseSummary {
            apples_at_risk: a
                .bruise
                .apples
                .iter()
                .filter(|x| x.at_risk)
                .map(|x| &*x.apple)
                .collect(),
            apples: &a.bruise.apples,
            contacts_at_risk: a.bruise.contacts_at_risk().collect(),
        }),
        pulse_fits: analysis.map(|a| a.pulse_fits.as_slice()),
        transitions: r.transition_summary.as_ref(),
        audit: analysis.map(|a| a.audit.points.as_slice()),
        probes: r
            .probes
            .iter()
            .map(|p| {
                let stem = probe::stem(&p.apple);
                ProbeSummary {
                    apple: &p.apple,
                    mass_kg: p.mass_kg,
                    settings: &p.spec,
                    files: [format!("{stem}_trace.csv"), format!("{stem}_impacts.csv")],
                    impacts: &p.impacts,
                }
            })
            .collect(),
    };
    let mut bytes = serde_json::to_vec_pretty(&s).map_err(std::io::Error::other)?;
    bytes.push(b'\n');
    atomic::write_file(path, &bytes)
}

/// Writes the scenario as it was run (`scenario.json`).
pub fn write_scenario(path: &Path, sc: &Scenario) -> std::io::Result<()> {
    // The scenario as run: the sleep thresholds its accuracy chose are written out.
    let mut sc = sc.clone();
    let rule = sc.model.sleep.rule(sc.accuracy);
    sc.model.sleep.speed_m_s = Some(rule.speed_m_s);
    sc.model.sleep.time_s = Some(rule.time_s);
    let mut bytes = serde_json::to_vec_pretty(&sc).map_err(std::io::Error::other)?;
    bytes.push(b'\n');
    atomic::write_file(path, &bytes)
}

/// Header of `bodies.csv` (one row per apple per sample).
/// `slip_m_s` is the slip speed of the contact the apple slides or rolls on (0 in the air; empty
/// when `output.transitions.enabled` is false).
pub const BODIES_HEADER: [&str; 17] = [
    "time_s",
    "apple",
    "x_m",
    "y_m",
    "z_m",
    "vx_m_s",
    "vy_m_s",
    "vz_m_s",
    "wx_rad_s",
    "wy_rad_s",
    "wz_rad_s",
    "fx_n",
    "fy_n",
    "fz_n",
    "slip_m_s",
    "diameter_m",
    "mass_kg",
];

/// A sample sink streaming `bodies.csv` to a temporary file, renamed on [`BodiesCsv::commit`].
pub struct BodiesCsv {
    w: AtomicCsv,
}

impl BodiesCsv {
    /// Starts `path`.
    pub fn create(path: &Path) -> std::io::Result<Self> {
        let w = AtomicCsv::create(path, &BODIES_HEADER)?;
        Ok(Self { w })
    }

    /// Finishes the file under its final name.
    pub fn commit(self) -> std::io::Result<()> {
        self.w.commit()
    }
}

impl SampleSink for BodiesCsv {
    fn sample(&mut self, time_s: f64, apples: &[AppleState]) -> std::io::Result<()> {
        let t = time_s.to_string();
        for a in apples {
            let p = a.position;
            let v = a.velocity;
            let w = a.angular_velocity;
            let f = a.contact_force;
            self.w.write_record([
                t.as_str(),
                &a.name,
                &p.x.to_string(),
                &p.y.to_string(),
                &p.z.to_string(),
                &v.x.to_string(),
                &v.y.to_string(),
                &v.z.to_string(),
                &w.x.to_string(),
                &w.y.to_string(),
                &w.z.to_string(),
                &f.x.to_string(),
                &f.y.to_string(),
                &f.z.to_string(),
                &a.slip_speed.map(|x| x.to_string()).unwrap_or_default(),
                &a.diameter_m.to_string(),
                &a.mass_kg.to_string(),
            ])?;
        }
        Ok(())
    }
}

/// Writes `forces.csv`: every recorded force sample of every contact with a history, one row
/// each ([`plot::FORCES_HEADER`]; `contact` is the row index in `contacts.csv`).
pub fn write_forces(path: &Path, events: &[ContactEvent]) -> std::io::Result<()> {
    let mut w = AtomicCsv::create(path, &plot::FORCES_HEADER)?;
    for (k, e) in events.iter().enumerate() {
        let Some(h) = &e.history else { continue };
        let k = k.to_string();
        for (t, p) in h {
            w.write_record([&k, &*e.a, &*e.b, &t.to_string(), &p.to_string()])?;
        }
    }
    w.commit()
}

/// Header of `pulse_fits.csv` (fields of [`PulseFit`]).
pub const PULSE_FITS_HEADER: [&str; 19] = [
    "contact",
    "a",
    "b",
    "samples",
    "fit_peak_force_n",
    "fit_contact_time_s",
    "fit_eps",
    "fit_tau",
    "rms_residual_n",
    "converged",
    "k_p",
    "k_p_shape",
    "k_p_measured",
    "peak_force_n",
    "contact_time_s",
    "restitution",
    "effective_mass_kg",
    "eq15_peak_force_n",
    "eq15_error",
];

/// Writes `pulse_fits.csv`: the fields of [`PulseFit`] (those of `summary.json`'s
/// `pulse_fits`) plus `eq15_error`, eq15_peak_force_n / peak_force_n - 1.
pub fn write_pulse_fits(path: &Path, fits: &[PulseFit]) -> std::io::Result<()> {
    let mut w = AtomicCsv::create(path, &PULSE_FITS_HEADER)?;
    for p in fits {
        w.write_record([
            p.contact.to_string(),
            p.a.to_string(),
            p.b.to_string(),
            p.samples.to_string(),
            p.fit_peak_force_n.to_string(),
            p.fit_contact_time_s.to_string(),
            p.fit_eps.to_string(),
            p.fit_tau.to_string(),
            p.rms_residual_n.to_string(),
            p.converged.to_string(),
            p.k_p.to_string(),
            p.k_p_shape.to_string(),
            p.k_p_measured.to_string(),
            p.peak_force_n.to_string(),
            p.contact_time_s.to_string(),
            p.restitution.to_string(),
            p.effective_mass_kg.to_string(),
            p.eq15_peak_force_n.to_string(),
            (p.eq15_peak_force_n / p.peak_force_n - 1.0).to_string(),
        ])?;
    }
    w.commit()
}

/// Header of `bruise.csv`: one row per apple per contact.
pub const BRUISE_HEADER: [&str; 23] = [
    "contact",
    "apple",
    "other",
    "t_start_s",
    "t_peak_s",
    "contact_point_m",
    "peak_force_n",
    "force_threshold_n",
    "mean_pressure_pa",
    "pressure_threshold_pa",
    "absorbed_energy_j",
    "energy_threshold_j",
    "velocity_change_m_s",
    "approach_speed_m_s",
    "at_risk",
    "exceeded",
    "apple_at_risk",
    "apple_peak_force_n",
    "peak_g",
    "static_max_force_n",
    "static_force_threshold_n",
    "static_max_pressure_pa",
    "static_pressure_threshold_pa",
];

/// Writes `bruise.csv`.
pub fn write_bruise(path: &Path, a: &Analysis) -> std::io::Result<()> {
    let mut w = AtomicCsv::create(path, &BRUISE_HEADER)?;
    for c in &a.bruise.contacts {
        let apple = a.bruise.apples.iter().find(|x| x.apple == c.apple);
        let p = c.contact_point_m;
        w.write_record([
            c.contact.to_string(),
            c.apple.to_string(),
            c.other.to_string(),
            c.t_start_s.to_string(),
            c.t_peak_s.to_string(),
            format!("{} {} {}", p[0], p[1], p[2]),
            c.peak_force_n.to_string(),
            c.thresholds.peak_force_n.to_string(),
            c.mean_pressure_pa.to_string(),
            opt(c.thresholds.mean_pressure_pa),
            c.absorbed_energy_j.to_string(),
            opt(c.thresholds.absorbed_energy_j),
            c.velocity_change_m_s.to_string(),
            c.approach_speed_m_s.to_string(),
            c.at_risk().to_string(),
            c.exceeded.clone(),
            apple.is_some_and(|x| x.at_risk).to_string(),
            apple
                .map(|x| x.peak_force_n.to_string())
                .unwrap_or_default(),
            c.peak_g.to_string(),
            opt(c.static_max_force_n),
            opt(c.thresholds.static_force_n),
            opt(c.static_max_pressure_pa),
            opt(c.thresholds.static_pressure_pa),
        ])?;
    }
    w.commit()
}

/// Errors of [`run_to_dir`].
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// The run itself failed (and wrote nothing).
    #[error(transparent)]
    Sim(#[from] crate::sim::SimError),
    /// An output file could not be written.
    #[error("writing {path}: {source}")]
    Io {
        /// The file or folder.
        path: std::path::PathBuf,
        /// OS error.
        source: std::io::Error,
    },
    /// The ParaView files could not be written (or `bodies.csv` could not be read back for them).
    #[error("ParaView output: {0}")]
    Vtk(#[from] vtk::VtkError),
    /// The result folder could not be locked, staged or switched in (another run is writing
    /// it, it is not a result folder, or the file system refused).
    #[error(transparent)]
    Folder(#[from] atomic::FolderError),
    /// The charts written into the set (`applesim run --plots`) failed.
    #[error("charts: {0}")]
    Plot(#[from] plot::PlotError),
}

fn io_at(path: &Path) -> impl FnOnce(std::io::Error) -> RunError + '_ {
    move |source| RunError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// Runs a validated scenario and writes its whole set of files into `out_dir` (see
/// [`run_into`] for the files), switching the set in at once: `out_dir` holds either the
/// previous run's complete set or this one's, never a mix, whatever stops the run (an error,
/// a full disk, kill -9). The folder is locked while the run runs (a second run into it is
/// refused with [`atomic::FolderError::Busy`]); a folder that is not a run's set is refused,
/// never replaced ([`atomic::FolderError::NotARunFolder`]); nothing temporary is left beside it.
pub fn run_to_dir(
    sc: &Scenario,
    base_dir: &Path,
    out_dir: &Path,
    progress: &mut dyn FnMut(f64),
) -> Result<RunResult, RunError> {
    run_to_dir_with(sc, base_dir, out_dir, progress, &mut |_, _| Ok(()))
}

/// [`run_to_dir`], with `also` writing more files into the set before it is switched in (its
/// first argument is the folder being written, under a temporary name; the charts of
/// `applesim run --plots` go in this way, so they belong to the set).
pub fn run_to_dir_with(
    sc: &Scenario,
    base_dir: &Path,
    out_dir: &Path,
    progress: &mut dyn FnMut(f64),
    also: &mut dyn FnMut(&Path, &RunResult) -> Result<(), RunError>,
) -> Result<RunResult, RunError> {
    let lock = atomic::FolderLock::acquire(out_dir)?;
    let stage = atomic::StagedFolder::begin(&lock)?;
    let named = |e: RunError| match e {
        // Name the file as the user knows it, not by its temporary folder.
        RunError::Io { path, source } => RunError::Io {
            path: stage.final_path(&path),
            source,
        },
        other => other,
    };
    let result = run_into(sc, base_dir, stage.path(), progress).map_err(named)?;
    also(stage.path(), &result).map_err(named)?;
    stage.commit()?;
    Ok(result)
}

/// Runs a validated scenario and writes into the folder `out_dir` (created if missing; use
/// [`run_to_dir`] for a result folder the user sees, this one writes in place):
/// `summary.json`, `contacts.csv`, `bodies.csv`, `scenario.json`, `bruise.csv`; in a scene with
/// a free-turning roller `rollers.csv` ([`rollers`]); with force
/// histories (`output.force_history`) `forces.csv` and `pulse_fits.csv`; with `output.vtk` the
/// ParaView files ([`vtk`]). The analysis ([`crate::analysis::analyse`]) adds its headline
/// figures to the returned `metrics`. `summary.json` comes last.
pub fn run_into(
    sc: &Scenario,
    base_dir: &Path,
    out_dir: &Path,
    progress: &mut dyn FnMut(f64),
) -> Result<RunResult, RunError> {
    std::fs::create_dir_all(out_dir).map_err(io_at(out_dir))?;
    let sim = crate::sim::Simulation::new(sc, base_dir)?;
    let surfaces = sc
        .output
        .vtk
        .as_ref()
        .map(|_| vtk::SceneSurfaces::capture(sim.world()));
    let bodies_path = out_dir.join("bodies.csv");
    let mut bodies = BodiesCsv::create(&bodies_path).map_err(io_at(&bodies_path))?;
    let rollers_path = out_dir.join(ROLLERS_CSV);
    let mut rollers = match sim.world().has_free_rollers() {
        true => Some(RollersCsv::create(&rollers_path).map_err(io_at(&rollers_path))?),
        false => None,
    };
    let mut sink = rollers::RunSamples {
        bodies: &mut bodies,
        rollers: rollers.as_mut(),
        failed: None,
    };
    let mut result = match sim.run(&mut sink, progress) {
        Ok(r) => r,
        // A sample that could not be written names its file (and so the folder).
        Err(crate::sim::SimError::Io(source)) => {
            let path = out_dir.join(sink.failed.unwrap_or("bodies.csv"));
            return Err(RunError::Io { path, source });
        }
        Err(e) => return Err(e.into()),
    };
    bodies.commit().map_err(io_at(&bodies_path))?;
    if let Some(r) = rollers {
        r.commit().map_err(io_at(&rollers_path))?;
    }
    let analysis = crate::analysis::analyse(sc, &result);
    analysis.add_metrics(&mut result.metrics);
    if let (Some(v), Some(surfaces)) = (&sc.output.vtk, &surfaces) {
        let order: Vec<&str> = result.apples.iter().map(|a| a.name.as_str()).collect();
        let written = vtk::write_vtk(
            out_dir,
            sc,
            surfaces,
            &analysis.bruise,
            &order,
            v.interval_s,
        )?;
        result.warnings.extend(written.warnings);
        result
            .metrics
            .insert("vtk_frames".into(), written.frames.len() as f64);
    }
    if sc.output.force_history {
        let p = out_dir.join("forces.csv");
        write_forces(&p, &result.events).map_err(io_at(&p))?;
        let p = out_dir.join("pulse_fits.csv");
        write_pulse_fits(&p, &analysis.pulse_fits).map_err(io_at(&p))?;
    }
    let p = out_dir.join("bruise.csv");
    write_bruise(&p, &analysis).map_err(io_at(&p))?;
    let p = out_dir.join("audit.csv");
    audit::write_audit(&p, &analysis.audit).map_err(io_at(&p))?;
    let p = out_dir.join(audit::AUDIT_MD);
    let title = sc.description.as_deref().unwrap_or("run");
    atomic::write_file(&p, analysis.audit.markdown(title).as_bytes()).map_err(io_at(&p))?;
    let points = &analysis.contact_points;
    for pr in &result.probes {
        probe::write_probe(out_dir, pr, &result.events, points)
            .map_err(|(path, source)| RunError::Io { path, source })?;
    }
    if let Some(chart) =
        crate::analysis::audit::ird_chart(points, &analysis.bruise, &result.roster, title)
    {
        chart
            .write_svg(&out_dir.join("ird.svg"))
            .map_err(plot::PlotError::from)?;
    }
    let p = out_dir.join("contacts.csv");
    write_contacts(&p, &result.events, points, &result.roster).map_err(io_at(&p))?;
    if result.transition_summary.is_some() {
        let p = out_dir.join("transitions.csv");
        write_transitions(&p, &result.transitions).map_err(io_at(&p))?;
    }
    let p = out_dir.join("scenario.json");
    write_scenario(&p, sc).map_err(io_at(&p))?;
    let p = out_dir.join("summary.json");
    write_summary_with(&p, sc, &result, Some(&analysis)).map_err(io_at(&p))?;
    Ok(result)
}
