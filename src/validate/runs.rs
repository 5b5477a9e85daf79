//! Running one figure's batch spec through the batch machinery and reading its run folders
//! back: the scenario as run, `contacts.csv`, `bodies.csv` and the force curves.

use super::ValidateError;
use crate::batch::{self, runner, Batch, Shard};
use crate::output::plot::{self, ForceCurve};
use crate::scenario::{self, Scenario};
use std::path::{Path, PathBuf};

/// One contact of a run, from its `contacts.csv` row.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactRow {
    /// Row index in `contacts.csv` (from 0): the `contact` column of `forces.csv`.
    pub index: usize,
    /// Apple.
    pub a: String,
    /// Other body.
    pub b: String,
    /// First touch (s).
    pub t_start_s: f64,
    /// Duration (s); NaN while still open at the end of the run.
    pub duration_s: f64,
    /// Peak normal force (N).
    pub peak_force_n: f64,
    /// Largest overlap (m).
    pub max_overlap_m: f64,
    /// Approach speed at first touch (m/s).
    pub approach_speed_m_s: f64,
    /// Restitution; NaN when the run has none for it.
    pub restitution: f64,
}

/// One sample of one apple from `bodies.csv`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodySample {
    /// Time (s).
    pub time_s: f64,
    /// Centre (m).
    pub position_m: [f64; 3],
    /// Centre velocity (m/s).
    pub velocity_m_s: [f64; 3],
    /// Angular velocity (rad/s).
    pub angular_velocity_rad_s: [f64; 3],
}

/// One run of a figure's batch, read back.
#[derive(Debug, Clone)]
pub struct Run {
    /// Position in the batch's expansion.
    pub index: usize,
    /// The varied parameters' values by name, as numbers (NaN for non-numbers).
    pub params: Vec<(String, f64)>,
    /// The scenario as run.
    pub scenario: Scenario,
    /// The run's folder.
    pub dir: PathBuf,
    /// Its contacts, in `contacts.csv` order.
    pub contacts: Vec<ContactRow>,
}

impl Run {
    /// The value of parameter `name` (NaN when the batch has no such parameter).
    pub fn param(&self, name: &str) -> f64 {
        param(&self.params, name)
    }

    /// The contact between `a` and `b` with the largest peak force.
    pub fn strongest(&self, a: &str, b: &str) -> Option<&ContactRow> {
        self.contacts
            .iter()
            .filter(|c| c.a == a && c.b == b)
            .max_by(|x, y| {
                x.peak_force_n
                    .total_cmp(&y.peak_force_n)
                    .then(y.index.cmp(&x.index))
            })
    }

    /// The force curve of contact row `index` (time since first touch s, force N).
    pub fn force_curve(&self, index: usize) -> Result<ForceCurve, ValidateError> {
        let curves = plot::read_run(&self.dir).map_err(ValidateError::Plot)?;
        curves
            .forces
            .into_iter()
            .find(|c| c.contact == index)
            .ok_or_else(|| ValidateError::Read {
                path: self.dir.join("forces.csv"),
                message: format!("no force history of contact {index}"),
            })
    }

    /// The samples of apple `name` from `bodies.csv`.
    pub fn bodies(&self, name: &str) -> Result<Vec<BodySample>, ValidateError> {
        read_bodies(
            &crate::output::csv_file::locate(&self.dir, "bodies.csv"),
            name,
        )
    }
}

/// The value of `name` among a run's batch parameters, NaN when the batch has none: a trend over
/// a parameter the batch does not vary then fails visibly instead of comparing zeros.
pub fn param(params: &[(String, f64)], name: &str) -> f64 {
    params
        .iter()
        .find(|(n, _)| n == name)
        .map_or(f64::NAN, |(_, v)| *v)
}

/// A figure's batch after it ran.
#[derive(Debug, Clone)]
pub struct Executed {
    /// The spec file.
    pub spec: PathBuf,
    /// The spec's description.
    pub description: String,
    /// The runs that completed, in expansion order.
    pub runs: Vec<Run>,
    /// Runs that failed: (index, parameters, error).
    pub failed: Vec<(usize, String, String)>,
}

/// Runs the batch spec `spec` into `out` (every run afresh: a validation must reflect the
/// code as it is, never a run kept from an older build), merges it (`out/merged.csv`) and reads
/// every completed run back.
pub fn execute(spec: &Path, out: &Path, jobs: usize) -> Result<Executed, ValidateError> {
    let batch = batch::load(spec).map_err(ValidateError::Batch)?;
    let opts = runner::Options {
        jobs,
        shard: Shard::ALL,
        force: true,
        ..runner::Options::default()
    };
    let report = runner::run(&batch, out, &opts, &runner::Silent).map_err(ValidateError::Batch)?;
    batch::merge(out).map_err(ValidateError::Batch)?;
    let mut runs = Vec::new();
    for planned in &batch.runs {
        if report.failed.iter().any(|(k, _, _)| *k == planned.index) {
            continue;
        }
        runs.push(read_run(&batch, planned.index, out)?);
    }
    let failed = report
        .failed
        .iter()
        .map(|(k, _, e)| (*k, batch.runs[*k].label.clone(), e.clone()))
        .collect();
    Ok(Executed {
        spec: spec.to_path_buf(),
        description: batch.description.clone().unwrap_or_default(),
        runs,
        failed,
    })
}

fn read_run(batch: &Batch, index: usize, out: &Path) -> Result<Run, ValidateError> {
    let planned = &batch.runs[index];
    let dir = batch::manifest::run_dir(out, &planned.id);
    let value = planned.scenario.as_ref().map_err(|e| ValidateError::Read {
        path: dir.clone(),
        message: e.clone(),
    })?;
    let text = serde_json::to_string(value).expect("a JSON value serialises");
    let scenario = scenario::from_json(&text, &planned.label).map_err(|e| ValidateError::Read {
        path: dir.clone(),
        message: e.to_string(),
    })?;
    let params = batch
        .parameters
        .iter()
        .zip(&planned.values)
        .map(|(p, v)| (p.name.clone(), v.as_f64().unwrap_or(f64::NAN)))
        .collect();
    let contacts = read_contacts(&crate::output::csv_file::locate(&dir, "contacts.csv"))?;
    Ok(Run {
        index,
        params,
        scenario,
        dir,
        contacts,
    })
}

fn parse_err(path: &Path, message: impl std::fmt::Display) -> ValidateError {
    ValidateError::Read {
        path: path.to_path_buf(),
        message: message.to_string(),
    }
}

/// A CSV reader of the file at `path`, plain or gzipped ([`crate::output::csv_file::open`]).
fn reader(
    path: &Path,
) -> Result<
    (
        csv::Reader<crate::output::csv_file::Input>,
        csv::StringRecord,
    ),
    ValidateError,
> {
    let (_, mut rd) = crate::output::csv_file::reader(path).map_err(|e| parse_err(path, e))?;
    let header = rd.headers().map_err(|e| parse_err(path, e))?.clone();
    Ok((rd, header))
}

fn column(path: &Path, header: &csv::StringRecord, name: &str) -> Result<usize, ValidateError> {
    header
        .iter()
        .position(|c| c == name)
        .ok_or_else(|| parse_err(path, format!("no column '{name}'")))
}

fn number(path: &Path, s: &str) -> Result<f64, ValidateError> {
    if s.is_empty() {
        return Ok(f64::NAN);
    }
    s.parse()
        .map_err(|_| parse_err(path, format!("'{s}' is not a number")))
}

/// Reads a run's `contacts.csv`.
pub fn read_contacts(path: &Path) -> Result<Vec<ContactRow>, ValidateError> {
    let (mut rd, h) = reader(path)?;
    let names = [
        "a",
        "b",
        "t_start_s",
        "duration_s",
        "peak_force_n",
        "max_overlap_m",
        "approach_speed_m_s",
        "restitution",
    ];
    let c: Vec<usize> = names
        .iter()
        .map(|n| column(path, &h, n))
        .collect::<Result<_, _>>()?;
    let mut out = Vec::new();
    for (index, rec) in rd.records().enumerate() {
        let rec = rec.map_err(|e| parse_err(path, e))?;
        let num = |i: usize| number(path, &rec[c[i]]);
        out.push(ContactRow {
            index,
            a: rec[c[0]].to_string(),
            b: rec[c[1]].to_string(),
            t_start_s: num(2)?,
            duration_s: num(3)?,
            peak_force_n: num(4)?,
            max_overlap_m: num(5)?,
            approach_speed_m_s: num(6)?,
            restitution: num(7)?,
        });
    }
    Ok(out)
}

/// Reads the samples of apple `name` from a `bodies.csv`.
pub fn read_bodies(path: &Path, name: &str) -> Result<Vec<BodySample>, ValidateError> {
    let (mut rd, h) = reader(path)?;
    let names = [
        "time_s", "apple", "x_m", "y_m", "z_m", "vx_m_s", "vy_m_s", "vz_m_s", "wx_rad_s",
        "wy_rad_s", "wz_rad_s",
    ];
    let c: Vec<usize> = names
        .iter()
        .map(|n| column(path, &h, n))
        .collect::<Result<_, _>>()?;
    let mut out = Vec::new();
    for rec in rd.records() {
        let rec = rec.map_err(|e| parse_err(path, e))?;
        if &rec[c[1]] != name {
            continue;
        }
        let num = |i: usize| number(path, &rec[c[i]]);
        out.push(BodySample {
            time_s: num(0)?,
            position_m: [num(2)?, num(3)?, num(4)?],
            velocity_m_s: [num(5)?, num(6)?, num(7)?],
            angular_velocity_rad_s: [num(8)?, num(9)?, num(10)?],
        });
    }
    Ok(out)
}
