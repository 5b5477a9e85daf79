//! What the validation measures in one run, next to its reference: an impact of one apple on a
//! flat ([`ImpactRun`], Figs. 1-5 and the eq. 12 batch) or a slip-to-roll launch ([`RollRun`],
//! Figs. 6-7).
//!
//! Everything a reference value needs (mass, touch speed, materials, eq. 12 coefficients,
//! gravity) is read from the scenario as run, never from the run's results, and passed to
//! [`super::reference`]; only the measured columns come from the run's files.

use super::reference::{self, Elastic, Eq12Sign, ImpactOutcome, SlipToRoll};
use super::runs::{param, Executed, Run};
use super::ValidateError;
use crate::scenario::{AppleSpec, Scenario, SurfaceSpec};
use crate::world;

/// One impact of one apple on a flat platform, measured and referenced.
#[derive(Debug, Clone, PartialEq)]
pub struct ImpactRun {
    /// Legend and table label.
    pub label: String,
    /// The batch parameters of the run, by name.
    pub params: Vec<(String, f64)>,
    /// Normal speed at touch (m/s), from the scenario: the launch speed plus the fall through
    /// any starting gap.
    pub v0_m_s: f64,
    /// Apple mass (kg).
    pub mass_kg: f64,
    /// Apple diameter (m).
    pub diameter_m: f64,
    /// Apple shear modulus (Pa).
    pub apple_shear_modulus_pa: f64,
    /// Platform shear modulus (Pa).
    pub platform_shear_modulus_pa: f64,
    /// Hertz stiffness k = 4/3 E* sqrt(R) (N/m^1.5).
    pub stiffness: f64,
    /// Eq. 12 ke of the pair (1: elastic).
    pub ke: f64,
    /// Eq. 12 lambda of the pair (s/m).
    pub lambda_s_m: f64,
    /// Gravity along the platform normal (m/s^2).
    pub gravity_m_s2: f64,
    /// Row of `contacts.csv`.
    pub contact: usize,
    /// Peak force (N).
    pub peak_force_n: f64,
    /// Contact time (s).
    pub contact_time_s: f64,
    /// Largest overlap (m).
    pub max_overlap_m: f64,
    /// Measured restitution (NaN if none).
    pub restitution: f64,
    /// Measured approach speed at first touch (m/s).
    pub approach_speed_m_s: f64,
    /// The reference integration of the same impact (same mass, speed, law, gravity).
    pub reference: ImpactOutcome,
    /// The no-gravity elastic closed form (physics.md section 4), for comparison.
    pub closed_form: ImpactOutcome,
}

impl ImpactRun {
    /// The value of the batch parameter `name` of its run (NaN when the batch has none): the
    /// trends of a figure are over what its batch varies.
    pub fn param(&self, name: &str) -> f64 {
        param(&self.params, name)
    }
}

/// One slip-to-roll run (Figs. 6-7).
#[derive(Debug, Clone, PartialEq)]
pub struct RollRun {
    /// Legend and table label.
    pub label: String,
    /// Launch speed along x (m/s).
    pub v0_m_s: f64,
    /// Launch spin about y (rad/s).
    pub w0_rad_s: f64,
    /// Apple radius R (m).
    pub radius_m: f64,
    /// Time at which the slip speed v - (R - u) w reaches zero (s); NaN if it never did.
    pub t_roll_s: f64,
    /// Centre speed at the end of the run, rolling (m/s).
    pub rolling_speed_m_s: f64,
    /// Mean lever arm R - u (centre height above the plate) while sliding, as run (m).
    pub lever_m: f64,
    /// Resting sag u = (2 m g / ((1 + ke) k))^(2/3) under eq. 12 (physics.md section 3) (m):
    /// the closed form's lever is R - u.
    pub resting_overlap_m: f64,
    /// Friction coefficient.
    pub friction: f64,
    /// Closed form with the lever R - u, u the resting sag (physics.md section 6).
    pub closed: SlipToRoll,
    /// Closed form with the lever R.
    pub closed_plain: SlipToRoll,
}

/// The error for a spec whose scenes are not what the validation measures (the specs under
/// scenarios/paper/ edited out of shape): a validation must stop rather than check the wrong thing.
pub(super) fn shape(ex: &Executed, message: impl Into<String>) -> ValidateError {
    ValidateError::Shape {
        spec: ex.spec.display().to_string(),
        message: message.into(),
    }
}

/// The material `name` of a scenario, as the reference reads it (physics.md section 1): by the
/// modulus the scenario gives, never through the product's conversion.
fn material(ex: &Executed, sc: &Scenario, name: &str) -> Result<Elastic, ValidateError> {
    let m = sc
        .materials
        .get(name)
        .ok_or_else(|| shape(ex, format!("no material '{name}'")))?;
    match (m.shear_modulus_pa, m.youngs_modulus_pa) {
        (Some(g), _) => Ok(Elastic::from_shear(g, m.poisson_ratio.unwrap_or(f64::NAN))),
        (None, Some(e)) => Ok(Elastic::from_youngs(e, m.poisson_ratio.unwrap_or(f64::NAN))),
        (None, None) => Err(shape(ex, format!("material '{name}' has no modulus"))),
    }
}

/// (friction, ke, lambda) of a material pair: its `pairs` entry, else `contact` (the paper's
/// scenarios give ke and lambda: the validation runs eq. 12).
fn coefficients(sc: &Scenario, m1: &str, m2: &str) -> (f64, f64, f64) {
    let c = sc.pair_law(m1, m2);
    (c.friction, c.ke.unwrap_or(1.0), c.lambda_s_m.unwrap_or(0.0))
}

/// The platform an apple meets in the validation's scenes: a plane with normal +z, or a bin's
/// floor (unrotated): its material and height.
fn platform(ex: &Executed, sc: &Scenario, other: &str) -> Result<(String, f64), ValidateError> {
    for s in &sc.surfaces {
        match s {
            SurfaceSpec::Plane(p) if p.name == other => {
                if p.normal != [0.0, 0.0, 1.0] {
                    return Err(shape(ex, format!("plane '{other}' must face +z")));
                }
                return Ok((p.material.clone(), p.point_m[2]));
            }
            SurfaceSpec::Bin(b) if format!("{}/floor", b.name) == other => {
                if b.rotation.is_some() {
                    return Err(shape(ex, format!("bin '{}' must not be rotated", b.name)));
                }
                let m = b
                    .wall_materials
                    .as_ref()
                    .and_then(|w| w.floor.clone())
                    .unwrap_or_else(|| b.material.clone());
                return Ok((m, b.position_m[2]));
            }
            _ => {}
        }
    }
    Err(shape(ex, format!("no flat platform '{other}'")))
}

/// Measures the strongest contact of apple `apple` with the flat `other` in `run` and computes
/// the reference integration of the same impact.
pub(super) fn impact(
    ex: &Executed,
    run: &Run,
    apple: &str,
    other: &str,
    label: String,
) -> Result<ImpactRun, ValidateError> {
    let sc = &run.scenario;
    // The apples of the run as its world resolves them (their initial conditions and masses).
    let plan = world::roster::plan(sc).map_err(|e| shape(ex, format!("run {}: {e}", run.index)))?;
    let spec: &AppleSpec = plan
        .initial
        .iter()
        .map(|(a, _)| a)
        .find(|a| a.name == apple)
        .ok_or_else(|| shape(ex, format!("run {}: no apple '{apple}'", run.index)))?;
    let density = sc
        .materials
        .get(&spec.material)
        .and_then(|m| m.density_kg_m3);
    let mass_kg = Some(world::apple_mass(spec, density))
        .filter(|m| m.is_finite() && *m > 0.0)
        .ok_or_else(|| shape(ex, format!("apple '{apple}' has no mass")))?;
    let (plate_material, plate_z) = platform(ex, sc, other)?;
    let a = material(ex, sc, &spec.material)?;
    let p = material(ex, sc, &plate_material)?;
    let r = spec.diameter_m / 2.0;
    let k = reference::flat_stiffness(a, p, r);
    let (_, ke, lambda) = coefficients(sc, &spec.material, &plate_material);
    let g = -sc.gravity_m_s2[2];
    // Touch speed: the launch speed plus the fall through the starting gap, v^2 = v0^2 + 2 g h.
    let gap = spec.position_m[2] - r - plate_z;
    let v0 = (spec.velocity_m_s[2].powi(2) + 2.0 * g * gap.max(0.0)).sqrt();
    let row = run.strongest(apple, other).ok_or_else(|| {
        shape(
            ex,
            format!("run {}: '{apple}' never touched '{other}'", run.index),
        )
    })?;
    if !(v0.is_finite() && v0 > 0.0 && g.is_finite() && mass_kg > 0.0 && k > 0.0) {
        return Err(shape(
            ex,
            format!(
                "run {}: apple '{apple}' must approach '{other}' (touch speed {v0} m/s, mass {mass_kg} kg, gravity {g} m/s^2)",
                run.index
            ),
        ));
    }
    // The reference integrates the same impact from the touch. Its step is set by the elastic
    // no-gravity contact time (physics.md section 4), lengthened for eq. 12's slower unloading
    // (section 3: t_c = t_H / 2 (1 + 1/sqrt(ke))).
    let scale =
        reference::elastic_impact(mass_kg, v0, k).contact_time_s * 0.5 * (1.0 + 1.0 / ke.sqrt());
    let reference = if ke == 1.0 {
        reference::integrate_impact(mass_kg, v0, g, scale, |u, _| reference::hertz(k, u))
    } else {
        reference::integrate_impact(mass_kg, v0, g, scale, |u, w| {
            reference::eq12(k, ke, lambda, Eq12Sign::Dissipative, u, w)
        })
    }
    .ok_or_else(|| {
        shape(
            ex,
            format!(
                "run {}: the reference integration of '{apple}' on '{other}' never lifts off",
                run.index
            ),
        )
    })?;
    Ok(ImpactRun {
        label,
        params: run.params.clone(),
        v0_m_s: v0,
        mass_kg,
        diameter_m: spec.diameter_m,
        apple_shear_modulus_pa: a.shear_modulus_pa,
        platform_shear_modulus_pa: p.shear_modulus_pa,
        stiffness: k,
        ke,
        lambda_s_m: lambda,
        gravity_m_s2: g,
        contact: row.index,
        peak_force_n: row.peak_force_n,
        contact_time_s: row.duration_s,
        max_overlap_m: row.max_overlap_m,
        restitution: row.restitution,
        approach_speed_m_s: row.approach_speed_m_s,
        reference,
        closed_form: reference::elastic_impact(mass_kg, v0, k),
    })
}

/// Measures the slip-to-roll transition of the apple `apple` in `run` on a plate at z = 0.
///
/// The slip speed of the contact point is v_x - (R - u) w_y, R - u being the centre's height
/// above the plate; the transition is where it reaches zero, found (as in tests/slip_to_roll.rs)
/// on the straight line through the last two samples of the sliding phase (the slip falls
/// linearly while sliding).
pub(super) fn roll(ex: &Executed, run: &Run, label: String) -> Result<RollRun, ValidateError> {
    let sc = &run.scenario;
    let spec = sc
        .apples
        .first()
        .ok_or_else(|| shape(ex, format!("run {}: no apple", run.index)))?;
    let s = run.bodies(&spec.name)?;
    let plate = match sc.surfaces.first() {
        Some(SurfaceSpec::Plane(p)) if p.normal == [0.0, 0.0, 1.0] && p.point_m[2] == 0.0 => {
            p.material.clone()
        }
        _ => {
            return Err(shape(
                ex,
                format!(
                    "run {}: the first surface must be a plane through z = 0 facing +z",
                    run.index
                ),
            ))
        }
    };
    let (mu, ke, _) = coefficients(sc, &spec.material, &plate);
    let g = -sc.gravity_m_s2[2];
    let r = spec.diameter_m / 2.0;
    // The lever of the closed form, R - u with u the resting sag under eq. 12 (physics.md
    // sections 3 and 6), from the materials and the mass alone, not from the run.
    let mass_kg = world::apple_mass(
        spec,
        sc.materials
            .get(&spec.material)
            .and_then(|m| m.density_kg_m3),
    );
    let k = reference::flat_stiffness(
        material(ex, sc, &spec.material)?,
        material(ex, sc, &plate)?,
        r,
    );
    let sag = reference::resting_overlap(mass_kg, g, k, ke);
    let (v0, w0) = (spec.velocity_m_s[0], spec.angular_velocity_rad_s[1]);
    let slip: Vec<(f64, f64)> = s
        .iter()
        .map(|b| {
            (
                b.time_s,
                b.velocity_m_s[0] - b.position_m[2] * b.angular_velocity_rad_s[1],
            )
        })
        .collect();
    let s0 = slip.first().map_or(f64::NAN, |p| p.1);
    let k = slip
        .iter()
        .position(|&(_, v)| v.abs() < 1e-3 * s0.abs() || v.signum() != s0.signum());
    let (t_roll, lever) = match k {
        Some(k) if k >= 2 => {
            let (t1, v1) = slip[k - 2];
            let (t2, v2) = slip[k - 1];
            let lever = s[..k].iter().map(|b| b.position_m[2]).sum::<f64>() / k as f64;
            (t2 + v2 * (t2 - t1) / (v1 - v2), lever)
        }
        _ => (
            f64::NAN,
            s.iter().map(|b| b.position_m[2]).sum::<f64>() / s.len().max(1) as f64,
        ),
    };
    let last = s
        .last()
        .ok_or_else(|| shape(ex, format!("run {}: no samples", run.index)))?;
    Ok(RollRun {
        label,
        v0_m_s: v0,
        w0_rad_s: w0,
        radius_m: r,
        t_roll_s: t_roll,
        rolling_speed_m_s: last.velocity_m_s[0],
        lever_m: lever,
        friction: mu,
        resting_overlap_m: sag,
        closed: reference::slip_to_roll_with_lever(v0, w0, r, r - sag, mu, g),
        closed_plain: reference::slip_to_roll(v0, w0, r, mu, g),
    })
}
