//! Checks of the apples a scenario feeds in: generators, sources, files of apples, their
//! names, masses and counts (split from `validate` to keep files small).

use super::*;

pub(super) fn generator(f: &str, g: &GeneratorSpec, mats: &BTreeMap<&str, Material>) -> R {
    match g {
        GeneratorSpec::Grid(s) => {
            prefix_and_material(f, &s.name, &s.material, s.mass_kg, mats)?;
            s.diameter_m.validate(&format!("{f}.diameter_m"))?;
            aspect(f, s.aspect.as_ref())?;
            feed_mass_density(f, s.mass_kg, &s.diameter_m, s.aspect.as_ref())?;
            ranges::POSITION.check_each(&format!("{f}.origin_m"), s.origin_m)?;
            ranges::SPEED.check_norm(&format!("{f}.velocity_m_s"), s.velocity_m_s)?;
            ranges::LENGTH.check_each(&format!("{f}.spacing_m"), s.spacing_m)?;
            ranges::JITTER.check(&format!("{f}.jitter_m"), s.jitter_m)?;
        }
        GeneratorSpec::RandomFill(s) => {
            prefix_and_material(f, &s.name, &s.material, s.mass_kg, mats)?;
            s.diameter_m.validate(&format!("{f}.diameter_m"))?;
            aspect(f, s.aspect.as_ref())?;
            feed_mass_density(f, s.mass_kg, &s.diameter_m, s.aspect.as_ref())?;
            ranges::POSITION.check_each(&format!("{f}.region_min_m"), s.region_min_m)?;
            ranges::POSITION.check_each(&format!("{f}.region_max_m"), s.region_max_m)?;
            // The region's own field, not the count that could not be placed in it.
            for i in 0..3 {
                let (lo, hi) = (s.region_min_m[i], s.region_max_m[i]);
                // Spheroids are placed turned at random: by their bounding balls.
                let (d, what) = match &s.aspect {
                    Some(a) if !a.is_sphere() && a.min() > 1.0 => (
                        s.diameter_m.min_m() * a.min(),
                        "the smallest diameter times the smallest aspect",
                    ),
                    _ => (s.diameter_m.min_m(), "the smallest diameter"),
                };
                if hi - lo < d {
                    return Err(ScenarioError::invalid(
                        format!("{f}.region_max_m[{i}]"),
                        format!(
                            "{} m is {} region_min_m[{i}] = {} m: the region must hold whole apples, at least {} m ({what}) across",
                            num(hi),
                            if hi <= lo { "not above" } else { "too close to" },
                            num(lo),
                            num(d)
                        ),
                    ));
                }
            }
            ranges::SPEED.check_norm(&format!("{f}.velocity_m_s"), s.velocity_m_s)?;
        }
        GeneratorSpec::File(s) => {
            prefix_and_material(f, &s.name, &s.material, s.mass_kg, mats)?;
            ranges::SPEED.check_norm(&format!("{f}.velocity_m_s"), s.velocity_m_s)?;
            file_apples(f, s)?;
            if let Some(list) = &s.loaded {
                let d = list.0.iter().map(|a| a.diameter_m);
                let lo = d.clone().fold(f64::INFINITY, f64::min);
                let hi = d.fold(0.0, f64::max);
                mass_density(f, s.mass_kg, lo, hi)?;
                // Spheroids: each its own volume (the extremes of diameter and aspect need not
                // meet in one apple).
                for a in list.0.iter().filter(|a| a.height_m.is_some()) {
                    let x = a.height_m.unwrap_or(a.diameter_m) / a.diameter_m;
                    shaped_mass_density(f, s.mass_kg, a.diameter_m, a.diameter_m, (x, x))?;
                }
            }
        }
    }
    Ok(())
}

/// A source: its apples' fields, where they appear (`position_m` with its jitter, in range),
/// and its `motion`, checked as a surface's is (`scenario::motion::validate`).
pub(super) fn source(
    f: &str,
    src: &crate::scenario::SourceSpec,
    mats: &BTreeMap<&str, Material>,
    gravity_m_s2: [f64; 3],
) -> R {
    prefix_and_material(f, &src.name, &src.material, src.mass_kg, mats)?;
    src.diameter_m.validate(&format!("{f}.diameter_m"))?;
    aspect(f, src.aspect.as_ref())?;
    feed_mass_density(f, src.mass_kg, &src.diameter_m, src.aspect.as_ref())?;
    ranges::POSITION.check_each(&format!("{f}.position_m"), src.position_m)?;
    ranges::SPEED.check_norm(&format!("{f}.velocity_m_s"), src.velocity_m_s)?;
    ranges::RATE.check(&format!("{f}.rate_per_s"), src.rate_per_s)?;
    ranges::TIME.check(&format!("{f}.start_s"), src.start_s)?;
    for (at, j) in src.jitter_m.values() {
        ranges::JITTER.check(&format!("{f}.jitter_m{at}"), j)?;
    }
    let w = src.jitter_m.half_widths(crate::math::vec3(gravity_m_s2));
    if (0..3).any(|c| src.position_m[c].abs() + w[c] > ranges::POSITION.max) {
        return Err(ScenarioError::invalid(
            format!("{f}.jitter_m"),
            format!(
                "{} m about position_m places apples outside the range of fruit handling ({})",
                num(w.into_iter().fold(0.0, f64::max)),
                ranges::POSITION.describe()
            ),
        ));
    }
    if let Some(m) = &src.motion {
        crate::scenario::motion::validate(&format!("{f}.motion"), m)?;
    }
    Ok(())
}

/// Generators and sources name their apples `NAME-1`, `NAME-2`, ...: two with one name would
/// give two apples one name (found here before thousands of apples are generated).
/// A mass given with the diameters it goes with (`d_min`..`d_max`): the density they make must
/// be one of the density range (0.1 mg in an apple of 80 mm is a mistyped exponent).
pub(super) fn mass_density(f: &str, mass: Option<f64>, d_min: f64, d_max: f64) -> R {
    let Some(m) = mass else { return Ok(()) };
    let volume = |d: f64| std::f64::consts::PI / 6.0 * d * d * d;
    for d in [d_min, d_max] {
        let rho = m / volume(d);
        if !ranges::DENSITY.contains(rho) {
            return Err(ScenarioError::invalid(
                format!("{f}.mass_kg"),
                format!(
                    "{} kg in an apple of {} m is a density of {} kg/m^3, outside the range of fruit handling ({})",
                    num(m),
                    num(d),
                    ranges::num3(rho),
                    ranges::DENSITY.describe()
                ),
            ));
        }
    }
    Ok(())
}

/// [`mass_density`] for spheroids of diameters `d_min`..`d_max` and aspects (height over
/// diameter) `aspect.0`..`aspect.1`: the volume pi/6 D^3 (H/D), the densest at the smallest
/// diameter and aspect, the lightest at the largest.
pub(super) fn shaped_mass_density(
    f: &str,
    mass: Option<f64>,
    d_min: f64,
    d_max: f64,
    aspect: (f64, f64),
) -> R {
    let Some(m) = mass else { return Ok(()) };
    for (d, x) in [(d_min, aspect.0), (d_max, aspect.1)] {
        let rho = m / (std::f64::consts::PI / 6.0 * d * d * d * x);
        if !ranges::DENSITY.contains(rho) {
            return Err(ScenarioError::invalid(
                format!("{f}.mass_kg"),
                format!(
                    "{} kg in an apple of {} m by {} m (diameter by height) is a density of {} kg/m^3, outside the range of fruit handling ({})",
                    num(m),
                    num(d),
                    ranges::num3(d * x),
                    ranges::num3(rho),
                    ranges::DENSITY.describe()
                ),
            ));
        }
    }
    Ok(())
}

/// The mass check of a generator's or source's apples: by their diameters alone without an
/// aspect (or with an aspect of 1), else with the aspect's span too.
fn feed_mass_density(
    f: &str,
    mass: Option<f64>,
    d: &crate::scenario::DiameterSpec,
    aspect: Option<&crate::scenario::AspectSpec>,
) -> R {
    match aspect {
        Some(a) if !a.is_sphere() => {
            shaped_mass_density(f, mass, d.min_m(), d.max_m(), (a.min(), a.max()))
        }
        _ => mass_density(f, mass, d.min_m(), d.max_m()),
    }
}

/// A generator's or source's `aspect`, checked when given.
fn aspect(f: &str, a: Option<&crate::scenario::AspectSpec>) -> R {
    match a {
        Some(a) => a.validate(&format!("{f}.aspect")),
        None => Ok(()),
    }
}

pub(super) fn prefixes(sc: &Scenario) -> R {
    let mut seen: BTreeMap<&str, String> = BTreeMap::new();
    let all = sc
        .generators
        .iter()
        .enumerate()
        .map(|(k, g)| (format!("generators[{k}]"), g.name()))
        .chain(
            sc.sources
                .iter()
                .enumerate()
                .map(|(k, s)| (format!("sources[{k}]"), s.name.as_str())),
        );
    for (field, n) in all {
        if let Some(first) = seen.get(n) {
            return Err(ScenarioError::invalid(
                format!("{field}.name"),
                format!(
                    "'{n}' is already the name of {first}: their apples would have the same names"
                ),
            ));
        }
        seen.insert(n, field);
    }
    Ok(())
}

/// At most [`ranges::APPLE_COUNT`] apples in all, checked before any generator is expanded (a
/// count of 1e9 would otherwise be allocated here). The field named is the one that crosses it.
pub(super) fn apple_count(sc: &Scenario) -> R {
    let max = ranges::APPLE_COUNT.max;
    let mut total = sc.apples.len() as f64;
    if total > max {
        return Err(ranges::APPLE_COUNT.refusal("apples", total));
    }
    for (k, g) in sc.generators.iter().enumerate() {
        let n = g.count();
        total += n;
        if total > max {
            return Err(count_refusal(&format!("generators[{k}].count"), n, total));
        }
    }
    for (k, s) in sc.sources.iter().enumerate() {
        total += s.count as f64;
        if total > max {
            return Err(count_refusal(
                &format!("sources[{k}].count"),
                s.count as f64,
                total,
            ));
        }
    }
    Ok(())
}

pub(super) fn count_refusal(field: &str, n: f64, total: f64) -> ScenarioError {
    ScenarioError::invalid(
        field,
        format!(
            "{} apples ({} in the scenario so far) is outside the range of fruit handling ({})",
            num(n),
            num(total),
            ranges::APPLE_COUNT.describe()
        ),
    )
}

/// The apples of a `file` generator: read, at least one, unique names, diameters and positions
/// in range. Errors name `generators[k].file` and the entry (`pile.json[3]`), since the file is
/// the user's input as much as the scenario.
pub(super) fn file_apples(f: &str, s: &FileSpec) -> R {
    let field = format!("{f}.file");
    let Some(list) = &s.loaded else {
        return Err(ScenarioError::invalid(
            field,
            format!(
                "'{}' has not been read: load the scenario with scenario::load, or call Scenario::read_files with its folder",
                s.file
            ),
        ));
    };
    if list.0.is_empty() {
        return Err(ScenarioError::invalid(
            field,
            format!("'{}' lists no apple: give at least one", s.file),
        ));
    }
    let in_file = |e: ScenarioError, apple: &str| match e {
        ScenarioError::Invalid { field: at, message } => {
            ScenarioError::invalid(field.clone(), format!("{at}: {message} (apple '{apple}')"))
        }
        other => other,
    };
    let mut seen = HashSet::new();
    for (k, a) in list.0.iter().enumerate() {
        let at = format!("{}[{k}]", s.file);
        name(&format!("{at}.name"), &a.name).map_err(|e| in_file(e, &a.name))?;
        if !seen.insert(a.name.as_str()) {
            return Err(ScenarioError::invalid(
                field,
                format!(
                    "{at}.name: '{}' is used twice: names must be unique",
                    a.name
                ),
            ));
        }
        ranges::DIAMETER
            .check(&format!("{at}.diameter_m"), a.diameter_m)
            .map_err(|e| in_file(e, &a.name))?;
        shape(&at, a.diameter_m, a.height_m).map_err(|e| in_file(e, &a.name))?;
        rotation_of(&a.rotation, &at).map_err(|e| in_file(e, &a.name))?;
        ranges::POSITION
            .check_each(&format!("{at}.position_m"), a.position_m)
            .map_err(|e| in_file(e, &a.name))?;
    }
    Ok(())
}

pub(super) fn prefix_and_material(
    f: &str,
    prefix: &str,
    material: &str,
    m: Option<f64>,
    mats: &BTreeMap<&str, Material>,
) -> R {
    name(&format!("{f}.name"), prefix)?;
    let mat = material_of(&format!("{f}.material"), material, mats)?;
    mass(f, material, m, mat)
}
