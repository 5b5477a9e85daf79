//! The run-folder reader behind the charts: what `contacts.csv`, `forces.csv`, `bodies.csv` and
//! `transitions.csv` of one run hold, as curves ([`RunCurves`]).
//!
//! Charts are drawn from the files of a run folder rather than from the run in memory, so saved
//! runs can be drawn and compared at any time (`applesim plot`), and the validation report draws
//! its figures from the runs its batches wrote. Reading is kept apart from drawing
//! ([`super`]) so a reader of the file formats finds them in one place.

use super::PlotError;
use crate::output::csv_file::{locate, Input};
use std::collections::BTreeMap;
use std::path::Path;

/// Header of `forces.csv`: one row per recorded force sample of a contact (`contact` is the
/// contact's row index in `contacts.csv`, from 0).
pub const FORCES_HEADER: [&str; 5] = ["contact", "a", "b", "time_s", "force_n"];

/// One contact's force curve read from a run folder.
#[derive(Debug, Clone, PartialEq)]
pub struct ForceCurve {
    /// Row index in `contacts.csv`.
    pub contact: usize,
    /// Apple.
    pub a: String,
    /// Other body.
    pub b: String,
    /// First touch (s).
    pub t_start_s: f64,
    /// Peak force (N).
    pub peak_force_n: f64,
    /// Duration of its impact pulse (s; `contacts.csv` `impact_duration_s`): `None` for a
    /// contact that started at rest, or a run folder written before the column existed.
    pub impact_duration_s: Option<f64>,
    /// Whether `contacts.csv` has the `impact_duration_s` column (run folders written before it
    /// existed do not).
    pub impact_known: bool,
    /// (time since first touch s, force N), with the zero-force touch and parting instants.
    pub points: Vec<(f64, f64)>,
}

/// One apple's kinematics read from `bodies.csv`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Kinematics {
    /// (time s, centre speed m/s).
    pub speed: Vec<(f64, f64)>,
    /// (time s, angular speed rad/s).
    pub spin: Vec<(f64, f64)>,
    /// (time s, slip speed m/s) when `bodies.csv` has the `slip_m_s` column filled.
    pub slip: Vec<(f64, f64)>,
}

/// One row of `transitions.csv` as the charts need it.
#[derive(Debug, Clone, PartialEq)]
pub struct TransitionMark {
    /// Apple.
    pub apple: String,
    /// New state (`sliding`, `rolling`, `airborne`).
    pub to: String,
    /// Surface it is on after (empty when airborne).
    pub surface: String,
    /// Time (s).
    pub time_s: f64,
    /// Slip speed then (m/s).
    pub slip_m_s: f64,
    /// Distance along the surface (m; NaN when none).
    pub along_m: f64,
}

/// What the charts need from one run folder.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RunCurves {
    /// Contacts with a recorded force curve (empty without `forces.csv`).
    pub forces: Vec<ForceCurve>,
    /// Apples in order of first appearance in `bodies.csv`.
    pub apples: Vec<(String, Kinematics)>,
    /// Whether `forces.csv` was there.
    pub has_forces: bool,
    /// Rows of `transitions.csv` (empty without it).
    pub transitions: Vec<TransitionMark>,
}

/// A CSV error of the file at `path`, named so a user finds the broken file.
fn parse_error(path: &Path, e: impl std::fmt::Display) -> PlotError {
    PlotError::Parse {
        path: path.to_path_buf(),
        message: e.to_string(),
    }
}

/// A CSV reader of the file at `path`, plain or gzipped ([`crate::output::csv_file::open`]).
fn reader(path: &Path) -> Result<csv::Reader<Input>, PlotError> {
    crate::output::csv_file::reader(path)
        .map(|(_, rd)| rd)
        .map_err(|e| parse_error(path, e))
}

/// Column indices of `names` in a CSV header.
fn columns(
    path: &Path,
    rd: &mut csv::Reader<Input>,
    names: &[&str],
) -> Result<Vec<usize>, PlotError> {
    let h = rd.headers().map_err(|e| parse_error(path, e))?;
    names
        .iter()
        .map(|n| {
            h.iter()
                .position(|c| c == *n)
                .ok_or_else(|| parse_error(path, format!("no column '{n}'")))
        })
        .collect()
}

/// A number of a CSV cell; an empty cell (a value a run did not have) reads as NaN.
fn num(path: &Path, s: &str) -> Result<f64, PlotError> {
    if s.is_empty() {
        return Ok(f64::NAN);
    }
    s.parse()
        .map_err(|_| parse_error(path, format!("'{s}' is not a number")))
}

/// Reads the curves of a run folder (its CSV files plain or gzipped). A contact whose force
/// history was kept over its impact only (`contacts.csv` `force_history_cut_s`) ends at its
/// last kept sample, without the parting point.
pub fn read_run(dir: &Path) -> Result<RunCurves, PlotError> {
    let mut out = RunCurves::default();
    let contacts_path = locate(dir, "contacts.csv");
    let forces_path = locate(dir, "forces.csv");
    if forces_path.exists() {
        out.has_forces = true;
        let mut rd = reader(&contacts_path)?;
        let c = columns(
            &contacts_path,
            &mut rd,
            &["a", "b", "t_start_s", "t_end_s", "peak_force_n"],
        )?;
        // Older run folders have no impact column: their charts fall back to the force curve.
        let impact_col = rd
            .headers()
            .ok()
            .and_then(|h| h.iter().position(|c| c == "impact_duration_s"));
        let cut_col = rd
            .headers()
            .ok()
            .and_then(|h| h.iter().position(|c| c == "force_history_cut_s"));
        let mut by_index = Vec::new();
        for rec in rd.records() {
            let rec = rec.map_err(|e| parse_error(&contacts_path, e))?;
            let t0 = num(&contacts_path, &rec[c[2]])?;
            let t1 = num(&contacts_path, &rec[c[3]])?;
            let cut = match cut_col {
                Some(i) => num(&contacts_path, rec.get(i).unwrap_or(""))?.is_finite(),
                None => false,
            };
            by_index.push(ForceCurve {
                contact: by_index.len(),
                a: rec[c[0]].to_string(),
                b: rec[c[1]].to_string(),
                t_start_s: t0,
                peak_force_n: num(&contacts_path, &rec[c[4]])?,
                impact_duration_s: match impact_col {
                    Some(i) => Some(num(&contacts_path, rec.get(i).unwrap_or(""))?)
                        .filter(|x| x.is_finite()),
                    None => None,
                },
                impact_known: impact_col.is_some(),
                points: if t1.is_finite() && !cut {
                    vec![(t1 - t0, 0.0)]
                } else {
                    vec![]
                },
            });
        }
        let mut rd = reader(&forces_path)?;
        let c = columns(&forces_path, &mut rd, &["contact", "time_s", "force_n"])?;
        let mut curves: BTreeMap<usize, Vec<(f64, f64)>> = BTreeMap::new();
        for rec in rd.records() {
            let rec = rec.map_err(|e| parse_error(&forces_path, e))?;
            let k: usize = rec[c[0]].parse().map_err(|_| {
                parse_error(&forces_path, format!("bad contact index '{}'", &rec[c[0]]))
            })?;
            curves.entry(k).or_default().push((
                num(&forces_path, &rec[c[1]])?,
                num(&forces_path, &rec[c[2]])?,
            ));
        }
        for (k, pts) in curves {
            let Some(fc) = by_index.get_mut(k) else {
                return Err(parse_error(
                    &forces_path,
                    format!("contact {k} is not in contacts.csv"),
                ));
            };
            let end = fc.points.pop();
            let t0 = fc.t_start_s;
            fc.points.push((0.0, 0.0));
            fc.points.extend(pts.into_iter().map(|(t, p)| (t - t0, p)));
            fc.points.extend(end);
        }
        out.forces = by_index
            .into_iter()
            .filter(|f| f.points.len() > 2)
            .collect();
    }
    let bodies_path = locate(dir, "bodies.csv");
    let mut rd = reader(&bodies_path)?;
    let c = columns(
        &bodies_path,
        &mut rd,
        &[
            "time_s", "apple", "vx_m_s", "vy_m_s", "vz_m_s", "wx_rad_s", "wy_rad_s", "wz_rad_s",
        ],
    )?;
    let slip_col = rd
        .headers()
        .ok()
        .and_then(|h| h.iter().position(|c| c == "slip_m_s"));
    let mut order: BTreeMap<String, usize> = BTreeMap::new();
    for rec in rd.records() {
        let rec = rec.map_err(|e| parse_error(&bodies_path, e))?;
        let t = num(&bodies_path, &rec[c[0]])?;
        let g = |i: usize| num(&bodies_path, &rec[c[i]]);
        let v = (g(2)?.powi(2) + g(3)?.powi(2) + g(4)?.powi(2)).sqrt();
        let w = (g(5)?.powi(2) + g(6)?.powi(2) + g(7)?.powi(2)).sqrt();
        let name = &rec[c[1]];
        let k = match order.get(name) {
            Some(&k) => k,
            None => {
                order.insert(name.to_string(), out.apples.len());
                out.apples.push((name.to_string(), Kinematics::default()));
                out.apples.len() - 1
            }
        };
        out.apples[k].1.speed.push((t, v));
        out.apples[k].1.spin.push((t, w));
        if let Some(sc) = slip_col {
            let x = num(&bodies_path, rec.get(sc).unwrap_or(""))?;
            if x.is_finite() {
                out.apples[k].1.slip.push((t, x));
            }
        }
    }
    let tr_path = locate(dir, "transitions.csv");
    if tr_path.exists() {
        let mut rd = reader(&tr_path)?;
        let c = columns(
            &tr_path,
            &mut rd,
            &["apple", "to", "surface", "time_s", "slip_m_s", "along_m"],
        )?;
        for rec in rd.records() {
            let rec = rec.map_err(|e| parse_error(&tr_path, e))?;
            out.transitions.push(TransitionMark {
                apple: rec[c[0]].to_string(),
                to: rec[c[1]].to_string(),
                surface: rec[c[2]].to_string(),
                time_s: num(&tr_path, &rec[c[3]])?,
                slip_m_s: num(&tr_path, &rec[c[4]])?,
                along_m: num(&tr_path, &rec[c[5]])?,
            });
        }
    }
    Ok(out)
}
