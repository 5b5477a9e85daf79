//! Outputs of a run: `summary.json`, `contacts.csv`, `bodies.csv`, `transitions.csv` (and the
//! scenario as run); with free-turning rollers `rollers.csv` ([`rollers`]);
//! with force histories `forces.csv` and `pulse_fits.csv`; always `apple_contacts.csv` and
//! `bruises.csv` (the fruit's damage); on request the
//! ParaView files ([`vtk`]) and the charts ([`plot`]).
//!
//! Every file is written whole or not at all, and a run's folder is switched in as a whole set
//! ([`atomic`], [`crate::run::to_dir`]). Numbers in the CSV files are printed by one formatter
//! ([`number`]: 9 significant digits by default, `output.precision`), gzipped with
//! `output.compress` ([`csv_file`]); `summary.json` keeps Rust's shortest round-trip form (its
//! metrics are what `applesim merge` tabulates, digit for digit). The same run gives
//! byte-identical files; the one exception is `wall_time_s` in `summary.json`, a measurement of
//! the machine.

pub mod atomic;
pub mod audit;
pub mod compare;
pub mod csv_file;
pub mod number;
pub mod plot;
pub mod probe;
pub mod report;
pub mod rollers;
pub mod vtk;

use crate::analysis::bruise::{AppleAssessment, Cause, LargestBruise};
use crate::analysis::pulse::PulseFit;
use crate::analysis::Analysis;
use crate::record::events::ContactEvent;
use crate::record::series::{AppleState, SampleSink};
use crate::record::transitions::{Transition, TransitionSummary};
use crate::scenario::Scenario;
use crate::sim::{AppleFinal, RunResult};
use atomic::AtomicCsv;
pub use csv_file::CsvFormat;
pub use number::NumberFormat;
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
    /// The interval of `bodies.csv`, and why: given by the scenario, or the default that follows
    /// the run's length and apples ([`crate::scenario::output::sampling`]).
    pub sampling: crate::scenario::Sampling,
    /// The force histories kept, and why: given by the scenario, or the default that follows
    /// the run's apples ([`crate::scenario::output::force_history`]).
    pub force_history: crate::scenario::HistoryChoice,
    /// Wall-clock time of the stepping loop (s).
    pub wall_time_s: f64,
    /// Contact events (with `output.compress` in [`CONTACTS_JSON_GZ`] beside it instead).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub contacts: Option<&'a [ContactEvent]>,
    /// With `output.compress`: the file holding the contact events, [`CONTACTS_JSON_GZ`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub contacts_file: Option<&'static str>,
    /// Final state and peak force per apple, and its damage (bruises, grade) when assessed.
    pub apples: Vec<AppleRow<'a>>,
    /// Warnings.
    pub warnings: &'a [String],
    /// Apples per fate, throughput per bin, what each source fed (`fates`, `throughput`,
    /// `sources`).
    #[serde(flatten)]
    pub line: &'a crate::sim::fate::LineEnd,
    /// Key results as flat, unit-suffixed numbers (what `applesim merge` tabulates).
    pub metrics: &'a std::collections::BTreeMap<String, f64>,
    /// The fruit's damage: the grading standard and the headline counts (per apple in
    /// `apples[]`, per site in `bruises.csv`, per apple and contact in `apple_contacts.csv`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub damage: Option<DamageSummary<'a>>,
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

/// One apple in `summary.json`: its final state and fate, and its damage when assessed (a
/// probe has none).
#[derive(Debug, Serialize)]
pub struct AppleRow<'a> {
    /// The final state.
    #[serde(flatten)]
    pub end: &'a AppleFinal,
    /// The damage.
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    pub damage: Option<AppleDamage<'a>>,
}

/// An apple's damage in `summary.json` (`analysis::bruise::AppleAssessment`).
#[derive(Debug, Serialize)]
pub struct AppleDamage<'a> {
    /// Energy it absorbed in its impacts (J; its own shares of the contacts' losses).
    pub absorbed_energy_j: f64,
    /// Its bruises.
    pub bruises: usize,
    /// Bruise volume, all bruises (mm^3; absent for an onset model).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bruise_volume_mm3: Option<f64>,
    /// Its largest bruise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub largest_bruise: Option<&'a LargestBruise>,
    /// Its grade.
    pub grade: &'a str,
    /// Why not the best class (empty when it meets it).
    pub grade_why: &'a str,
    /// The hit that first put it below the best class.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub downgraded_by: Option<&'a Cause>,
}

impl<'a> AppleDamage<'a> {
    fn of(a: &'a AppleAssessment) -> Self {
        Self {
            absorbed_energy_j: a.absorbed_energy_j,
            bruises: a.bruises,
            bruise_volume_mm3: a.bruise_volume_mm3,
            largest_bruise: a.largest_bruise.as_ref(),
            grade: &a.grade,
            grade_why: &a.grade_why,
            downgraded_by: a.downgraded_by.as_ref(),
        }
    }
}

/// The damage section of `summary.json`.
#[derive(Debug, Serialize)]
pub struct DamageSummary<'a> {
    /// The grading standard (`user` for the scenario's own classes).
    pub standard: &'a str,
    /// Its grades, best first.
    pub grades: &'a [String],
    /// Apples with a bruise.
    pub apples_bruised: usize,
    /// Apples graded below the best class.
    pub apples_downgraded: usize,
    /// Bruise volume of all apples (mm^3; absent for onset models).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub total_bruise_volume_mm3: Option<f64>,
    /// Apples per grade, best first.
    pub apples_per_grade: Vec<(&'a str, usize)>,
    /// The damage model of each apple material.
    pub models: std::collections::BTreeMap<&'a str, &'static str>,
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
    /// Its impacts, as in the impacts file, each with the transfer point where it happened.
    pub impacts: Vec<ProbeImpactRow<'a>>,
}

/// One impact of a probe in `summary.json`.
#[derive(Debug, Serialize)]
pub struct ProbeImpactRow<'a> {
    /// The impact as the device reports it.
    #[serde(flatten)]
    pub impact: &'a crate::record::probe::ProbeImpact,
    /// Where in the line ([`probe::transfer_points`]).
    pub transfer_point: String,
}

/// Header of `contacts.csv`.
pub const CONTACT_HEADER: [&str; 42] = [
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
    "a_absorbed_energy_j",
    "b_absorbed_energy_j",
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
    "impact_a_absorbed_energy_j",
    "impact_b_absorbed_energy_j",
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
    "force_history_cut_s",
];

/// Writes `contacts.csv` (numbers as `nf` prints them).
pub fn write_contacts(
    path: &Path,
    events: &[ContactEvent],
    points: &[String],
    roster: &crate::world::Roster,
    nf: NumberFormat,
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
                (nf.num(x.velocity_change_m_s), nf.num(x.peak_g))
            }
            _ => (String::new(), String::new()),
        };
        let (a_dv, a_g) = side(a, true);
        let (b_dv, b_g) = side(b, false);
        let i = e.impact.as_ref();
        let r = e.resting.as_ref();
        let num = |x: Option<f64>| nf.opt(x);
        w.write_record([
            e.a.to_string(),
            e.b.to_string(),
            nf.num(e.t_start_s),
            nf.opt(e.t_end_s),
            nf.opt(e.duration_s),
            nf.num(e.peak_force_n),
            nf.num(e.t_peak_s),
            nf.num(e.impulse_n_s),
            nf.num(e.max_overlap_m),
            nf.num(e.max_contact_radius_m),
            nf.num(e.max_pressure_pa),
            nf.num(e.approach_speed_m_s),
            nf.opt(e.separation_speed_m_s),
            nf.opt(e.restitution),
            nf.num(e.absorbed_energy_j),
            nf.num(e.a_absorbed_energy_j),
            nf.num(e.absorbed_energy_j - e.a_absorbed_energy_j),
            e.steps.to_string(),
            nf.point(e.contact_point_m),
            num(a.map(|x| x.0)),
            num(a.map(|x| x.1)),
            num(b.map(|x| x.0)),
            num(b.map(|x| x.1)),
            num(i.map(|p| p.peak_force_n)),
            num(i.map(|p| p.t_peak_s)),
            num(i.map(|p| p.duration_s)),
            num(i.map(|p| p.impulse_n_s)),
            num(i.map(|p| p.absorbed_energy_j)),
            num(i.map(|p| p.a_absorbed_energy_j)),
            num(i.map(|p| p.absorbed_energy_j - p.a_absorbed_energy_j)),
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
            num(e.history_cut_s),
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
pub fn write_transitions(
    path: &Path,
    rows: &[Transition],
    nf: NumberFormat,
) -> std::io::Result<()> {
    let mut w = AtomicCsv::create(path, &TRANSITION_HEADER)?;
    for e in rows {
        let name = |s: &Option<std::sync::Arc<str>>| s.as_deref().unwrap_or("").to_string();
        w.write_record([
            e.apple.to_string(),
            e.from.as_str().to_string(),
            e.to.as_str().to_string(),
            name(&e.from_surface),
            name(&e.surface),
            nf.num(e.time_s),
            nf.num(e.position_m[0]),
            nf.num(e.position_m[1]),
            nf.num(e.position_m[2]),
            nf.opt(e.along_m),
            nf.num(e.speed_m_s),
            nf.num(e.spin_rad_s),
            nf.num(e.slip_m_s),
            nf.num(e.slid_m),
            nf.num(e.sliding_time_s),
            nf.num(e.since_previous_s),
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
        sampling: sc.sampling(),
        force_history: crate::scenario::output::force_history(sc),
        wall_time_s: r.wall_time_s,
        contacts: (!sc.output.compress).then_some(r.events.as_slice()),
        contacts_file: sc.output.compress.then_some(CONTACTS_JSON_GZ),
        apples: r
            .apples
            .iter()
            .map(|end| AppleRow {
                end,
                damage: analysis
                    .and_then(|a| a.bruise.apples.iter().find(|x| *x.apple == *end.name))
                    .map(AppleDamage::of),
            })
            .collect(),
        warnings: &r.warnings,
        line: &r.line,
        metrics: &r.metrics,
        damage: analysis.map(|a| {
            let b = &a.bruise;
            DamageSummary {
                standard: &b.standard,
                grades: &b.grades,
                apples_bruised: b.apples_bruised(),
                apples_downgraded: b.apples_downgraded(),
                total_bruise_volume_mm3: Some(b.total_bruise_volume_mm3())
                    .filter(|v| v.is_finite()),
                apples_per_grade: b
                    .grades
                    .iter()
                    .map(|g| {
                        (
                            g.as_str(),
                            b.apples.iter().filter(|x| &x.grade == g).count(),
                        )
                    })
                    .collect(),
                models: b
                    .apples
                    .iter()
                    .map(|x| (x.material.as_str(), x.model))
                    .collect(),
            }
        }),
        pulse_fits: analysis.map(|a| a.pulse_fits.as_slice()),
        transitions: r.transition_summary.as_ref(),
        audit: analysis.map(|a| a.audit.points.as_slice()),
        probes: r
            .probes
            .iter()
            .map(|p| {
                let stem = probe::stem(&p.apple);
                let points = match analysis {
                    Some(a) => probe::transfer_points(p, &r.events, &a.contact_points),
                    None => vec![String::new(); p.impacts.len()],
                };
                ProbeSummary {
                    apple: &p.apple,
                    mass_kg: p.mass_kg,
                    settings: &p.spec,
                    files: [format!("{stem}_trace.csv"), format!("{stem}_impacts.csv")],
                    impacts: p
                        .impacts
                        .iter()
                        .zip(points)
                        .map(|(impact, transfer_point)| ProbeImpactRow {
                            impact,
                            transfer_point,
                        })
                        .collect(),
                }
            })
            .collect(),
    };
    if sc.output.compress {
        write_contacts_json_gz(&path.with_file_name(CONTACTS_JSON_GZ), &r.events)?;
    }
    let mut bytes = serde_json::to_vec_pretty(&s).map_err(std::io::Error::other)?;
    bytes.push(b'\n');
    atomic::write_file(path, &bytes)
}

/// With `output.compress`, summary.json's `contacts` list is written gzipped beside it under
/// this name (the same objects in the same order; summary.json names it in `contacts_file`): it
/// is most of summary.json in a run with many contacts (2100 bytes a contact, 85 % of the bin
/// fill's 7 MB), and a batch's folders are then about 3.4 times smaller, not 2.5.
pub const CONTACTS_JSON_GZ: &str = "contacts.json.gz";

/// Writes `contacts` as a pretty-printed JSON array, gzipped, whole or not at all.
fn write_contacts_json_gz(path: &Path, contacts: &[ContactEvent]) -> std::io::Result<()> {
    let file = atomic::AtomicFile::create(path)?;
    let mut gz = flate2::write::GzEncoder::new(file, flate2::Compression::new(atomic::GZIP_LEVEL));
    serde_json::to_writer_pretty(&mut gz, contacts).map_err(std::io::Error::other)?;
    std::io::Write::write_all(&mut gz, b"\n")?;
    gz.finish()?.commit()
}

/// Writes the scenario as it was run (`scenario.json`).
pub fn write_scenario(path: &Path, sc: &Scenario) -> std::io::Result<()> {
    // The scenario as run: the sleep thresholds its accuracy chose and the sample interval
    // (given, or the default for its length and apples) are written out.
    let mut sc = sc.clone();
    sc.output.sample_interval_s = Some(sc.sample_interval_s());
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

/// The columns `bodies.csv` adds after [`BODIES_HEADER`] in a run with spheroidal apples
/// (issue 29): the height along the apple's own z axis and its orientation as a unit quaternion
/// (w first; its frame to the world's). A sphere's row has its diameter as height and the
/// identity. Runs of spheres keep the 17 columns, byte for byte.
pub const BODIES_SHAPE_HEADER: [&str; 5] = ["height_m", "qw", "qx", "qy", "qz"];

/// A sample sink streaming `bodies.csv` to a temporary file, renamed on [`BodiesCsv::commit`].
pub struct BodiesCsv {
    w: AtomicCsv,
    nf: NumberFormat,
    /// The cells of one row, reused.
    cells: Vec<String>,
    /// With the shape columns ([`BODIES_SHAPE_HEADER`]).
    shaped: bool,
}

impl BodiesCsv {
    /// Starts `path` (gzipped when its name ends in `.gz`), numbers as `nf` prints them; with
    /// the shape columns when `shaped` (a run with spheroids).
    pub fn create(path: &Path, nf: NumberFormat, shaped: bool) -> std::io::Result<Self> {
        let header: Vec<&str> = if shaped {
            BODIES_HEADER
                .iter()
                .chain(&BODIES_SHAPE_HEADER)
                .copied()
                .collect()
        } else {
            BODIES_HEADER.to_vec()
        };
        let w = AtomicCsv::create(path, &header)?;
        Ok(Self {
            w,
            nf,
            cells: vec![String::new(); header.len()],
            shaped,
        })
    }

    /// Finishes the file under its final name.
    pub fn commit(self) -> std::io::Result<()> {
        self.w.commit()
    }
}

impl SampleSink for BodiesCsv {
    fn sample(&mut self, time_s: f64, apples: &[AppleState]) -> std::io::Result<()> {
        let nf = self.nf;
        let t = nf.num(time_s);
        for a in apples {
            let p = a.position;
            let v = a.velocity;
            let w = a.angular_velocity;
            let f = a.contact_force;
            let c = &mut self.cells;
            c[0].clone_from(&t);
            c[1].clear();
            c[1].push_str(&a.name);
            let numbers = [p.x, p.y, p.z, v.x, v.y, v.z, w.x, w.y, w.z, f.x, f.y, f.z];
            for (cell, x) in c[2..14].iter_mut().zip(numbers) {
                cell.clear();
                nf.push(cell, x);
            }
            c[14].clear();
            if let Some(x) = a.slip_speed {
                nf.push(&mut c[14], x);
            }
            c[15].clear();
            nf.push(&mut c[15], a.diameter_m);
            c[16].clear();
            nf.push(&mut c[16], a.mass_kg);
            if self.shaped {
                let (h, q) = match &a.shape {
                    Some(sh) => (sh.height_m, sh.rotation),
                    None => (a.diameter_m, rapier3d_f64::math::Rotation::IDENTITY),
                };
                for (cell, x) in c[17..22].iter_mut().zip([h, q.w, q.x, q.y, q.z]) {
                    cell.clear();
                    nf.push(cell, x);
                }
            }
            self.w.write_record(c.iter())?;
        }
        Ok(())
    }
}

/// Writes `forces.csv`: every recorded force sample of every contact with a history, one row
/// each ([`plot::FORCES_HEADER`]; `contact` is the row index in `contacts.csv`).
pub fn write_forces(path: &Path, events: &[ContactEvent], nf: NumberFormat) -> std::io::Result<()> {
    let mut w = AtomicCsv::create(path, &plot::FORCES_HEADER)?;
    for (k, e) in events.iter().enumerate() {
        let Some(h) = &e.history else { continue };
        let k = k.to_string();
        for (t, p) in h {
            w.write_record([&k, &*e.a, &*e.b, &nf.num(*t), &nf.num(*p)])?;
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
pub fn write_pulse_fits(path: &Path, fits: &[PulseFit], nf: NumberFormat) -> std::io::Result<()> {
    let mut w = AtomicCsv::create(path, &PULSE_FITS_HEADER)?;
    for p in fits {
        w.write_record([
            p.contact.to_string(),
            p.a.to_string(),
            p.b.to_string(),
            p.samples.to_string(),
            nf.num(p.fit_peak_force_n),
            nf.num(p.fit_contact_time_s),
            nf.num(p.fit_eps),
            nf.num(p.fit_tau),
            nf.num(p.rms_residual_n),
            p.converged.to_string(),
            nf.num(p.k_p),
            nf.num(p.k_p_shape),
            nf.num(p.k_p_measured),
            nf.num(p.peak_force_n),
            nf.num(p.contact_time_s),
            nf.num(p.restitution),
            nf.num(p.effective_mass_kg),
            nf.num(p.eq15_peak_force_n),
            nf.num(p.eq15_peak_force_n / p.peak_force_n - 1.0),
        ])?;
    }
    w.commit()
}

/// Header of `apple_contacts.csv`: one row per apple per contact (fruit only), its side of the
/// contact and what it did to the apple ([`crate::analysis::bruise::ContactAssessment`]).
pub const APPLE_CONTACTS_HEADER: [&str; 22] = [
    "contact",
    "apple",
    "other",
    "transfer_point",
    "t_start_s",
    "t_peak_s",
    "contact_point_m",
    "peak_force_n",
    "peak_pressure_pa",
    "absorbed_energy_j",
    "contact_absorbed_energy_j",
    "velocity_change_m_s",
    "peak_g",
    "approach_speed_m_s",
    "bruised",
    "site",
    "volume_mm3",
    "apple_grade",
    "static_max_force_n",
    "static_max_pressure_pa",
    "exceeded",
    "outside_validity",
];

/// The name of the per apple per contact file.
pub const APPLE_CONTACTS_CSV: &str = "apple_contacts.csv";

/// Each apple's grade by its name (the `apple_grade` column of the damage files).
fn grades_by_apple(a: &Analysis) -> std::collections::BTreeMap<&str, &str> {
    a.bruise
        .apples
        .iter()
        .map(|x| (&*x.apple, x.grade.as_str()))
        .collect()
}

/// Writes `apple_contacts.csv`.
pub fn write_apple_contacts(path: &Path, a: &Analysis, nf: NumberFormat) -> std::io::Result<()> {
    let mut w = AtomicCsv::create(path, &APPLE_CONTACTS_HEADER)?;
    let grade = grades_by_apple(a);
    for c in &a.bruise.contacts {
        let p = c.contact_point_m;
        w.write_record([
            c.contact.to_string(),
            c.apple.to_string(),
            c.other.to_string(),
            c.transfer_point.clone(),
            nf.num(c.t_start_s),
            nf.num(c.t_peak_s),
            nf.point(p),
            nf.num(c.peak_force_n),
            nf.num(c.peak_pressure_pa),
            nf.num(c.absorbed_energy_j),
            nf.num(c.contact_absorbed_energy_j),
            nf.num(c.velocity_change_m_s),
            nf.num(c.peak_g),
            nf.num(c.approach_speed_m_s),
            c.bruised.to_string(),
            c.site.map(|s| s.to_string()).unwrap_or_default(),
            nf.opt(c.volume_mm3),
            grade.get(&*c.apple).copied().unwrap_or("").to_string(),
            nf.opt(c.static_max_force_n),
            nf.opt(c.static_max_pressure_pa),
            c.exceeded.clone(),
            c.outside_validity.unwrap_or("").to_string(),
        ])?;
    }
    w.commit()
}

/// Header of `bruises.csv`: one row per bruise site of each apple
/// ([`crate::analysis::bruise::BruiseSite`]); `x`, `y`, `z` locate the site on the apple, a unit
/// vector from its centre in its own frame.
pub const BRUISES_HEADER: [&str; 16] = [
    "apple",
    "site",
    "x",
    "y",
    "z",
    "first_hit_s",
    "last_hit_s",
    "hits",
    "transfer_points",
    "absorbed_energy_j",
    "bruised",
    "volume_mm3",
    "area_mm2",
    "depth_mm",
    "diameter_mm",
    "apple_grade",
];

/// The name of the per site file.
pub const BRUISES_CSV: &str = "bruises.csv";

/// Writes `bruises.csv`.
pub fn write_bruises(path: &Path, a: &Analysis, nf: NumberFormat) -> std::io::Result<()> {
    let mut w = AtomicCsv::create(path, &BRUISES_HEADER)?;
    let grade = grades_by_apple(a);
    for s in &a.bruise.sites {
        w.write_record([
            s.apple.to_string(),
            s.site.to_string(),
            nf.num(s.direction[0]),
            nf.num(s.direction[1]),
            nf.num(s.direction[2]),
            nf.num(s.first_hit_s),
            nf.num(s.last_hit_s),
            s.hits.to_string(),
            s.transfer_points.join("; "),
            nf.num(s.absorbed_energy_j),
            s.bruised.to_string(),
            nf.opt(s.volume_mm3),
            nf.opt(s.area_mm2),
            nf.opt(s.depth_mm),
            nf.opt(s.diameter_mm),
            grade.get(&*s.apple).copied().unwrap_or("").to_string(),
        ])?;
    }
    w.commit()
}
