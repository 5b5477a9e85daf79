//! Validation of a parsed scenario: every check names the field and the value it saw.

use super::{Scenario, ScenarioError, SurfaceSpec};
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
    let built = match (m.shear_modulus_pa, m.youngs_modulus_pa) {
        (Some(g), None) => Material::from_shear(g, m.poisson_ratio, m.density_kg_m3),
        (None, Some(e)) => Material::from_youngs(e, m.poisson_ratio, m.density_kg_m3),
        (Some(_), Some(_)) => {
            return Err(ScenarioError::invalid(
                base,
                "gives both shear_modulus_pa and youngs_modulus_pa: give one (E = 2 G (1 + nu))",
            ))
        }
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
    positive("time_step_s", sc.time_step_s)?;
    if sc.time_step_s > sc.duration_s {
        return Err(ScenarioError::invalid(
            "time_step_s",
            format!(
                "{} is longer than duration_s = {}",
                sc.time_step_s, sc.duration_s
            ),
        ));
    }
    finite3("gravity_m_s2", sc.gravity_m_s2)?;
    positive("output.sample_interval_s", sc.output.sample_interval_s)?;
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
            return Err(ScenarioError::invalid("materials", "a material has an empty name"));
        }
        mats.insert(name.as_str(), material(name, m)?);
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
        let f = format!("apples[{k}]");
        if a.name.trim().is_empty() {
            return Err(ScenarioError::invalid(format!("{f}.name"), "empty name"));
        }
        if !names.insert(a.name.clone()) {
            return Err(ScenarioError::invalid(
                format!("{f}.name"),
                format!("'{}' is used twice: names must be unique", a.name),
            ));
        }
        let Some(m) = mats.get(a.material.as_str()) else {
            return Err(ScenarioError::invalid(
                format!("{f}.material"),
                format!("unknown material '{}' (defined: {})", a.material, list(&mats)),
            ));
        };
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
        finite3(&format!("{f}.angular_velocity_rad_s"), a.angular_velocity_rad_s)?;
    }
    for (k, s) in sc.surfaces.iter().enumerate() {
        let f = format!("surfaces[{k}]");
        if s.name().trim().is_empty() {
            return Err(ScenarioError::invalid(format!("{f}.name"), "empty name"));
        }
        if !names.insert(s.name().to_string()) {
            return Err(ScenarioError::invalid(
                format!("{f}.name"),
                format!("'{}' is used twice: names must be unique", s.name()),
            ));
        }
        match s {
            SurfaceSpec::Plane(p) => {
                if !mats.contains_key(p.material.as_str()) {
                    return Err(ScenarioError::invalid(
                        format!("{f}.material"),
                        format!("unknown material '{}' (defined: {})", p.material, list(&mats)),
                    ));
                }
                finite3(&format!("{f}.point_m"), p.point_m)?;
                unit3(&format!("{f}.normal"), p.normal)?;
            }
        }
    }
    check_apple_overlaps(sc)
}

fn list(mats: &BTreeMap<&str, Material>) -> String {
    mats.keys().cloned().collect::<Vec<_>>().join(", ")
}

/// Two apples may touch but must not start inside each other.
fn check_apple_overlaps(sc: &Scenario) -> R {
    let pos: Vec<Vec3> = sc.apples.iter().map(|a| vec3(a.position_m)).collect();
    let r: Vec<f64> = sc.apples.iter().map(|a| a.diameter_m / 2.0).collect();
    let mut list: NeighborList<()> = NeighborList::new(0.0);
    list.update(&pos, &r, &vec![true; pos.len()], |_| {});
    for p in list.pairs() {
        let (i, j) = (p.i as usize, p.j as usize);
        let d = (pos[i] - pos[j]).length();
        let u = r[i] + r[j] - d;
        // A touching pair placed with round numbers may overlap by a rounding error.
        if u > 1e-9 * (r[i] + r[j]) {
            return Err(ScenarioError::invalid(
                format!("apples[{j}].position_m"),
                format!(
                    "apple '{}' starts {:.4} mm inside apple '{}' (centres {:.4} mm apart, radii {} + {} m): move them apart",
                    sc.apples[j].name,
                    u * 1e3,
                    sc.apples[i].name,
                    d * 1e3,
                    r[i],
                    r[j]
                ),
            ));
        }
    }
    Ok(())
}
