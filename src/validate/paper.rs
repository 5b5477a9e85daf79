//! The paper's words and numbers, and our choices where it is silent, as data: `paper.json`
//! beside this file, compiled in and read once.
//!
//! Each figure of the report is one entry: the spec that runs it, the paper's caption and
//! claims as quoted, the checks that hold the runs to those claims (with the paper's sentence
//! each rests on), the columns of its table and the notes under it. [`super::figures`] has one
//! builder for all of them, so a figure differs from another only here; likewise the errata's
//! titles and quotes ([`super::errata`]) and the report's table of parameters the paper leaves
//! out ([`super::report`]). Changing a quote or a tolerance is an edit of the JSON, not of code.

use serde::Deserialize;
use std::sync::OnceLock;

/// The whole of `paper.json`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Paper {
    /// The paper's Figs. 1-7, in report order.
    pub figures: Vec<FigureSpec>,
    /// The eq. 12 restitution batch: the runs behind errata 4 and 5, not a figure of the paper.
    pub eq12: FigureSpec,
    /// The paper's inconsistencies (physics.md section 9), in order.
    pub errata: Vec<ErratumText>,
    /// The parameters the paper leaves out, what we chose and why (physics.md section 8).
    pub decisions: Vec<Decision>,
}

/// One figure: what runs it and what the paper says about it.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FigureSpec {
    /// `fig1`, ...: the prefix of its check keys and chart files.
    pub id: String,
    /// The batch spec in the specs folder (`fig1.json`).
    pub spec: String,
    /// Heading in the report.
    pub title: String,
    /// What the paper shows and claims, quoted where it is the paper's sentence.
    pub paper: String,
    /// What the runs are and how they are measured.
    pub runs: Runs,
}

/// The two kinds of runs the paper's figures are made of.
#[derive(Debug, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum Runs {
    /// One apple hitting a flat (Figs. 1-5): peak force and contact time.
    Impacts(ImpactSpec),
    /// An apple launched on a plate that slides, then rolls (Figs. 6-7).
    Rolls(RollSpec),
}

/// An impact figure.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImpactSpec {
    /// The apple measured (the bottom layer's middle one in Fig. 5).
    pub apple: String,
    /// The flat it hits: a plane's name or a bin's `NAME/floor`.
    pub other: String,
    /// What the batch varies.
    pub sweep: Sweep,
    /// Title of the force chart.
    pub chart: String,
    /// The checks, in the order the report lists them.
    pub checks: Vec<CheckSpec>,
    /// The table of the runs: caption and what each cell shows.
    pub columns: Vec<(String, Column)>,
    /// Remarks under the table.
    pub notes: Vec<Note>,
}

/// A slip-to-roll figure.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RollSpec {
    /// What the batch varies.
    pub sweep: Sweep,
    /// The paper's bound on the time to rolling (s).
    pub within_s: f64,
    /// The paper's sentence for it.
    pub source: String,
}

/// What a figure's batch varies: it names the runs (legends, table rows), keys their checks
/// and groups and orders them for the trends.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Sweep {
    /// Impact speed (Fig. 1).
    Speed,
    /// Apple diameter at two speeds (Fig. 2).
    SizeAndSpeed,
    /// Apple shear modulus G1 (Fig. 3).
    AppleModulus,
    /// Platform shear modulus G2 (Fig. 4).
    PlatformModulus,
    /// Layers of apples at two landing speeds (Fig. 5).
    LayersAndSpeed,
    /// Eq. 12's ke (the restitution batch).
    Ke,
    /// Launch spin (Fig. 6).
    Spin,
    /// Launch speed along the plate (Fig. 7).
    LaunchSpeed,
}

/// One check of an impact figure, or a group of them.
#[derive(Debug, Deserialize)]
#[serde(tag = "check", rename_all = "snake_case", deny_unknown_fields)]
pub enum CheckSpec {
    /// The peak force and contact time the paper's text quotes for Fig. 1
    /// ([`super::reference::FIG1_QUOTED`]), at the paper's tolerance.
    Quoted {
        /// Where the paper says it.
        source: String,
    },
    /// Every impact's peak force and contact time against the reference integration of the same
    /// impact (in a layered figure, only the apples that land alone).
    Reference,
    /// A trend the paper states, held at every step of the sweep.
    Trend {
        /// Key after `ID/trend/`.
        key: String,
        /// The measure that moves.
        of: Measure,
        /// Which way.
        goes: Direction,
        /// Only the runs up to this value of the sweep (the part the paper's figure varies).
        #[serde(default)]
        up_to: Option<f64>,
        /// The check in words; `{v}` is the speed of the group.
        what: String,
        /// The paper's sentence.
        source: String,
    },
    /// The checks inside, once per impact speed, over that speed's runs.
    PerSpeed {
        /// The checks of each speed.
        checks: Vec<CheckSpec>,
    },
    /// Fig. 1: the contact time falls "slightly": |d ln t / d ln v0| from the slowest to the
    /// fastest run below `limit`.
    TimeFallsSlightly {
        /// Largest log-slope.
        limit: f64,
        /// How "slightly" is read.
        source: String,
    },
    /// Fig. 2: every size stays longer at the lower speed.
    TimeLongerAtLowerSpeed {
        /// The check in words.
        what: String,
        /// The paper's sentence.
        source: String,
    },
    /// Fig. 4: the peak force against steel's, unchanged on stiff platforms and well below it on
    /// platforms no stiffer than the apple.
    PlatformAgainstSteel {
        /// Platforms from this shear modulus on count as stiff (Pa).
        stiff_from_pa: f64,
        /// Largest change of the peak force on a stiff platform (fraction).
        stiff_limit: f64,
        /// The paper's sentence on stiff platforms.
        stiff_source: String,
        /// Smallest reduction on a platform no stiffer than the apple (fraction).
        soft_limit: f64,
        /// The paper's sentence on soft platforms.
        soft_source: String,
    },
    /// The eq. 12 batch: restitution against the integration and against sqrt(ke), and without
    /// gravity peak force and contact time against physics.md section 3.
    Restitution,
}

/// What a trend is about.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Measure {
    /// Peak force of the impact.
    PeakForce,
    /// Its contact time.
    ContactTime,
}

/// Which way a trend goes along the sweep.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Direction {
    /// Rises at every step.
    Up,
    /// Falls at every step.
    Down,
}

/// What a cell of an impact figure's table shows (each in its own format, as the report has
/// always printed it).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Column {
    /// Touch speed (m/s), shortest form.
    TouchSpeed,
    /// Touch speed (m/s), 4 decimals.
    #[serde(rename = "touch_speed_4")]
    TouchSpeed4,
    /// The batch's launch speed (m/s).
    LaunchSpeed,
    /// Layers of apples.
    Layers,
    /// Diameter (mm).
    DiameterMm,
    /// Mass (kg).
    Mass,
    /// Apple shear modulus (MPa).
    AppleModulusMpa,
    /// Platform shear modulus, named ("4e9 Pa (wood)").
    Platform,
    /// G2 / G1.
    ModulusRatio,
    /// Peak force (N).
    PeakForce,
    /// Contact time (ms).
    ContactTime,
    /// Largest overlap / R (%), with this many decimals.
    OverlapPercent(usize),
    /// Peak force against that on steel (%).
    ChangeVsSteel,
    /// The reference integration's peak force (N).
    ReferencePeakForce,
    /// Its contact time (ms).
    ReferenceContactTime,
    /// The no-gravity closed form's peak force (N).
    ClosedFormPeakForce,
    /// Its contact time (ms).
    ClosedFormContactTime,
    /// The paper's quoted point at this speed, if any.
    Quoted,
}

/// A remark under an impact figure's table, computed from its runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Note {
    /// How much gravity adds to the slowest impact (Fig. 1).
    GravityEffect,
    /// The simulator's approach speed against v0 (Fig. 1).
    ApproachSpeed,
    /// The deepest overlap of the sweep (Fig. 4).
    DeepestOverlap,
    /// How much the platforms' unstated Poisson ratio matters (Fig. 4).
    PlatformPoisson,
    /// How much longer the bottom apple stays pressed with more layers (Fig. 5).
    LayersStay,
}

/// The words of one erratum; the evidence with numbers is computed ([`super::errata`]).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ErratumText {
    /// Heading.
    pub title: String,
    /// What the paper says.
    pub paper: String,
    /// Evidence that needs no number (notation), before any computed one.
    #[serde(default)]
    pub evidence: Vec<String>,
}

/// One row of the report's table of parameters the paper leaves out.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Decision {
    /// The parameter.
    pub parameter: String,
    /// What the paper gives.
    pub paper: String,
    /// What we use.
    pub ours: String,
    /// Why.
    pub why: String,
}

/// `paper.json`, parsed on first use. It is compiled in, so a malformed file is a bug of this
/// build, caught by the unit test below before anything runs.
pub fn paper() -> &'static Paper {
    static PAPER: OnceLock<Paper> = OnceLock::new();
    PAPER.get_or_init(|| {
        serde_json::from_str(include_str!("paper.json")).expect("paper.json parses (unit-tested)")
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_json_parses_and_holds_every_figure_and_erratum() {
        let p = paper();
        let ids: Vec<&str> = p.figures.iter().map(|f| f.id.as_str()).collect();
        assert_eq!(
            ids,
            ["fig1", "fig2", "fig3", "fig4", "fig5", "fig6", "fig7"]
        );
        assert_eq!(p.errata.len(), 8);
        assert_eq!(p.decisions.len(), 12);
        for f in &p.figures {
            assert_eq!(f.spec, format!("{}.json", f.id));
        }
    }
}
