//! Validation of a parsed scenario: every check names the field and the value it saw.

use super::generators::{FileSpec, GeneratorSpec};
use super::surfaces::{rotation_of, ChuteProfile, SurfaceSpec};
use super::{AppleSpec, Scenario, ScenarioError, TimeStep};
use crate::contact::{Material, MaterialError};
use crate::layer::grid::NeighborList;
use crate::math::{vec3, Vec3};
use std::collections::{BTreeMap, HashSet};

type R = Result<(), ScenarioError>;

fn positive(field: &str, v: f64) -> R {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(ScenarioError::invalid(
            field,
            format!("{v} must be a finite number > 0"),
        ))
    }
}

fn non_negative(field: &str, v: f64) -> R {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err(ScenarioError::invalid(
            field,
            format!("{v} must be a finite number >= 0"),
        ))
    }
}

fn finite3(field: &str, v: [f64; 3]) -> R {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(ScenarioError::invalid(
            field,
            format!("{v:?} must hold finite numbers"),
        ))
    }
}

/// Checks a unit vector given by the user (normals): zero and non-unit vectors are refused
/// rather than silently normalised, because a wrong normal usually means a wrong layout.
pub(crate) fn unit3(field: &str, v: [f64; 3]) -> R {
    finite3(field, v)?;
    let len = vec3(v).length();
    if (len - 1.0).abs() > 1e-6 {
        return Err(ScenarioError::invalid(
            field,
            format!("{v:?} has length {len}: give a unit vector"),
        ));
    }
    Ok(())
}

/// The material built from a spec, with the error naming the field.
pub(crate) fn material(name: &str, m: &super::MaterialSpec) -> Result<Material, ScenarioError> {
    let base = format!("materials.{name}");
    let built =
        match (m.shear_modulus_pa, m.youngs_modulus_pa) {
            (Some(g), None) => Material::from_shear(g, m.poisson_ratio, m.density_kg_m3),
            (None, Some(e)) => Material::from_youngs(e, m.poisson_ratio, m.density_kg_m3),
            (Some(_), Some(_)) => return Err(ScenarioError::invalid(
                base,
                "gives both shear_modulus_pa and youngs_modulus_pa: give one (E = 2 G (1 + nu))",
            )),
            (None, None) => {
                return Err(ScenarioError::invalid(
                    base,
                    "needs shear_modulus_pa or youngs_modulus_pa",
                ))
            }
        };
    built.map_err(|e| match e {
        MaterialError::BadModulus { field, value } => ScenarioError::invalid(
            format!("{base}.{field}"),
            format!("{value} must be a finite number > 0 (Pa)"),
        ),
        MaterialError::BadPoisson(nu) => ScenarioError::invalid(
            format!("{base}.poisson_ratio"),
            format!("{nu} must lie in (-1, 0.5); 0.5 is incompressible, outside Hertz theory"),
        ),
        MaterialError::BadDensity(rho) => ScenarioError::invalid(
            format!("{base}.density_kg_m3"),
            format!("{rho} must be a finite number > 0"),
        ),
    })
}

fn coefficients(field: &str, friction: Option<f64>, ke: Option<f64>, lambda: Option<f64>) -> R {
    if let Some(mu) = friction {
        if !(mu.is_finite() && mu >= 0.0) {
            return Err(ScenarioError::invalid(
                format!("{field}.friction"),
                format!("{mu} must be a finite number >= 0"),
            ));
        }
    }
    if let Some(ke) = ke {
        if !(ke > 0.0 && ke <= 1.0) {
            return Err(ScenarioError::invalid(
                format!("{field}.ke"),
                format!("{ke} must lie in (0, 1]: 1 is elastic, restitution tends to sqrt(ke)"),
            ));
        }
    }
    if let Some(l) = lambda {
        if !(l.is_finite() && l >= 0.0) {
            return Err(ScenarioError::invalid(
                format!("{field}.lambda_s_m"),
                format!("{l} must be a finite number >= 0 (s/m)"),
            ));
        }
    }
    Ok(())
}

/// Validates everything that can be checked without building the world.
pub fn validate(sc: &Scenario) -> R {
    positive("duration_s", sc.duration_s)?;
    if let TimeStep::Fixed(dt) = sc.time_step_s {
        positive("time_step_s", dt)?;
        if dt > sc.duration_s {
            return Err(ScenarioError::invalid(
                "time_step_s",
                format!("{dt} is longer than duration_s = {}", sc.duration_s),
            ));
        }
    }
    if let Some(a) = sc.accuracy {
        let n = a.steps_per_contact();
        if !(n.is_finite() && n >= 5.0) {
            return Err(ScenarioError::invalid(
                "accuracy",
                format!("{n} steps per contact: give at least 5 (10 is about 1 % on peak forces)"),
            ));
        }
    }
    if let Some(m) = sc.max_time_step_s {
        positive("max_time_step_s", m)?;
    }
    if !(sc.model.energy_tolerance.is_finite() && sc.model.energy_tolerance > 0.0) {
        return Err(ScenarioError::invalid(
            "model.energy_tolerance",
            format!("{} must be > 0", sc.model.energy_tolerance),
        ));
    }
    if sc.model.max_steps == 0 {
        return Err(ScenarioError::invalid("model.max_steps", "must be > 0"));
    }
    finite3("gravity_m_s2", sc.gravity_m_s2)?;
    positive("output.sample_interval_s", sc.output.sample_interval_s)?;
    let tr = &sc.output.transitions;
    positive("output.transitions.slip_speed_m_s", tr.slip_speed_m_s)?;
    non_negative(
        "output.transitions.relative_tolerance",
        tr.relative_tolerance,
    )?;
    if !(tr.hysteresis >= 1.0 && tr.hysteresis.is_finite()) {
        return Err(ScenarioError::invalid(
            "output.transitions.hysteresis",
            format!("must be a finite number >= 1, got {}", tr.hysteresis),
        ));
    }
    non_negative("output.transitions.min_dwell_s", tr.min_dwell_s)?;
    positive("output.transitions.histogram_bin_m", tr.histogram_bin_m)?;
    if let Some(v) = &sc.output.vtk {
        positive("output.vtk.interval_s", v.interval_s)?;
    }
    positive("model.max_overlap_ratio", sc.model.max_overlap_ratio)?;
    if !(sc.model.min_steps_per_impact.is_finite() && sc.model.min_steps_per_impact >= 0.0) {
        return Err(ScenarioError::invalid(
            "model.min_steps_per_impact",
            format!("{} must be >= 0", sc.model.min_steps_per_impact),
        ));
    }
    if sc.materials.is_empty() {
        return Err(ScenarioError::invalid("materials", "no material defined"));
    }
    let mut mats = BTreeMap::new();
    for (name, m) in &sc.materials {
        if name.trim().is_empty() {
            return Err(ScenarioError::invalid(
                "materials",
                "a material has an empty name",
            ));
        }
        mats.insert(name.as_str(), material(name, m)?);
        if let Some(b) = &m.bruise {
            let f = format!("materials.{name}.bruise");
            for (field, v) in [
                ("peak_force_n", b.peak_force_n),
                ("mean_pressure_pa", b.mean_pressure_pa),
                ("absorbed_energy_j", b.absorbed_energy_j),
            ] {
                if let Some(v) = v {
                    positive(&format!("{f}.{field}"), v)?;
                }
            }
        }
    }
    let c = &sc.contact;
    coefficients("contact", Some(c.friction), Some(c.ke), Some(c.lambda_s_m))?;
    let mut seen_pairs = HashSet::new();
    for (k, p) in sc.pairs.iter().enumerate() {
        let f = format!("pairs[{k}]");
        for (n, m) in p.materials.iter().enumerate() {
            if !mats.contains_key(m.as_str()) {
                return Err(ScenarioError::invalid(
                    format!("{f}.materials[{n}]"),
                    format!("unknown material '{m}' (defined: {})", list(&mats)),
                ));
            }
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
    }

    let mut names = HashSet::new();
    for (k, a) in sc.apples.iter().enumerate() {
        apple(&format!("apples[{k}]"), a, &mats, &mut names)?;
    }
    for (k, g) in sc.generators.iter().enumerate() {
        let f = format!("generators[{k}]");
        match g {
            GeneratorSpec::Grid(s) => {
                prefix_and_material(&f, &s.name, &s.material, s.mass_kg, &mats)?;
                s.diameter_m.validate(&format!("{f}.diameter_m"))?;
                finite3(&format!("{f}.origin_m"), s.origin_m)?;
                finite3(&format!("{f}.velocity_m_s"), s.velocity_m_s)?;
                for (c, &x) in s.spacing_m.iter().enumerate() {
                    positive(&format!("{f}.spacing_m[{c}]"), x)?;
                }
                if !(s.jitter_m.is_finite() && s.jitter_m >= 0.0) {
                    return Err(ScenarioError::invalid(
                        format!("{f}.jitter_m"),
                        format!("{} must be >= 0", s.jitter_m),
                    ));
                }
            }
            GeneratorSpec::RandomFill(s) => {
                prefix_and_material(&f, &s.name, &s.material, s.mass_kg, &mats)?;
                s.diameter_m.validate(&format!("{f}.diameter_m"))?;
                finite3(&format!("{f}.region_min_m"), s.region_min_m)?;
                finite3(&format!("{f}.region_max_m"), s.region_max_m)?;
                finite3(&format!("{f}.velocity_m_s"), s.velocity_m_s)?;
            }
            GeneratorSpec::File(s) => {
                prefix_and_material(&f, &s.name, &s.material, s.mass_kg, &mats)?;
                finite3(&format!("{f}.velocity_m_s"), s.velocity_m_s)?;
                file_apples(&f, s)?;
            }
        }
    }
    for (k, src) in sc.sources.iter().enumerate() {
        let f = format!("sources[{k}]");
        prefix_and_material(&f, &src.name, &src.material, src.mass_kg, &mats)?;
        src.diameter_m.validate(&format!("{f}.diameter_m"))?;
        finite3(&format!("{f}.position_m"), src.position_m)?;
        finite3(&format!("{f}.velocity_m_s"), src.velocity_m_s)?;
        positive(&format!("{f}.rate_per_s"), src.rate_per_s)?;
        if !(src.start_s.is_finite() && src.start_s >= 0.0) {
            return Err(ScenarioError::invalid(
                format!("{f}.start_s"),
                format!("{} must be >= 0", src.start_s),
            ));
        }
        if !(src.jitter_m.is_finite() && src.jitter_m >= 0.0) {
            return Err(ScenarioError::invalid(
                format!("{f}.jitter_m"),
                format!("{} must be >= 0", src.jitter_m),
            ));
        }
    }
    let sl = &sc.model.sleep;
    positive("model.sleep.speed_m_s", sl.speed_m_s)?;
    positive("model.sleep.time_s", sl.time_s)?;
    for (k, s) in sc.surfaces.iter().enumerate() {
        surface(&format!("surfaces[{k}]"), s, &mats, &mut names)?;
    }
    let all = sc.initial_apples()?;
    if all.is_empty() && sc.sources.is_empty() {
        return Err(ScenarioError::invalid(
            "apples",
            "no apple: give apples, generators or sources",
        ));
    }
    let mut gen_names = HashSet::new();
    for a in &all[sc.apples.len()..] {
        if names.contains(&a.name) || !gen_names.insert(a.name.clone()) {
            return Err(ScenarioError::invalid(
                "generators",
                format!(
                    "generated apple name '{}' is already used: change the generator's name",
                    a.name
                ),
            ));
        }
    }
    check_apple_overlaps(&all, sc.apples.len())
}

/// The apples of a `file` generator: read, at least one, unique non-empty names, diameters > 0
/// and finite positions. Errors name `generators[k].file` and the entry (`pile.json[3]`), since
/// the file is the user's input as much as the scenario.
fn file_apples(f: &str, s: &FileSpec) -> R {
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
    let mut seen = HashSet::new();
    for (k, a) in list.0.iter().enumerate() {
        let at = format!("{}[{k}]", s.file);
        if a.name.trim().is_empty() {
            return Err(ScenarioError::invalid(
                field,
                format!("{at}.name: empty name"),
            ));
        }
        if !seen.insert(a.name.as_str()) {
            return Err(ScenarioError::invalid(
                field,
                format!(
                    "{at}.name: '{}' is used twice: names must be unique",
                    a.name
                ),
            ));
        }
        if !(a.diameter_m.is_finite() && a.diameter_m > 0.0) {
            return Err(ScenarioError::invalid(
                field,
                format!(
                    "{at}.diameter_m: {} must be a finite number > 0 (apple '{}')",
                    a.diameter_m, a.name
                ),
            ));
        }
        if !a.position_m.iter().all(|x| x.is_finite()) {
            return Err(ScenarioError::invalid(
                field,
                format!(
                    "{at}.position_m: {:?} must hold finite numbers (apple '{}')",
                    a.position_m, a.name
                ),
            ));
        }
    }
    Ok(())
}

fn material_of<'a>(
    field: &str,
    name: &str,
    mats: &'a BTreeMap<&str, Material>,
) -> Result<&'a Material, ScenarioError> {
    mats.get(name).ok_or_else(|| {
        ScenarioError::invalid(
            field,
            format!("unknown material '{name}' (defined: {})", list(mats)),
        )
    })
}

fn prefix_and_material(
    f: &str,
    name: &str,
    material: &str,
    mass: Option<f64>,
    mats: &BTreeMap<&str, Material>,
) -> R {
    if name.trim().is_empty() {
        return Err(ScenarioError::invalid(format!("{f}.name"), "empty name"));
    }
    let m = material_of(&format!("{f}.material"), material, mats)?;
    match mass {
        Some(x) => positive(&format!("{f}.mass_kg"), x),
        None if m.density_kg_m3.is_none() => Err(ScenarioError::invalid(
            format!("{f}.mass_kg"),
            format!("missing, and material '{material}' has no density_kg_m3 to derive it from"),
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
    if a.name.trim().is_empty() {
        return Err(ScenarioError::invalid(format!("{f}.name"), "empty name"));
    }
    if !names.insert(a.name.clone()) {
        return Err(ScenarioError::invalid(
            format!("{f}.name"),
            format!("'{}' is used twice: names must be unique", a.name),
        ));
    }
    let m = material_of(&format!("{f}.material"), &a.material, mats)?;
    positive(&format!("{f}.diameter_m"), a.diameter_m)?;
    match a.mass_kg {
        Some(mass) => positive(&format!("{f}.mass_kg"), mass)?,
        None if m.density_kg_m3.is_none() => {
            return Err(ScenarioError::invalid(
                format!("{f}.mass_kg"),
                format!(
                    "missing, and material '{}' has no density_kg_m3 to derive it from",
                    a.material
                ),
            ))
        }
        None => {}
    }
    finite3(&format!("{f}.position_m"), a.position_m)?;
    finite3(&format!("{f}.velocity_m_s"), a.velocity_m_s)?;
    finite3(
        &format!("{f}.angular_velocity_rad_s"),
        a.angular_velocity_rad_s,
    )
}

fn size3(field: &str, v: [f64; 3]) -> R {
    for (c, &x) in v.iter().enumerate() {
        positive(&format!("{field}[{c}]"), x)?;
    }
    Ok(())
}

fn surface(
    f: &str,
    s: &SurfaceSpec,
    mats: &BTreeMap<&str, Material>,
    names: &mut HashSet<String>,
) -> R {
    if s.name().trim().is_empty() {
        return Err(ScenarioError::invalid(format!("{f}.name"), "empty name"));
    }
    if s.name().contains('/') {
        return Err(ScenarioError::invalid(
            format!("{f}.name"),
            format!("'{}': '/' is reserved for the walls of a bin", s.name()),
        ));
    }
    if !names.insert(s.name().to_string()) {
        return Err(ScenarioError::invalid(
            format!("{f}.name"),
            format!("'{}' is used twice: names must be unique", s.name()),
        ));
    }
    match s {
        SurfaceSpec::Plane(p) => {
            material_of(&format!("{f}.material"), &p.material, mats)?;
            finite3(&format!("{f}.point_m"), p.point_m)?;
            unit3(&format!("{f}.normal"), p.normal)?;
        }
        SurfaceSpec::Box(b) => {
            material_of(&format!("{f}.material"), &b.material, mats)?;
            size3(&format!("{f}.size_m"), b.size_m)?;
            finite3(&format!("{f}.position_m"), b.position_m)?;
            rotation_of(&b.rotation, f)?;
        }
        SurfaceSpec::Conveyor(b) => {
            material_of(&format!("{f}.material"), &b.material, mats)?;
            size3(&format!("{f}.size_m"), b.size_m)?;
            finite3(&format!("{f}.position_m"), b.position_m)?;
            rotation_of(&b.rotation, f)?;
            if !b.belt_velocity_m_s.is_finite() {
                return Err(ScenarioError::invalid(
                    format!("{f}.belt_velocity_m_s"),
                    "must be finite",
                ));
            }
        }
        SurfaceSpec::Chute(c) => {
            material_of(&format!("{f}.material"), &c.material, mats)?;
            positive(&format!("{f}.length_m"), c.length_m)?;
            finite3(&format!("{f}.position_m"), c.position_m)?;
            rotation_of(&c.rotation, f)?;
            if let Some(t) = c.thickness_m {
                positive(&format!("{f}.thickness_m"), t)?;
            }
            if !(c.incline_deg.is_finite() && c.incline_deg.abs() < 90.0) {
                return Err(ScenarioError::invalid(
                    format!("{f}.incline_deg"),
                    format!("{} must lie in (-90, 90)", c.incline_deg),
                ));
            }
            match c.profile {
                ChuteProfile::Flat => {
                    let w = c.width_m.ok_or_else(|| {
                        ScenarioError::invalid(format!("{f}.width_m"), "a flat chute needs width_m")
                    })?;
                    positive(&format!("{f}.width_m"), w)?;
                    if c.radius_m.is_some() || c.half_angle_deg.is_some() {
                        return Err(ScenarioError::invalid(
                            format!("{f}.radius_m"),
                            "radius_m and half_angle_deg belong to a trough, not a flat chute",
                        ));
                    }
                }
                ChuteProfile::Trough => {
                    let r = c.radius_m.ok_or_else(|| {
                        ScenarioError::invalid(format!("{f}.radius_m"), "a trough needs radius_m")
                    })?;
                    positive(&format!("{f}.radius_m"), r)?;
                    if c.width_m.is_some() {
                        return Err(ScenarioError::invalid(
                            format!("{f}.width_m"),
                            "a trough's width is set by radius_m",
                        ));
                    }
                    if let Some(h) = c.half_angle_deg {
                        if !(h > 0.0 && h <= 90.0) {
                            return Err(ScenarioError::invalid(
                                format!("{f}.half_angle_deg"),
                                format!("{h} must lie in (0, 90]"),
                            ));
                        }
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
            size3(&format!("{f}.inner_size_m"), b.inner_size_m)?;
            if let Some(t) = b.wall_thickness_m {
                positive(&format!("{f}.wall_thickness_m"), t)?;
            }
            finite3(&format!("{f}.position_m"), b.position_m)?;
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
            let sc = m.scale.vector();
            if !(sc.is_finite() && sc.min_element() > 0.0) {
                return Err(ScenarioError::invalid(
                    format!("{f}.scale"),
                    format!("{sc:?}: scale factors must be > 0"),
                ));
            }
            finite3(&format!("{f}.position_m"), m.position_m)?;
            rotation_of(&m.rotation, f)?;
        }
    }
    Ok(())
}

fn list(mats: &BTreeMap<&str, Material>) -> String {
    mats.keys().cloned().collect::<Vec<_>>().join(", ")
}

/// Two apples may touch but must not start inside each other. `listed` apples come from
/// `apples[]`; the rest were generated (named in the message, field `generators`).
fn check_apple_overlaps(all: &[AppleSpec], listed: usize) -> R {
    let pos: Vec<Vec3> = all.iter().map(|a| vec3(a.position_m)).collect();
    let r: Vec<f64> = all.iter().map(|a| a.diameter_m / 2.0).collect();
    let mut list = NeighborList::new(0.0);
    list.update(&pos, &r, &[], true, |_| {});
    for p in list.pairs() {
        let (i, j) = (p.i as usize, p.j as usize);
        let d = (pos[i] - pos[j]).length();
        let u = r[i] + r[j] - d;
        // A touching pair placed with round numbers may overlap by a rounding error.
        if u > 1e-9 * (r[i] + r[j]) {
            let field = if j < listed {
                format!("apples[{j}].position_m")
            } else {
                "generators".to_string()
            };
            return Err(ScenarioError::invalid(
                field,
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
