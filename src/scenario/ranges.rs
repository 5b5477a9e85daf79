//! The physical ranges of fruit handling: every number of a scenario is checked against one of
//! these before anything is built (README "Scenario format", "Ranges" has the same table).
//!
//! Outside them the physics stops making sense for a packhouse line, or the numbers stop being
//! numbers: a speed of 1e200 m/s passes through the floor in one step, a shear modulus of
//! 5e-324 Pa makes every contact last for ever, a position of 1e308 m leaves no digits for a
//! millimetre of overlap. The ranges are generous (a cherry to a pumpkin, soft foam to diamond,
//! a drop to a bullet) but finite, so a mistyped exponent is refused with the field, the value
//! and the range instead of running into nonsense or a hang.

use super::ScenarioError;

/// One physical range: `min (<|<=) symbol (<|<=) max`, in `unit`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Range {
    /// What is measured (the README table's first column).
    pub quantity: &'static str,
    /// The symbol in messages: `|v|` for a magnitude, `D`, `G`, ...
    pub symbol: &'static str,
    /// SI unit (empty for a pure number).
    pub unit: &'static str,
    /// Smallest value.
    pub min: f64,
    /// Whether `min` itself is refused.
    pub min_open: bool,
    /// Largest value.
    pub max: f64,
    /// Whether `max` itself is refused.
    pub max_open: bool,
    /// The fields it applies to (documentation).
    pub fields: &'static str,
    /// Appended to a refusal: what the bound means.
    pub hint: &'static str,
}

/// A magnitude: |x| <= max.
const fn magnitude(
    quantity: &'static str,
    symbol: &'static str,
    max: f64,
    unit: &'static str,
    fields: &'static str,
) -> Range {
    Range {
        quantity,
        symbol,
        unit,
        min: 0.0,
        min_open: false,
        max,
        max_open: false,
        fields,
        hint: "",
    }
}

/// A closed interval [min, max].
const fn closed(
    quantity: &'static str,
    symbol: &'static str,
    min: f64,
    max: f64,
    unit: &'static str,
    fields: &'static str,
) -> Range {
    Range {
        quantity,
        symbol,
        unit,
        min,
        min_open: false,
        max,
        max_open: false,
        fields,
        hint: "",
    }
}

/// (0, max]: positive, any size down to zero excluded.
const fn positive(
    quantity: &'static str,
    symbol: &'static str,
    max: f64,
    unit: &'static str,
    fields: &'static str,
) -> Range {
    Range {
        quantity,
        symbol,
        unit,
        min: 0.0,
        min_open: true,
        max,
        max_open: false,
        fields,
        hint: "",
    }
}

impl Range {
    const fn hint(self, hint: &'static str) -> Self {
        Range { hint, ..self }
    }

    /// Whether `x` lies in the range (never for NaN).
    pub fn contains(&self, x: f64) -> bool {
        let above = if self.min_open {
            x > self.min
        } else {
            x >= self.min
        };
        let below = if self.max_open {
            x < self.max
        } else {
            x <= self.max
        };
        above && below
    }

    /// The range as written in messages: `|v| <= 100 m/s`, `1000 Pa <= G <= 1e13 Pa`,
    /// `0 < ke <= 1`.
    pub fn describe(&self) -> String {
        let u = |x: f64| with_unit(x, self.unit);
        let hi_op = if self.max_open { "<" } else { "<=" };
        if self.symbol.starts_with('|') && self.min == 0.0 && !self.min_open {
            return format!("{} {hi_op} {}", self.symbol, u(self.max));
        }
        let lo_op = if self.min_open { "<" } else { "<=" };
        format!(
            "{} {lo_op} {} {hi_op} {}",
            u(self.min),
            self.symbol,
            u(self.max)
        )
    }

    /// The refusal of `x` (shown as `shown`, e.g. a vector's magnitude) in `field`.
    pub fn refusal(&self, field: &str, shown: f64) -> ScenarioError {
        let hint = if self.hint.is_empty() {
            String::new()
        } else {
            format!("; {}", self.hint)
        };
        ScenarioError::invalid(
            field,
            format!(
                "{} is outside the range of fruit handling ({}){hint}",
                with_unit(shown, self.unit),
                self.describe()
            ),
        )
    }

    /// Checks one number.
    pub fn check(&self, field: &str, x: f64) -> Result<(), ScenarioError> {
        if self.contains(x) {
            Ok(())
        } else {
            Err(self.refusal(field, x))
        }
    }

    /// Checks a vector's magnitude (speeds, accelerations): the field is the whole vector.
    pub fn check_norm(&self, field: &str, v: [f64; 3]) -> Result<(), ScenarioError> {
        // Scaled so that components near f64::MAX do not overflow to an infinite length.
        let m = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let len = if m > 0.0 && m.is_finite() {
            m * v.iter().map(|x| (x / m) * (x / m)).sum::<f64>().sqrt()
        } else {
            m
        };
        if v.iter().all(|x| x.is_finite()) && self.contains(len) {
            Ok(())
        } else {
            Err(self.refusal(field, len))
        }
    }

    /// Checks each component (positions, sizes): the field named is the component, `field[i]`.
    pub fn check_each(&self, field: &str, v: [f64; 3]) -> Result<(), ScenarioError> {
        for (i, &x) in v.iter().enumerate() {
            self.check_component(field, i, x)?;
        }
        Ok(())
    }

    /// Checks one component `field[i]`; a magnitude range applies to |x|.
    fn check_component(&self, field: &str, i: usize, x: f64) -> Result<(), ScenarioError> {
        let y = if self.symbol.starts_with('|') {
            x.abs()
        } else {
            x
        };
        if self.contains(y) {
            Ok(())
        } else {
            Err(self.refusal(&format!("{field}[{i}]"), x))
        }
    }

    /// Checks a signed number whose magnitude is bounded (a belt speed): |x| in the range.
    pub fn check_abs(&self, field: &str, x: f64) -> Result<(), ScenarioError> {
        if self.contains(x.abs()) {
            Ok(())
        } else {
            Err(self.refusal(field, x))
        }
    }
}

/// A number as written in messages: plain for ordinary magnitudes, scientific for very large or
/// very small ones (`1e200`, not two hundred digits).
pub fn num(x: f64) -> String {
    let a = x.abs();
    if a != 0.0 && a.is_finite() && !(1e-4..1e5).contains(&a) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

/// [`num`] rounded to three significant digits, for derived figures (`0.0134`).
pub fn num3(x: f64) -> String {
    num(format!("{x:.2e}").parse().unwrap_or(x))
}

fn with_unit(x: f64, unit: &str) -> String {
    if unit.is_empty() {
        num(x)
    } else {
        format!("{} {unit}", num(x))
    }
}

/// Speeds of apples, generated apples, sources and belts.
pub const SPEED: Range = magnitude(
    "speed",
    "|v|",
    100.0,
    "m/s",
    "`velocity_m_s` of apples, generators and sources (magnitude), `belt_velocity_m_s`, `motion.translation.velocity_m_s` (magnitude) and the speed between two `motion.translation.keyframes`, a roller's surface speed `angular_velocity_rad_s` x `radius_m`",
);
/// Speed thresholds (slip detection, sleep).
pub const SPEED_THRESHOLD: Range = positive(
    "speed threshold",
    "v",
    100.0,
    "m/s",
    "`output.transitions.slip_speed_m_s`, `model.sleep.speed_m_s`",
);
/// Spin of an apple.
pub const ANGULAR_SPEED: Range = magnitude(
    "angular speed",
    "|w|",
    1e4,
    "rad/s",
    "`apples[].angular_velocity_rad_s` (magnitude), a roller's and `motion.rotation`'s `angular_velocity_rad_s`, the rate between two `motion.rotation.keyframes`",
);
/// Gravity (an acceleration; zero for the paper's gravity-free checks).
pub const ACCELERATION: Range = magnitude(
    "acceleration",
    "|g|",
    1000.0,
    "m/s^2",
    "`gravity_m_s2` (magnitude; 0 allowed)",
);
/// Every coordinate of a position.
pub const POSITION: Range = magnitude(
    "position",
    "|x|",
    1e4,
    "m",
    "each coordinate of `position_m`, `point_m`, `origin_m`, `region_min_m`, `region_max_m`, `motion.translation.keyframes` offsets, and of every generated apple",
);
/// How far a `place` moves a surface from the port it is put at.
pub const OFFSET: Range = magnitude(
    "placement offset",
    "|d|",
    1e4,
    "m",
    "`place.gap_m`, `place.drop_m`, `place.side_m`",
);
/// The gap between an apple put `on` a surface and the surface.
pub const CLEARANCE: Range = closed(
    "clearance",
    "c",
    0.0,
    1e4,
    "m",
    "`on.clearance_m` (0: the apple touches the surface)",
);
/// Apple diameters.
pub const DIAMETER: Range = closed(
    "apple diameter",
    "D",
    1e-3,
    1.0,
    "m",
    "`diameter_m` (apples, generators, sources, file lists; a distribution's whole span), `mean_m`",
);
/// The spread of a diameter distribution.
pub const DIAMETER_SPREAD: Range = closed(
    "diameter spread",
    "s",
    0.0,
    1.0,
    "m",
    "`diameter_m.spread_m`",
);
/// Apple heights (stem to calyx): at most twice the largest diameter ([`ASPECT`]).
pub const HEIGHT: Range = positive(
    "apple height",
    "H",
    2.0,
    "m",
    "`height_m` (apples, file lists)",
);
/// Height over diameter of a spheroidal apple: cultivars run about 0.8 to 1.1 (issue 29); past
/// 2:1 either way a fruit is a disc or a rod, not an apple.
pub const ASPECT: Range = closed(
    "apple aspect",
    "H/D",
    0.5,
    2.0,
    "",
    "`height_m` / `diameter_m` (apples, file lists), `aspect` (generators, sources; a distribution's whole span), `aspect.mean`",
);
/// The spread of an aspect distribution.
pub const ASPECT_SPREAD: Range = closed("aspect spread", "s", 0.0, 1.5, "", "`aspect.spread`");
/// Apple masses.
pub const MASS: Range = closed("apple mass", "m", 1e-5, 1000.0, "kg", "`mass_kg`");
/// Sizes of surfaces and spacings.
pub const LENGTH: Range = closed(
    "length",
    "L",
    1e-4,
    1e4,
    "m",
    "`size_m`, `inner_size_m`, `length_m`, `width_m`, `radius_m`, `thickness_m`, `wall_thickness_m`, `spacing_m`",
);
/// Thickness of a pad bonded on a surface (docs/physics.md section 13).
pub const PAD_THICKNESS: Range = positive("pad thickness", "h", 0.1, "m", "`padding.thickness_m`");
/// Random offsets.
pub const JITTER: Range = closed(
    "jitter",
    "j",
    0.0,
    10.0,
    "m",
    "`jitter_m` (a number, or each of `[jx, jy, jz]`)",
);
/// Histogram bins of the slip/roll summary.
pub const BIN: Range = closed(
    "histogram bin",
    "b",
    1e-3,
    100.0,
    "m",
    "`output.transitions.histogram_bin_m`",
);
/// Elastic moduli.
pub const MODULUS: Range = closed(
    "elastic modulus",
    "modulus",
    1e3,
    1e13,
    "Pa",
    "`shear_modulus_pa`, `youngs_modulus_pa` (and the one derived from the other)",
)
.hint("soft foam to diamond");
/// Poisson's ratio.
pub const POISSON: Range = Range {
    quantity: "Poisson's ratio",
    symbol: "nu",
    unit: "",
    min: -1.0,
    min_open: true,
    max: 0.5,
    max_open: true,
    fields: "`poisson_ratio`",
    hint: "0.5 is incompressible, outside Hertz theory",
};
/// Densities.
pub const DENSITY: Range = closed(
    "density",
    "rho",
    1.0,
    1e5,
    "kg/m^3",
    "`density_kg_m3`; a given `mass_kg` over the apple's volume",
);
/// Coulomb friction coefficients.
pub const FRICTION: Range = closed(
    "friction coefficient",
    "mu",
    0.0,
    10.0,
    "",
    "`friction` (contact, pairs)",
);
/// The eq. 12 energy-loss coefficient.
pub const KE: Range = positive(
    "eq. 12 energy-loss coefficient",
    "ke",
    1.0,
    "",
    "`ke` (contact, pairs)",
)
.hint("1 is elastic, restitution tends to sqrt(ke)");
/// The eq. 12 rate constant.
pub const LAMBDA: Range = closed(
    "eq. 12 rate constant",
    "lambda",
    0.0,
    1e6,
    "s/m",
    "`lambda_s_m` (contact, pairs)",
);
/// Simulated times and intervals.
pub const DURATION: Range = closed(
    "duration",
    "t",
    1e-9,
    1e5,
    "s",
    "`duration_s`, `output.sample_interval_s`, `output.vtk.interval_s`, `model.sleep.time_s` (1e5 s: 28 hours of line)",
);
/// Moments in a run (may be 0).
pub const TIME: Range = closed(
    "time",
    "t",
    0.0,
    1e5,
    "s",
    "`sources[].start_s`, `output.transitions.min_dwell_s`, `motion` keyframe times",
);
/// Time steps.
pub const TIME_STEP: Range = closed(
    "time step",
    "dt",
    1e-9,
    1.0,
    "s",
    "`time_step_s` (a number), `max_time_step_s`",
);
/// Steps per contact (accuracy targets).
pub const STEPS_PER_CONTACT: Range = closed(
    "steps per contact",
    "n",
    5.0,
    1e4,
    "",
    "`accuracy` (a number)",
)
.hint("10 is about 1 % on peak forces");
/// The fewest steps an impact may take with a fixed step (0 turns the check off).
pub const MIN_STEPS: Range = closed(
    "fewest steps per impact",
    "n",
    0.0,
    1e4,
    "",
    "`model.min_steps_per_impact`",
);
/// Emission rates of sources.
pub const RATE: Range = closed(
    "emission rate",
    "r",
    1e-6,
    1e4,
    "/s",
    "`sources[].rate_per_s`",
);
/// Apples in one scenario: listed, generated and fed in, together.
pub const APPLE_COUNT: Range = closed(
    "apples in a scenario",
    "N",
    0.0,
    1e6,
    "",
    "`apples`, `generators[].count`, `sources[].count` together",
);
/// Largest overlap as a fraction of the radius.
pub const OVERLAP_RATIO: Range =
    positive("overlap ratio", "u/R", 1.0, "", "`model.max_overlap_ratio`");
/// The bound of LIGGGHTS's tangential dashpot (`contact::HISTORY_DASHPOT_BOUND`): below 2, where
/// the explicit dashpot overshoots and grows.
pub const HISTORY_DASHPOT_BOUND: Range = Range {
    quantity: "history dashpot bound",
    symbol: "b",
    unit: "",
    min: 0.0,
    min_open: true,
    max: 2.0,
    max_open: true,
    fields: "`model.history_dashpot_bound`",
    hint: "at 2 LIGGGHTS's explicit tangential dashpot overshoots and grows; the default is 1.5",
};
/// Energy rise tolerated, as a fraction.
pub const ENERGY_TOLERANCE: Range = positive(
    "energy tolerance",
    "dE/E",
    1000.0,
    "",
    "`model.energy_tolerance`",
);
/// Memory budget of a run (MiB).
pub const MEMORY_BUDGET: Range = closed(
    "memory budget",
    "M",
    1.0,
    1e8,
    "MiB",
    "`model.max_memory_mb`",
);
/// Output budget of a run (MiB).
pub const OUTPUT_BUDGET: Range = closed(
    "output budget",
    "S",
    1.0,
    1e9,
    "MiB",
    "`model.max_output_mb`",
);
/// Coefficient of restitution.
pub const RESTITUTION: Range = positive("restitution", "e", 1.0, "", "`restitution`");
/// Coefficient of rolling friction (the rolling torque's lever over R*).
pub const ROLLING_FRICTION: Range = closed(
    "rolling friction",
    "mu_r",
    0.0,
    1.0,
    "",
    "`rolling_friction`",
);
/// Damping ratio of the rolling spring.
pub const ROLLING_DAMPING: Range = closed(
    "rolling damping",
    "eta_r",
    0.0,
    10.0,
    "",
    "`rolling_damping`",
);
/// Step budget of a run.
pub const MAX_STEPS: Range = closed("step budget", "steps", 1.0, 1e12, "", "`model.max_steps`");
/// The slip detector's relative tolerance.
pub const RELATIVE_TOLERANCE: Range = closed(
    "relative tolerance",
    "r",
    0.0,
    100.0,
    "",
    "`output.transitions.relative_tolerance`",
);
/// The slip detector's hysteresis factor.
pub const HYSTERESIS: Range = closed(
    "hysteresis factor",
    "h",
    1.0,
    1000.0,
    "",
    "`output.transitions.hysteresis`",
);
/// Mesh scale factors.
pub const SCALE: Range = closed(
    "mesh scale",
    "s",
    1e-6,
    1e6,
    "",
    "`surfaces[].scale` (each factor)",
);
/// Rotation angles.
pub const ANGLE: Range = magnitude(
    "rotation angle",
    "|a|",
    360.0,
    "deg",
    "`rotation.angle_deg`, `rotation.euler_xyz_deg`",
);
/// Angles turned by a keyframed rotation (a part may turn many times).
pub const TURN: Range = magnitude(
    "turned angle",
    "|a|",
    1e9,
    "deg",
    "`motion.rotation.keyframes` angles",
);
/// Chute slopes.
pub const INCLINE: Range = Range {
    quantity: "chute slope",
    symbol: "incline",
    unit: "deg",
    min: -90.0,
    min_open: true,
    max: 90.0,
    max_open: true,
    fields: "`incline_deg`",
    hint: "",
};
/// Angular half-width of a trough.
pub const HALF_ANGLE: Range = positive("trough half-angle", "a", 90.0, "deg", "`half_angle_deg`");
/// Damage model: force thresholds.
pub const BRUISE_FORCE: Range = positive(
    "bruise force",
    "F",
    1e6,
    "N",
    "`damage.peak_force_n`, `damage.static_force_n`",
);
/// Damage model: pressure thresholds.
pub const BRUISE_PRESSURE: Range = positive(
    "bruise pressure",
    "p",
    1e10,
    "Pa",
    "`damage.critical_pressure_pa`, `damage.static_pressure_pa`",
);
/// Damage model: the energy threshold.
pub const BRUISE_ENERGY_THRESHOLD: Range = closed(
    "bruise threshold energy",
    "E_th",
    0.0,
    1e4,
    "J",
    "`damage.threshold_energy_j`",
);
/// Damage model: bruise susceptibility.
pub const BRUISE_SUSCEPTIBILITY: Range = positive(
    "bruise susceptibility",
    "BS",
    1e9,
    "mm^3/J",
    "`damage.bruise_susceptibility_mm3_j` (1 ml/J = 1000 mm^3/J)",
);
/// Damage model: the weight of repeated hits.
pub const REPEAT_WEIGHT: Range = closed(
    "repeat weight",
    "beta",
    0.0,
    1.0,
    "",
    "`damage.repeat_weight`",
);
/// Damage model: bruise shape ratios.
pub const BRUISE_SHAPE_RATIO: Range = closed(
    "bruise shape ratio",
    "r",
    0.01,
    100.0,
    "",
    "`damage.width_ratio`, `damage.depth_ratio`",
);
/// Grading limits.
pub const BRUISE_SIZE_LIMIT: Range = closed(
    "grading limit (mm, mm^2 or mm^3)",
    "L",
    0.0,
    1e9,
    "",
    "`grading.classes[].max_bruise_diameter_mm`, `max_bruise_depth_mm`, `max_bruise_area_mm2`, `max_bruise_volume_mm3`, `max_total_area_mm2`, `max_total_volume_mm3`",
);
/// A material's loss factor.
pub const LOSS_FACTOR: Range = closed(
    "loss factor",
    "eta",
    0.0,
    1.0,
    "",
    "`materials.NAME.loss_factor` (the share of its stored energy a body dissipates)",
);
/// Sampling rates of a virtual instrumented sphere.
pub const PROBE_RATE: Range = closed(
    "probe sampling rate",
    "f",
    1.0,
    1e7,
    "Hz",
    "`probe.sample_rate_hz`",
);
/// Trigger levels of a virtual instrumented sphere.
pub const PROBE_TRIGGER: Range =
    positive("probe trigger level", "a", 1e5, "g", "`probe.trigger_g`");
/// The window a virtual instrumented sphere keeps around an impact.
pub const PROBE_WINDOW: Range = closed("probe window", "w", 0.0, 1.0, "s", "`probe.window_s`");

/// A free-turning roller's own moment of inertia about its axis.
pub const ROLLER_INERTIA: Range = positive(
    "roller moment of inertia",
    "I",
    100.0,
    "kg m^2",
    "`free_turning.moment_of_inertia_kg_m2`",
);
/// A free-turning roller's bearing friction torque.
pub const BEARING_TORQUE: Range = closed(
    "bearing torque",
    "T",
    0.0,
    1000.0,
    "N m",
    "`free_turning.bearing_torque_n_m`",
);

/// Every range, in the README's order.
pub const TABLE: &[Range] = &[
    SPEED,
    SPEED_THRESHOLD,
    ANGULAR_SPEED,
    ACCELERATION,
    POSITION,
    OFFSET,
    CLEARANCE,
    DIAMETER,
    DIAMETER_SPREAD,
    HEIGHT,
    ASPECT,
    ASPECT_SPREAD,
    MASS,
    LENGTH,
    PAD_THICKNESS,
    JITTER,
    BIN,
    MODULUS,
    POISSON,
    DENSITY,
    FRICTION,
    KE,
    LAMBDA,
    RESTITUTION,
    ROLLING_FRICTION,
    ROLLING_DAMPING,
    DURATION,
    TIME,
    TIME_STEP,
    STEPS_PER_CONTACT,
    MIN_STEPS,
    RATE,
    APPLE_COUNT,
    MEMORY_BUDGET,
    OUTPUT_BUDGET,
    OVERLAP_RATIO,
    ENERGY_TOLERANCE,
    HISTORY_DASHPOT_BOUND,
    MAX_STEPS,
    RELATIVE_TOLERANCE,
    HYSTERESIS,
    SCALE,
    ANGLE,
    TURN,
    INCLINE,
    HALF_ANGLE,
    ROLLER_INERTIA,
    BEARING_TORQUE,
    BRUISE_FORCE,
    BRUISE_PRESSURE,
    BRUISE_ENERGY_THRESHOLD,
    BRUISE_SUSCEPTIBILITY,
    REPEAT_WEIGHT,
    BRUISE_SHAPE_RATIO,
    BRUISE_SIZE_LIMIT,
    LOSS_FACTOR,
    PROBE_RATE,
    PROBE_TRIGGER,
    PROBE_WINDOW,
];

/// The table as Markdown rows (`| quantity | range | fields |`), as in the README.
pub fn markdown_table() -> String {
    let mut s = String::from("| quantity | range | fields |\n|---|---|---|\n");
    for r in TABLE {
        s.push_str(&format!(
            "| {} | `{}` | {} |\n",
            r.quantity,
            // A bar in a table cell ends the cell, even inside backticks.
            r.describe().replace('|', "\\|"),
            r.fields
        ));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages() {
        let e = SPEED
            .check_norm("apples[0].velocity_m_s", [0.0, 0.0, -1e200])
            .unwrap_err();
        assert_eq!(
            e.to_string(),
            "apples[0].velocity_m_s: 1e200 m/s is outside the range of fruit handling (|v| <= 100 m/s)"
        );
        assert_eq!(MODULUS.describe(), "1000 Pa <= modulus <= 1e13 Pa");
        assert_eq!(KE.describe(), "0 < ke <= 1");
        assert!(SPEED.check_norm("v", [f64::MAX, f64::MAX, 0.0]).is_err());
        assert!(SPEED.check_norm("v", [60.0, 60.0, 60.0]).is_err());
        assert!(SPEED.check_norm("v", [0.0, 0.0, -1.4]).is_ok());
        assert!(DURATION.check("t", f64::NAN).is_err());
        let e = POSITION
            .check_each("apples[0].position_m", [0.0, 1e308, 0.0])
            .unwrap_err();
        assert!(e
            .to_string()
            .starts_with("apples[0].position_m[1]: 1e308 m"));
        assert_eq!(num(5e-324), "5e-324");
        assert_eq!(num(0.08), "0.08");
        assert_eq!(num(-1100000.0), "-1.1e6");
        assert_eq!(num3(0.013404128655316453), "0.0134");
        assert_eq!(num3(1234567.0), "1.23e6");
    }

    #[test]
    fn the_readme_holds_the_table() {
        let readme = include_str!("../../README.md");
        assert!(
            readme.contains(&markdown_table()),
            "README's range table is out of date; it should read:\n{}",
            markdown_table()
        );
    }
}
