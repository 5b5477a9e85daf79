//! Scenario files: serde types (the JSON contract of README "Scenario format") and validation.
//!
//! Every field name carries its unit. Unknown fields are errors (a misspelt field must not be
//! silently ignored), every number is checked against its physical range ([`ranges`]), and every
//! mistake is reported on one line with the exact JSON path of the field at fault, inside
//! surfaces, generators and distributions too (`de`).

pub mod budget;
pub mod damage;
mod de;
pub mod generators;
pub mod lab;
pub mod layout;
pub mod models;
pub mod motion;
pub mod output;
pub mod presets;
pub mod ranges;
pub mod stepping;
pub mod surfaces;
pub(crate) mod validate;

use crate::contact::spheroid::Spheroid;
use rapier3d_f64::math::Rotation;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use thiserror::Error;

pub use generators::{
    AspectSpec, DiameterSpec, FileApple, FileSpec, GeneratorSpec, JitterSpec, SourceSpec,
};
pub use output::{ForceHistory, HistoryChoice, Precision, Sampling};
pub use stepping::{Accuracy, Fidelity, TimeStep};
pub use surfaces::{ContactModel, RotationSpec, SurfaceSpec};
pub use validate::validate;

/// A user mistake in a scenario, with the path of the field at fault.
#[derive(Debug, Error)]
pub enum ScenarioError {
    /// The file could not be read.
    #[error("cannot read scenario '{path}': {source}")]
    Io {
        /// File path.
        path: PathBuf,
        /// OS error.
        source: std::io::Error,
    },
    /// Not valid JSON, or a field missing, unknown or of the wrong type.
    #[error("{file}: {path}: {message}")]
    Parse {
        /// File name (or `<input>`).
        file: String,
        /// JSON path of the field (`.` for the top level).
        path: String,
        /// What serde saw, with line and column.
        message: String,
    },
    /// A value out of range or inconsistent with another.
    #[error("{field}: {message}")]
    Invalid {
        /// JSON path of the field.
        field: String,
        /// What is wrong and what would be right.
        message: String,
    },
}

impl ScenarioError {
    /// An invalid-value error. Control characters (a line break in a name the message quotes)
    /// are escaped: a refusal is one line.
    pub fn invalid(field: impl Into<String>, message: impl Into<String>) -> Self {
        Self::Invalid {
            field: one_line(field.into()),
            message: one_line(message.into()),
        }
    }
}

/// `s` with its control characters escaped (`\n`, `\u{1b}`), so that it prints as one line, and
/// shortened where a user's text would swamp it ([`shorten`]: a 100,000-character name was
/// echoed in full).
pub(crate) fn one_line(s: String) -> String {
    let s = if s.contains(char::is_control) {
        s.chars()
            .map(|c| {
                if c.is_control() {
                    c.escape_default().to_string()
                } else {
                    c.to_string()
                }
            })
            .collect()
    } else {
        s
    };
    shorten(s)
}

/// Longest run of characters without white space an error line shows whole ([`shorten`]).
pub const MAX_ECHOED_WORD_CHARS: usize = 120;

/// Longest error line shown whole, in characters ([`shorten`]).
pub const MAX_ECHOED_LINE_CHARS: usize = 4000;

/// An error line as it is shown: every run of more than [`MAX_ECHOED_WORD_CHARS`] characters
/// without white space (a long name, alone or inside a field path) keeps its first and last 40
/// characters around `...(N characters)...`, and a line still longer than
/// [`MAX_ECHOED_LINE_CHARS`] keeps its first 2000 and last 1000 characters likewise. Short
/// lines are returned as they are.
pub fn shorten(s: String) -> String {
    const KEEP: usize = 40;
    let cut = |chars: &[char], head: usize, tail: usize| -> String {
        let mut out: String = chars[..head].iter().collect();
        out.push_str(&format!("...({} characters)...", chars.len()));
        out.extend(&chars[chars.len() - tail..]);
        out
    };
    if s.len() <= MAX_ECHOED_WORD_CHARS {
        return s;
    }
    let mut out = String::with_capacity(s.len().min(2 * MAX_ECHOED_LINE_CHARS));
    let mut word: Vec<char> = Vec::new();
    let flush = |word: &mut Vec<char>, out: &mut String| {
        if word.len() > MAX_ECHOED_WORD_CHARS {
            out.push_str(&cut(word, KEEP, KEEP));
        } else {
            out.extend(word.iter());
        }
        word.clear();
    };
    for c in s.chars() {
        if c.is_whitespace() {
            flush(&mut word, &mut out);
            out.push(c);
        } else {
            word.push(c);
        }
    }
    flush(&mut word, &mut out);
    let chars: Vec<char> = out.chars().collect();
    if chars.len() > MAX_ECHOED_LINE_CHARS {
        cut(&chars, 2000, 1000)
    } else {
        out
    }
}

/// A complete scenario.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    /// Free text shown in reports.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub description: Option<String>,
    /// Simulated time (s).
    pub duration_s: f64,
    /// Time step: seconds, `"auto"` or `"adaptive"` (see [`TimeStep`]).
    pub time_step_s: TimeStep,
    /// Steps per contact the `auto` and `adaptive` steps aim at, and the fewest an impact may get
    /// before the run is refused (see [`Accuracy`]; default `balanced`, 20 steps).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub accuracy: Option<Accuracy>,
    /// Largest step the `auto` and `adaptive` policies may take (s); default the output interval,
    /// at most 1 ms (`auto`) or 10 ms (`adaptive`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_time_step_s: Option<f64>,
    /// Which parts of the contact model run (see [`Fidelity`]; default `hertz-damped`).
    #[serde(default)]
    pub fidelity: Fidelity,
    /// Gravity vector (m/s^2), e.g. [0, 0, -9.81]; z is up by convention.
    pub gravity_m_s2: [f64; 3],
    /// What is written and how often.
    #[serde(default)]
    pub output: OutputSpec,
    /// Named materials (a name given twice is refused).
    #[serde(deserialize_with = "de::unique_map")]
    pub materials: BTreeMap<String, MaterialSpec>,
    /// Contact coefficients for every pair of materials without its own entry in `pairs`.
    pub contact: ContactSpec,
    /// Per-pair overrides of `contact`.
    #[serde(default)]
    pub pairs: Vec<PairSpec>,
    /// Which parts of the contact law are on and the stability limits.
    #[serde(default)]
    pub model: ModelSpec,
    /// Apples placed one by one.
    #[serde(default)]
    pub apples: Vec<AppleSpec>,
    /// Generators placing many apples at the start (grid / layers, random fill).
    #[serde(default)]
    pub generators: Vec<GeneratorSpec>,
    /// Sources feeding apples in over time.
    #[serde(default)]
    pub sources: Vec<SourceSpec>,
    /// Surfaces (platforms, walls, belts, chutes, bins, meshes).
    #[serde(default)]
    pub surfaces: Vec<SurfaceSpec>,
    /// The grading standard apples are graded by (default `usda-wa`; docs/damage.md).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub grading: Option<damage::GradingSpec>,
}

impl Scenario {
    /// The contact law of a pair of materials (either order): its `pairs` entry over `contact`,
    /// or `contact`.
    pub fn pair_law(&self, m1: &str, m2: &str) -> ContactSpec {
        self.pairs
            .iter()
            .find(|p| {
                (p.materials[0] == m1 && p.materials[1] == m2)
                    || (p.materials[0] == m2 && p.materials[1] == m1)
            })
            .map_or(self.contact, |p| p.over(&self.contact))
    }

    /// Steps per contact the scenario asks for (its `accuracy`, default `balanced`).
    pub fn steps_per_contact(&self) -> f64 {
        self.accuracy.unwrap_or_default().steps_per_contact()
    }

    /// Fewest steps an impact may take before the run is refused: the `accuracy` target when
    /// given (or when the step is `auto` / `adaptive`), else `model.min_steps_per_impact`.
    pub fn required_steps_per_impact(&self) -> f64 {
        match (self.accuracy, self.time_step_s) {
            (Some(a), _) => a.steps_per_contact(),
            (None, TimeStep::Fixed(_)) => self.model.min_steps_per_impact,
            (None, _) => Accuracy::default().steps_per_contact(),
        }
    }

    /// The largest step the `auto` and `adaptive` policies may take (s): `max_time_step_s`, or
    /// by default the output interval, at most 1 ms for `auto` and 10 ms for `adaptive` (which
    /// shortens its steps wherever contacts need it).
    pub fn max_step_s(&self) -> f64 {
        let cap = if self.time_step_s == TimeStep::Adaptive {
            1e-2
        } else {
            1e-3
        };
        self.max_time_step_s
            .unwrap_or_else(|| self.sample_interval_s().min(cap))
    }

    /// The interval of `bodies.csv` (s): `output.sample_interval_s`, or the default that
    /// follows the run's length and apples ([`output::sampling`]).
    pub fn sample_interval_s(&self) -> f64 {
        self.sampling().interval_s
    }

    /// The interval of `bodies.csv` and why ([`output::sampling`]).
    pub fn sampling(&self) -> Sampling {
        output::sampling(self)
    }

    /// The force histories the run keeps: `output.force_history`, or the default that follows
    /// the run's apples ([`output::force_history`]).
    pub fn force_history(&self) -> ForceHistory {
        output::force_history(self).kept
    }

    /// Reads the apple lists of `file` generators, resolving their paths against `base_dir` (the
    /// scenario's folder, as for mesh surfaces). [`load`] does this; a scenario parsed with
    /// [`from_json`] needs it before [`validate`] and running when it has a `file` generator.
    pub fn read_files(&mut self, base_dir: &Path) -> Result<(), ScenarioError> {
        for (k, g) in self.generators.iter_mut().enumerate() {
            if let GeneratorSpec::File(f) = g {
                f.read(base_dir, &format!("generators[{k}]"))?;
            }
        }
        for (name, m) in self.materials.iter_mut() {
            if let Some(d) = &mut m.damage {
                damage::read_file(d, base_dir, &format!("materials.{name}.damage"))?;
            }
        }
        Ok(())
    }

    /// The surface of the scenario a part of the world belongs to (a bin's wall `BIN/x_min`, a
    /// roller bed's roller `BED/3`), in words for a message: "surfaces\[k\]: its position_m, ..."
    /// (what puts it there). `None` for a part of no listed surface.
    pub fn surface_fields_of(&self, part: &str) -> Option<String> {
        let (k, s) = self.surfaces.iter().enumerate().find(|(_, s)| {
            part == s.name()
                || part
                    .strip_prefix(s.name())
                    .is_some_and(|rest| rest.starts_with('/'))
        })?;
        Some(format!("surfaces[{k}]: its {}", s.placing_fields()))
    }

    /// The field that places apple `index` of [`Scenario::initial_apples`], for messages about
    /// where it starts: `apples[k].position_m` for a listed apple, else its generator's
    /// `origin_m` (grid), `region_min_m` (random fill) or `file`. Found without generating.
    pub fn initial_apple_field(&self, index: usize) -> String {
        if index < self.apples.len() {
            return format!("apples[{index}].position_m");
        }
        let mut first = self.apples.len();
        for (k, g) in self.generators.iter().enumerate() {
            let n = g.count() as usize;
            let field = match g {
                GeneratorSpec::Grid(_) => "origin_m",
                GeneratorSpec::RandomFill(_) => "region_min_m",
                GeneratorSpec::File(_) => "file",
            };
            if index < first.saturating_add(n) {
                return format!("generators[{k}].{field}");
            }
            first = first.saturating_add(n);
        }
        "generators".into()
    }

    /// The apples present at t = 0: the listed ones, then each generator's in order.
    pub fn initial_apples(&self) -> Result<Vec<AppleSpec>, ScenarioError> {
        let mut all = self.apples.clone();
        for (k, g) in self.generators.iter().enumerate() {
            let more = generators::expand(g, &all, &format!("generators[{k}]"))?;
            all.extend(more);
        }
        Ok(all)
    }
}

/// Output settings.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// Interval of the `bodies.csv` time series (s); rounded to a whole number of steps. Absent,
    /// it follows the run's length and apples ([`output::sampling`]: 1 ms for a short run).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sample_interval_s: Option<f64>,
    /// Which part of each contact's force history is kept (for plots and the pulse fit): the
    /// impact pulse (`true`), the whole contact (`"full"`, capped per contact) or none
    /// (`false`). Absent, it follows the run's apples ([`output::force_history`]: the impact
    /// pulses of a run of at most 50 apples, none of a larger one).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub force_history: Option<ForceHistory>,
    /// Significant digits of the numbers in the CSV files (default 9) or `"full"`.
    #[serde(default, skip_serializing_if = "Precision::is_default")]
    pub precision: Precision,
    /// Write every CSV file gzipped (`NAME.csv.gz`).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub compress: bool,
    /// ParaView time series of the apples and surfaces (`scene.pvd`, `vtk/`); off when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vtk: Option<VtkSpec>,
    /// Slip-to-roll detection (`transitions.csv`, docs/transitions.md); on with the defaults
    /// when absent.
    #[serde(default, skip_serializing_if = "TransitionSpec::is_default")]
    pub transitions: TransitionSpec,
}

/// Settings of the slip/roll detector (docs/transitions.md). A rolling apple starts sliding when
/// a contact's slip speed exceeds `hysteresis` times the threshold max(`slip_speed_m_s`,
/// `relative_tolerance` |v|), |v| the apple's speed, and rolls again once every slip is below the
/// threshold; a new state counts only once it has lasted `min_dwell_s` (it is then dated back to
/// where it began).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TransitionSpec {
    /// Detect and record transitions.
    #[serde(default = "default_true")]
    pub enabled: bool,
    /// Absolute slip-speed threshold (m/s).
    #[serde(default = "default_slip_speed")]
    pub slip_speed_m_s: f64,
    /// Threshold relative to the apple's centre speed.
    #[serde(default = "default_relative_tolerance")]
    pub relative_tolerance: f64,
    /// A rolling apple starts sliding only above this multiple of the threshold (>= 1).
    #[serde(default = "default_hysteresis")]
    pub hysteresis: f64,
    /// Shortest state that counts (s): briefer slips, bounces and rolls are not transitions.
    #[serde(default = "default_min_dwell")]
    pub min_dwell_s: f64,
    /// Bin width of the per-surface histograms of where apples start rolling (m).
    #[serde(default = "default_histogram_bin")]
    pub histogram_bin_m: f64,
}

fn default_slip_speed() -> f64 {
    5e-3
}

fn default_relative_tolerance() -> f64 {
    0.01
}

fn default_hysteresis() -> f64 {
    2.0
}

fn default_min_dwell() -> f64 {
    0.01
}

fn default_histogram_bin() -> f64 {
    0.05
}

impl Default for TransitionSpec {
    fn default() -> Self {
        Self {
            enabled: true,
            slip_speed_m_s: default_slip_speed(),
            relative_tolerance: default_relative_tolerance(),
            hysteresis: default_hysteresis(),
            min_dwell_s: default_min_dwell(),
            histogram_bin_m: default_histogram_bin(),
        }
    }
}

impl TransitionSpec {
    /// Whether these are the defaults (then omitted from the scenario as written).
    pub fn is_default(&self) -> bool {
        *self == Self::default()
    }
}

/// VTK output for ParaView (docs/analysis.md, "ParaView").
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VtkSpec {
    /// Interval between frames (s). Frames are taken from the `bodies.csv` samples, so the
    /// interval is rounded up to a whole number of `output.sample_interval_s`.
    pub interval_s: f64,
}

fn default_true() -> bool {
    true
}

/// A material: shear or Young's modulus (one of them), Poisson's ratio, and density when an
/// apple's mass is derived from it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    /// A preset of the material table ([`presets`], docs/materials.md) whose values fill what the
    /// scenario leaves out.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub preset: Option<String>,
    /// Shear modulus G (Pa).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shear_modulus_pa: Option<f64>,
    /// Young's modulus E (Pa).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub youngs_modulus_pa: Option<f64>,
    /// Poisson's ratio, in (-1, 0.5) (required, unless a preset gives it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub poisson_ratio: Option<f64>,
    /// Density (kg/m^3).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub density_kg_m3: Option<f64>,
    /// The share of the elastic energy stored in this material that it dissipates in one
    /// impact (1 - e^2 of it struck by a rigid body), in [0, 1]: how a contact's loss is shared
    /// between its bodies (docs/damage.md section 1). Unknown by default: the material then
    /// loses what its contact loses as a whole.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub loss_factor: Option<f64>,
    /// The damage model of apples of this material (read for apple materials only; default the
    /// `generic` preset; docs/damage.md).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub damage: Option<damage::DamageSpec>,
    /// Earlier versions' bruise thresholds, now `damage` (refused with the way to keep them).
    #[serde(default, skip_serializing)]
    pub bruise: Option<serde_json::Value>,
}

/// Contact coefficients.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    /// Coulomb friction coefficient (>= 0).
    pub friction: f64,
    /// Eq. 12 energy-loss coefficient ke in (0, 1]; 1 is elastic, e -> sqrt(ke) for lambda v >> 1.
    /// Needed by the eq. 12 damping models.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ke: Option<f64>,
    /// Eq. 12 rate constant lambda (s/m, >= 0). Needed by the eq. 12 damping models.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lambda_s_m: Option<f64>,
    /// Normal damping model (default `eq12`, the paper's).
    #[serde(default)]
    pub damping: models::Damping,
    /// Coefficient of restitution of the `viscoelastic` damping (and of the damping of the
    /// `history` tangential model; with eq. 12 that takes sqrt(ke)).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub restitution: Option<f64>,
    /// Tangential model (default `mindlin`).
    #[serde(default)]
    pub tangential: models::Tangential,
    /// Rolling-resistance model (default `elastic-plastic`; `none` is the paper's model).
    #[serde(default)]
    pub rolling: models::Rolling,
    /// Coefficient of rolling friction mu_r (default 0.03, see
    /// [`models::DEFAULT_ROLLING_FRICTION`]).
    #[serde(default = "default_rolling_friction")]
    pub rolling_friction: f64,
    /// Damping ratio of the `elastic-plastic` rolling spring (default 1: critical, see
    /// [`models::DEFAULT_ROLLING_DAMPING`]; 0 is LIGGGHTS `epsd2`).
    #[serde(default = "default_rolling_damping")]
    pub rolling_damping: f64,
    /// Twisting-resistance model (default `none`, as the paper, LIGGGHTS and EDEM; `coulomb`
    /// stops apples spinning about the contact normal, see [`models::Twisting`]).
    #[serde(default, skip_serializing_if = "is_default")]
    pub twisting: models::Twisting,
}

fn is_default<T: Default + PartialEq>(v: &T) -> bool {
    *v == T::default()
}

fn default_rolling_friction() -> f64 {
    models::DEFAULT_ROLLING_FRICTION
}

fn default_rolling_damping() -> f64 {
    models::DEFAULT_ROLLING_DAMPING
}

impl ContactSpec {
    /// The paper's model with these coefficients (eq. 12, Mindlin, no rolling resistance).
    pub fn paper(friction: f64, ke: f64, lambda_s_m: f64) -> Self {
        Self {
            friction,
            ke: Some(ke),
            lambda_s_m: Some(lambda_s_m),
            damping: models::Damping::Eq12,
            restitution: None,
            tangential: models::Tangential::Mindlin,
            rolling: models::Rolling::None,
            rolling_friction: 0.0,
            rolling_damping: 0.0,
            twisting: models::Twisting::None,
        }
    }
}

/// Overrides of the contact coefficients for one pair of materials.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PairSpec {
    /// The two material names (either order).
    pub materials: [String; 2],
    /// Friction for this pair.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction: Option<f64>,
    /// ke for this pair.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ke: Option<f64>,
    /// lambda for this pair (s/m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lambda_s_m: Option<f64>,
    /// Damping model for this pair.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub damping: Option<models::Damping>,
    /// Restitution for this pair (`viscoelastic`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub restitution: Option<f64>,
    /// Tangential model for this pair.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tangential: Option<models::Tangential>,
    /// Rolling model for this pair.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rolling: Option<models::Rolling>,
    /// Coefficient of rolling friction for this pair.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rolling_friction: Option<f64>,
    /// Rolling damping ratio for this pair.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rolling_damping: Option<f64>,
    /// Twisting model for this pair.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub twisting: Option<models::Twisting>,
}

impl PairSpec {
    /// The law of this pair: its own settings over `contact`'s.
    pub fn over(&self, c: &ContactSpec) -> ContactSpec {
        ContactSpec {
            friction: self.friction.unwrap_or(c.friction),
            ke: self.ke.or(c.ke),
            lambda_s_m: self.lambda_s_m.or(c.lambda_s_m),
            damping: self.damping.unwrap_or(c.damping),
            restitution: self.restitution.or(c.restitution),
            tangential: self.tangential.unwrap_or(c.tangential),
            rolling: self.rolling.unwrap_or(c.rolling),
            rolling_friction: self.rolling_friction.unwrap_or(c.rolling_friction),
            rolling_damping: self.rolling_damping.unwrap_or(c.rolling_damping),
            twisting: self.twisting.unwrap_or(c.twisting),
        }
    }
}

/// Model options.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelSpec {
    /// Largest overlap allowed, as a fraction of the smaller radius, before the run is refused.
    #[serde(default = "default_max_overlap_ratio")]
    pub max_overlap_ratio: f64,
    /// Fewest steps an impact may be resolved in before the run is refused, for a fixed
    /// `time_step_s` without `accuracy` (with `accuracy` its steps per contact are required).
    #[serde(default = "default_min_steps")]
    pub min_steps_per_impact: f64,
    /// Sleeping of apples at rest.
    #[serde(default)]
    pub sleep: SleepSpec,
    /// Largest rise of the total energy (kinetic, potential, elastic) above what the scene
    /// started with (plus what sources fed in), as a fraction, before the run is refused. Not
    /// checked in scenes with a belt (a belt feeds energy in).
    #[serde(default = "default_energy_tolerance")]
    pub energy_tolerance: f64,
    /// Bound of LIGGGHTS's `tangential history` dashpot (`contact.tangential: "history"`):
    /// gamma_t dt / m_t <= this / n for an apple with n contacts, in (0, 2). The default 1.5 is
    /// this project's choice ([`crate::contact::HISTORY_DASHPOT_BOUND`] says why); the explicit
    /// dashpot overshoots and grows from 2 on.
    #[serde(default = "default_history_dashpot_bound")]
    pub history_dashpot_bound: f64,
    /// Largest number of steps a run may take before it is refused (a step far too small for the
    /// scene would otherwise run for days).
    #[serde(default = "default_max_steps")]
    pub max_steps: u64,
    /// Largest memory a run is estimated to need before it is refused, MiB ([`budget`]).
    #[serde(default = "default_max_memory_mb")]
    pub max_memory_mb: f64,
    /// Largest size of the output files a run is estimated to write before it is refused, MiB
    /// ([`budget`]).
    #[serde(default = "default_max_output_mb")]
    pub max_output_mb: f64,
    /// The box the scene lives in: an apple whose centre leaves it has left the scene (it is
    /// reported and taken out of the run). Without it, only apples that fall below every
    /// surface leave.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scene_bounds: Option<BoundsSpec>,
}

/// An axis-aligned box (`model.scene_bounds`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoundsSpec {
    /// The corner with the smallest coordinates (m).
    pub min_m: [f64; 3],
    /// The corner with the largest coordinates (m).
    pub max_m: [f64; 3],
}

impl BoundsSpec {
    /// Whether the point `p` is inside the box (or on its faces).
    pub fn contains(&self, p: [f64; 3]) -> bool {
        (0..3).all(|i| p[i] >= self.min_m[i] && p[i] <= self.max_m[i])
    }
}

fn default_max_memory_mb() -> f64 {
    budget::DEFAULT_MAX_MEMORY_MB
}

fn default_max_output_mb() -> f64 {
    budget::DEFAULT_MAX_OUTPUT_MB
}

/// 5 %: the discrete energy of a resolved contact ripples by about (pi / N)^2 / 8 with N steps
/// per contact (1.2 % at 10 steps) without drifting; a run that goes unstable grows without bound.
fn default_energy_tolerance() -> f64 {
    0.05
}

fn default_max_steps() -> u64 {
    200_000_000
}

/// Apples at rest cost (almost) nothing: an apple whose speed (centre and surface, |v| and
/// |w| R) stays below `speed_m_s` for `time_s`, with no moving neighbour or moving surface, is
/// put to sleep (not integrated, its contacts with sleeping apples and fixed surfaces not
/// evaluated) and woken when something changes around it. The rule is in `docs/design.md`.
///
/// Unset, the two thresholds follow `accuracy` ([`SleepSpec::rule`]): `preview` freezes apples
/// slower than 1 cm/s for 0.1 s, every other accuracy slower than 5 mm/s for 0.2 s.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SleepSpec {
    /// Whether apples may sleep.
    #[serde(default = "default_true")]
    pub enabled: bool,
    /// Speed below which an apple counts as still (m/s); default by accuracy.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub speed_m_s: Option<f64>,
    /// How long it must stay still before sleeping (s); default by accuracy.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time_s: Option<f64>,
    /// Whether apples at rest on a running belt ride it: carried at its velocity, their contact
    /// frozen, by the same rule in the belt's frame (default true; `layer::sleep`).
    #[serde(default = "default_true")]
    pub carried: bool,
}

/// The sleep thresholds of a run (see [`SleepSpec`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SleepRule {
    /// Speed below which an apple counts as still (m/s).
    pub speed_m_s: f64,
    /// How long it must stay still before sleeping (s).
    pub time_s: f64,
}

impl SleepSpec {
    /// The thresholds: the scenario's own, else those of `accuracy`. `preview` asks for a fast
    /// answer: a pile whose last apples creep at millimetres per second is at rest for it, and
    /// its coarser steps leave a settling pile a little more agitated than `balanced`'s (measured
    /// on the 1000-apple pile, docs/performance.md "Time to an answer": with 5 mm/s and 0.2 s
    /// its top apples slept up to 1 s later than at `balanced`, with 1 cm/s and 0.1 s no later).
    /// `balanced` and `precise` keep 5 mm/s and 0.2 s: 0.1 % of a 1 m/s impact speed.
    pub fn rule(&self, accuracy: Option<Accuracy>) -> SleepRule {
        let (speed, time) = match accuracy {
            Some(Accuracy::Preview) => (0.01, 0.1),
            _ => (0.005, 0.2),
        };
        SleepRule {
            speed_m_s: self.speed_m_s.unwrap_or(speed),
            time_s: self.time_s.unwrap_or(time),
        }
    }
}

impl Default for SleepSpec {
    fn default() -> Self {
        Self {
            enabled: true,
            speed_m_s: None,
            time_s: None,
            carried: true,
        }
    }
}

fn default_max_overlap_ratio() -> f64 {
    0.5
}

fn default_history_dashpot_bound() -> f64 {
    crate::contact::HISTORY_DASHPOT_BOUND
}

fn default_min_steps() -> f64 {
    10.0
}

impl Default for ModelSpec {
    fn default() -> Self {
        Self {
            max_overlap_ratio: default_max_overlap_ratio(),
            min_steps_per_impact: default_min_steps(),
            sleep: SleepSpec::default(),
            energy_tolerance: default_energy_tolerance(),
            history_dashpot_bound: default_history_dashpot_bound(),
            max_steps: default_max_steps(),
            max_memory_mb: default_max_memory_mb(),
            max_output_mb: default_max_output_mb(),
            scene_bounds: None,
        }
    }
}

/// One apple: a uniform solid sphere, or a uniform spheroid when its height differs from its
/// diameter (issue 29, docs/shape.md).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AppleSpec {
    /// Unique name.
    pub name: String,
    /// Material name.
    pub material: String,
    /// Diameter (m): the equatorial one of a spheroid.
    pub diameter_m: f64,
    /// Height (m): the extent along the apple's own z axis, stem to calyx. Absent (or equal to
    /// the diameter): a sphere, on the sphere's exact code path.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub height_m: Option<f64>,
    /// Starting orientation, in the surfaces' forms (axis and angle, or Euler angles): turns the
    /// apple's own axes, its z axis the stem. Identity when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rotation: Option<RotationSpec>,
    /// Mass (kg); default density x volume (of the sphere, or of the spheroid).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mass_kg: Option<f64>,
    /// Centre (m); may be left out for an apple placed `on` a surface.
    #[serde(default = "layout::unset")]
    pub position_m: [f64; 3],
    /// Placed on a surface (resolved into `position_m` when loaded).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub on: Option<layout::OnSpec>,
    /// Centre velocity (m/s).
    #[serde(default)]
    pub velocity_m_s: [f64; 3],
    /// Angular velocity (rad/s).
    #[serde(default)]
    pub angular_velocity_rad_s: [f64; 3],
    /// Makes this apple a virtual instrumented sphere: its accelerometer trace and impact table
    /// are written as a sensor ball reports them (`probe_NAME_trace.csv`,
    /// `probe_NAME_impacts.csv`). Give the apple the device's size, mass and material.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub probe: Option<crate::record::probe::ProbeSpec>,
}

impl AppleSpec {
    /// Height along its own z axis (m): `height_m`, or the diameter (a sphere).
    pub fn height(&self) -> f64 {
        self.height_m.unwrap_or(self.diameter_m)
    }

    /// Whether it is a spheroid: a height given that is not its diameter. Everything else keeps
    /// the sphere's exact code, so that a sphere scenario's outputs do not change.
    pub fn is_spheroid(&self) -> bool {
        self.height_m.is_some_and(|h| h != self.diameter_m)
    }

    /// Its shape: equatorial radius half the diameter, polar half-height half the height.
    pub fn spheroid(&self) -> Spheroid {
        Spheroid::new(0.5 * self.diameter_m, 0.5 * self.height())
    }

    /// Radius of the smallest ball about its centre that holds it, whatever its orientation (m):
    /// half the larger of diameter and height.
    pub fn bounding_radius_m(&self) -> f64 {
        0.5 * self.diameter_m.max(self.height())
    }

    /// Its starting orientation (identity when `rotation` is absent); a mistake names
    /// `{field}.rotation...` (`field` is the apple's path, `apples[3]`).
    pub fn orientation(&self, field: &str) -> Result<Rotation, ScenarioError> {
        surfaces::rotation_of(&self.rotation, field)
    }
}

/// Parses a scenario from JSON text; `file` names the source in messages. A leading UTF-8
/// byte-order mark is skipped (editors on Windows write one); anything but white space after the
/// scenario's closing brace is refused (a second scenario pasted below the first would otherwise
/// be ignored in silence).
pub fn from_json(text: &str, file: &str) -> Result<Scenario, ScenarioError> {
    let mut sc: Scenario = parse_one(text, file)?;
    presets::resolve(&mut sc)?;
    layout::resolve(&mut sc)?;
    Ok(sc)
}

/// Parses exactly one JSON value of type `T` from `text` (after an optional byte-order mark),
/// with every error naming the JSON path of the field at fault (`.` for the top level).
pub(crate) fn parse_one<T: serde::de::DeserializeOwned>(
    text: &str,
    file: &str,
) -> Result<T, ScenarioError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let de = &mut serde_json::Deserializer::from_str(text);
    let value = serde_path_to_error::deserialize(de::Strict(&mut *de)).map_err(|e| {
        let inner = e.inner();
        let path = if inner.is_syntax() || inner.is_eof() {
            // serde knows the enclosing object at best (`model.?`); the text says more.
            de::path_at(text, de::offset_of(text, inner.line(), inner.column()))
        } else {
            e.path().to_string()
        };
        parse_error(file, &path, e.into_inner())
    })?;
    de.end().map_err(|e| ScenarioError::Parse {
        file: one_line(file.to_string()),
        path: ".".into(),
        message: format!(
            "more text after the end of the JSON document at line {} column {}: a file holds one scenario (remove what follows, or split it into files)",
            e.line(),
            e.column()
        ),
    })?;
    Ok(value)
}

/// A parse error at `path` (as `serde_path_to_error` prints it, `.` when empty), with the path
/// a nested deserializer ([`de`]) put in the message joined to it, and a missing field named as
/// the path of that field.
fn parse_error(file: &str, path: &str, e: serde_json::Error) -> ScenarioError {
    let path = if path.is_empty() { "." } else { path };
    let at = if e.line() > 0 {
        format!(" at line {} column {}", e.line(), e.column())
    } else {
        String::new()
    };
    let full = e.to_string();
    let message = full.strip_suffix(&at).unwrap_or(&full);
    let (path, message, at) = match de::split(message) {
        // Found inside a buffered surface or generator: the position is the end of the
        // element, no help; the path is exact.
        Some((inner, rest)) => (de::join(path, inner), rest.to_string(), String::new()),
        None => (path.to_string(), message.to_string(), at),
    };
    // "missing field `x`" at `apples[0]` names `apples[0].x`.
    let (path, message) = match message
        .strip_prefix("missing field `")
        .and_then(|m| m.split_once('`'))
    {
        Some((field, rest)) => (
            de::join(&path, field),
            format!(
                "missing: a required field{rest}{}",
                if at.is_empty() {
                    String::new()
                } else {
                    format!(" (the object ends{at})")
                }
            ),
        ),
        // "duplicate field `x`" at `contact` names `contact.x`.
        None => match message
            .strip_prefix("duplicate field `")
            .and_then(|m| m.split_once('`'))
        {
            Some((field, rest)) => (
                de::join(&path, field),
                format!("given twice{rest}{at}: give each field once"),
            ),
            None => (path, format!("{message}{at}")),
        },
    };
    ScenarioError::Parse {
        file: one_line(file.to_string()),
        path: one_line(path),
        message: one_line(message),
    }
}

/// Reads, parses and validates a scenario file, with the apple lists of its `file` generators
/// (relative to the file's folder).
pub fn load(path: &Path) -> Result<Scenario, ScenarioError> {
    let text = std::fs::read_to_string(path).map_err(|source| ScenarioError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let mut sc = from_json(&text, &path.display().to_string())?;
    sc.read_files(path.parent().unwrap_or(Path::new("")))?;
    validate(&sc)?;
    Ok(sc)
}
