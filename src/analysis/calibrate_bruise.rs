//! Calibrating a damage model from a lab's drop tests (`applesim calibrate-bruise`,
//! docs/damage.md section 8).
//!
//! A drop test gives, per drop, how it was dropped (a height, an impact speed, or the peak force
//! the lab measured), onto what, the apple's size and mass, and the bruise (a volume, a surface
//! diameter and depth, or bruised yes/no). The bruise depends on what the apple went through,
//! which the lab did not measure: so each drop is simulated with the simulator itself (the
//! one-impact scenario of [`super::calibrate`]: the apple touching a flat of the surface's
//! material at the drop's speed, sqrt(2 g h) for a height, gravity on), its hit taken as a run
//! takes it ([`super::bruise::hit_of`]: the apple's share of the impact's loss, the peak force,
//! the peak centre pressure, the contact radius, the apple's own deformation), and the model's
//! coefficients fitted to the measured bruises ([`crate::analysis::damage::fit`]). A drop given
//! by its peak force is simulated at the speed that gives that force, found by bisection.

use super::bruise::hit_of;
use super::calibrate::{step_until, CalibrateError, OneImpact};
use super::damage::fit::{self, Fit, FitError, FitOptions, Measured, Method};
use super::damage::geometry::cap_volume;
use super::damage::Hit;
use crate::math::human;
use crate::scenario::damage::{self as spec, DamageModelName, DamageSpec};
use crate::scenario::lab::LabSetup;
use crate::scenario::ranges::{self, Range};
use crate::scenario::ScenarioError;
use std::collections::BTreeMap;
use std::path::Path;
use thiserror::Error;

/// Gravity of the drops (m/s^2): a drop from height h touches at sqrt(2 g h).
pub const STANDARD_GRAVITY_M_S2: f64 = 9.81;

/// Default steps per elastic contact time of a simulated drop. The energy an impact absorbs
/// converges at first order in the step: a drop's absorbed energy moves by about 2e-4 of itself
/// from 200 steps to the converged value, 5e-5 at 1000 (docs/damage.md section 8). A drop costs
/// a few thousand steps of one apple.
pub const DEFAULT_STEPS_PER_DROP: f64 = 1000.0;

/// The columns a drops file may have.
pub const COLUMNS: &[&str] = &[
    "id",
    "height_m",
    "speed_m_s",
    "peak_force_n",
    "surface",
    "diameter_m",
    "mass_kg",
    "volume_mm3",
    "diameter_mm",
    "depth_mm",
    "bruised",
];

/// The columns that say how a drop was dropped (one per row).
const DROP_COLUMNS: &[&str] = &["height_m", "speed_m_s", "peak_force_n"];

/// Why a calibration was refused or failed: each names the file, and the row and column where
/// one is at fault (rows are numbered as a spreadsheet shows them: the header is row 1).
#[derive(Debug, Error)]
pub enum DropsError {
    /// A file could not be read.
    #[error("cannot read '{file}': {source}")]
    Io {
        /// The file.
        file: String,
        /// The OS error.
        source: std::io::Error,
    },
    /// A bad value, or one missing, in a cell.
    #[error("{file}, row {row}, column {column}: {message}")]
    Cell {
        /// The file.
        file: String,
        /// The row (the header is row 1).
        row: usize,
        /// The column's name.
        column: String,
        /// What is wrong and what would be right.
        message: String,
    },
    /// A row at fault as a whole.
    #[error("{file}, row {row}: {message}")]
    Row {
        /// The file.
        file: String,
        /// The row.
        row: usize,
        /// What is wrong.
        message: String,
    },
    /// A file at fault as a whole (no drops, a missing column).
    #[error("{file}: {message}")]
    File {
        /// The file.
        file: String,
        /// What is wrong.
        message: String,
    },
    /// The lab file was refused.
    #[error("{file}: {source}")]
    Lab {
        /// The lab file.
        file: String,
        /// The refusal, naming the field.
        source: Box<ScenarioError>,
    },
    /// A drop could not be simulated.
    #[error("{file}, row {row}: the drop's simulation failed: {source}")]
    Simulation {
        /// The drops file.
        file: String,
        /// The row.
        row: usize,
        /// Why.
        source: Box<CalibrateError>,
    },
    /// The coefficients could not be fitted.
    #[error("{file}: the {model} model cannot be fitted: {source}")]
    Fit {
        /// The drops file.
        file: String,
        /// The model.
        model: &'static str,
        /// Why.
        source: FitError,
    },
    /// A bad option.
    #[error("{option}: {message}")]
    Option {
        /// The option.
        option: String,
        /// What is wrong.
        message: String,
    },
}

/// How a drop was dropped.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum DropDefinition {
    /// Fall height of the apple's lowest point onto the surface (m).
    Height(f64),
    /// Impact speed (m/s).
    Speed(f64),
    /// The peak force the lab measured (N): simulated at the speed that gives it.
    PeakForce(f64),
}

impl DropDefinition {
    /// As a person writes it (`h 0.1 m`, `v 1.4 m/s`, `F 57 N`).
    pub fn describe(&self) -> String {
        match *self {
            DropDefinition::Height(h) => format!("h {} m", human(h, 4, 3)),
            DropDefinition::Speed(v) => format!("v {} m/s", human(v, 4, 3)),
            DropDefinition::PeakForce(f) => format!("F {} N", human(f, 4, 1)),
        }
    }
}

/// How the bruise was given.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BruiseAs {
    /// `volume_mm3`.
    Volume,
    /// `diameter_mm` and `depth_mm` (mm), turned into the spherical cap's volume.
    Cap {
        /// Surface diameter (mm).
        diameter_mm: f64,
        /// Depth (mm).
        depth_mm: f64,
    },
    /// `bruised` (yes/no).
    YesNo,
}

/// One drop of a drops file.
#[derive(Debug, Clone, PartialEq)]
pub struct Drop {
    /// Its row (the header is row 1).
    pub row: usize,
    /// The lab's name for it (`id`), if given.
    pub id: Option<String>,
    /// How it was dropped.
    pub how: DropDefinition,
    /// The surface it struck (a lab file's surface or material).
    pub surface: String,
    /// Apple diameter (m).
    pub diameter_m: f64,
    /// Apple mass (kg).
    pub mass_kg: f64,
    /// The bruise (a volume, from a cap too, or yes/no).
    pub measured: Measured,
    /// How the bruise was given.
    pub given_as: BruiseAs,
}

/// A drops file read.
#[derive(Debug, Clone, PartialEq)]
pub struct Drops {
    /// The file's name, for messages.
    pub file: String,
    /// The drops, in the file's order.
    pub drops: Vec<Drop>,
}

impl Drops {
    /// Whether the bruises are volumes (else yes/no).
    pub fn volumes(&self) -> bool {
        self.drops
            .first()
            .is_some_and(|d| matches!(d.measured, Measured::Volume(_)))
    }
}

/// Reads a drops file: a CSV with a header row of [`COLUMNS`] (any order, each once; unknown
/// ones are refused), one drop per row. A drop needs `surface` (a surface or material of `lab`),
/// `diameter_m`, `mass_kg`, one of `height_m`, `speed_m_s`, `peak_force_n`, and its bruise as
/// one of `volume_mm3`, `diameter_mm` with `depth_mm`, or `bruised` (yes/no, 1/0, true/false);
/// every drop's bruise is given alike (volumes, or yes/no). `id` is the lab's name for a drop.
/// Lines starting with `#` are comments.
pub fn read_drops(path: &Path, lab: &LabSetup) -> Result<Drops, DropsError> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|source| DropsError::Io {
        file: file.clone(),
        source,
    })?;
    parse_drops(&text, &file, lab)
}

/// [`read_drops`] of a text (`file` names it in messages).
pub fn parse_drops(text: &str, file: &str, lab: &LabSetup) -> Result<Drops, DropsError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let file_err = |message: String| DropsError::File {
        file: file.to_string(),
        message,
    };
    let mut rdr = csv::ReaderBuilder::new()
        .has_headers(true)
        .comment(Some(b'#'))
        .trim(csv::Trim::All)
        .flexible(false)
        .from_reader(text.as_bytes());
    // The row of a record starting at a byte offset: the line it is on, comment lines counted as
    // a spreadsheet shows them (the csv reader's own line count skips them, and a record's
    // offset is where the reader started looking for it: before the comments and blank lines
    // that precede it).
    let lines: Vec<&str> = text.split('\n').collect();
    let line_at = |byte: u64| {
        let mut line = text.as_bytes()[..(byte as usize).min(text.len())]
            .iter()
            .filter(|&&b| b == b'\n')
            .count();
        while lines.get(line).is_some_and(|l| {
            let l = l.trim();
            l.is_empty() || l.starts_with('#')
        }) && line + 1 < lines.len()
        {
            line += 1;
        }
        line + 1
    };
    let header_row = |e: &csv::Error| e.position().map_or(1, |p| line_at(p.byte()));
    let headers = rdr
        .headers()
        .map_err(|e| DropsError::Row {
            file: file.to_string(),
            row: header_row(&e),
            message: format!("not a CSV header: {e}"),
        })?
        .clone();
    let hrow = headers.position().map_or(1, |p| line_at(p.byte()));
    let mut index: BTreeMap<&str, usize> = BTreeMap::new();
    for (k, h) in headers.iter().enumerate() {
        let cell = |message: String| DropsError::Cell {
            file: file.to_string(),
            row: hrow,
            column: if h.is_empty() {
                format!("{} (unnamed)", k + 1)
            } else {
                h.to_string()
            },
            message,
        };
        let Some(known) = COLUMNS.iter().find(|c| **c == h) else {
            return Err(cell(format!(
                "unknown column '{h}': the columns are {}",
                COLUMNS.join(", ")
            )));
        };
        if index.insert(known, k).is_some() {
            return Err(cell(format!("column '{h}' is given twice")));
        }
    }
    for need in ["surface", "diameter_m", "mass_kg"] {
        if !index.contains_key(need) {
            return Err(file_err(format!(
                "no column '{need}': every drop needs its surface, diameter_m and mass_kg"
            )));
        }
    }
    if !DROP_COLUMNS.iter().any(|c| index.contains_key(c)) {
        return Err(file_err(
            "no column height_m, speed_m_s or peak_force_n: say how each drop was dropped".into(),
        ));
    }
    match (
        index.contains_key("diameter_mm"),
        index.contains_key("depth_mm"),
    ) {
        (true, false) => {
            return Err(file_err(
                "column diameter_mm without depth_mm: a bruise's volume needs both".into(),
            ))
        }
        (false, true) => {
            return Err(file_err(
                "column depth_mm without diameter_mm: a bruise's volume needs both".into(),
            ))
        }
        _ => {}
    }
    if !["volume_mm3", "diameter_mm", "bruised"]
        .iter()
        .any(|c| index.contains_key(c))
    {
        return Err(file_err(
            "no column volume_mm3, diameter_mm and depth_mm, or bruised: give each drop's bruise"
                .into(),
        ));
    }

    let mut drops = Vec::new();
    // The row and kind of the first bruise given (volumes or yes/no).
    let mut kind: Option<(usize, bool)> = None;
    for rec in rdr.records() {
        let rec = rec.map_err(|e| {
            let row = e.position().map_or(0, |p| line_at(p.byte()));
            let message = match e.kind() {
                csv::ErrorKind::UnequalLengths {
                    expected_len, len, ..
                } => format!("{len} fields where the header has {expected_len}"),
                _ => format!("not CSV: {e}"),
            };
            DropsError::Row {
                file: file.to_string(),
                row,
                message,
            }
        })?;
        let row = rec.position().map_or(0, |p| line_at(p.byte()));
        let cell_err = |column: &str, message: String| DropsError::Cell {
            file: file.to_string(),
            row,
            column: column.to_string(),
            message,
        };
        let get = |c: &str| -> Option<&str> {
            index
                .get(c)
                .and_then(|&k| rec.get(k))
                .filter(|s| !s.is_empty())
        };
        let number = |c: &str, range: &Range| -> Result<Option<f64>, DropsError> {
            let Some(s) = get(c) else { return Ok(None) };
            let v: f64 = s
                .parse()
                .map_err(|_| cell_err(c, format!("'{s}' is not a number")))?;
            if !range.contains(v) {
                return Err(cell_err(
                    c,
                    format!("{s} is out of range: {}", range.describe()),
                ));
            }
            Ok(Some(v))
        };
        let required = |c: &str, range: &Range, what: &str| -> Result<f64, DropsError> {
            number(c, range)?.ok_or_else(|| cell_err(c, format!("empty: give the {what}")))
        };
        // How it was dropped: one of the drop columns.
        let given: Vec<&str> = DROP_COLUMNS
            .iter()
            .copied()
            .filter(|c| get(c).is_some())
            .collect();
        let how = match given.as_slice() {
            [] => {
                let present: Vec<&str> = DROP_COLUMNS
                    .iter()
                    .copied()
                    .filter(|c| index.contains_key(c))
                    .collect();
                return Err(cell_err(
                    present[0],
                    format!(
                        "empty: say how the drop was dropped ({})",
                        present.join(" or ")
                    ),
                ));
            }
            [c] => match *c {
                "height_m" => DropDefinition::Height(number(c, &HEIGHT)?.unwrap_or(0.0)),
                "speed_m_s" => DropDefinition::Speed(number(c, &SPEED)?.unwrap_or(0.0)),
                _ => DropDefinition::PeakForce(number(c, &ranges::BRUISE_FORCE)?.unwrap_or(0.0)),
            },
            [a, b, ..] => {
                return Err(cell_err(
                    b,
                    format!("both {a} and {b} given: say how the drop was dropped one way"),
                ))
            }
        };
        let surface = get("surface")
            .ok_or_else(|| cell_err("surface", "empty: name the surface struck".into()))?;
        if lab.surface(surface).is_none() {
            return Err(cell_err(
                "surface",
                format!(
                    "unknown surface '{surface}': name a surface or material of the lab file ({})",
                    lab.surface_names()
                ),
            ));
        }
        let diameter_m = required("diameter_m", &ranges::DIAMETER, "apple's diameter (m)")?;
        let mass_kg = required("mass_kg", &ranges::MASS, "apple's mass (kg)")?;
        // The bruise: one of a volume, a cap, yes/no.
        let volume = number("volume_mm3", &ranges::BRUISE_SIZE_LIMIT)?;
        let cap_d = number("diameter_mm", &ranges::BRUISE_SIZE_LIMIT)?;
        let cap_h = number("depth_mm", &ranges::BRUISE_SIZE_LIMIT)?;
        let yes_no = match get("bruised") {
            None => None,
            Some(s) => Some(match s.to_ascii_lowercase().as_str() {
                "yes" | "1" | "true" => true,
                "no" | "0" | "false" => false,
                _ => {
                    return Err(cell_err(
                        "bruised",
                        format!("'{s}' is not yes/no (yes, no, 1, 0, true, false)"),
                    ))
                }
            }),
        };
        let cap = match (cap_d, cap_h) {
            (None, None) => None,
            (Some(_), None) => {
                return Err(cell_err(
                    "depth_mm",
                    "empty: a bruise's diameter_mm needs its depth_mm (0 0 for no bruise)".into(),
                ))
            }
            (None, Some(_)) => {
                return Err(cell_err(
                    "diameter_mm",
                    "empty: a bruise's depth_mm needs its diameter_mm (0 0 for no bruise)".into(),
                ))
            }
            (Some(d), Some(h)) => {
                if (d == 0.0) != (h == 0.0) {
                    return Err(cell_err(
                        if d == 0.0 { "diameter_mm" } else { "depth_mm" },
                        format!(
                            "diameter {d} mm with depth {h} mm: a bruise has both or neither (0 0 for no bruise)"
                        ),
                    ));
                }
                Some((d, h))
            }
        };
        let mut bruise_columns: Vec<&str> = Vec::new();
        if volume.is_some() {
            bruise_columns.push("volume_mm3");
        }
        if cap.is_some() {
            bruise_columns.push("diameter_mm");
        }
        if yes_no.is_some() {
            bruise_columns.push("bruised");
        }
        let (measured, given_as) = match (volume, cap, yes_no) {
            (Some(v), None, None) => (Measured::Volume(v), BruiseAs::Volume),
            (None, Some((d, h)), None) => (
                Measured::Volume(cap_volume(d, h)),
                BruiseAs::Cap {
                    diameter_mm: d,
                    depth_mm: h,
                },
            ),
            (None, None, Some(b)) => (Measured::Bruised(b), BruiseAs::YesNo),
            (None, None, None) => {
                let first = ["volume_mm3", "diameter_mm", "bruised"]
                    .into_iter()
                    .find(|c| index.contains_key(c))
                    .unwrap_or("volume_mm3");
                return Err(cell_err(
                    first,
                    "empty: give the drop's bruise (a volume of 0, or bruised no, for none)".into(),
                ));
            }
            _ => {
                return Err(cell_err(
                    bruise_columns[1],
                    format!(
                        "the bruise is given twice ({}): give it one way",
                        bruise_columns.join(" and ")
                    ),
                ))
            }
        };
        let is_volume = matches!(measured, Measured::Volume(_));
        match kind {
            None => kind = Some((row, is_volume)),
            Some((first, v)) if v != is_volume => {
                return Err(cell_err(
                    bruise_columns[0],
                    format!(
                        "row {first} gives {} and this row {}: give every drop's bruise the same way (a volume of 0 for a drop without a bruise)",
                        if v { "a volume" } else { "bruised yes/no" },
                        if is_volume { "a volume" } else { "bruised yes/no" },
                    ),
                ))
            }
            _ => {}
        }
        drops.push(Drop {
            row,
            id: get("id").map(String::from),
            how,
            surface: surface.to_string(),
            diameter_m,
            mass_kg,
            measured,
            given_as,
        });
    }
    if drops.is_empty() {
        return Err(file_err("no drops: the file has a header only".into()));
    }
    Ok(Drops {
        file: file.to_string(),
        drops,
    })
}

/// Fall heights (m): a fall from 500 m would touch at 99 m/s, the simulator's speed limit.
const HEIGHT: Range = Range {
    quantity: "drop height",
    symbol: "h",
    unit: "m",
    min: 0.0,
    min_open: true,
    max: 500.0,
    max_open: false,
    fields: "`height_m`",
    hint: "",
};

/// Impact speeds (m/s): as an apple's in a scenario, but above 0.
const SPEED: Range = Range {
    quantity: "impact speed",
    symbol: "v",
    unit: "m/s",
    min: 0.0,
    min_open: true,
    max: 100.0,
    max_open: false,
    fields: "`speed_m_s`",
    hint: "",
};

/// What the simulation says one drop did to the apple.
#[derive(Debug, Clone, PartialEq)]
pub struct DropHit {
    /// Impact speed simulated (m/s).
    pub speed_m_s: f64,
    /// The apple's hit, as a run takes it ([`hit_of`]).
    pub hit: Hit,
    /// The impact's whole loss (J; the apple's share is `hit.absorbed_energy_j`).
    pub contact_absorbed_energy_j: f64,
    /// Restitution, when the apple lifted off.
    pub restitution: Option<f64>,
    /// Time step (s).
    pub time_step_s: f64,
    /// What the pad of a padded surface went through, if it reached the end of the thin-layer
    /// law or bottomed out (docs/physics.md section 13).
    pub pad_warnings: Vec<String>,
}

/// Simulates the apple striking the flat of `imp` at `v0` (m/s) with `steps_per_impact` steps
/// per elastic contact time on the flat's own material, until its impact is over (at lift-off,
/// or when the overlap turns back: the apple stays on the flat), and takes its hit.
pub fn simulate_drop(
    imp: &OneImpact,
    v0: f64,
    steps_per_impact: f64,
) -> Result<DropHit, CalibrateError> {
    let bad = |field: &str, message: String| CalibrateError::Input {
        field: field.into(),
        message,
    };
    if !(v0.is_finite() && v0 > 0.0) {
        return Err(bad(
            "speed_m_s",
            format!("{v0} must be a finite number > 0"),
        ));
    }
    if !(steps_per_impact.is_finite() && steps_per_impact >= 10.0) {
        return Err(bad(
            "--steps-per-impact",
            format!("{steps_per_impact}: give at least 10"),
        ));
    }
    let t_h = imp.elastic(&imp.surface_material, v0)?.contact_time_s;
    let t_soft = match &imp.padding {
        Some(p) => t_h.max(imp.elastic(&p.material, v0)?.contact_time_s),
        None => t_h,
    };
    let dt = t_h / steps_per_impact;
    // The impact is over long before: a damped, padded landing takes a few contact times.
    let max_steps = (40.0 * t_soft / dt).ceil() as u64;
    let sc = imp.scenario(v0, dt, (max_steps + 2) as f64 * dt);
    let found = step_until(&sc, dt, max_steps, |w, taken, _| {
        let e = match w.layer.finished_events().first() {
            Some(e) => e.clone(),
            None => w.layer.open_events_after_impact().into_iter().next()?,
        };
        let pulse = e.impact?;
        Some((e, pulse, taken, w.layer.take_pad_warnings()))
    })?;
    let Some((e, pulse, taken, pad_warnings)) = found else {
        return Err(bad(
            "speed_m_s",
            format!(
                "the impact at {v0} m/s was not over after {} s (40 elastic contact times)",
                human(max_steps as f64 * dt, 4, 6)
            ),
        ));
    };
    Ok(DropHit {
        speed_m_s: v0,
        hit: hit_of(&pulse, true).0,
        contact_absorbed_energy_j: pulse.absorbed_energy_j,
        restitution: e.restitution,
        time_step_s: taken,
        pad_warnings,
    })
}

/// The impact speed at which the simulated drop of `imp` peaks at `force_n`, by bisection in
/// ln v0 (the peak force rises with the speed) from a bracket about the elastic Hertz estimate,
/// to 1e-9 of the speed; with the drop at that speed and the number of drops simulated.
pub fn speed_for_force(
    imp: &OneImpact,
    force_n: f64,
    steps_per_impact: f64,
) -> Result<(DropHit, usize), CalibrateError> {
    let mut runs = 0usize;
    let mut sim = |v: f64| {
        runs += 1;
        simulate_drop(imp, v, steps_per_impact)
    };
    // Elastic Hertz: F ~ v^(6/5).
    let f1 = imp.elastic(&imp.surface_material, 1.0)?.peak_force_n;
    let guess = (force_n / f1).powf(5.0 / 6.0).clamp(1e-4, 50.0);
    let unreachable = |message: String| CalibrateError::Input {
        field: "peak_force_n".into(),
        message,
    };
    let first = sim(guess)?;
    let (mut lo, mut hi) = if first.hit.peak_force_n < force_n {
        let mut lo = first;
        loop {
            let v = 2.0 * lo.speed_m_s;
            if v > 100.0 {
                return Err(unreachable(format!(
                    "{force_n} N is not reached below 100 m/s (at {} m/s: {} N)",
                    human(lo.speed_m_s, 4, 3),
                    human(lo.hit.peak_force_n, 4, 1)
                )));
            }
            let h = sim(v)?;
            if h.hit.peak_force_n >= force_n {
                break (lo, h);
            }
            lo = h;
        }
    } else {
        let mut hi = first;
        loop {
            let v = 0.5 * hi.speed_m_s;
            if v < 1e-5 {
                return Err(unreachable(format!(
                    "{force_n} N is exceeded even at {} m/s",
                    human(hi.speed_m_s, 4, 6)
                )));
            }
            let h = sim(v)?;
            if h.hit.peak_force_n < force_n {
                break (h, hi);
            }
            hi = h;
        }
    };
    while hi.speed_m_s / lo.speed_m_s - 1.0 > 1e-9 {
        let h = sim((lo.speed_m_s * hi.speed_m_s).sqrt())?;
        if h.hit.peak_force_n < force_n {
            lo = h;
        } else {
            hi = h;
        }
    }
    let best = if (hi.hit.peak_force_n - force_n).abs() < (force_n - lo.hit.peak_force_n).abs() {
        hi
    } else {
        lo
    };
    Ok((best, runs))
}

/// The options of a calibration.
#[derive(Debug, Clone, PartialEq)]
pub struct Options {
    /// The model to fit.
    pub model: DamageModelName,
    /// The apple's material (a key of the lab file's materials).
    pub apple_material: String,
    /// Time steps per elastic contact time.
    pub steps_per_impact: f64,
    /// The fit's options (the pressure-area model's depth ratio).
    pub fit: FitOptions,
    /// The preset the written entry names (`--preset`): yes/no data fit the energy model's
    /// threshold only and take BS from it.
    pub preset: Option<String>,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            model: DamageModelName::Energy,
            apple_material: "apple".into(),
            steps_per_impact: DEFAULT_STEPS_PER_DROP,
            fit: FitOptions::default(),
            preset: None,
        }
    }
}

/// One drop, simulated.
#[derive(Debug, Clone, PartialEq)]
pub struct SimulatedDrop {
    /// The drop as given.
    pub drop: Drop,
    /// What the simulation says it did.
    pub sim: DropHit,
    /// Drops simulated for it (more than one when given by its peak force).
    pub simulations: usize,
}

/// A calibration: the drops simulated, the fit, and the damage entry to write.
#[derive(Debug, Clone, PartialEq)]
pub struct BruiseCalibration {
    /// The drops file.
    pub drops_file: String,
    /// The lab file.
    pub lab_file: String,
    /// The apple's material.
    pub apple_material: String,
    /// Each drop, in the file's order.
    pub drops: Vec<SimulatedDrop>,
    /// The fit.
    pub fit: Fit,
    /// The damage entry to write: the fit's model and coefficients, `preset` when needed,
    /// `source` saying where they come from.
    pub spec: DamageSpec,
    /// Notes on the fit (what yes/no data cannot say, where BS comes from, what the data
    /// leave undetermined); in the written entry's `source` too.
    pub notes: Vec<String>,
    /// What the simulations warned of (a pad at the end of its law or bottomed out), per row.
    pub warnings: Vec<String>,
}

/// Simulates every drop and fits `opts.model` to the bruises.
pub fn calibrate_bruise(
    lab: &LabSetup,
    lab_file: &str,
    drops: &Drops,
    opts: &Options,
) -> Result<BruiseCalibration, DropsError> {
    let option = |option: &str, message: String| DropsError::Option {
        option: option.into(),
        message,
    };
    if !lab.materials.contains_key(&opts.apple_material) {
        return Err(option(
            "--apple-material",
            format!(
                "no material '{}' in {lab_file} (defined: {})",
                opts.apple_material,
                lab.material_names()
            ),
        ));
    }
    let volumes = drops.volumes();
    // Yes/no data fit the energy model's threshold only: BS comes from a preset.
    let preset = match &opts.preset {
        Some(p) => Some(
            spec::damage_preset(p)
                .ok_or_else(|| {
                    let names: Vec<&str> = spec::DAMAGE_PRESETS.iter().map(|p| p.name).collect();
                    option(
                        "--preset",
                        format!("unknown damage preset '{p}': one of {}", names.join(", ")),
                    )
                })?
                .name,
        ),
        None => None,
    };
    let mut notes = Vec::new();
    let base_preset = if opts.model == DamageModelName::Energy && !volumes {
        let p = preset.unwrap_or(spec::DEFAULT_PRESET);
        let pr = spec::damage_preset(p).expect("a preset of the table");
        let Some(bs) = pr
            .bruise_susceptibility_mm3_j
            .filter(|_| pr.model == opts.model)
        else {
            return Err(option(
                "--preset",
                format!(
                    "'{p}' is a {} preset: yes/no data fit the energy model's threshold only and take BS from an energy preset; name one",
                    pr.model.as_str()
                ),
            ));
        };
        notes.push(format!(
            "bruised yes/no data give the onset only: E_th is fitted, BS is the preset '{p}''s {} mm^3/J",
            human(bs.value, 6, 0)
        ));
        Some(p.to_string())
    } else {
        if !volumes {
            notes.push("bruised yes/no data give the onset only".into());
        }
        preset.map(String::from)
    };

    let mut out = Vec::with_capacity(drops.drops.len());
    for d in &drops.drops {
        let sim_err = |source: CalibrateError| match source {
            CalibrateError::Scenario(e) => DropsError::Lab {
                file: lab_file.to_string(),
                source: Box::new(e),
            },
            source => DropsError::Simulation {
                file: drops.file.clone(),
                row: d.row,
                source: Box::new(source),
            },
        };
        let surface = lab.surface(&d.surface).ok_or_else(|| DropsError::Cell {
            file: drops.file.clone(),
            row: d.row,
            column: "surface".into(),
            message: format!("unknown surface '{}'", d.surface),
        })?;
        let mut materials = lab.materials.clone();
        // Damage entries are analysis: the impact does not read them.
        for m in materials.values_mut() {
            m.damage = None;
        }
        let imp = OneImpact {
            materials,
            contact: lab.contact,
            pairs: lab.pairs.clone(),
            apple_material: opts.apple_material.clone(),
            surface_name: d.surface.clone(),
            surface_material: surface.material,
            padding: surface.padding,
            diameter_m: d.diameter_m,
            mass_kg: d.mass_kg,
            gravity_m_s2: STANDARD_GRAVITY_M_S2,
        };
        let (sim, simulations) = match d.how {
            DropDefinition::Height(h) => (
                simulate_drop(
                    &imp,
                    (2.0 * STANDARD_GRAVITY_M_S2 * h).sqrt(),
                    opts.steps_per_impact,
                )
                .map_err(sim_err)?,
                1,
            ),
            DropDefinition::Speed(v) => (
                simulate_drop(&imp, v, opts.steps_per_impact).map_err(sim_err)?,
                1,
            ),
            DropDefinition::PeakForce(f) => {
                speed_for_force(&imp, f, opts.steps_per_impact).map_err(sim_err)?
            }
        };
        out.push(SimulatedDrop {
            drop: d.clone(),
            sim,
            simulations,
        });
    }
    let warnings = out
        .iter()
        .flat_map(|d| {
            d.sim
                .pad_warnings
                .iter()
                .map(move |w| format!("row {}: {w}", d.drop.row))
        })
        .collect();
    let hits: Vec<Hit> = out.iter().map(|d| d.sim.hit).collect();
    let measured: Vec<Measured> = out.iter().map(|d| d.drop.measured).collect();
    let mut f =
        fit::fit(opts.model, &hits, &measured, opts.fit).map_err(|source| DropsError::Fit {
            file: drops.file.clone(),
            model: opts.model.as_str(),
            source,
        })?;
    if opts.model == DamageModelName::PeakForce && volumes {
        notes.push(
            "the peak-force model is an onset: fitted to whether each volume is above 0".into(),
        );
    }
    f.spec.preset = base_preset;
    notes.extend(f.notes.iter().cloned());
    let mut cal = BruiseCalibration {
        drops_file: drops.file.clone(),
        lab_file: lab_file.to_string(),
        apple_material: opts.apple_material.clone(),
        drops: out,
        spec: f.spec.clone(),
        fit: f,
        notes,
        warnings,
    };
    cal.spec.source = Some(cal.source_text());
    spec::validate(&cal.spec, "the fitted damage entry").map_err(|e| DropsError::File {
        file: drops.file.clone(),
        message: format!("the fitted coefficients are refused: {e}"),
    })?;
    Ok(cal)
}

/// A coefficient with its standard error, as printed (`5000.0 +- 1.2 mm^3/J`).
fn show_coefficient(c: &fit::Coefficient) -> String {
    let unit = if c.unit.is_empty() {
        String::new()
    } else {
        format!(" {}", c.unit)
    };
    match c.std_error {
        Some(se) => format!(
            "{} = {} +- {}{unit}",
            c.symbol,
            human(c.value, 6, 0),
            human(se, 3, 0)
        ),
        None => format!("{} = {}{unit}", c.symbol, human(c.value, 6, 0)),
    }
}

impl BruiseCalibration {
    /// What the data were (`volumes`, `bruised yes/no`).
    fn data_kind(&self) -> &'static str {
        match self.fit.drops.first().map(|d| d.measured) {
            Some(Measured::Volume(_)) => "volumes",
            _ => "bruised yes/no",
        }
    }

    /// The fit's method in words.
    pub fn method_text(&self) -> String {
        match self.fit.method {
            Method::LeastSquares => "least squares on the bruise volumes; standard errors sqrt(diag(s^2 (J^T J)^-1)) of the fit's Jacobian J, s^2 = SSR / (n - p)".into(),
            Method::Separating { below, above } => {
                let c = &self.fit.coefficients[0];
                format!(
                    "the data separate: no bruise up to {}, bruises from {} {}; the threshold is the midpoint (the data bound it to that interval, no standard error)",
                    human(below, 6, 0),
                    human(above, 6, 0),
                    c.unit
                )
            }
            Method::Logistic { width } => format!(
                "the yes/no data overlap: maximum likelihood of a logistic onset P = 1 / (1 + exp(-(x - x50) / w)), w = {} {}; the threshold is x50, its standard error from the inverse Fisher information",
                human(width, 4, 0),
                self.fit.coefficients[0].unit
            ),
        }
    }

    /// The fitted coefficients, as printed, joined by `, `.
    pub fn coefficients_text(&self) -> String {
        self.fit
            .coefficients
            .iter()
            .map(show_coefficient)
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// The fit's residuals in words: the RMS of volume residuals, or the drops misclassified.
    pub fn residual_text(&self) -> String {
        let n = self.fit.drops.len();
        match self.fit.residual_rms_mm3 {
            Some(rms) => format!(
                "residual RMS {} mm^3 over {n} drops ({} degree{} of freedom), {} misclassified (bruised or not)",
                human(rms, 4, 1),
                self.fit.dof,
                if self.fit.dof == 1 { "" } else { "s" },
                self.fit.misclassified
            ),
            None => format!(
                "{} of {n} drops misclassified (bruised or not)",
                self.fit.misclassified
            ),
        }
    }

    /// The `source` of the written entry: the data, the fit, its residuals and the
    /// coefficients' uncertainty.
    pub fn source_text(&self) -> String {
        let mut s = format!(
            "applesim calibrate-bruise: {} ({} drops, {}), lab file {}, apple material '{}'; {} model: {} ({}); {}",
            self.drops_file,
            self.drops.len(),
            self.data_kind(),
            self.lab_file,
            self.apple_material,
            self.fit.model.as_str(),
            self.coefficients_text(),
            self.method_text(),
            self.residual_text()
        );
        for n in &self.notes {
            s.push_str("; ");
            s.push_str(n);
        }
        s
    }

    /// The onset variable's column heading for the drops table.
    fn x_heading(&self) -> &'static str {
        match self.fit.model {
            DamageModelName::Energy => "E_abs_j",
            DamageModelName::PressureArea => "p0_mpa",
            DamageModelName::PeakForce => "F_n",
        }
    }

    /// The drops table: one row per drop with what the simulation gave and what the fit says
    /// of it. Plain text, aligned (`markdown` false), or a Markdown table.
    pub fn drops_table(&self, markdown: bool) -> String {
        let head = [
            "row",
            "id",
            "surface",
            "drop",
            "v0_m_s",
            "E_abs_j",
            "F_n",
            "p0_mpa",
            "a_mm",
            "delta_mm",
            "measured",
            "predicted",
            "residual",
        ];
        let mut rows: Vec<Vec<String>> = Vec::new();
        for (d, f) in self.drops.iter().zip(&self.fit.drops) {
            let h = &d.sim.hit;
            let measured = match (f.measured, d.drop.given_as) {
                (
                    Measured::Volume(v),
                    BruiseAs::Cap {
                        diameter_mm,
                        depth_mm,
                    },
                ) => format!(
                    "{v:.1} ({} x {} mm)",
                    human(diameter_mm, 4, 1),
                    human(depth_mm, 4, 1)
                ),
                (Measured::Volume(v), _) => format!("{v:.1}"),
                (Measured::Bruised(b), _) => if b { "yes" } else { "no" }.into(),
            };
            let predicted = match (f.predicted_volume_mm3, f.probability) {
                (Some(v), _) => format!("{v:.1}"),
                (None, Some(p)) => format!(
                    "{} (P {:.3})",
                    if f.predicted_bruised { "yes" } else { "no" },
                    p
                ),
                (None, None) => if f.predicted_bruised { "yes" } else { "no" }.into(),
            };
            let residual = match f.residual_mm3 {
                Some(r) => format!("{r:+.1}"),
                None => {
                    if f.predicted_bruised == f.measured.bruised() {
                        "ok".into()
                    } else {
                        "wrong".into()
                    }
                }
            };
            rows.push(vec![
                d.drop.row.to_string(),
                d.drop.id.clone().unwrap_or_else(|| "-".into()),
                d.drop.surface.clone(),
                d.drop.how.describe(),
                format!("{:.4}", d.sim.speed_m_s),
                format!("{:.5}", h.absorbed_energy_j),
                format!("{:.2}", h.peak_force_n),
                format!("{:.4}", h.peak_pressure_pa * 1e-6),
                format!("{:.3}", h.contact_radius_m * 1e3),
                format!("{:.3}", h.indentation_m * 1e3),
                measured,
                predicted,
                residual,
            ]);
        }
        if markdown {
            let mut s = format!("| {} |\n", head.join(" | "));
            s.push_str(&format!("|{}\n", "---|".repeat(head.len())));
            for r in &rows {
                s.push_str(&format!("| {} |\n", r.join(" | ")));
            }
            s
        } else {
            let mut w: Vec<usize> = head.iter().map(|h| h.len()).collect();
            for r in &rows {
                for (k, c) in r.iter().enumerate() {
                    w[k] = w[k].max(c.chars().count());
                }
            }
            let line = |cells: Vec<String>| -> String {
                cells
                    .iter()
                    .enumerate()
                    .map(|(k, c)| format!("{c:>width$}", width = w[k]))
                    .collect::<Vec<_>>()
                    .join("  ")
                    .trim_end()
                    .to_string()
            };
            let mut s = line(head.iter().map(|h| h.to_string()).collect());
            s.push('\n');
            for r in rows {
                s.push_str(&line(r));
                s.push('\n');
            }
            s
        }
    }

    /// The report as plain text (what the command prints).
    pub fn report_text(&self) -> String {
        let mut s = format!(
            "{} drops of {} simulated (apple material '{}' of {}, gravity {} m/s^2)\n\n",
            self.drops.len(),
            self.drops_file,
            self.apple_material,
            self.lab_file,
            STANDARD_GRAVITY_M_S2
        );
        s.push_str(&self.drops_table(false));
        s.push_str(&format!(
            "\n(the {} column is the model's variable; v0 the impact speed simulated)\n",
            self.x_heading()
        ));
        s.push_str(&format!(
            "\n{} model: {}\nmethod: {}\n{}\n",
            self.fit.model.as_str(),
            self.coefficients_text(),
            self.method_text(),
            self.residual_text()
        ));
        for n in &self.notes {
            s.push_str(&format!("note: {n}\n"));
        }
        for w in &self.warnings {
            s.push_str(&format!("warning: {w}\n"));
        }
        s
    }

    /// The report as Markdown (the `.report.md` file beside the preset).
    pub fn report_markdown(&self, preset_file: &str) -> String {
        let mut s = format!(
            "# Bruise calibration: {}\n\nWritten by `applesim calibrate-bruise` (docs/damage.md section 8). The preset is `{preset_file}`; a scenario names it as `\"damage\": {{\"file\": \"{preset_file}\"}}`.\n\n",
            self.drops_file
        );
        s.push_str(&format!(
            "- Drops: {} ({}), from `{}`\n- Lab file: `{}`, apple material `{}`; gravity {} m/s^2; each drop simulated from touch at its impact speed (sqrt(2 g h) for a height; the speed giving the measured peak force, by bisection, for a force)\n- Model: {}\n- Coefficients: {}\n- Method: {}\n- Residuals: {}\n",
            self.drops.len(),
            self.data_kind(),
            self.drops_file,
            self.lab_file,
            self.apple_material,
            STANDARD_GRAVITY_M_S2,
            self.fit.model.as_str(),
            self.coefficients_text(),
            self.method_text(),
            self.residual_text()
        ));
        for n in &self.notes {
            s.push_str(&format!("- Note: {n}\n"));
        }
        for w in &self.warnings {
            s.push_str(&format!("- Warning: {w}\n"));
        }
        s.push_str("\n## Drops\n\nv0: the impact speed simulated (m/s); E_abs: the energy the apple absorbed (its share of the impact's loss, J); F: peak force (N); p0: peak centre pressure (MPa); a: contact radius (mm); delta: the apple's deformation (mm); volumes in mm^3.\n\n");
        s.push_str(&self.drops_table(true));
        s.push_str("\nThe standard errors measure the scatter of the measured bruises about the model. They do not include the uncertainty of what each drop's simulation was given (the apple's modulus, the restitution, the mass): change those in the lab file and refit to see how far the coefficients move.\n");
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lab() -> LabSetup {
        LabSetup::from_json(
            r#"{"materials": {"apple": {"preset": "apple-paper"}, "steel": {"preset": "steel"},
                "foam": {"youngs_modulus_pa": 1e6, "poisson_ratio": 0.3}},
               "contact": {"friction": 0.3, "ke": 0.25, "lambda_s_m": 1000},
               "surfaces": {"padded": {"material": "steel", "padding": {"material": "foam", "thickness_m": 0.01}}}}"#,
            "lab.json",
        )
        .unwrap()
    }

    fn err(text: &str) -> String {
        parse_drops(text, "drops.csv", &lab())
            .unwrap_err()
            .to_string()
    }

    #[test]
    fn reads_every_way_of_giving_a_drop_and_its_bruise() {
        let d = parse_drops(
            "id,height_m,speed_m_s,peak_force_n,surface,diameter_m,mass_kg,volume_mm3,diameter_mm,depth_mm\n\
             # a comment\n\
             a,0.1,,,steel,0.08,0.2,120,,\n\
             b,,1.5,,foam,0.08,0.2,,10,3\n\
             # another\n\
             c,,,57,padded,0.08,0.2,0,,\n",
            "drops.csv",
            &lab(),
        )
        .unwrap();
        assert_eq!(d.drops.len(), 3);
        assert_eq!(d.drops[0].row, 3);
        assert_eq!(d.drops[2].row, 6);
        assert_eq!(d.drops[0].how, DropDefinition::Height(0.1));
        assert_eq!(d.drops[1].how, DropDefinition::Speed(1.5));
        assert_eq!(d.drops[2].how, DropDefinition::PeakForce(57.0));
        assert_eq!(d.drops[1].measured, Measured::Volume(cap_volume(10.0, 3.0)));
        assert!(d.volumes());
        let d = parse_drops(
            "height_m,surface,diameter_m,mass_kg,bruised\n0.1,steel,0.08,0.2,Yes\n0.05,steel,0.08,0.2,0\n",
            "drops.csv",
            &lab(),
        )
        .unwrap();
        assert_eq!(d.drops[0].measured, Measured::Bruised(true));
        assert_eq!(d.drops[1].measured, Measured::Bruised(false));
        assert!(!d.volumes());
    }

    #[test]
    fn refusals_name_the_file_row_and_column() {
        let head = "height_m,surface,diameter_m,mass_kg,volume_mm3\n";
        for (body, want) in [
            (
                "height_m,surface,diameter_m,mass_kg,volume\n0.1,steel,0.08,0.2,1\n",
                "drops.csv, row 1, column volume: unknown column 'volume'",
            ),
            (
                &*format!("{head}0.1,steel,0.08,,1\n"),
                "drops.csv, row 2, column mass_kg: empty",
            ),
            (
                &*format!("{head}0.1,steel,0.08,0.2,1\n0.1,wood,0.08,0.2,1\n"),
                "drops.csv, row 3, column surface: unknown surface 'wood'",
            ),
            (
                &*format!("{head}0.1,steel,0.08,0.2,x\n"),
                "drops.csv, row 2, column volume_mm3: 'x' is not a number",
            ),
            (
                &*format!("{head}-0.1,steel,0.08,0.2,1\n"),
                "drops.csv, row 2, column height_m: -0.1 is out of range",
            ),
            (
                &*format!("{head}0.1,steel,0.08,0.2\n"),
                "drops.csv, row 2: 4 fields where the header has 5",
            ),
            (
                "height_m,speed_m_s,surface,diameter_m,mass_kg,volume_mm3\n0.1,1.4,steel,0.08,0.2,1\n",
                "drops.csv, row 2, column speed_m_s: both height_m and speed_m_s given",
            ),
            (
                "height_m,surface,diameter_m,mass_kg,volume_mm3,bruised\n0.1,steel,0.08,0.2,1,\n0.2,steel,0.08,0.2,,yes\n",
                "drops.csv, row 3, column bruised: row 2 gives a volume and this row bruised yes/no",
            ),
            (
                "height_m,surface,diameter_m,mass_kg,bruised\n0.1,steel,0.08,0.2,maybe\n",
                "drops.csv, row 2, column bruised: 'maybe' is not yes/no",
            ),
            (
                "height_m,surface,diameter_m,mass_kg,diameter_mm,depth_mm\n0.1,steel,0.08,0.2,10,\n",
                "drops.csv, row 2, column depth_mm: empty",
            ),
            (
                "height_m,height_m,surface,diameter_m,mass_kg,volume_mm3\n",
                "drops.csv, row 1, column height_m: column 'height_m' is given twice",
            ),
            (head, "drops.csv: no drops"),
            (
                "surface,diameter_m,mass_kg,volume_mm3\nsteel,0.08,0.2,1\n",
                "drops.csv: no column height_m, speed_m_s or peak_force_n",
            ),
        ] {
            let e = err(body);
            assert!(e.starts_with(want), "{e}\nwanted: {want}");
        }
    }
}
