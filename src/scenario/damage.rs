//! What a scenario says about fruit damage: the damage model of each apple material
//! (`materials.NAME.damage`), the grading standard (`grading`), and the tables of presets a
//! scenario can name, each number with its source and how well it is sourced (docs/damage.md).
//!
//! The tables are data; the models themselves (energy, pressure-area, peak-force), the sites on
//! the fruit and the grading are pure functions in [`crate::analysis::damage`]. A scenario's own
//! numbers override a calibration file's (`damage.file`, written by `applesim calibrate-bruise`),
//! which override the preset's, which override [`DEFAULT_PRESET`]'s.
//!
//! Source tags, as in the project's literature file (`shared/literature/bruise-models.md`):
//! `\[R-abs\]` read in an abstract, `\[R-reg\]` read in regulation text, `\[R-sec\]` read in a
//! secondary summary, `\[INF\]` our inference, `\[UNV\]` not verified in a source.

use super::{ranges, ScenarioError};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The damage model of apples of one material (`materials.NAME.damage`): a preset, a calibration
/// file, or a model with its coefficients; whatever is left out comes from the preset (default
/// [`DEFAULT_PRESET`]).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DamageSpec {
    /// A preset of [`DAMAGE_PRESETS`] (default [`DEFAULT_PRESET`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub preset: Option<String>,
    /// A calibration file written by `applesim calibrate-bruise` (relative to the scenario): its
    /// model and coefficients fill what this entry leaves out. Read when the scenario is loaded
    /// and written into the run's `scenario.json` as values, with `source` naming the file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub file: Option<String>,
    /// `energy`, `pressure-area` or `peak-force`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub model: Option<DamageModelName>,
    /// Energy model: bruise susceptibility BS, bruise volume per joule the apple absorbs above
    /// the threshold (mm^3/J; 1 ml/J = 1000 mm^3/J).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bruise_susceptibility_mm3_j: Option<f64>,
    /// Energy model: the energy the apple absorbs in one hit below which it does not bruise (J).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub threshold_energy_j: Option<f64>,
    /// Pressure-area model: the contact pressure above which the flesh bruises (Pa): the bruise
    /// is the part of the Hertz patch where the pressure exceeds it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub critical_pressure_pa: Option<f64>,
    /// Peak-force model: the impact peak force above which the apple bruises (N); an onset
    /// model, it gives no bruise size.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub peak_force_n: Option<f64>,
    /// Weight beta in [0, 1] of repeated hits at one site: hardest first, the hits count with
    /// weights 1, beta, beta^2, ... (each repeat adds less; the bruise stabilises).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub repeat_weight: Option<f64>,
    /// Contact-patch width over bruise width (the bruise's surface diameter is the contact
    /// diameter over this).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub width_ratio: Option<f64>,
    /// Bruise depth over the apple's own deformation at the peak (pressure-area model).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub depth_ratio: Option<f64>,
    /// Largest static force of a resting contact (N), flagged in `apple_contacts.csv` (storage
    /// loads); no default.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub static_force_n: Option<f64>,
    /// Largest mean pressure of a resting contact (Pa), flagged likewise; no default.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub static_pressure_pa: Option<f64>,
    /// Where these coefficients come from (free text; a calibration file's name and fit).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub source: Option<String>,
}

/// The damage models (docs/damage.md section 2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum DamageModelName {
    /// Bruise volume linear in the energy the apple absorbs above a threshold.
    Energy,
    /// The part of the Hertz patch above a critical pressure is bruised.
    PressureArea,
    /// Bruised when the peak force exceeds a threshold (onset only).
    PeakForce,
}

impl DamageModelName {
    /// The name a scenario uses.
    pub fn as_str(self) -> &'static str {
        match self {
            DamageModelName::Energy => "energy",
            DamageModelName::PressureArea => "pressure-area",
            DamageModelName::PeakForce => "peak-force",
        }
    }
}

/// One number of a preset with its source.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sourced {
    /// The value (SI, or mm^3/J for a susceptibility).
    pub value: f64,
    /// Where it comes from and how well (a source tag).
    pub source: &'static str,
    /// Its uncertainty as a user should read it.
    pub uncertainty: &'static str,
}

const fn sourced(value: f64, source: &'static str, uncertainty: &'static str) -> Sourced {
    Sourced {
        value,
        source,
        uncertainty,
    }
}

/// A damage preset: a model with its coefficients, each with its source.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DamagePreset {
    /// The name a scenario uses.
    pub name: &'static str,
    /// The cultivar or case.
    pub cultivar: &'static str,
    /// The model.
    pub model: DamageModelName,
    /// Energy model: BS (mm^3/J).
    pub bruise_susceptibility_mm3_j: Option<Sourced>,
    /// Energy model: E_th (J).
    pub threshold_energy_j: Option<Sourced>,
    /// Pressure-area model: p_c (Pa).
    pub critical_pressure_pa: Option<Sourced>,
    /// Peak-force model: F_th (N).
    pub peak_force_n: Option<Sourced>,
    /// What the model was measured on, and outside which the run warns.
    pub validity: Validity,
}

/// Where a model was measured: outside it the run warns (`summary.json` warnings).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Validity {
    /// Largest energy absorbed in one hit that the source's tests reached (J).
    pub max_energy_j: Option<f64>,
    /// Largest peak force the source's tests reached (N).
    pub max_force_n: Option<f64>,
    /// Measured on surfaces much stiffer than the fruit only (a hit where the apple took less
    /// than [`RIGID_SHARE`] of the deformation is outside).
    pub rigid_surfaces_only: bool,
    /// The range in words.
    pub text: &'static str,
}

/// The apple's share of a contact's deformation above which the other body counts as rigid for
/// [`Validity::rigid_surfaces_only`] (the other body at most a tenth as compliant).
pub const RIGID_SHARE: f64 = 0.9;

/// Repeated hits at one site (bruise-models.md M10): hardest first, the hits count with weights
/// 1, beta, beta^2, ... From the potato analogue (Molema 1999, \[R-sec\]): 0.6 J split over 9
/// impacts at one site bruised 64 % less than one impact of 0.6 J; with every hit at 0.067 J,
/// (1 - beta^9) / (9 (1 - beta)) = 0.36 gives beta = 0.70 \[INF\]. The apple pendulum studies say
/// that each repeat adds less and that the bruise stabilises by about the fifth hit \[R-abs\]; the
/// geometric weights do both.
pub const REPEAT_WEIGHT: Sourced = sourced(
    0.7,
    "potato analogue (Molema 1999, via a secondary summary [R-sec]): 9 hits of 0.067 J bruise 36 % of one 0.6 J hit, so (1 - beta^9)/(9 (1 - beta)) = 0.36, beta = 0.70 [INF]; apples: each repeat adds less and the bruise stabilises after about five hits [R-abs]",
    "no apple figure: a fit to another crop's one data point; replace it with your own repeat tests",
);

/// Contact width over bruise width (Stropek & Golacki 2020, pears, the three highest velocities
/// \[R-abs\]).
pub const WIDTH_RATIO: Sourced = sourced(
    1.4,
    "Stropek & Golacki 2020, Postharvest Biol. Technol. 163:111120, pears: contact width about 1.4 x bruise width at the highest velocities [R-abs]",
    "pears, not apples; three velocities",
);

/// Bruise depth over the fruit's peak deformation (same source).
pub const DEPTH_RATIO: Sourced = sourced(
    2.5,
    "Stropek & Golacki 2020 (pears): bruise depth about 2.5 x the peak deformation [R-abs]",
    "pears, not apples; three velocities",
);

const E_TH_GALA: Sourced = sourced(
    0.08,
    "Royal Gala (BC), pendulum, drop steps of 2 cm: 'the bruise threshold of Gala apples was measured to be 0.08 J' (UBC undergraduate report [R-abs], low weight)",
    "one cultivar, one low-weight source; the other presets borrow it",
);

const E_TH_BORROWED: Sourced = sourced(
    0.08,
    "not given for this cultivar: Royal Gala's 0.08 J (UBC report [R-abs], low weight) borrowed",
    "borrowed from another cultivar",
);

const KHORASAN: &str =
    "five Iranian cultivars, pendulum at 0.276, 0.590 and 0.976 J, flat and round impactors (ijbse.ut.ac.ir article 35202 [R-abs])";

const ENERGY_VALIDITY: Validity = Validity {
    max_energy_j: Some(1.0),
    max_force_n: None,
    rigid_surfaces_only: false,
    text: "single hits up to about 1 J absorbed (the pendulum tests reached 0.976 J)",
};

const fn khorasan(name: &'static str, cultivar: &'static str, bs: f64) -> DamagePreset {
    DamagePreset {
        name,
        cultivar,
        model: DamageModelName::Energy,
        bruise_susceptibility_mm3_j: Some(sourced(
            bs,
            KHORASAN,
            "a cultivar mean; the abstract gives no spread",
        )),
        threshold_energy_j: Some(E_TH_BORROWED),
        critical_pressure_pa: None,
        peak_force_n: None,
        validity: ENERGY_VALIDITY,
    }
}

/// The preset a material without `damage.preset` gets.
pub const DEFAULT_PRESET: &str = "generic";

/// The damage presets (docs/damage.md section 3).
pub const DAMAGE_PRESETS: &[DamagePreset] = &[
    DamagePreset {
        name: "generic",
        cultivar: "an apple of unknown cultivar",
        model: DamageModelName::Energy,
        bruise_susceptibility_mm3_j: Some(sourced(
            4700.0,
            "median of the six cultivar values retrieved, 3.71-6.7 ml/J (five Iranian cultivars, ijbse 35202; Royal Gala, UBC) [R-abs]",
            "the cultivars span 3710-6700 mm^3/J (-21 % to +43 %); ripeness, temperature and turgor move it further (WSU-TFREC [R-reg])",
        )),
        threshold_energy_j: Some(E_TH_GALA),
        critical_pressure_pa: None,
        peak_force_n: None,
        validity: ENERGY_VALIDITY,
    },
    DamagePreset {
        name: "royal-gala",
        cultivar: "Royal Gala (British Columbia), fresh (no water immersion)",
        model: DamageModelName::Energy,
        bruise_susceptibility_mm3_j: Some(sourced(
            6700.0,
            "UBC report: 6.7 without immersion, 2.31 after 18 h in water; the unit was lost in the page, ml/J inferred from the magnitudes [R-abs, unit INF]",
            "one low-weight source; falls to 2310 mm^3/J with turgor loss",
        )),
        threshold_energy_j: Some(E_TH_GALA),
        critical_pressure_pa: None,
        peak_force_n: None,
        validity: ENERGY_VALIDITY,
    },
    khorasan("abbasi", "Abbasi", 3710.0),
    khorasan("red-lobnani", "red Lobnani", 3950.0),
    khorasan("golden-lobnani", "golden (yellow) Lobnani", 4120.0),
    khorasan("golshahi", "Golshahi", 5290.0),
    khorasan("aroos", "Aroos", 6230.0),
    DamagePreset {
        name: "flesh-pressure",
        cultivar: "apple flesh (cultivar not stated)",
        model: DamageModelName::PressureArea,
        bruise_susceptibility_mm3_j: None,
        threshold_energy_j: None,
        critical_pressure_pa: Some(sourced(
            2.9e5,
            "'apple flesh failure stress was 0.29 MPa' (static compression with pressure film, Chinese journal Food & Machinery 31(5) [R-abs]); it is within 8 % of the peak Hertz pressure of the paper's apple at Jazz's 22 N no-bruise force on aluminium (0.268 MPa) [INF]",
            "static test; Wang et al. 2024 put the no-bruise edge at 0.10 MPa static; dynamic values unknown",
        )),
        peak_force_n: None,
        validity: Validity {
            max_energy_j: None,
            max_force_n: Some(90.0),
            rigid_surfaces_only: false,
            text: "loads up to about 90 N (the pressure-area mapping erred more above 90 N, Wang et al. 2024 [R-abs])",
        },
    },
    DamagePreset {
        name: "jazz",
        cultivar: "Jazz",
        model: DamageModelName::PeakForce,
        bruise_susceptibility_mm3_j: None,
        threshold_energy_j: None,
        critical_pressure_pa: None,
        peak_force_n: Some(sourced(
            22.0,
            "Fu et al. 2017 (Trans. ASABE) / 2016 ASABE paper 162461461: 'no bruising resulted when apples were impacted at 22 N with the bare aluminum plate' [R-abs]",
            "the highest force without bruising of seven levels, 50 apples each; the onset lies between 22 N and the next level, not given",
        )),
        validity: Validity {
            max_energy_j: None,
            max_force_n: None,
            rigid_surfaces_only: true,
            text: "hard surfaces only: on 12.7 mm foams the same apples took 95-160 N without bruising (Fu et al. [R-abs])",
        },
    },
    DamagePreset {
        name: "paper-firm",
        cultivar: "firm varieties (the paper)",
        model: DamageModelName::PeakForce,
        bruise_susceptibility_mm3_j: None,
        threshold_energy_j: None,
        critical_pressure_pa: None,
        peak_force_n: Some(sourced(
            80.0,
            "the 2019 paper: 80 N for firm varieties (units missing; newtons by context, physics.md section 8)",
            "the paper cites no test",
        )),
        validity: Validity {
            max_energy_j: None,
            max_force_n: None,
            rigid_surfaces_only: true,
            text: "hard surfaces only (a force threshold does not transfer to soft ones)",
        },
    },
    DamagePreset {
        name: "paper-soft",
        cultivar: "soft varieties (the paper)",
        model: DamageModelName::PeakForce,
        bruise_susceptibility_mm3_j: None,
        threshold_energy_j: None,
        critical_pressure_pa: None,
        peak_force_n: Some(sourced(
            37.5,
            "the 2019 paper: 35-40 N for soft varieties (middle of the range)",
            "+-2.5 N as printed; the paper cites no test",
        )),
        validity: Validity {
            max_energy_j: None,
            max_force_n: None,
            rigid_surfaces_only: true,
            text: "hard surfaces only (a force threshold does not transfer to soft ones)",
        },
    },
];

/// The preset named `name`.
pub fn damage_preset(name: &str) -> Option<&'static DamagePreset> {
    DAMAGE_PRESETS.iter().find(|p| p.name == name)
}

/// The grading standard (`grading`): a named standard of [`STANDARDS`], or a user's own table
/// of classes.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GradingSpec {
    /// A standard of [`STANDARDS`] (default [`DEFAULT_STANDARD`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub standard: Option<String>,
    /// A user's own classes, best first (instead of `standard`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub classes: Option<Vec<GradeClass>>,
    /// The grade of an apple that meets no class (with `classes`; default `reject`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub below: Option<String>,
}

/// One class of a grading standard: the bruising it tolerates. A limit left out is not checked;
/// an apple meets the class when its bruises meet every limit given.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GradeClass {
    /// The class's name.
    pub name: String,
    /// Most bruises (0: no bruising at all).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_bruises: Option<u32>,
    /// Largest surface diameter of one bruise (mm).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_bruise_diameter_mm: Option<f64>,
    /// Largest depth of one bruise (mm).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_bruise_depth_mm: Option<f64>,
    /// Largest surface area of one bruise (mm^2).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_bruise_area_mm2: Option<f64>,
    /// Largest volume of one bruise (mm^3).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_bruise_volume_mm3: Option<f64>,
    /// Largest bruised surface area of the apple, all bruises together (mm^2).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_total_area_mm2: Option<f64>,
    /// Largest bruise volume of the apple, all bruises together (mm^3).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_total_volume_mm3: Option<f64>,
}

/// A named grading standard.
#[derive(Debug, Clone, PartialEq)]
pub struct Standard {
    /// The name a scenario uses.
    pub name: &'static str,
    /// The classes, best first.
    pub classes: Vec<GradeClass>,
    /// The grade of an apple that meets none.
    pub below: &'static str,
    /// Where the limits come from and how well.
    pub source: &'static str,
}

/// The standard a scenario without `grading` uses: the US grades with Washington State's bruise
/// sizes, the best-sourced limits retrieved (regulation text).
pub const DEFAULT_STANDARD: &str = "usda-wa";

/// The names of the standards of [`standard`].
pub const STANDARDS: &[&str] = &["usda-wa", "eu", "research-500"];

const IN: f64 = 25.4;

fn class(name: &str) -> GradeClass {
    GradeClass {
        name: name.to_string(),
        ..GradeClass::default()
    }
}

/// A bruise of diameter `d` (mm) and depth `h` (mm) at most: one of WAC 16-403-174's sizes. Lesser
/// bruises that together detract as much count as one (the rule's words): their total area at
/// most that of a disc of diameter `d` \[INF\].
fn wa_class(name: &str, d: f64, h: f64) -> GradeClass {
    GradeClass {
        max_bruise_diameter_mm: Some(d),
        max_bruise_depth_mm: Some(h),
        max_total_area_mm2: Some(std::f64::consts::PI * d * d / 4.0),
        ..class(name)
    }
}

/// The named standard `name` (docs/damage.md section 5).
pub fn standard(name: &str) -> Option<Standard> {
    Some(match name {
        "usda-wa" => Standard {
            name: "usda-wa",
            classes: vec![
                wa_class("US Extra Fancy", 5.0 / 8.0 * IN, IN / 8.0),
                wa_class("US Fancy", 7.0 / 8.0 * IN, 3.0 / 16.0 * IN),
                wa_class("US Utility", 9.0 / 8.0 * IN, 3.0 / 8.0 * IN),
            ],
            below: "cull",
            source: "7 CFR 51.300-301: US Extra Fancy free from injury by bruises, US Fancy free from damage [R-reg]; WAC 16-403-174 bruise sizes [R-reg]: injury > 1/8 in deep or > 5/8 in across, damage > 3/16 in or > 7/8 in, serious damage > 3/8 in or > 1 1/8 in; US Utility free from serious damage [UNV]; lesser bruises that together detract as much: their total area against the disc of the limit [INF]",
        },
        "eu" => Standard {
            name: "eu",
            classes: vec![
                GradeClass {
                    max_bruises: Some(0),
                    ..class("Extra")
                },
                GradeClass {
                    max_total_area_mm2: Some(100.0),
                    ..class("Class I")
                },
                GradeClass {
                    max_total_area_mm2: Some(150.0),
                    ..class("Class II")
                },
            ],
            below: "out of class",
            source: "EU marketing standard for apples (Reg. 543/2011 Annex I Part B Part 1; UNECE FFV-50): Extra free from defects [R-reg]; Class I slight bruising up to 1 cm^2 in total, Class II up to 1.5 cm^2 [UNV: verify on EUR-Lex]; discolouration not modelled",
        },
        "research-500" => Standard {
            name: "research-500",
            classes: vec![GradeClass {
                max_bruise_volume_mm3: Some(500.0),
                ..class("sound")
            }],
            below: "commercially bruised",
            source: "Van Zeebroeck et al. 2008/09, Biosyst. Eng.: 'commercially significant bruising (i.e. apples with bruise volume of maximum bruise above 500 mm3)' [R-abs]",
        },
        _ => return None,
    })
}

/// Reads `damage.file` (relative to `base_dir`): its fields fill what the entry leaves out, and
/// `source` names the file. The file is a JSON object of [`DamageSpec`]'s fields, with its own
/// `source`; it may not name another file.
pub fn read_file(spec: &mut DamageSpec, base_dir: &Path, field: &str) -> Result<(), ScenarioError> {
    let Some(name) = spec.file.take() else {
        return Ok(());
    };
    let path = base_dir.join(&name);
    let f = format!("{field}.file");
    let text = std::fs::read_to_string(&path).map_err(|e| {
        ScenarioError::invalid(&f, format!("cannot read '{}': {e}", path.display()))
    })?;
    let from: DamageSpec = serde_json::from_str(&text).map_err(|e| {
        ScenarioError::invalid(
            &f,
            format!("'{}' is not a damage calibration: {e}", path.display()),
        )
    })?;
    if from.file.is_some() {
        return Err(ScenarioError::invalid(
            &f,
            format!(
                "'{}' names another file: a calibration file holds values only",
                path.display()
            ),
        ));
    }
    macro_rules! fill {
        ($($x:ident),*) => { $( if spec.$x.is_none() { spec.$x = from.$x.clone(); } )* };
    }
    fill!(
        preset,
        model,
        bruise_susceptibility_mm3_j,
        threshold_energy_j,
        critical_pressure_pa,
        peak_force_n,
        repeat_weight,
        width_ratio,
        depth_ratio,
        static_force_n,
        static_pressure_pa
    );
    let fitted = from.source.unwrap_or_default();
    spec.source = Some(match spec.source.take() {
        Some(own) => format!("{own}; file {name}: {fitted}"),
        None => format!("file {name}: {fitted}"),
    });
    Ok(())
}

/// Checks a material's damage entry (`field` its JSON path).
pub fn validate(spec: &DamageSpec, field: &str) -> Result<(), ScenarioError> {
    let preset = match &spec.preset {
        Some(p) => damage_preset(p).ok_or_else(|| {
            let names: Vec<&str> = DAMAGE_PRESETS.iter().map(|p| p.name).collect();
            ScenarioError::invalid(
                format!("{field}.preset"),
                format!("unknown damage preset '{p}': one of {}", names.join(", ")),
            )
        })?,
        None => damage_preset(DEFAULT_PRESET).expect("the default preset is in the table"),
    };
    let f = |x: &str| format!("{field}.{x}");
    if let Some(v) = spec.bruise_susceptibility_mm3_j {
        ranges::BRUISE_SUSCEPTIBILITY.check(&f("bruise_susceptibility_mm3_j"), v)?;
    }
    if let Some(v) = spec.threshold_energy_j {
        ranges::BRUISE_ENERGY_THRESHOLD.check(&f("threshold_energy_j"), v)?;
    }
    if let Some(v) = spec.critical_pressure_pa {
        ranges::BRUISE_PRESSURE.check(&f("critical_pressure_pa"), v)?;
    }
    if let Some(v) = spec.peak_force_n {
        ranges::BRUISE_FORCE.check(&f("peak_force_n"), v)?;
    }
    if let Some(v) = spec.static_force_n {
        ranges::BRUISE_FORCE.check(&f("static_force_n"), v)?;
    }
    if let Some(v) = spec.static_pressure_pa {
        ranges::BRUISE_PRESSURE.check(&f("static_pressure_pa"), v)?;
    }
    if let Some(v) = spec.repeat_weight {
        ranges::REPEAT_WEIGHT.check(&f("repeat_weight"), v)?;
    }
    if let Some(v) = spec.width_ratio {
        ranges::BRUISE_SHAPE_RATIO.check(&f("width_ratio"), v)?;
    }
    if let Some(v) = spec.depth_ratio {
        ranges::BRUISE_SHAPE_RATIO.check(&f("depth_ratio"), v)?;
    }
    // The model needs its coefficients: the entry's, or the preset's when the model is the
    // preset's.
    let model = spec.model.unwrap_or(preset.model);
    let same = model == preset.model;
    let need = |given: Option<f64>, preset_has: bool, name: &str| {
        if given.is_some() || (same && preset_has) {
            Ok(())
        } else {
            Err(ScenarioError::invalid(
                f(name),
                format!(
                    "missing: the {} model needs it (the preset '{}' is a {} model)",
                    model.as_str(),
                    preset.name,
                    preset.model.as_str()
                ),
            ))
        }
    };
    match model {
        DamageModelName::Energy => {
            need(
                spec.bruise_susceptibility_mm3_j,
                preset.bruise_susceptibility_mm3_j.is_some(),
                "bruise_susceptibility_mm3_j",
            )?;
            need(
                spec.threshold_energy_j,
                preset.threshold_energy_j.is_some(),
                "threshold_energy_j",
            )?;
        }
        DamageModelName::PressureArea => need(
            spec.critical_pressure_pa,
            preset.critical_pressure_pa.is_some(),
            "critical_pressure_pa",
        )?,
        DamageModelName::PeakForce => need(
            spec.peak_force_n,
            preset.peak_force_n.is_some(),
            "peak_force_n",
        )?,
    }
    Ok(())
}

/// Checks the grading entry.
pub fn validate_grading(g: &GradingSpec) -> Result<(), ScenarioError> {
    match (&g.standard, &g.classes) {
        (Some(_), Some(_)) => {
            return Err(ScenarioError::invalid(
                "grading",
                "gives both standard and classes: name a standard or give your own classes",
            ))
        }
        (Some(s), None) if standard(s).is_none() => {
            return Err(ScenarioError::invalid(
                "grading.standard",
                format!("unknown standard '{s}': one of {}", STANDARDS.join(", ")),
            ))
        }
        (None, Some(classes)) => {
            if classes.is_empty() {
                return Err(ScenarioError::invalid(
                    "grading.classes",
                    "empty: give at least one class, best first",
                ));
            }
            for (k, c) in classes.iter().enumerate() {
                let f = |x: &str| format!("grading.classes[{k}].{x}");
                if c.name.trim().is_empty() {
                    return Err(ScenarioError::invalid(f("name"), "empty: name the class"));
                }
                for (name, v) in [
                    ("max_bruise_diameter_mm", c.max_bruise_diameter_mm),
                    ("max_bruise_depth_mm", c.max_bruise_depth_mm),
                    ("max_bruise_area_mm2", c.max_bruise_area_mm2),
                    ("max_bruise_volume_mm3", c.max_bruise_volume_mm3),
                    ("max_total_area_mm2", c.max_total_area_mm2),
                    ("max_total_volume_mm3", c.max_total_volume_mm3),
                ] {
                    if let Some(v) = v {
                        ranges::BRUISE_SIZE_LIMIT.check(&f(name), v)?;
                    }
                }
            }
        }
        (None, None) | (Some(_), None) => {}
    }
    if g.below.is_some() && g.classes.is_none() {
        return Err(ScenarioError::invalid(
            "grading.below",
            "goes with classes: a named standard has its own",
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_preset_has_its_models_coefficients_and_validates() {
        for p in DAMAGE_PRESETS {
            let spec = DamageSpec {
                preset: Some(p.name.into()),
                ..Default::default()
            };
            validate(&spec, "m").unwrap_or_else(|e| panic!("{}: {e}", p.name));
            for s in [
                p.bruise_susceptibility_mm3_j,
                p.threshold_energy_j,
                p.critical_pressure_pa,
                p.peak_force_n,
            ]
            .into_iter()
            .flatten()
            {
                assert!(!s.source.is_empty() && !s.uncertainty.is_empty());
            }
        }
        assert!(damage_preset(DEFAULT_PRESET).is_some());
        for s in STANDARDS {
            assert!(standard(s).is_some());
        }
        assert!(standard(DEFAULT_STANDARD).is_some());
    }

    #[test]
    fn a_model_without_its_coefficient_is_refused_naming_it() {
        let spec = DamageSpec {
            model: Some(DamageModelName::PressureArea),
            ..Default::default()
        };
        let e = validate(&spec, "materials.apple.damage")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("materials.apple.damage.critical_pressure_pa"),
            "{e}"
        );
        // The preset's model with its coefficient: fine.
        let spec = DamageSpec {
            preset: Some("flesh-pressure".into()),
            ..Default::default()
        };
        validate(&spec, "m").unwrap();
    }

    #[test]
    fn wa_sizes_in_millimetres() {
        let s = standard("usda-wa").unwrap();
        let c = &s.classes[0];
        assert!((c.max_bruise_diameter_mm.unwrap() - 15.875).abs() < 1e-12);
        assert!((c.max_bruise_depth_mm.unwrap() - 3.175).abs() < 1e-12);
        assert!((c.max_total_area_mm2.unwrap() - 197.93).abs() < 0.01);
    }
}
