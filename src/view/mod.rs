//! The browser viewer of a run: one self-contained HTML file (`applesim view RUN_DIR`,
//! `applesim run ... --view`) that opens offline by double-click.
//!
//! The viewer reads a finished run folder from disk, not a run in memory, so that any run
//! folder can be viewed, however old and however it was made (a batch run, a copy from a
//! cluster). What it reads:
//! - `summary.json` (required: it is what makes a folder a run; the run's end time, the final
//!   positions when no body was sampled);
//! - `bodies.csv` (required: the apples' positions, speeds and contact state, decimated to
//!   [`ViewOptions::max_frames`] frames and quantised, see below);
//! - `contacts.csv` (required: every contact's surface or apple, times, peak force, pressure and
//!   point);
//! - `scenario.json` (required: the surfaces, re-built as in the run and tessellated as the
//!   ParaView output draws them);
//! - `apple_contacts.csv`, `transitions.csv` (optional: which contacts bruised an apple, and
//!   when apples slide, roll or fly; without them the page says what it falls back to).
//! - `rollers.csv` (optional: the free-turning rollers' angles per sample, to draw them turning;
//!   a run from before it was written draws them without their turn, and says so).
//!
//! The page embeds three.js (vendored in `assets/three/`, MIT) and the hand-written template
//! `assets/view/view.html`. The run's data goes in as JSON with the bulky arrays base64-encoded:
//! apple centres as u16 per axis over the box of all sampled centres (step = box size / 65535
//! per axis, written on the page), speeds as u16 over [0, largest speed], motion states as u8;
//! in a run with spheroids (`bodies.csv`'s shape columns, issue 29) each apple's height and its
//! orientation per frame, the unit quaternion's x y z w as i16 over [-1, 1] (step 1/32767: the
//! drawn turn within 1e-4 rad), which the page draws as ellipsoids. A run of spheres embeds
//! neither, so its page holds the data it held before.
//!
//! Everything is checked before anything is written: a folder that is not a run, a missing file,
//! a truncated or malformed CSV is a [`ViewError`] naming the file, and no HTML is written
//! (the file itself is written whole or not at all, [`crate::output::atomic`]). The same run
//! folder and options give the same bytes.

use crate::math::Vec3;
use crate::output::atomic;
use crate::output::vtk::SceneSurfaces;
use crate::scenario::surfaces::{rotation_of, SurfaceSpec};
use crate::scenario::Scenario;
use serde::Serialize;
use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

mod read;
mod scene;

use read::*;
pub use read::{CURVE_POINTS, MAX_CURVES};
use scene::*;

/// three.js core (r185, MIT; `assets/three/LICENSE`).
const THREE_CORE: &str = include_str!("../../assets/three/three.core.min.js");
/// three.js renderer module (r185), importing the core.
const THREE_MODULE: &str = include_str!("../../assets/three/three.module.min.js");
/// three.js OrbitControls add-on (r185), importing `three`.
const ORBIT_CONTROLS: &str = include_str!("../../assets/three/OrbitControls.js");
/// three.js licence, carried inside every page.
const THREE_LICENSE: &str = include_str!("../../assets/three/LICENSE");
/// The page template; `/*@DATA@*/`, `/*@THREE_CORE@*/`, ... are replaced.
const TEMPLATE: &str = include_str!("../../assets/view/view.html");

/// Default frame budget: enough for smooth playback (frames are interpolated) at a few MB for a
/// thousand apples.
pub const DEFAULT_MAX_FRAMES: usize = 600;

/// Motion states embedded per apple per frame.
pub mod motion {
    /// Not in the run yet (a source feeds it in later).
    pub const ABSENT: u8 = 0;
    /// No contact.
    pub const AIRBORNE: u8 = 1;
    /// A contact slides.
    pub const SLIDING: u8 = 2;
    /// In contact, nothing slides (rolling, resting, riding a belt).
    pub const ROLLING: u8 = 3;
    /// In contact; sliding or rolling unknown (no slip column, transitions off).
    pub const CONTACT: u8 = 4;
}

/// Options of [`write_view`].
#[derive(Debug, Clone)]
pub struct ViewOptions {
    /// Largest number of frames embedded (>= 2); the samples of `bodies.csv` are thinned
    /// evenly to this, keeping the first and the last.
    pub max_frames: usize,
    /// Folder that the scenario's mesh `file` paths resolve against (the scenario's folder);
    /// default the run folder.
    pub asset_dir: Option<PathBuf>,
    /// The run's name on the page; default the folder's path. (`applesim run --view` writes
    /// the page while the run's folder still has its temporary name.)
    pub label: Option<String>,
}

impl Default for ViewOptions {
    fn default() -> Self {
        Self {
            max_frames: DEFAULT_MAX_FRAMES,
            asset_dir: None,
            label: None,
        }
    }
}

/// Errors of the viewer. Each names the file at fault; nothing is written when one occurs.
#[derive(Debug, thiserror::Error)]
pub enum ViewError {
    /// The folder is not a run folder.
    #[error("{path}: not a run folder ({reason})")]
    NotARun {
        /// The folder.
        path: PathBuf,
        /// Why.
        reason: String,
    },
    /// A file a view needs is missing.
    #[error("{path}: missing: {why}")]
    Missing {
        /// The file.
        path: PathBuf,
        /// What it is needed for.
        why: &'static str,
    },
    /// A file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// OS error.
        source: std::io::Error,
    },
    /// A file's content is malformed or truncated.
    #[error("{path}: {message}")]
    Bad {
        /// The file.
        path: PathBuf,
        /// What is wrong, with the line where it is known.
        message: String,
    },
    /// A bad option.
    #[error("{0}")]
    Option(String),
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> ViewError + '_ {
    move |source| ViewError::Io {
        path: path.to_path_buf(),
        source,
    }
}

fn bad(path: &Path, message: impl Into<String>) -> ViewError {
    ViewError::Bad {
        path: path.to_path_buf(),
        message: message.into(),
    }
}

/// What was written, for the command's report and the tests.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ViewStats {
    /// Apples in the scene.
    pub apples: usize,
    /// Surface parts drawn (a bin counts its floor and four walls).
    pub surfaces: usize,
    /// Samples in `bodies.csv`.
    pub samples: usize,
    /// Frames embedded.
    pub frames: usize,
    /// Contacts listed.
    pub contacts: usize,
    /// Size of the page (bytes).
    pub bytes: usize,
    /// Position quantisation step per axis (m).
    pub position_step_m: [f64; 3],
    /// What the page says is missing or approximated.
    pub notes: Vec<String>,
}

/// Writes the viewer page of the run in `run_dir` to `out` (whole or not at all).
pub fn write_view(run_dir: &Path, out: &Path, opts: &ViewOptions) -> Result<ViewStats, ViewError> {
    let (html, stats) = build_page(run_dir, opts)?;
    if let Some(parent) = out.parent().filter(|p| !p.as_os_str().is_empty()) {
        if !parent.is_dir() {
            return Err(ViewError::Io {
                path: parent.to_path_buf(),
                source: std::io::Error::new(std::io::ErrorKind::NotFound, "no such folder"),
            });
        }
    }
    atomic::write_file(out, html.as_bytes()).map_err(io(out))?;
    Ok(stats)
}

/// The viewer page of the run in `run_dir`, and what it holds.
pub fn build_page(run_dir: &Path, opts: &ViewOptions) -> Result<(String, ViewStats), ViewError> {
    if opts.max_frames < 2 {
        return Err(ViewError::Option(format!(
            "--max-frames {}: give at least 2",
            opts.max_frames
        )));
    }
    let data = collect(run_dir, opts)?;
    let mut json = serde_json::to_string(&data.page).map_err(|e| bad(run_dir, e.to_string()))?;
    // Inside a <script> element: no `</script>` or `<!--` may appear, whatever a name holds.
    json = json.replace('<', "\\u003c");
    let html = TEMPLATE
        .replace("/*@THREE_LICENSE@*/", &THREE_LICENSE.replace("*/", "* /"))
        .replace("/*@THREE_CORE@*/", THREE_CORE)
        .replace("/*@THREE_MODULE@*/", THREE_MODULE)
        .replace("/*@ORBIT_CONTROLS@*/", ORBIT_CONTROLS)
        .replace("/*@DATA@*/", &json);
    let mut stats = data.stats;
    stats.bytes = html.len();
    Ok((html, stats))
}

/// The page's data (serialised into the page as JSON).
#[derive(Debug, Serialize)]
struct Page {
    format: u32,
    applesim_version: &'static str,
    run: RunInfo,
    notes: Vec<String>,
    /// Quantisation box of the apple centres (m).
    box_lo_m: [f64; 3],
    /// Step of the u16 positions per axis (m).
    position_step_m: [f64; 3],
    /// Step of the u16 speeds (m/s).
    speed_step_m_s: f64,
    /// Frame times (s).
    times_s: Vec<f64>,
    /// Samples in bodies.csv (the frames are a thinning of them).
    samples: usize,
    apples: Vec<AppleInfo>,
    /// Per frame, per apple, x y z as u16 little-endian, base64.
    positions_b64: String,
    /// Per frame, per apple, speed as u16 little-endian, base64.
    speeds_b64: String,
    /// Per frame, per apple, a [`motion`] state, base64.
    states_b64: String,
    /// Per frame, per apple, the contact force on it |f| (bodies.csv `fx_n`..`fz_n`) as u16
    /// little-endian over [0, largest], base64: the apple's history plot.
    forces_b64: String,
    /// A run with spheroids: per frame, per apple, its orientation (bodies.csv `qw`..`qz`, the
    /// apple's frame to the world's) as the unit quaternion's x y z w, each i16 little-endian
    /// of [`ORIENTATION_SCALE`] times it, base64. None for a run of spheres (the page draws
    /// spheres, as before spheroids).
    #[serde(skip_serializing_if = "Option::is_none")]
    orientations_b64: Option<String>,
    /// Step of the u16 forces (N).
    force_step_n: f64,
    /// Where the states come from.
    states_source: &'static str,
    surfaces: Vec<SurfaceInfo>,
    /// The moving bodies: those that carry surfaces away from where the scenario puts them (a
    /// translation or rotation `motion`) and powered rollers turning about their own axes.
    movers: Vec<MoverInfo>,
    /// The names of [`ContactInfo`]'s fields, in the order of each row of `contacts`.
    contact_fields: &'static [&'static str],
    /// The names of an apple's side of a contact (`side_a`, `side_b`), in order.
    side_fields: &'static [&'static str],
    /// One array per contact (rows rather than objects: a tenth of the size for a big run),
    /// numbers to 6 significant digits, times whole.
    contacts: Vec<serde_json::Value>,
    /// Force curves of the contacts over a bruise threshold (from forces.csv when the run kept
    /// force histories): contact row index -> [times (s), forces (N)], at most
    /// [`CURVE_POINTS`] points each, 5 significant digits.
    curves: BTreeMap<usize, [Vec<serde_json::Value>; 2]>,
    /// The transfer points (contacts.csv `transfer_point`, the audit's rows): contact rows refer
    /// to them by index.
    transfer_points: Vec<String>,
    /// The names of a bruise site row's fields, in the order of each row of `sites`.
    site_fields: &'static [&'static str],
    /// The bruises of bruises.csv (its sites that are bruised or have a volume), one array each
    /// ([`SITE_FIELDS`]).
    sites: Vec<serde_json::Value>,
    /// The grading standard and its grades (summary.json `damage`), when the run graded apples.
    #[serde(skip_serializing_if = "Option::is_none")]
    damage: Option<DamageInfo>,
    /// The line audit (audit.csv), when the run wrote it.
    #[serde(skip_serializing_if = "Option::is_none")]
    audit: Option<AuditInfo>,
    /// The bruise force threshold(s) in use (N), for the legend.
    bruise_force_n: Vec<f64>,
    /// Largest impact peak force of the run (N).
    max_peak_force_n: f64,
    /// Scene extent for the camera (apples and bounded surfaces), m.
    scene_lo_m: [f64; 3],
    /// Scene extent for the camera, m.
    scene_hi_m: [f64; 3],
    /// Gravity (m/s^2): the page's "up" is against it.
    gravity_m_s2: [f64; 3],
}

#[derive(Debug, Serialize)]
struct RunInfo {
    folder: String,
    description: Option<String>,
    simulated_time_s: f64,
    steps: u64,
}

#[derive(Debug, Serialize)]
struct AppleInfo {
    name: String,
    /// Diameter (m): a spheroid's equatorial one.
    diameter_m: f64,
    /// Height along its own z axis (m), in a run with spheroids (a sphere's: its diameter).
    #[serde(skip_serializing_if = "Option::is_none")]
    height_m: Option<f64>,
    mass_kg: f64,
    /// Its grade at the end, why not the best class, and what first put it below it
    /// (summary.json), when the run graded it.
    #[serde(skip_serializing_if = "Option::is_none")]
    grade: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    grade_why: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    downgraded_by: Option<serde_json::Value>,
    /// Its grade's rank over time: (time, rank) at each change, from rank 0 (the best class):
    /// the grade of the bruises whose first hit is at or before that time, at their sizes in
    /// bruises.csv.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    grade_steps: Vec<(f64, usize)>,
}

impl AppleInfo {
    fn new(name: &str, diameter_m: f64, mass_kg: f64) -> Self {
        Self {
            name: name.to_string(),
            diameter_m,
            height_m: None,
            mass_kg,
            grade: None,
            grade_why: None,
            downgraded_by: None,
            grade_steps: Vec::new(),
        }
    }
}

/// The grading standard of the run (summary.json `damage`).
#[derive(Debug, Serialize)]
struct DamageInfo {
    standard: String,
    /// The grades, best first, the one below every class last.
    grades: Vec<String>,
}

/// The line audit (audit.csv) as written: its columns and rows.
#[derive(Debug, Serialize)]
pub(super) struct AuditInfo {
    columns: Vec<String>,
    rows: Vec<Vec<serde_json::Value>>,
}

#[derive(Debug, Serialize)]
struct SurfaceInfo {
    name: String,
    kind: &'static str,
    material: String,
    /// Triangle vertices, f32 little-endian x y z, base64 (three per triangle, unindexed).
    triangles_b64: String,
    /// A roller: per triangle, 1 on a dark stripe and 0 on a light one, so that its turn shows.
    #[serde(skip_serializing_if = "Option::is_none")]
    stripes_b64: Option<String>,
    /// A belt: its direction of travel (world unit vector) and speed (m/s).
    #[serde(skip_serializing_if = "Option::is_none")]
    belt: Option<Belt>,
    /// The index in `movers` of the body that carries it, if it moves.
    #[serde(skip_serializing_if = "Option::is_none")]
    mover: Option<usize>,
}

/// A moving body: its origin at rest (a roller's centre, else the world's origin) and its pose
/// per frame. The page draws its parts' triangles (at their rest poses) relative to the origin
/// and moves them by the pose, interpolated between frames: the origin in a straight line, the
/// rotation about it, so that a roller turns in place between frames.
#[derive(Debug, Serialize)]
struct MoverInfo {
    /// The surface (a roller bed's roller) whose motion it is.
    name: String,
    /// The body's origin at rest (m).
    origin_m: [f64; 3],
    /// Per frame, the body's pose ([`crate::world::motion::Motion::pose`]): translation x y z
    /// (m) then rotation quaternion x y z w, f32 little-endian, base64.
    poses_b64: String,
    /// The same poses, to carry the contacts' marks.
    #[serde(skip)]
    poses: Vec<rapier3d_f64::math::Pose>,
}

#[derive(Debug, Serialize)]
struct Belt {
    direction: [f64; 3],
    speed_m_s: f64,
    /// Centre of the belt's top face (m), and its half length along the travel.
    top_centre_m: [f64; 3],
    half_length_m: f64,
}

/// The order of a contact row's fields in the page: `tp` the transfer point's index in
/// `transfer_points` (-1: none), `carrier` the moving body that carries its mark (-1: none;
/// `local_m` is then the point in that body's frame, as its parts' triangles are), `side_a`,
/// `side_b` the apples' sides from apple_contacts.csv ([`SIDE_FIELDS`], null when none),
/// `t_impact_s` the time of its impact's peak force (null without an impact): the hit's time,
/// from which its figures and its bruise count (the contact's `t_peak_s` is that of its largest
/// force, which a resting load after the impact may set later).
const CONTACT_FIELDS: [&str; 18] = [
    "a",
    "b_apple",
    "b",
    "t_start_s",
    "t_end_s",
    "t_peak_s",
    "impact_n",
    "peak_force_n",
    "max_pressure_pa",
    "point_m",
    "risk_a",
    "risk_b",
    "tp",
    "carrier",
    "local_m",
    "side_a",
    "side_b",
    "t_impact_s",
];

/// The order of an apple's side of a contact (apple_contacts.csv): the energy it absorbed (J),
/// its peak acceleration (g), velocity change (m/s), its part of its site's bruise volume (mm^3;
/// null for an onset model), the site's index (-1: none), 1 when the hit alone bruised it.
const SIDE_FIELDS: [&str; 6] = [
    "energy_j",
    "peak_g",
    "dv_m_s",
    "volume_mm3",
    "site",
    "bruised",
];

/// The order of a bruise site row's fields in the page: the apple's index, the site's index on
/// it, its first hit (s), hits, the transfer points, the energy absorbed there (J), 1 when it is
/// a bruise, volume (mm^3), area (mm^2), depth and diameter (mm), where it is in the apple's
/// frame (bruises.csv x y z), and where it is drawn: the world direction from the apple's centre
/// to its first hit's contact point at that hit's peak (the page draws apples without turning).
const SITE_FIELDS: [&str; 13] = [
    "apple",
    "site",
    "first_hit_s",
    "hits",
    "transfer_points",
    "energy_j",
    "bruised",
    "volume_mm3",
    "area_mm2",
    "depth_mm",
    "diameter_mm",
    "dir_apple",
    "dir_world",
];

/// `x` to 6 significant digits (what the page shows, at a third of the text). Times are kept
/// whole: a hit counts from its own time, which a frame's time may be within 6 digits of.
fn sig6(x: f64) -> serde_json::Value {
    let r: f64 = format!("{x:.5e}").parse().unwrap_or(x);
    serde_json::json!(r)
}

impl ContactInfo {
    fn row(&self) -> serde_json::Value {
        serde_json::json!([
            self.a,
            self.b_apple,
            self.b,
            self.t_start_s,
            self.t_end_s,
            self.t_peak_s,
            sig6(self.impact_n),
            sig6(self.peak_force_n),
            sig6(self.max_pressure_pa),
            self.point_m.map(sig6),
            self.risk_a,
            self.risk_b,
            self.tp,
            self.carrier,
            self.local_m.map(|p| p.map(sig6)),
            self.side_a.as_ref().map(side_row),
            self.side_b.as_ref().map(side_row),
            self.t_impact_s,
        ])
    }
}

/// An apple's side of a contact as a page row ([`SIDE_FIELDS`]).
fn side_row(h: &HitRow) -> serde_json::Value {
    serde_json::json!([
        sig6(h.absorbed_energy_j),
        sig6(h.peak_g),
        sig6(h.velocity_change_m_s),
        h.volume_mm3.map(sig6),
        h.site.map_or(-1, |s| s as i64),
        h.bruised as u8,
    ])
}

#[derive(Debug)]
struct ContactInfo {
    /// Apple index.
    a: u32,
    /// The other apple's index, or -1.
    b_apple: i64,
    /// The other party's name (a surface's, or the apple's).
    b: String,
    t_start_s: f64,
    /// Separation (s); `None` while still in contact at the end.
    t_end_s: Option<f64>,
    t_peak_s: f64,
    /// Peak force of the impact (N; 0 for a contact that starts at rest).
    impact_n: f64,
    /// Duration of the impact (s), if the contact had one.
    impact_duration_s: Option<f64>,
    /// Peak force of the whole contact (N).
    peak_force_n: f64,
    /// Peak mean pressure (Pa).
    max_pressure_pa: f64,
    point_m: [f64; 3],
    /// Over a bruise threshold for apple a / b ("" when not; else which thresholds).
    risk_a: String,
    risk_b: String,
    /// Index of its transfer point in the page's list (-1: none).
    tp: i64,
    /// The moving body carrying its mark (-1: none).
    carrier: i64,
    /// The point in the carrier's frame.
    local_m: Option<[f64; 3]>,
    /// Apple a's and b's sides (apple_contacts.csv).
    side_a: Option<HitRow>,
    side_b: Option<HitRow>,
    /// Time of the impact's peak force (s), the hit's time; none without an impact.
    t_impact_s: Option<f64>,
}

struct Collected {
    page: Page,
    stats: ViewStats,
}

/// summary.json, read for what the viewer needs.
#[derive(serde::Deserialize)]
struct SummaryIn {
    simulated_time_s: f64,
    #[serde(default)]
    steps: u64,
    #[serde(default)]
    description: Option<String>,
    #[serde(default)]
    apples: Vec<SummaryApple>,
    #[serde(default)]
    damage: Option<SummaryDamage>,
}

#[derive(serde::Deserialize)]
struct SummaryApple {
    name: String,
    diameter_m: f64,
    mass_kg: f64,
    final_position_m: [f64; 3],
    #[serde(default)]
    grade: Option<String>,
    #[serde(default)]
    grade_why: Option<String>,
    #[serde(default)]
    downgraded_by: Option<serde_json::Value>,
}

#[derive(serde::Deserialize)]
struct SummaryDamage {
    standard: String,
    grades: Vec<String>,
}

/// Pass 1 over bodies.csv: sample times, apples, extents.
struct BodiesScan {
    times: Vec<f64>,
    apples: Vec<AppleInfo>,
    index: HashMap<String, u32>,
    lo: Vec3,
    hi: Vec3,
    max_speed: f64,
    /// Largest contact force on an apple in a sample (N).
    max_force: f64,
    has_slip: bool,
    /// The apples of the last sample.
    last_names: Vec<String>,
}

struct BodyCols {
    t: usize,
    apple: usize,
    p: [usize; 3],
    v: [usize; 3],
    f: [usize; 3],
    slip: usize,
    d: usize,
    m: usize,
    /// `height_m`, `qw`, `qx`, `qy`, `qz`: a run with spheroids.
    shape: Option<[usize; 5]>,
}

/// The embedded orientations' scale: a quaternion component q is stored as the i16 nearest
/// q times this (each within half a step, 1.5e-5, of the unit quaternion's: the drawn turn
/// within 6e-5 rad of bodies.csv's).
const ORIENTATION_SCALE: f64 = 32767.0;

/// Transitions of one apple: (time, from, to), in time order.
type Track = Vec<(f64, u8, u8)>;

fn collect(run_dir: &Path, opts: &ViewOptions) -> Result<Collected, ViewError> {
    if !run_dir.is_dir() {
        return Err(ViewError::NotARun {
            path: run_dir.to_path_buf(),
            reason: if run_dir.exists() {
                "a file, not a folder".into()
            } else {
                "no such folder".into()
            },
        });
    }
    let summary_path = run_dir.join("summary.json");
    if !summary_path.is_file() {
        return Err(ViewError::NotARun {
            path: run_dir.to_path_buf(),
            reason: "no summary.json: give the folder `applesim run --out` wrote".into(),
        });
    }
    let text = std::fs::read_to_string(&summary_path).map_err(io(&summary_path))?;
    let summary: SummaryIn = serde_json::from_str(&text).map_err(|e| {
        bad(
            &summary_path,
            format!("{e}: not an applesim summary, or the file is truncated"),
        )
    })?;
    let bodies_path = require(run_dir, "bodies.csv", "the apples' positions over time")?;
    let contacts_path = require(run_dir, "contacts.csv", "the contacts")?;
    let scenario_path = require(run_dir, "scenario.json", "the surfaces of the scene")?;
    let sc_text = std::fs::read_to_string(&scenario_path).map_err(io(&scenario_path))?;
    let sc: Scenario = crate::scenario::from_json(&sc_text, &scenario_path.display().to_string())
        .map_err(|e| bad(&scenario_path, e.to_string()))?;

    let mut notes = Vec::new();

    // Pass 1: times, apples, extents.
    let (scan, cols) = scan_bodies(&bodies_path)?;
    if let Some(&last) = scan.times.last() {
        let end = summary.simulated_time_s;
        if (last - end).abs() > 1e-9 * end.abs().max(1e-9) {
            return Err(bad(
                &bodies_path,
                format!(
                    "the last sample is at t = {last} s but the run ended at t = {end} s (summary.json): the file is truncated"
                ),
            ));
        }
    }
    // The last sample holds every apple of the run (none is ever removed): one cut short at a
    // row boundary is refused.
    if !scan.times.is_empty() && !summary.apples.is_empty() {
        let have: std::collections::HashSet<&str> =
            scan.last_names.iter().map(String::as_str).collect();
        let missing: Vec<&str> = summary
            .apples
            .iter()
            .map(|a| a.name.as_str())
            .filter(|n| !have.contains(n))
            .collect();
        if !missing.is_empty() {
            return Err(bad(
                &bodies_path,
                format!(
                    "the last sample (t = {} s) has {} of the {} apples of summary.json ({}{} missing): the file is truncated",
                    scan.times[scan.times.len() - 1],
                    summary.apples.len() - missing.len(),
                    summary.apples.len(),
                    missing[..missing.len().min(3)].join(", "),
                    if missing.len() > 3 { ", ..." } else { "" }
                ),
            ));
        }
    }
    let mut apples = scan.apples;
    let mut index = scan.index;
    let sampled = !scan.times.is_empty();
    let (mut lo, mut hi) = (scan.lo, scan.hi);
    // No sample: the apples stand at their final positions (summary.json), one frame.
    let mut finals: Vec<[f64; 3]> = Vec::new();
    if !sampled {
        notes.push(if summary.apples.is_empty() {
            "bodies.csv holds no sample and the run has no apple: only the surfaces are shown".to_string()
        } else {
            format!(
                "bodies.csv holds no sample: the {} apples are shown at their final positions (summary.json), without motion, speeds or states",
                summary.apples.len()
            )
        });
        for a in &summary.apples {
            index.insert(a.name.clone(), apples.len() as u32);
            apples.push(AppleInfo::new(&a.name, a.diameter_m, a.mass_kg));
            let p = crate::math::vec3(a.final_position_m);
            lo = lo.min(p);
            hi = hi.max(p);
            finals.push(a.final_position_m);
        }
    }
    let n = apples.len();
    if n == 0 {
        lo = Vec3::ZERO;
        hi = Vec3::ZERO;
    }
    let step = {
        let s = (hi - lo) / 65535.0;
        [s.x, s.y, s.z]
    };
    let speed_step = scan.max_speed / 65535.0;
    let force_step = scan.max_force / 65535.0;

    // What each hit did to each apple (apple_contacts.csv) and the bruise sites (bruises.csv),
    // when the run assessed its fruit's damage.
    let hits_path = crate::output::csv_file::locate(run_dir, crate::output::APPLE_CONTACTS_CSV);
    let hits = if hits_path.is_file() {
        Some(read_apple_contacts(&hits_path)?)
    } else {
        None
    };
    let sites_path = crate::output::csv_file::locate(run_dir, crate::output::BRUISES_CSV);
    let site_rows = match (&hits, sites_path.is_file()) {
        (Some(_), true) => read_sites(&sites_path)?,
        _ => Vec::new(),
    };
    // A site is drawn in the direction of its first hit's contact point from the apple's
    // centre at that hit's peak: the centre there is wanted from bodies.csv.
    let mut first_hit: HashMap<(&str, usize), &HitRow> = HashMap::new();
    for h in hits.iter().flatten() {
        if let Some(site) = h.site {
            let e = first_hit.entry((h.apple.as_str(), site)).or_insert(h);
            if h.t_peak_s < e.t_peak_s {
                *e = h;
            }
        }
    }
    // Per apple: (time, site row) wanted, in time order, and the centres found.
    let mut wanted: Vec<Vec<(f64, usize)>> = vec![Vec::new(); n];
    for (k, srow) in site_rows.iter().enumerate() {
        let (Some(&i), Some(h)) = (
            index.get(&srow.apple),
            first_hit.get(&(srow.apple.as_str(), srow.site)),
        ) else {
            continue;
        };
        wanted[i as usize].push((h.t_peak_s, k));
    }
    for w in &mut wanted {
        w.sort_by(|a, b| a.0.total_cmp(&b.0));
    }
    let mut centre_at: Vec<Option<[f64; 3]>> = vec![None; site_rows.len()];

    // Motion states from transitions.csv when the run wrote it.
    let transitions_path = crate::output::csv_file::locate(run_dir, "transitions.csv");
    let tracks = if transitions_path.is_file() && sampled {
        Some(read_transitions(&transitions_path, &index)?)
    } else {
        None
    };
    let states_source = match (&tracks, scan.has_slip, sampled) {
        (_, _, false) => "none",
        (Some(_), _, _) => "transitions.csv",
        (None, true, _) => "bodies.csv slip speed",
        (None, false, _) => "bodies.csv contact force",
    };
    match states_source {
        "none" => {}
        "transitions.csv" => {}
        "bodies.csv slip speed" => notes.push(
            "no transitions.csv: sliding and rolling are told from each sample's slip speed (max(5 mm/s, 1 % of the speed)), without the detector's hysteresis".into(),
        ),
        _ => notes.push(
            "slip/roll detection was off in this run (output.transitions.enabled: false): apples are shown airborne or in contact, not sliding or rolling".into(),
        ),
    }

    // Pass 2: the picked frames.
    let frames_idx: Vec<usize> = if sampled {
        pick_frames(scan.times.len(), opts.max_frames)
    } else {
        vec![0]
    };
    let nf = frames_idx.len();
    let mut frame_of = vec![u32::MAX; scan.times.len()];
    if sampled {
        for (f, &s) in frames_idx.iter().enumerate() {
            frame_of[s] = f as u32;
        }
    }
    let mut pos = vec![0u16; nf * n * 3];
    let mut spd = vec![0u16; nf * n];
    let mut st = vec![motion::ABSENT; nf * n];
    let mut frc = vec![0u16; nf * n];
    // The identity for apples not in a frame, and for the one frame of a run without samples
    // (its final orientations are not in summary.json).
    let mut ori: Option<Vec<i16>> = cols.shape.map(|_| {
        let mut v = vec![0i16; nf * n * 4];
        v.chunks_mut(4)
            .for_each(|q| q[3] = ORIENTATION_SCALE as i16);
        v
    });
    let times: Vec<f64> = if sampled {
        frames_idx.iter().map(|&s| scan.times[s]).collect()
    } else {
        vec![summary.simulated_time_s]
    };
    // Per apple: its previous sample (time, centre) and the next wanted centre.
    let mut prev: Vec<Option<(f64, [f64; 3])>> = vec![None; n];
    let mut next = vec![0usize; n];
    if sampled {
        let mut r = csv_reader(&bodies_path)?;
        let mut rec = csv::StringRecord::new();
        let mut sample = 0usize;
        let mut last_t = f64::NAN;
        let mut first = true;
        while r
            .read_record(&mut rec)
            .map_err(|e| csv_err(&bodies_path, e))?
        {
            let line = rec.position().map_or(0, |p| p.line());
            let t = num(&bodies_path, line, "time_s", &rec[cols.t])?;
            if !first && t != last_t {
                sample += 1;
            }
            first = false;
            last_t = t;
            // The file is read twice; one that changed in between (a run writing it again) is
            // refused rather than misread.
            let changed = || {
                bad(
                    &bodies_path,
                    format!("line {line}: the file changed while it was read: view it again"),
                )
            };
            let f = *frame_of.get(sample).ok_or_else(changed)?;
            let i = *index.get(&rec[cols.apple]).ok_or_else(changed)? as usize;
            let g = |c: usize, name: &str| num(&bodies_path, line, name, &rec[c]);
            if f == u32::MAX && next[i] == wanted[i].len() {
                continue;
            }
            let p = [
                g(cols.p[0], "x_m")?,
                g(cols.p[1], "y_m")?,
                g(cols.p[2], "z_m")?,
            ];
            // Centres wanted at or before this sample: between the apple's two samples around
            // them, in a straight line (as the page moves it between frames).
            while let Some(&(tw, k)) = wanted[i].get(next[i]) {
                if tw > t {
                    break;
                }
                centre_at[k] = Some(match prev[i] {
                    Some((t0, p0)) if t > t0 => {
                        let a = ((tw - t0) / (t - t0)).clamp(0.0, 1.0);
                        [0, 1, 2].map(|j| p0[j] + a * (p[j] - p0[j]))
                    }
                    _ => p,
                });
                next[i] += 1;
            }
            prev[i] = Some((t, p));
            if f == u32::MAX {
                continue;
            }
            let k = f as usize * n + i;
            for a in 0..3 {
                pos[3 * k + a] = q16(p[a], lo[a], step[a]);
            }
            let v = Vec3::new(
                g(cols.v[0], "vx_m_s")?,
                g(cols.v[1], "vy_m_s")?,
                g(cols.v[2], "vz_m_s")?,
            );
            spd[k] = q16(v.length(), 0.0, speed_step);
            let force = Vec3::new(
                g(cols.f[0], "fx_n")?,
                g(cols.f[1], "fy_n")?,
                g(cols.f[2], "fz_n")?,
            );
            frc[k] = q16(force.length(), 0.0, force_step);
            if let (Some(c), Some(o)) = (&cols.shape, ori.as_mut()) {
                let (_, q) = shape_of(&bodies_path, line, c, &rec)?;
                for (slot, x) in o[4 * k..4 * k + 4].iter_mut().zip(q) {
                    *slot = (x * ORIENTATION_SCALE).round() as i16;
                }
            }
            let slip = opt_num(&bodies_path, line, "slip_m_s", &rec[cols.slip])?;
            st[k] = if let Some(track) = tracks.as_ref().map(|tr| tr.get(&(i as u32))) {
                match track {
                    Some(tr) => {
                        // The state entered by the last transition at or before t, else the
                        // state the first one left.
                        match tr.iter().rev().find(|x| x.0 <= t) {
                            Some(x) => x.2,
                            None => tr[0].1,
                        }
                    }
                    None => {
                        if force.length() == 0.0 {
                            motion::AIRBORNE
                        } else {
                            motion::ROLLING
                        }
                    }
                }
            } else if force.length() == 0.0 {
                motion::AIRBORNE
            } else {
                match slip {
                    Some(s) if s > (0.005f64).max(0.01 * v.length()) => motion::SLIDING,
                    Some(_) => motion::ROLLING,
                    None => motion::CONTACT,
                }
            };
        }
    } else {
        for (i, p) in finals.iter().enumerate() {
            for a in 0..3 {
                pos[3 * i + a] = q16(p[a], lo[a], step[a]);
            }
            st[i] = motion::CONTACT;
        }
    }
    let mut le = Vec::with_capacity(pos.len() * 2);
    for x in &pos {
        le.extend_from_slice(&x.to_le_bytes());
    }
    let positions_b64 = b64(&le);
    le.clear();
    for x in &spd {
        le.extend_from_slice(&x.to_le_bytes());
    }
    let speeds_b64 = b64(&le);
    le.clear();
    for x in &frc {
        le.extend_from_slice(&x.to_le_bytes());
    }
    let forces_b64 = b64(&le);
    let orientations_b64 = ori.map(|o| {
        le.clear();
        for x in &o {
            le.extend_from_slice(&x.to_le_bytes());
        }
        b64(&le)
    });
    let states_b64 = b64(&st);
    // Centres wanted after the last sample: the last one.
    for (i, w) in wanted.iter().enumerate() {
        for &(_, k) in w {
            if centre_at[k].is_none() {
                centre_at[k] = prev.get(i).copied().flatten().map(|x| x.1);
            }
        }
    }

    // Contacts, with what they did to each apple.
    // The paper's firm-variety force threshold: the mark of a run folder without
    // apple_contacts.csv, and the force bar's reference tick.
    let default_threshold = PAPER_FIRM_FORCE_N;
    if hits.is_none() {
        notes.push(format!(
            "no apple_contacts.csv (a run of applesim from before the damage model): contacts are marked as bruising by their impact peak force over {default_threshold} N only, and the apples have no bruise volume, grade, absorbed energy, peak g or velocity change"
        ));
    } else if !sites_path.is_file() {
        notes.push("no bruises.csv: the bruise sites are not drawn".into());
    }
    let thresholds = vec![default_threshold];
    let sides: Option<HashMap<(usize, String), HitRow>> = hits.as_ref().map(|hs| {
        hs.iter()
            .map(|h| ((h.contact, h.apple.clone()), h.clone()))
            .collect()
    });
    let (mut contacts, transfer_points) =
        read_contacts(&contacts_path, &index, sides.as_ref(), default_threshold)?;
    let max_peak = contacts.iter().map(|c| c.impact_n).fold(0.0, f64::max);
    let forces_path = crate::output::csv_file::locate(run_dir, "forces.csv");
    let mut curves = BTreeMap::new();
    if forces_path.is_file() {
        let mut risky: Vec<usize> = (0..contacts.len())
            .filter(|&k| !contacts[k].risk_a.is_empty() || !contacts[k].risk_b.is_empty())
            .collect();
        risky.sort_by(|&x, &y| {
            contacts[y]
                .impact_n
                .total_cmp(&contacts[x].impact_n)
                .then(x.cmp(&y))
        });
        let left_out = risky.len().saturating_sub(MAX_CURVES);
        risky.truncate(MAX_CURVES);
        // The impact pulse (and as much again), not the resting time after it: a long resting
        // contact thinned to 64 points would hide the pulse.
        let until = |c: &ContactInfo| match c.impact_duration_s {
            Some(d) => c.t_start_s + 2.0 * d,
            None => f64::INFINITY,
        };
        curves = read_curves(
            &forces_path,
            &risky
                .into_iter()
                .map(|k| (k, until(&contacts[k])))
                .collect(),
        )?;
        notes.push(format!(
            "force curves (forces.csv, at most {CURVE_POINTS} points each) are shown for the {} contact(s) over a bruise threshold{}: click an apple, then a red row",
            curves.len(),
            if left_out > 0 {
                format!(" with the largest impacts ({left_out} more left out)")
            } else {
                String::new()
            }
        ));
    } else {
        notes.push(if sc.force_history().is_kept() {
            "no forces.csv: contacts show their peak figures, not force curves".to_string()
        } else {
            "force histories were not kept (output.force_history: false): contacts show their peak figures, not force curves".to_string()
        });
    }
    if contacts.is_empty() {
        notes.push("no contact in contacts.csv: nothing to colour by force".into());
    }

    // Surfaces, rebuilt from the scenario as run.
    let base = opts
        .asset_dir
        .clone()
        .unwrap_or_else(|| run_dir.to_path_buf());
    let rollers_path = crate::output::csv_file::locate(run_dir, crate::output::ROLLERS_CSV);
    let spins = match rollers_path.is_file() {
        true => Some(read_rollers(&rollers_path, &times, &sc)?),
        false => None,
    };
    // A spheroid reaches out to its larger semi-axis.
    let rmax = apples
        .iter()
        .map(|a| a.diameter_m.max(a.height_m.unwrap_or(0.0)) / 2.0)
        .fold(0.0, f64::max);
    let (surfaces, movers, bounded_lo, bounded_hi) = surfaces_of(
        &sc,
        &base,
        lo,
        hi,
        n > 0,
        rmax,
        &times,
        spins.as_ref(),
        &mut notes,
    );
    carry_marks(&mut contacts, &transfer_points, &surfaces, &movers, &times);
    let mut scene_lo = lo;
    let mut scene_hi = hi;
    if n > 0 {
        scene_lo -= Vec3::splat(rmax);
        scene_hi += Vec3::splat(rmax);
    }

    // Bruise sites, grades over time, the audit.
    // The bruises only: a site hit without bruising (most of a heap's) is drawn as nothing.
    let sites: Vec<serde_json::Value> = site_rows
        .iter()
        .zip(&centre_at)
        .filter(|(srow, _)| srow.bruised || srow.volume_mm3.is_some_and(|v| v > 0.0))
        .filter_map(|(srow, c)| {
            let i = *index.get(&srow.apple)?;
            let h = first_hit.get(&(srow.apple.as_str(), srow.site))?;
            let c = crate::math::vec3((*c)?);
            let d = (crate::math::vec3(h.point_m) - c).normalize_or_zero();
            let dir_world = [d.x, d.y, d.z].map(sig6);
            let dir_apple = srow.direction.map(sig6);
            Some(serde_json::json!([
                i,
                srow.site,
                srow.first_hit_s,
                srow.hits,
                srow.transfer_points,
                sig6(srow.absorbed_energy_j),
                srow.bruised as u8,
                srow.volume_mm3.map(sig6),
                srow.area_mm2.map(sig6),
                srow.depth_mm.map(sig6),
                srow.diameter_mm.map(sig6),
                dir_apple,
                dir_world,
            ]))
        })
        .collect();
    let damage = summary.damage.as_ref().map(|d| DamageInfo {
        standard: d.standard.clone(),
        grades: d.grades.clone(),
    });
    if damage.is_some() {
        let (_, classes, below) = crate::analysis::bruise::grading(&sc);
        let by_name: HashMap<&str, &SummaryApple> = summary
            .apples
            .iter()
            .map(|a| (a.name.as_str(), a))
            .collect();
        for a in apples.iter_mut() {
            let Some(sa) = by_name.get(a.name.as_str()) else {
                continue;
            };
            a.grade = sa.grade.clone();
            a.grade_why = sa.grade_why.clone();
            a.downgraded_by = sa.downgraded_by.clone();
            if a.grade.is_some() {
                a.grade_steps = grade_steps(&classes, &below, &site_rows, &a.name);
            }
        }
    }
    let audit_path = crate::output::csv_file::locate(run_dir, "audit.csv");
    let audit = if audit_path.is_file() {
        Some(read_audit_table(&audit_path)?)
    } else {
        None
    };
    if let (Some(a), Some(b)) = (bounded_lo, bounded_hi) {
        if n > 0 {
            scene_lo = scene_lo.min(a);
            scene_hi = scene_hi.max(b);
        } else {
            scene_lo = a;
            scene_hi = b;
        }
    }
    notes.push(format!(
        "positions quantised to {} x {} x {} mm (1/65535 of the box of the apples' centres), speeds to {} mm/s; {} of {} samples of bodies.csv shown, interpolated between frames",
        fmt_mm(step[0]),
        fmt_mm(step[1]),
        fmt_mm(step[2]),
        fmt_mm(speed_step),
        nf.min(scan.times.len()),
        scan.times.len()
    ));

    let stats = ViewStats {
        apples: n,
        surfaces: surfaces.len(),
        samples: scan.times.len(),
        frames: nf,
        contacts: contacts.len(),
        bytes: 0,
        position_step_m: step,
        notes: notes.clone(),
    };
    // The page travels: it names the run by its folder's own name, and its notes name files
    // relative to the run's or the assets' folder, never by where they lie on this machine.
    let label = opts
        .label
        .as_ref()
        .map(PathBuf::from)
        .unwrap_or_else(|| run_dir.to_path_buf());
    let mut prefixes: Vec<String> = Vec::new();
    for d in [run_dir, base.as_path(), label.as_path()] {
        prefixes.push(d.display().to_string());
        if let Ok(c) = d.canonicalize() {
            prefixes.push(c.display().to_string());
        }
    }
    if let Ok(c) = std::env::current_dir() {
        prefixes.push(c.display().to_string());
    }
    let notes = notes.iter().map(|x| strip_paths(x, &prefixes)).collect();
    let page = Page {
        format: 2,
        applesim_version: env!("CARGO_PKG_VERSION"),
        run: RunInfo {
            folder: folder_name(&label),
            description: summary.description,
            simulated_time_s: summary.simulated_time_s,
            steps: summary.steps,
        },
        notes,
        box_lo_m: [lo.x, lo.y, lo.z],
        position_step_m: step,
        speed_step_m_s: speed_step,
        times_s: times,
        samples: scan.times.len(),
        apples,
        positions_b64,
        speeds_b64,
        states_b64,
        forces_b64,
        orientations_b64,
        force_step_n: force_step,
        states_source,
        surfaces,
        movers,
        contact_fields: &CONTACT_FIELDS,
        side_fields: &SIDE_FIELDS,
        contacts: contacts.iter().map(ContactInfo::row).collect(),
        curves,
        transfer_points,
        site_fields: &SITE_FIELDS,
        sites,
        damage,
        audit,
        bruise_force_n: thresholds,
        max_peak_force_n: max_peak,
        scene_lo_m: [scene_lo.x, scene_lo.y, scene_lo.z],
        scene_hi_m: [scene_hi.x, scene_hi.y, scene_hi.z],
        gravity_m_s2: sc.gravity_m_s2,
    };
    Ok(Collected { page, stats })
}

fn fmt_mm(m: f64) -> String {
    let mm = m * 1e3;
    if mm == 0.0 {
        "0".into()
    } else {
        format!("{mm:.3}")
    }
}

/// The paper's bruise threshold for firm varieties (N; the `paper-firm` damage preset).
const PAPER_FIRM_FORCE_N: f64 = 80.0;

/// The name a page gives its run: the folder's own name (its last component; `.` and `..`
/// resolved), never the path that leads to it on this machine.
fn folder_name(p: &Path) -> String {
    let name = |q: &Path| {
        q.file_name()
            .map(|n| n.to_string_lossy().to_string())
            .filter(|n| !n.is_empty())
    };
    name(p)
        .or_else(|| p.canonicalize().ok().as_deref().and_then(name))
        .unwrap_or_else(|| "run".into())
}

/// `s` with every path under one of `prefixes` (folders) made relative to it: a note naming
/// `/home/me/runs/x/mesh.obj` names `mesh.obj`.
fn strip_paths(s: &str, prefixes: &[String]) -> String {
    let mut out = s.to_string();
    let mut sorted: Vec<&String> = prefixes.iter().filter(|p| p.len() > 1).collect();
    // The longest first: a folder inside another is stripped whole.
    sorted.sort_by_key(|p| std::cmp::Reverse(p.len()));
    for p in sorted {
        let with_sep = format!("{}{}", p.trim_end_matches('/'), std::path::MAIN_SEPARATOR);
        out = out.replace(&with_sep, "");
    }
    out
}

/// The grade of an apple over time (`name`'s bruised sites of `sites`, counted from their first
/// hit at their sizes in bruises.csv, graded by `classes`): (time, rank) at each change of rank,
/// the best class (0) before the first. The last is the grade of all its bruises, summary.json's.
fn grade_steps(
    classes: &[crate::scenario::damage::GradeClass],
    below: &str,
    sites: &[SiteRow],
    name: &str,
) -> Vec<(f64, usize)> {
    use crate::analysis::damage::grade::{grade, BruiseSize};
    let mut mine: Vec<&SiteRow> = sites
        .iter()
        .filter(|s| s.apple == name && s.bruised)
        .collect();
    mine.sort_by(|a, b| a.first_hit_s.total_cmp(&b.first_hit_s));
    let mut steps = Vec::new();
    let mut rank = 0;
    let mut so_far: Vec<BruiseSize> = Vec::new();
    for s in mine {
        so_far.push(BruiseSize {
            volume_mm3: s.volume_mm3,
            diameter_mm: s.diameter_mm,
            depth_mm: s.depth_mm,
            area_mm2: s.area_mm2,
        });
        let g = grade(classes, below, &so_far);
        if g.rank != rank {
            rank = g.rank;
            steps.push((s.first_hit_s, rank));
        }
    }
    steps
}

/// Where each contact's mark is drawn: a contact with a moving part (its surface, or for two
/// apples the part its transfer point names: `apples in BIN`, `apples on PART`) is carried by
/// that part's body, its point kept in the body's frame (`local_m`) as the body was posed at the
/// contact's peak by the page's own interpolation between frames; so the mark sits where the
/// contact was on the part at every frame.
fn carry_marks(
    contacts: &mut [ContactInfo],
    transfer_points: &[String],
    surfaces: &[SurfaceInfo],
    movers: &[MoverInfo],
    times: &[f64],
) {
    if movers.is_empty() || times.is_empty() {
        return;
    }
    let mover_of_part = |part: &str| -> Option<usize> {
        surfaces
            .iter()
            .find(|s| s.name == part || s.name.starts_with(&format!("{part}/")))
            .and_then(|s| s.mover)
    };
    for c in contacts.iter_mut() {
        let part = if c.b_apple < 0 {
            Some(c.b.as_str())
        } else {
            usize::try_from(c.tp)
                .ok()
                .and_then(|k| transfer_points.get(k))
                .and_then(|tp| {
                    tp.strip_prefix("apples in ")
                        .or_else(|| tp.strip_prefix("apples on "))
                })
        };
        let Some(m) = part.and_then(mover_of_part) else {
            continue;
        };
        let pose = pose_between_frames(&movers[m].poses, times, c.t_peak_s);
        // The page draws the body's parts at (rest - origin), moved by the pose: the point in
        // those coordinates.
        let local = pose.inverse_transform_point(crate::math::vec3(c.point_m));
        c.carrier = m as i64;
        c.local_m = Some([local.x, local.y, local.z]);
    }
}

/// A body's pose at time `t` as the page draws it from its poses at the frames' `times`: the
/// translation in a straight line and the rotation by the shorter way round between the two
/// frames around `t` (held before the first and after the last).
fn pose_between_frames(
    poses: &[rapier3d_f64::math::Pose],
    times: &[f64],
    t: f64,
) -> rapier3d_f64::math::Pose {
    let f = times.partition_point(|&x| x <= t).saturating_sub(1);
    let f1 = (f + 1).min(times.len() - 1);
    let span = times[f1] - times[f];
    let a = if span > 0.0 {
        ((t - times[f]) / span).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let (p, q) = (poses[f], poses[f1]);
    rapier3d_f64::math::Pose::from_parts(
        p.translation + (q.translation - p.translation) * a,
        p.rotation.slerp(q.rotation, a),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_matches_rfc4648() {
        assert_eq!(b64(b""), "");
        assert_eq!(b64(b"f"), "Zg==");
        assert_eq!(b64(b"fo"), "Zm8=");
        assert_eq!(b64(b"foo"), "Zm9v");
        assert_eq!(b64(b"foobar"), "Zm9vYmFy");
    }

    #[test]
    fn frames_keep_first_and_last() {
        assert_eq!(pick_frames(3, 10), vec![0, 1, 2]);
        let f = pick_frames(1001, 11);
        assert_eq!(f.len(), 11);
        assert_eq!(f[0], 0);
        assert_eq!(*f.last().unwrap(), 1000);
        assert_eq!(f[5], 500);
    }

    /// The page names its run by the folder's own name and its notes name files relative to
    /// the run's or the assets' folder.
    #[test]
    fn the_page_names_no_local_path() {
        assert_eq!(folder_name(Path::new("/home/me/runs/line")), "line");
        assert_eq!(folder_name(Path::new("runs/line/")), "line");
        let notes = strip_paths(
            "surface 'plate' is not drawn: /home/me/runs/line/plate.obj: not found",
            &["/home/me".into(), "/home/me/runs/line".into()],
        );
        assert_eq!(notes, "surface 'plate' is not drawn: plate.obj: not found");
    }

    /// An apple's grade over time: the best class until its first bruise that breaks a limit,
    /// then lower as more bruises count from their first hits (a user table: A up to 15 mm
    /// across, B up to 22 mm, C below); a site that is not a bruise does not count.
    #[test]
    fn grades_fall_as_bruises_arise() {
        let (_, classes, below) = crate::analysis::bruise::grading(
            &crate::scenario::from_json(
                r#"{"duration_s": 1, "time_step_s": 1e-4, "gravity_m_s2": [0, 0, -9.81], "materials": {},
                    "contact": {"friction": 0.3, "ke": 0.09, "lambda_s_m": 1000},
                    "grading": {"classes": [{"name": "A", "max_bruise_diameter_mm": 15},
                                            {"name": "B", "max_bruise_diameter_mm": 22}],
                                "below": "C"}}"#,
                "test",
            )
            .unwrap(),
        );
        let site = |t: f64, d: f64, bruised: bool| SiteRow {
            apple: "a".into(),
            site: 0,
            direction: [0.0, 0.0, 1.0],
            first_hit_s: t,
            hits: 1,
            transfer_points: String::new(),
            absorbed_energy_j: 0.1,
            bruised,
            volume_mm3: Some(100.0),
            area_mm2: Some(std::f64::consts::PI * d * d / 4.0),
            depth_mm: Some(1.0),
            diameter_mm: Some(d),
        };
        let sites = [
            site(2.0, 10.0, true),
            site(3.0, 20.0, true),
            site(1.0, 30.0, false),
            site(4.0, 25.0, true),
        ];
        assert_eq!(
            grade_steps(&classes, &below, &sites, "a"),
            [(3.0, 1), (4.0, 2)]
        );
        assert!(grade_steps(&classes, &below, &sites, "b").is_empty());
    }

    #[test]
    fn quantisation_is_nearest() {
        assert_eq!(q16(0.0, 0.0, 1e-3), 0);
        assert_eq!(q16(65.535, 0.0, 1e-3), 65535);
        assert_eq!(q16(1.0004, 0.0, 1e-3), 1000);
        assert_eq!(q16(5.0, 5.0, 0.0), 0);
    }
}
