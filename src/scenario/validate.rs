//! Validation of a parsed scenario: every check names the field and the value it saw, and every
//! number is checked against its physical range ([`super::ranges`]).

use super::generators::{FileSpec, GeneratorSpec};
use super::ranges::{self, num};
use super::surfaces::{rotation_of, ChuteProfile, ContactModel, RollerSpec, Scale, SurfaceSpec};
use super::{models, AppleSpec, ContactSpec, Scenario, ScenarioError, TimeStep};
use crate::contact::{Material, MaterialError};
use crate::layer::grid::NeighborList;
use crate::math::{vec3, Vec3};
use std::collections::{BTreeMap, HashSet};

mod feed;
use feed::*;

type R = Result<(), ScenarioError>;

/// Longest name of an apple, surface, material or generator (characters).
pub const MAX_NAME_CHARS: usize = 256;

/// Checks a unit vector given by the user (normals): zero and non-unit vectors are refused
/// rather than silently normalised, because a wrong normal usually means a wrong layout.
pub(crate) fn unit3(field: &str, v: [f64; 3]) -> R {
    let len = vec3(v).length();
    if !(len.is_finite() && (len - 1.0).abs() <= 1e-6) {
        return Err(ScenarioError::invalid(
            field,
            format!(
                "[{}, {}, {}] has length {}: give a unit vector",
                num(v[0]),
                num(v[1]),
                num(v[2]),
                num(len)
            ),
        ));
    }
    Ok(())
}

/// A name: not empty, no control characters, at most [`MAX_NAME_CHARS`] characters.
fn name(field: &str, n: &str) -> R {
    if n.trim().is_empty() {
        return Err(ScenarioError::invalid(field, "empty name"));
    }
    if n.chars().any(char::is_control) {
        return Err(ScenarioError::invalid(
            field,
            format!("'{n}' holds a control character (a line break, a tab...): names are one line of text"),
        ));
    }
    let chars = n.chars().count();
    if chars > MAX_NAME_CHARS {
        return Err(ScenarioError::invalid(
            field,
            format!("a name of {chars} characters: give at most {MAX_NAME_CHARS}"),
        ));
    }
    Ok(())
}

/// The material built from a spec, with the error naming the field.
pub(crate) fn material(name: &str, m: &super::MaterialSpec) -> Result<Material, ScenarioError> {
    let base = format!("materials.{name}");
    let preset_note = || match &m.preset {
        Some(p) => format!(" (the preset '{p}' does not give one: its source does not)"),
        None => String::new(),
    };
    let Some(nu) = m.poisson_ratio else {
        return Err(match &m.preset {
            // A preset that does not give it: the field is what is missing.
            Some(_) => ScenarioError::invalid(
                format!("{base}.poisson_ratio"),
                format!(
                    "missing: a material needs its Poisson's ratio{}",
                    preset_note()
                ),
            ),
            // Neither the field nor a preset: the material says too little.
            None => ScenarioError::invalid(
                base,
                "gives no poisson_ratio and no preset that gives one: a material needs its Poisson's ratio",
            ),
        });
    };
    ranges::POISSON.check(&format!("{base}.poisson_ratio"), nu)?;
    if let Some(rho) = m.density_kg_m3 {
        ranges::DENSITY.check(&format!("{base}.density_kg_m3"), rho)?;
    }
    let built =
        match (m.shear_modulus_pa, m.youngs_modulus_pa) {
            (Some(g), None) => {
                ranges::MODULUS.check(&format!("{base}.shear_modulus_pa"), g)?;
                Material::from_shear(g, nu, m.density_kg_m3)
            }
            (None, Some(e)) => {
                ranges::MODULUS.check(&format!("{base}.youngs_modulus_pa"), e)?;
                Material::from_youngs(e, nu, m.density_kg_m3)
            }
            (Some(_), Some(_)) => return Err(ScenarioError::invalid(
                base,
                "gives both shear_modulus_pa and youngs_modulus_pa: give one (E = 2 G (1 + nu))",
            )),
            (None, None) => {
                return Err(ScenarioError::invalid(
                    base,
                    format!(
                        "needs shear_modulus_pa or youngs_modulus_pa{}",
                        preset_note()
                    ),
                ))
            }
        };
    let built = built.map_err(|e| match e {
        MaterialError::BadModulus { field, value } => {
            ranges::MODULUS.refusal(&format!("{base}.{field}"), value)
        }
        MaterialError::BadPoisson(nu) => {
            ranges::POISSON.refusal(&format!("{base}.poisson_ratio"), nu)
        }
        MaterialError::BadDensity(rho) => {
            ranges::DENSITY.refusal(&format!("{base}.density_kg_m3"), rho)
        }
        MaterialError::BadLossFactor(eta) => {
            ranges::LOSS_FACTOR.refusal(&format!("{base}.loss_factor"), eta)
        }
    })?;
    let built = match m.loss_factor {
        Some(eta) => {
            ranges::LOSS_FACTOR.check(&format!("{base}.loss_factor"), eta)?;
            built
                .with_loss_factor(eta)
                .map_err(|_| ranges::LOSS_FACTOR.refusal(&format!("{base}.loss_factor"), eta))?
        }
        None => built,
    };
    // The modulus derived from the other one and nu must make sense too (nu near -1 makes
    // G = E / (2 (1 + nu)) explode).
    // The field named: Poisson's ratio when a typical one (0.3) would have made the derived
    // modulus sensible, else the modulus given (G = E / 2.6 of 2000 Pa is out of range whatever
    // nu: the modulus is the mistake).
    let given = if m.shear_modulus_pa.is_some() {
        ("shear_modulus_pa", m.shear_modulus_pa.unwrap_or(0.0))
    } else {
        ("youngs_modulus_pa", m.youngs_modulus_pa.unwrap_or(0.0))
    };
    let typical = if m.shear_modulus_pa.is_some() {
        2.0 * given.1 * 1.3
    } else {
        given.1 / 2.6
    };
    let culprit = if ranges::MODULUS.contains(typical) {
        "poisson_ratio"
    } else {
        given.0
    };
    for (derived, symbol, v) in [
        ("shear", "G", built.shear_modulus_pa),
        ("Young's", "E", built.youngs_modulus_pa),
    ] {
        if !ranges::MODULUS.contains(v) {
            return Err(ScenarioError::invalid(
                format!("{base}.{culprit}"),
                if culprit == "poisson_ratio" {
                    format!(
                        "{} gives a {derived} modulus {symbol} = {} Pa, outside the range of fruit handling ({})",
                        num(nu),
                        ranges::num3(v),
                        ranges::MODULUS.describe()
                    )
                } else {
                    format!(
                        "{} Pa with poisson_ratio {} gives a {derived} modulus {symbol} = {} Pa, outside the range of fruit handling ({})",
                        num(given.1),
                        num(nu),
                        ranges::num3(v),
                        ranges::MODULUS.describe()
                    )
                },
            ));
        }
    }
    Ok(built)
}

fn coefficients(field: &str, friction: Option<f64>, ke: Option<f64>, lambda: Option<f64>) -> R {
    if let Some(mu) = friction {
        ranges::FRICTION.check(&format!("{field}.friction"), mu)?;
    }
    if let Some(ke) = ke {
        ranges::KE.check(&format!("{field}.ke"), ke)?;
    }
    if let Some(l) = lambda {
        ranges::LAMBDA.check(&format!("{field}.lambda_s_m"), l)?;
    }
    Ok(())
}

/// A pair's contact law as a whole (`field` names where it was written): the eq. 12 dampings
/// need ke and lambda, the viscoelastic one a restitution in (0, 1]; the rolling friction is a
/// coefficient like friction. A missing coefficient is named where `contact` would give it.
fn law(field: &str, c: &ContactSpec) -> R {
    coefficients(field, Some(c.friction), c.ke, c.lambda_s_m)?;
    if c.damping.uses_eq12() {
        for (name, v) in [("ke", c.ke), ("lambda_s_m", c.lambda_s_m)] {
            if v.is_none() {
                return Err(ScenarioError::invalid(
                    format!("{field}.{name}"),
                    format!(
                        "missing: the {} damping needs ke and lambda_s_m (or choose \"damping\": \"viscoelastic\" with a restitution)",
                        serde_json::to_value(c.damping).map(|v| v.to_string()).unwrap_or_default()
                    ),
                ));
            }
        }
    }
    match c.restitution {
        Some(e) => ranges::RESTITUTION.check(&format!("{field}.restitution"), e)?,
        None if c.damping == models::Damping::Viscoelastic => return Err(ScenarioError::invalid(
            format!("{field}.restitution"),
            "missing: the viscoelastic damping needs the coefficient of restitution (0 < e <= 1)",
        )),
        None => {}
    }
    ranges::ROLLING_FRICTION.check(&format!("{field}.rolling_friction"), c.rolling_friction)?;
    ranges::ROLLING_DAMPING.check(&format!("{field}.rolling_damping"), c.rolling_damping)
}

/// Validates everything that can be checked without building the world.
pub fn validate(sc: &Scenario) -> R {
    ranges::DURATION
        .check("duration_s", sc.duration_s)
        .map_err(|e| with_step_estimate(e, sc))?;
    if let TimeStep::Fixed(dt) = sc.time_step_s {
        ranges::TIME_STEP
            .check("time_step_s", dt)
            .map_err(|e| with_step_estimate(e, sc))?;
        if dt > sc.duration_s {
            return Err(ScenarioError::invalid(
                "time_step_s",
                format!(
                    "{} s is longer than duration_s = {} s",
                    num(dt),
                    num(sc.duration_s)
                ),
            ));
        }
    }
    if let Some(a) = sc.accuracy {
        ranges::STEPS_PER_CONTACT
            .check("accuracy", a.steps_per_contact())
            .map_err(|e| with_step_estimate(e, sc))?;
    }
    if let Some(m) = sc.max_time_step_s {
        ranges::TIME_STEP.check("max_time_step_s", m)?;
    }
    ranges::ACCELERATION.check_norm("gravity_m_s2", sc.gravity_m_s2)?;
    output(sc)?;
    model(sc)?;
    if sc.materials.is_empty() {
        return Err(ScenarioError::invalid("materials", "no material defined"));
    }
    let mut mats = BTreeMap::new();
    for (n, m) in &sc.materials {
        name(&format!("materials.{n}"), n)?;
        mats.insert(n.as_str(), material(n, m)?);
        if m.bruise.is_some() {
            return Err(ScenarioError::invalid(
                format!("materials.{n}.bruise"),
                "replaced by damage (docs/damage.md): {\"damage\": {\"model\": \"peak-force\", \"peak_force_n\": F}} keeps a force threshold; static_force_n and static_pressure_pa move there too",
            ));
        }
        if let Some(d) = &m.damage {
            if d.file.is_some() {
                return Err(ScenarioError::invalid(
                    format!("materials.{n}.damage.file"),
                    "not read: load the scenario with scenario::load (or call Scenario::read_files) so that the file is read relative to it",
                ));
            }
            super::damage::validate(d, &format!("materials.{n}.damage"))?;
        }
    }
    if let Some(g) = &sc.grading {
        super::damage::validate_grading(g)?;
    }
    law("contact", &sc.contact)?;
    pairs(sc, &mats)?;

    let mut names = HashSet::new();
    for (k, a) in sc.apples.iter().enumerate() {
        apple(&format!("apples[{k}]"), a, &mats, &mut names)?;
    }
    probe_files(sc)?;
    for (k, g) in sc.generators.iter().enumerate() {
        generator(&format!("generators[{k}]"), g, &mats)?;
    }
    for (k, src) in sc.sources.iter().enumerate() {
        source(&format!("sources[{k}]"), src, &mats, sc.gravity_m_s2)?;
    }
    prefixes(sc)?;
    spheroids_with_balls(sc)?;
    apple_count(sc)?;
    bed_counts(sc)?;
    super::budget::check_memory(sc, sc.model.max_memory_mb)?;
    super::budget::check_output(sc, sc.model.max_output_mb)?;
    for (k, s) in sc.surfaces.iter().enumerate() {
        surface(&format!("surfaces[{k}]"), s, &mats, &mut names)?;
    }
    troughs(sc)?;
    // The apples present at the start, each with the generator that made it (None: listed).
    let mut all = sc.apples.clone();
    let mut made_by: Vec<Option<usize>> = vec![None; all.len()];
    for (k, g) in sc.generators.iter().enumerate() {
        let more = super::generators::expand(g, &all, &format!("generators[{k}]"))?;
        made_by.extend(std::iter::repeat_n(Some(k), more.len()));
        all.extend(more);
    }
    if all.is_empty() && sc.sources.is_empty() {
        // A generator that makes no apple is the likely mistake when there is one.
        let field = if sc.generators.is_empty() {
            "apples".to_string()
        } else {
            "generators[0].count".to_string()
        };
        return Err(ScenarioError::invalid(
            field,
            "no apple in the scenario: give apples, generators (with a count > 0) or sources",
        ));
    }
    let mut gen_names = HashSet::new();
    for (a, by) in all.iter().zip(&made_by).skip(sc.apples.len()) {
        let k = by.unwrap_or_default();
        if !a
            .position_m
            .iter()
            .all(|x| ranges::POSITION.contains(x.abs()))
        {
            return Err(ScenarioError::invalid(
                format!("generators[{k}]"),
                format!(
                    "apple '{}' is placed at [{}, {}, {}] m, outside the range of fruit handling ({})",
                    a.name,
                    num(a.position_m[0]),
                    num(a.position_m[1]),
                    num(a.position_m[2]),
                    ranges::POSITION.describe()
                ),
            ));
        }
        if names.contains(&a.name) || !gen_names.insert(a.name.clone()) {
            return Err(ScenarioError::invalid(
                format!("generators[{k}].name"),
                format!(
                    "generated apple name '{}' is already used: change the generator's name",
                    a.name
                ),
            ));
        }
    }
    inside_bounds(sc, &all, |k| match made_by[k] {
        None => format!("apples[{k}].position_m"),
        // The field that places the generator's apples.
        Some(_) => sc.initial_apple_field(k),
    })?;
    check_apple_overlaps(&all, |j, i| match (made_by[j], made_by[i]) {
        (None, _) => format!("apples[{j}].position_m"),
        (Some(k), Some(l)) if k == l && matches!(sc.generators[k], GeneratorSpec::Grid(_)) => {
            format!("generators[{k}].spacing_m")
        }
        (Some(k), _) => format!("generators[{k}]"),
    })
}

fn output(sc: &Scenario) -> R {
    if let Some(s) = sc.output.sample_interval_s {
        ranges::DURATION.check("output.sample_interval_s", s)?;
    }
    let tr = &sc.output.transitions;
    ranges::SPEED_THRESHOLD.check("output.transitions.slip_speed_m_s", tr.slip_speed_m_s)?;
    ranges::RELATIVE_TOLERANCE.check(
        "output.transitions.relative_tolerance",
        tr.relative_tolerance,
    )?;
    ranges::HYSTERESIS.check("output.transitions.hysteresis", tr.hysteresis)?;
    ranges::TIME.check("output.transitions.min_dwell_s", tr.min_dwell_s)?;
    ranges::BIN.check("output.transitions.histogram_bin_m", tr.histogram_bin_m)?;
    if let Some(v) = &sc.output.vtk {
        ranges::DURATION.check("output.vtk.interval_s", v.interval_s)?;
    }
    Ok(())
}

fn model(sc: &Scenario) -> R {
    let m = &sc.model;
    ranges::OVERLAP_RATIO.check("model.max_overlap_ratio", m.max_overlap_ratio)?;
    ranges::MIN_STEPS.check("model.min_steps_per_impact", m.min_steps_per_impact)?;
    ranges::ENERGY_TOLERANCE.check("model.energy_tolerance", m.energy_tolerance)?;
    ranges::HISTORY_DASHPOT_BOUND.check("model.history_dashpot_bound", m.history_dashpot_bound)?;
    ranges::MAX_STEPS.check("model.max_steps", m.max_steps as f64)?;
    ranges::MEMORY_BUDGET.check("model.max_memory_mb", m.max_memory_mb)?;
    ranges::OUTPUT_BUDGET.check("model.max_output_mb", m.max_output_mb)?;
    if let Some(v) = m.sleep.speed_m_s {
        ranges::SPEED_THRESHOLD.check("model.sleep.speed_m_s", v)?;
    }
    if let Some(v) = m.sleep.time_s {
        ranges::DURATION.check("model.sleep.time_s", v)?;
    }
    if let Some(b) = &m.scene_bounds {
        ranges::POSITION.check_each("model.scene_bounds.min_m", b.min_m)?;
        ranges::POSITION.check_each("model.scene_bounds.max_m", b.max_m)?;
        for i in 0..3 {
            if b.max_m[i] <= b.min_m[i] {
                return Err(ScenarioError::invalid(
                    format!("model.scene_bounds.max_m[{i}]"),
                    format!(
                        "{} m is not above min_m[{i}] = {} m: the box is empty",
                        num(b.max_m[i]),
                        num(b.min_m[i])
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// Apples and sources' spawn regions must start inside `model.scene_bounds` (an apple outside
/// would leave the scene at its first step): `apples` are those present at the start, `field`
/// names the field of the k-th.
fn inside_bounds(sc: &Scenario, all: &[AppleSpec], field: impl Fn(usize) -> String) -> R {
    let Some(b) = &sc.model.scene_bounds else {
        return Ok(());
    };
    let outside = |p: [f64; 3]| format!("[{}, {}, {}] m", num(p[0]), num(p[1]), num(p[2]));
    let bounds = format!(
        "model.scene_bounds ({} to {})",
        outside(b.min_m),
        outside(b.max_m)
    );
    // When no apple and no spawn point is inside, the box is the mistake (a mistyped bound),
    // not the apples: the bound that excludes the first one is named.
    let spawn_inside = |s: &crate::scenario::SourceSpec| {
        let j = s.jitter_m.bound_m();
        b.contains([0, 1, 2].map(|i| s.position_m[i] - j[i]))
            && b.contains([0, 1, 2].map(|i| s.position_m[i] + j[i]))
    };
    let none_inside =
        !all.iter().any(|a| b.contains(a.position_m)) && !sc.sources.iter().any(spawn_inside);
    let first = all
        .first()
        .map(|a| a.position_m)
        .or_else(|| sc.sources.first().map(|s| s.position_m));
    if let (true, Some(p)) = (none_inside, first) {
        for i in 0..3 {
            let (side, bound) = if p[i] < b.min_m[i] {
                ("min_m", b.min_m[i])
            } else if p[i] > b.max_m[i] {
                ("max_m", b.max_m[i])
            } else {
                continue;
            };
            return Err(ScenarioError::invalid(
                format!("model.scene_bounds.{side}[{i}]"),
                format!(
                    "{} m leaves every apple and spawn point outside the box (the first at {}): every apple would leave the scene at once",
                    num(bound),
                    outside(p)
                ),
            ));
        }
    }
    for (k, a) in all.iter().enumerate() {
        if !b.contains(a.position_m) {
            return Err(ScenarioError::invalid(
                field(k),
                format!(
                    "apple '{}' starts at {}, outside {bounds}: it would leave the scene at once",
                    a.name,
                    outside(a.position_m)
                ),
            ));
        }
    }
    // A moving source's spots are checked where its motion carries them, at every spawn time,
    // when the world is built (world::check_spawn_points).
    for (k, s) in sc
        .sources
        .iter()
        .enumerate()
        .filter(|(_, s)| s.motion.is_none())
    {
        let w = s.jitter_m.half_widths(crate::math::vec3(sc.gravity_m_s2));
        let lo = [0, 1, 2].map(|i| s.position_m[i] - w[i]);
        let hi = [0, 1, 2].map(|i| s.position_m[i] + w[i]);
        if !(b.contains(lo) && b.contains(hi)) {
            return Err(ScenarioError::invalid(
                format!("sources[{k}].position_m"),
                format!(
                    "the spawn point of source '{}' ({} +- [{}, {}, {}] m) is outside {bounds}: its apples would leave the scene at once",
                    s.name,
                    outside(s.position_m),
                    num(w[0]),
                    num(w[1]),
                    num(w[2]),
                ),
            ));
        }
    }
    Ok(())
}

fn pairs(sc: &Scenario, mats: &BTreeMap<&str, Material>) -> R {
    let mut seen_pairs = HashSet::new();
    for (k, p) in sc.pairs.iter().enumerate() {
        let f = format!("pairs[{k}]");
        for (n, m) in p.materials.iter().enumerate() {
            material_of(&format!("{f}.materials[{n}]"), m, mats)?;
        }
        let key = if p.materials[0] <= p.materials[1] {
            (p.materials[0].clone(), p.materials[1].clone())
        } else {
            (p.materials[1].clone(), p.materials[0].clone())
        };
        if !seen_pairs.insert(key) {
            return Err(ScenarioError::invalid(
                format!("{f}.materials"),
                format!(
                    "the pair {:?} is given twice",
                    [&p.materials[0], &p.materials[1]]
                ),
            ));
        }
        coefficients(&f, p.friction, p.ke, p.lambda_s_m)?;
        law(&f, &p.over(&sc.contact))?;
    }
    Ok(())
}

/// A refusal of the duration, the step or the accuracy, with what the run would have cost in
/// steps where the scenario says enough to tell (a fixed step: duration over step; an accuracy:
/// steps per impact), against `model.max_steps`.
fn with_step_estimate(e: ScenarioError, sc: &Scenario) -> ScenarioError {
    let steps = match (sc.time_step_s, sc.accuracy) {
        (TimeStep::Fixed(dt), _) => Some(sc.duration_s / dt),
        (_, Some(a)) => Some(a.steps_per_contact()),
        _ => None,
    };
    match (e, steps) {
        (ScenarioError::Invalid { field, message }, Some(n)) if n.is_finite() || n.is_nan() => {
            let what = match sc.time_step_s {
                TimeStep::Fixed(_) => "the run would take",
                _ => "every impact would take",
            };
            ScenarioError::Invalid {
                field,
                message: format!(
                    "{message}; {what} about {n:.3e} steps (model.max_steps = {})",
                    sc.model.max_steps
                ),
            }
        }
        (ScenarioError::Invalid { field, message }, Some(_)) => ScenarioError::Invalid {
            field,
            message: format!("{message}; the run would take more steps than any machine can"),
        },
        (e, _) => e,
    }
}

fn material_of<'a>(
    field: &str,
    name: &str,
    mats: &'a BTreeMap<&str, Material>,
) -> Result<&'a Material, ScenarioError> {
    mats.get(name).ok_or_else(|| {
        ScenarioError::invalid(
            field,
            format!(
                "unknown material '{name}': there is no materials.{name} (defined: {})",
                list(mats)
            ),
        )
    })
}

fn mass(f: &str, material: &str, mass: Option<f64>, m: &Material) -> R {
    match mass {
        Some(x) => ranges::MASS.check(&format!("{f}.mass_kg"), x),
        None if m.density_kg_m3.is_none() => Err(ScenarioError::invalid(
            format!("{f}.mass_kg"),
            format!(
                "missing, and materials.{material}.density_kg_m3 is not given to derive it from"
            ),
        )),
        None => Ok(()),
    }
}

fn apple(
    f: &str,
    a: &AppleSpec,
    mats: &BTreeMap<&str, Material>,
    names: &mut HashSet<String>,
) -> R {
    name(&format!("{f}.name"), &a.name)?;
    if !names.insert(a.name.clone()) {
        return Err(ScenarioError::invalid(
            format!("{f}.name"),
            format!("'{}' is used twice: names must be unique", a.name),
        ));
    }
    let m = material_of(&format!("{f}.material"), &a.material, mats)?;
    ranges::DIAMETER.check(&format!("{f}.diameter_m"), a.diameter_m)?;
    shape(f, a.diameter_m, a.height_m)?;
    a.orientation(f)?;
    mass(f, &a.material, a.mass_kg, m)?;
    match a.height_m {
        Some(h) if a.is_spheroid() => {
            let aspect = h / a.diameter_m;
            shaped_mass_density(f, a.mass_kg, a.diameter_m, a.diameter_m, (aspect, aspect))?
        }
        _ => mass_density(f, a.mass_kg, a.diameter_m, a.diameter_m)?,
    }
    ranges::POSITION.check_each(&format!("{f}.position_m"), a.position_m)?;
    ranges::SPEED.check_norm(&format!("{f}.velocity_m_s"), a.velocity_m_s)?;
    ranges::ANGULAR_SPEED.check_norm(
        &format!("{f}.angular_velocity_rad_s"),
        a.angular_velocity_rad_s,
    )?;
    if let Some(p) = &a.probe {
        ranges::PROBE_RATE.check(&format!("{f}.probe.sample_rate_hz"), p.sample_rate_hz)?;
        ranges::PROBE_TRIGGER.check(&format!("{f}.probe.trigger_g"), p.trigger_g)?;
        ranges::PROBE_WINDOW.check(&format!("{f}.probe.window_s"), p.window_s)?;
    }
    Ok(())
}

/// rapier has no spheroid shape: where rapier itself touches apples (the `rigid` fidelity, or
/// a surface with `"contact_model": "rigid"`) every apple carries a ball collider, which would
/// make a spheroid a ball there. Refused, naming the first field that makes a spheroid.
fn spheroids_with_balls(sc: &Scenario) -> R {
    let why = if sc.fidelity == super::Fidelity::Rigid {
        "the rigid fidelity has rapier compute every contact".to_string()
    } else if let Some((k, s)) = sc
        .surfaces
        .iter()
        .enumerate()
        .find(|(_, s)| s.contact_model() == ContactModel::Rigid)
    {
        format!(
            "surfaces[{k}] ('{}') has \"contact_model\": \"rigid\", so rapier touches every apple",
            s.name()
        )
    } else {
        return Ok(());
    };
    let shaped = |a: &Option<super::AspectSpec>| a.as_ref().is_some_and(|a| !a.is_sphere());
    let field = sc
        .apples
        .iter()
        .position(AppleSpec::is_spheroid)
        .map(|k| format!("apples[{k}].height_m"))
        .or_else(|| {
            sc.generators.iter().enumerate().find_map(|(k, g)| match g {
                GeneratorSpec::Grid(s) if shaped(&s.aspect) => {
                    Some(format!("generators[{k}].aspect"))
                }
                GeneratorSpec::RandomFill(s) if shaped(&s.aspect) => {
                    Some(format!("generators[{k}].aspect"))
                }
                GeneratorSpec::File(s)
                    if s.loaded.as_ref().is_some_and(|l| {
                        l.0.iter()
                            .any(|a| a.height_m.is_some_and(|h| h != a.diameter_m))
                    }) =>
                {
                    Some(format!("generators[{k}].file"))
                }
                _ => None,
            })
        })
        .or_else(|| {
            sc.sources
                .iter()
                .position(|s| shaped(&s.aspect))
                .map(|k| format!("sources[{k}].aspect"))
        });
    match field {
        Some(field) => Err(ScenarioError::invalid(
            field,
            format!(
                "a spheroidal apple (height other than its diameter) needs the Hertz contact layer: {why}, and rapier has no spheroid shape (its apples are balls); make these apples spheres, or give every surface the hertz contact_model and a fidelity other than rigid"
            ),
        )),
        None => Ok(()),
    }
}

/// The height of the apple at `f` (`apples[3]`), if given, against its diameter `d` (checked
/// first): a number in [`ranges::HEIGHT`], and height over diameter in [`ranges::ASPECT`]. Both
/// refusals name `{f}.height_m`.
pub(crate) fn shape(f: &str, d: f64, height_m: Option<f64>) -> R {
    let Some(h) = height_m else { return Ok(()) };
    let field = format!("{f}.height_m");
    ranges::HEIGHT.check(&field, h)?;
    let aspect = h / d;
    if ranges::ASPECT.contains(aspect) {
        return Ok(());
    }
    Err(ScenarioError::invalid(
        field,
        format!(
            "{} m over a diameter_m of {} m is an aspect (height / diameter) of {}, outside the range of fruit handling ({}): an apple is at most twice as tall as wide, or as wide as tall",
            num(h),
            num(d),
            crate::math::human(aspect, 4, 3),
            ranges::ASPECT.describe()
        ),
    ))
}

/// A probe apple's name makes its files' names ([`crate::record::probe::file_stem`]): two that
/// make the same file would write one over the other (the first probe's record lost), and one
/// too long for a file name would fail after the whole run. Both refused here, naming the
/// second apple's name.
fn probe_files(sc: &Scenario) -> R {
    use crate::record::probe::{file_stem, MAX_PROBE_NAME_CHARS};
    let mut stems: BTreeMap<String, usize> = BTreeMap::new();
    for (k, a) in sc.apples.iter().enumerate() {
        if a.probe.is_none() {
            continue;
        }
        let chars = a.name.chars().count();
        if chars > MAX_PROBE_NAME_CHARS {
            return Err(ScenarioError::invalid(
                format!("apples[{k}].name"),
                format!(
                    "a probe's name of {chars} characters: its files are named after it (probe_NAME_trace.csv), give at most {MAX_PROBE_NAME_CHARS}"
                ),
            ));
        }
        let stem = file_stem(&a.name);
        if let Some(&j) = stems.get(&stem) {
            return Err(ScenarioError::invalid(
                format!("apples[{k}].name"),
                format!(
                    "the probe '{}' would write the same files as the probe '{}' (apples[{j}]): {stem}_trace.csv (a name's characters other than letters, digits, '-' and '_' become '_'); rename one of them",
                    a.name, sc.apples[j].name
                ),
            ));
        }
        stems.insert(stem, k);
    }
    Ok(())
}

fn surface(
    f: &str,
    s: &SurfaceSpec,
    mats: &BTreeMap<&str, Material>,
    names: &mut HashSet<String>,
) -> R {
    name(&format!("{f}.name"), s.name())?;
    if s.name().contains('/') {
        return Err(ScenarioError::invalid(
            format!("{f}.name"),
            format!(
                "'{}': '/' is reserved for the walls of a bin and the rollers of a roller bed",
                s.name()
            ),
        ));
    }
    if !names.insert(s.name().to_string()) {
        return Err(ScenarioError::invalid(
            format!("{f}.name"),
            format!("'{}' is used twice: names must be unique", s.name()),
        ));
    }
    let length = |field: &str, x: f64| ranges::LENGTH.check(&format!("{f}.{field}"), x);
    let position =
        |field: &str, v: [f64; 3]| ranges::POSITION.check_each(&format!("{f}.{field}"), v);
    if let Some(pad) = s.padding() {
        material_of(&format!("{f}.padding.material"), &pad.material, mats)?;
        ranges::PAD_THICKNESS.check(&format!("{f}.padding.thickness_m"), pad.thickness_m)?;
        if s.contact_model() == ContactModel::Rigid {
            return Err(ScenarioError::invalid(
                format!("{f}.padding"),
                "a rigid surface (rapier's own contact) cannot model a pad: use the hertz contact_model",
            ));
        }
        if let SurfaceSpec::Chute(c) = s {
            if c.profile == ChuteProfile::Trough {
                return Err(ScenarioError::invalid(
                    format!("{f}.padding"),
                    "padding is for flat surfaces: the thin-layer law is for a flat layer, not a trough",
                ));
            }
        }
    }
    match s {
        SurfaceSpec::Plane(p) => {
            material_of(&format!("{f}.material"), &p.material, mats)?;
            position("point_m", p.point_m)?;
            unit3(&format!("{f}.normal"), p.normal)?;
        }
        SurfaceSpec::Box(b) => {
            material_of(&format!("{f}.material"), &b.material, mats)?;
            ranges::LENGTH.check_each(&format!("{f}.size_m"), b.size_m)?;
            position("position_m", b.position_m)?;
            rotation_of(&b.rotation, f)?;
        }
        SurfaceSpec::Conveyor(b) => {
            material_of(&format!("{f}.material"), &b.material, mats)?;
            ranges::LENGTH.check_each(&format!("{f}.size_m"), b.size_m)?;
            position("position_m", b.position_m)?;
            rotation_of(&b.rotation, f)?;
            ranges::SPEED.check_abs(&format!("{f}.belt_velocity_m_s"), b.belt_velocity_m_s)?;
        }
        SurfaceSpec::Chute(c) => {
            material_of(&format!("{f}.material"), &c.material, mats)?;
            length("length_m", c.length_m)?;
            position("position_m", c.position_m)?;
            rotation_of(&c.rotation, f)?;
            if let Some(t) = c.thickness_m {
                length("thickness_m", t)?;
            }
            ranges::INCLINE.check(&format!("{f}.incline_deg"), c.incline_deg)?;
            match c.profile {
                ChuteProfile::Flat => {
                    let w = c.width_m.ok_or_else(|| {
                        ScenarioError::invalid(format!("{f}.width_m"), "a flat chute needs width_m")
                    })?;
                    length("width_m", w)?;
                    if c.radius_m.is_some() || c.half_angle_deg.is_some() {
                        let field = if c.radius_m.is_some() {
                            "radius_m"
                        } else {
                            "half_angle_deg"
                        };
                        return Err(ScenarioError::invalid(
                            format!("{f}.{field}"),
                            "radius_m and half_angle_deg belong to a trough, not a flat chute",
                        ));
                    }
                }
                ChuteProfile::Trough => {
                    let r = c.radius_m.ok_or_else(|| {
                        ScenarioError::invalid(format!("{f}.radius_m"), "a trough needs radius_m")
                    })?;
                    length("radius_m", r)?;
                    if c.width_m.is_some() {
                        return Err(ScenarioError::invalid(
                            format!("{f}.width_m"),
                            "a trough's width is set by radius_m",
                        ));
                    }
                    if let Some(h) = c.half_angle_deg {
                        ranges::HALF_ANGLE.check(&format!("{f}.half_angle_deg"), h)?;
                    }
                }
            }
        }
        SurfaceSpec::Bin(b) => {
            material_of(&format!("{f}.material"), &b.material, mats)?;
            if let Some(w) = &b.wall_materials {
                for (wall, m) in [
                    ("floor", &w.floor),
                    ("x_min", &w.x_min),
                    ("x_max", &w.x_max),
                    ("y_min", &w.y_min),
                    ("y_max", &w.y_max),
                ] {
                    if let Some(m) = m {
                        material_of(&format!("{f}.wall_materials.{wall}"), m, mats)?;
                    }
                }
            }
            ranges::LENGTH.check_each(&format!("{f}.inner_size_m"), b.inner_size_m)?;
            if let Some(t) = b.wall_thickness_m {
                length("wall_thickness_m", t)?;
            }
            position("position_m", b.position_m)?;
            rotation_of(&b.rotation, f)?;
        }
        SurfaceSpec::Mesh(m) => {
            material_of(&format!("{f}.material"), &m.material, mats)?;
            if m.file.trim().is_empty() {
                return Err(ScenarioError::invalid(
                    format!("{f}.file"),
                    "empty file name",
                ));
            }
            match m.scale {
                Scale::Uniform(s) => ranges::SCALE.check(&format!("{f}.scale"), s)?,
                Scale::PerAxis(s) => ranges::SCALE.check_each(&format!("{f}.scale"), s)?,
            }
            position("position_m", m.position_m)?;
            rotation_of(&m.rotation, f)?;
        }
        SurfaceSpec::Roller(r) => roller(f, r, mats)?,
        SurfaceSpec::RollerBed(b) => {
            bed_count(f, b.count)?;
            // The fields every roller shares (radius, length, material, rates, the first
            // position) before the pitch that is compared with them.
            roller(f, &b.roller(0), mats)?;
            let axis = vec3(super::motion::unit_axis(&format!("{f}.axis"), b.axis)?);
            let dir = vec3(super::motion::unit_axis(
                &format!("{f}.pitch_direction"),
                b.pitch_direction,
            )?);
            if axis.dot(dir).abs() > 1e-9 {
                // Lines are laid out along the world axes: when only one of the two is along an
                // axis, the other is the likely mistake and is named (the pitch direction
                // otherwise).
                let aligned = |v: [f64; 3]| v.iter().filter(|x| **x != 0.0).count() == 1;
                let (field, other) = if aligned(b.pitch_direction) && !aligned(b.axis) {
                    ("axis", "pitch_direction")
                } else {
                    ("pitch_direction", "axis")
                };
                return Err(ScenarioError::invalid(
                    format!("{f}.{field}"),
                    format!(
                        "it makes {:.3} deg with the {other}: the rollers must follow each other across their axes (pitch_direction at right angles to axis)",
                        axis.dot(dir).clamp(-1.0, 1.0).acos().to_degrees()
                    ),
                ));
            }
            length("pitch_m", b.pitch_m)?;
            if b.count > 1 && b.pitch_m < 2.0 * b.radius_m {
                return Err(ScenarioError::invalid(
                    format!("{f}.pitch_m"),
                    format!(
                        "{} m is less than a roller's diameter ({} m): neighbouring rollers would overlap",
                        num(b.pitch_m),
                        num(2.0 * b.radius_m)
                    ),
                ));
            }
            // The rollers differ only in their positions: the last one must be in range too.
            let last = b.roller(b.count - 1);
            if !last
                .position_m
                .iter()
                .all(|x| ranges::POSITION.contains(x.abs()))
            {
                let p = last.position_m;
                return Err(ScenarioError::invalid(
                    format!("{f}.pitch_m"),
                    format!(
                        "{} rollers {} m apart put the last one, '{}', at [{}, {}, {}] m, outside the range of fruit handling ({}): fewer rollers or a shorter pitch_m",
                        b.count,
                        num(b.pitch_m),
                        last.name,
                        num(p[0]),
                        num(p[1]),
                        num(p[2]),
                        ranges::POSITION.describe()
                    ),
                ));
            }
        }
    }
    if let Some(m) = s.motion() {
        super::motion::validate(&format!("{f}.motion"), m)?;
    }
    Ok(())
}

/// A trough must be wider than every apple that can reach it: a trough tighter than an apple
/// is a conforming contact, outside Hertz theory (K1 + K2 <= 0). Checked against the largest
/// apple of every list, generator and source before the run (a fed apple met it 0.28 s into the
/// run, refused with no field). The field is the trough's `radius_m`.
fn troughs(sc: &Scenario) -> R {
    let mut largest: Vec<(f64, String)> = Vec::new();
    for (k, a) in sc.apples.iter().enumerate() {
        largest.push((
            a.diameter_m / 2.0,
            format!("apple '{}' (apples[{k}])", a.name),
        ));
    }
    for (k, g) in sc.generators.iter().enumerate() {
        let d = match g {
            GeneratorSpec::Grid(s) => s.diameter_m.max_m(),
            GeneratorSpec::RandomFill(s) => s.diameter_m.max_m(),
            GeneratorSpec::File(s) => s.loaded.as_ref().map_or(0.0, |l| {
                l.0.iter().map(|a| a.diameter_m).fold(0.0, f64::max)
            }),
        };
        largest.push((d / 2.0, format!("the apples of generators[{k}]")));
    }
    for (k, src) in sc.sources.iter().enumerate() {
        largest.push((
            src.diameter_m.max_m() / 2.0,
            format!("the apples of sources[{k}] ('{}')", src.name),
        ));
    }
    for (k, s) in sc.surfaces.iter().enumerate() {
        let SurfaceSpec::Chute(c) = s else { continue };
        let (ChuteProfile::Trough, Some(rs)) = (c.profile, c.radius_m) else {
            continue;
        };
        if let Some((r, who)) = largest.iter().find(|(r, _)| *r >= rs) {
            return Err(ScenarioError::invalid(
                format!("surfaces[{k}].radius_m"),
                format!(
                    "the trough '{}' of radius {} m is tighter than {who}, radius up to {} m: that would be a conforming contact (K1 + K2 <= 0), outside Hertz theory; make radius_m larger than the largest apple's radius",
                    c.name,
                    num(rs),
                    num(*r)
                ),
            ));
        }
    }
    Ok(())
}

/// The most rollers a roller bed may have (each is a rapier body and a surface).
pub const MAX_BED_ROLLERS: u32 = 10_000;

/// A roller bed's `count` in range (`f` the bed's JSON path).
fn bed_count(f: &str, count: u32) -> R {
    if !(1..=MAX_BED_ROLLERS).contains(&count) {
        return Err(ScenarioError::invalid(
            format!("{f}.count"),
            format!("{count} rollers: a roller bed has 1 to {MAX_BED_ROLLERS}"),
        ));
    }
    Ok(())
}

/// Every roller bed's `count` in range, checked before anything counts or expands the beds'
/// rollers (the budgets, the surfaces' own checks): a count of 4294967295 expanded first asked
/// for 1.2 TB and aborted, one of 1e6 took 0.9 GB before it was refused.
fn bed_counts(sc: &Scenario) -> R {
    for (k, s) in sc.surfaces.iter().enumerate() {
        if let SurfaceSpec::RollerBed(b) = s {
            bed_count(&format!("surfaces[{k}]"), b.count)?;
        }
    }
    Ok(())
}

/// The checks of a roller (`f` its JSON path; a roller bed's rollers share the bed's fields).
fn roller(f: &str, r: &RollerSpec, mats: &BTreeMap<&str, Material>) -> R {
    let length = |field: &str, x: f64| ranges::LENGTH.check(&format!("{f}.{field}"), x);
    let position =
        |field: &str, v: [f64; 3]| ranges::POSITION.check_each(&format!("{f}.{field}"), v);
    material_of(&format!("{f}.material"), &r.material, mats)?;
    length("radius_m", r.radius_m)?;
    length("length_m", r.length_m)?;
    position("position_m", r.position_m)?;
    super::motion::unit_axis(&format!("{f}.axis"), r.axis)?;
    let w = r.angular_velocity_rad_s;
    ranges::ANGULAR_SPEED.check_abs(&format!("{f}.angular_velocity_rad_s"), w)?;
    // Its surface speed is a speed like any other. The field named: the radius when the rate
    // would be sensible on any roller of a line (0.5 m, a drum), else the rate.
    if !ranges::SPEED.contains((w * r.radius_m).abs()) {
        let field = if ranges::SPEED.contains((w * 0.5).abs()) {
            "radius_m"
        } else {
            "angular_velocity_rad_s"
        };
        return Err(ScenarioError::invalid(
                format!("{f}.{field}"),
                format!(
                    "{} rad/s on a radius of {} m moves the roller's surface at {} m/s, outside the range of fruit handling ({})",
                    num(w),
                    num(r.radius_m),
                    ranges::num3((w * r.radius_m).abs()),
                    ranges::SPEED.describe()
                ),
            ));
    }
    if let Some(ft) = &r.free_turning {
        let g = format!("{f}.free_turning");
        ranges::ROLLER_INERTIA.check(
            &format!("{g}.moment_of_inertia_kg_m2"),
            ft.moment_of_inertia_kg_m2,
        )?;
        ranges::BEARING_TORQUE.check(&format!("{g}.bearing_torque_n_m"), ft.bearing_torque_n_m)?;
        if r.motion.as_ref().is_some_and(|m| m.rotation.is_some()) {
            return Err(ScenarioError::invalid(
                    format!("{f}.motion.rotation"),
                    "a free-turning roller may be carried (motion.translation) but not swung: its spin is integrated about a fixed axis direction",
                ));
        }
    }
    Ok(())
}

fn list(mats: &BTreeMap<&str, Material>) -> String {
    mats.keys().cloned().collect::<Vec<_>>().join(", ")
}

/// Two apples may touch but must not start inside each other. `field(j, i)` names the field at
/// fault when apple `j` starts inside apple `i` (j > i).
///
/// Pairs are found by their bounding balls; a pair with a spheroid is then tested exactly, by
/// the common normal of the two shapes ([`crate::contact::spheroid::pair`]: a normal along
/// which they do not overlap proves them apart, so a pair it finds apart is apart).
fn check_apple_overlaps(all: &[AppleSpec], field: impl Fn(usize, usize) -> String) -> R {
    let pos: Vec<Vec3> = all.iter().map(|a| vec3(a.position_m)).collect();
    let r: Vec<f64> = all.iter().map(AppleSpec::bounding_radius_m).collect();
    let mut list = NeighborList::new(0.0);
    list.update(&pos, &r, &[], true, |_| {});
    for p in list.pairs() {
        let (i, j) = (p.i as usize, p.j as usize);
        let (i, j) = (i.min(j), i.max(j));
        if all[i].is_spheroid() || all[j].is_spheroid() {
            spheroid_overlap(all, i, j, &field)?;
            continue;
        }
        let d = (pos[i] - pos[j]).length();
        let u = r[i] + r[j] - d;
        // A touching pair placed with round numbers may overlap by a rounding error.
        if u > 1e-9 * (r[i] + r[j]) {
            return Err(ScenarioError::invalid(
                field(j, i),
                format!(
                    "apple '{}' starts {:.4} mm inside apple '{}' (centres {:.4} mm apart, radii {} + {} m): move them apart",
                    all[j].name,
                    u * 1e3,
                    all[i].name,
                    d * 1e3,
                    r[i],
                    r[j]
                ),
            ));
        }
    }
    Ok(())
}

/// The exact test of [`check_apple_overlaps`] for a pair with a spheroid (j > i). Rotations
/// were checked with each apple (an unreadable one is taken as unturned here).
fn spheroid_overlap(
    all: &[AppleSpec],
    i: usize,
    j: usize,
    field: &impl Fn(usize, usize) -> String,
) -> R {
    use crate::contact::spheroid::pair;
    let (a, b) = (&all[i], &all[j]);
    let (xa, xb) = (vec3(a.position_m), vec3(b.position_m));
    let turned = |s: &AppleSpec| {
        s.orientation("")
            .unwrap_or(rapier3d_f64::math::Rotation::IDENTITY)
    };
    let n0 = (xb - xa).try_normalize().unwrap_or(Vec3::Z);
    let g = pair(
        xb,
        &turned(b),
        &b.spheroid(),
        xa,
        &turned(a),
        &a.spheroid(),
        n0,
    );
    // Never met in the tests; the bounding balls' overlap then, to be safe.
    let u = if g.overlap_m.is_finite() {
        g.overlap_m
    } else {
        a.bounding_radius_m() + b.bounding_radius_m() - (xb - xa).length()
    };
    // A touching pair placed with round numbers may overlap by a rounding error.
    if u > 1e-9 * (a.bounding_radius_m() + b.bounding_radius_m()) {
        let size = |s: &AppleSpec| format!("{} x {} m", num(s.diameter_m), num(s.height()));
        return Err(ScenarioError::invalid(
            field(j, i),
            format!(
                "apple '{}' starts {:.4} mm inside apple '{}' (centres {:.4} mm apart, diameter x height {} and {}, as turned): move them apart",
                b.name,
                u * 1e3,
                a.name,
                (xb - xa).length() * 1e3,
                size(a),
                size(b)
            ),
        ));
    }
    Ok(())
}
