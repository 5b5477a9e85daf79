//! The time-step policy: a fixed step, `auto` (a fixed step from the stiffest contact the scene
//! can produce), or `adaptive` (a step chosen every step from the contacts in progress and those
//! about to start).
//!
//! The criterion (physics.md section 10): the elastic contact time of an impact,
//! t_H = 2 * 1.4716 * u_max / v with u_max = (5 m v^2 / (4 k))^(2/5), must span N steps, N being the
//! accuracy target (preview 10, balanced 20, precise 50). `auto` takes, over every pair of kinds of
//! bodies the scene holds (the smallest apple of each material against each surface material and
//! against the smallest apple of each material), the shortest t_H at the largest approach speed
//! the scene can produce: the fastest initial or fed-in speed, plus free fall over the scene's
//! height, plus the fastest belt; apples meeting apples at twice that. `adaptive` asks the layer
//! every step (see `layer::StepStats::dt_limit_s`).

use crate::contact::{material::effective_modulus, normal, theory, Material};
use crate::layer::SurfaceId;
use crate::math::{vec3, Vec3};
use crate::scenario::{self, Fidelity, Scenario, ScenarioError, SurfaceSpec, TimeStep};
use crate::world::{sphere_mass, World};

/// The stiffest contact the scene can produce.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct StiffestContact {
    /// Its elastic contact time at the approach speed (s).
    pub contact_time_s: f64,
    /// Approach speed assumed (m/s).
    pub speed_m_s: f64,
    /// What meets what.
    pub pair: String,
}

/// How the run steps.
#[derive(Debug, Clone, PartialEq)]
pub enum Policy {
    /// The same step throughout (s).
    Fixed(f64),
    /// A step chosen every step, at most `max_s`, aiming at `steps_per_contact`.
    Adaptive {
        /// Steps per contact.
        steps_per_contact: f64,
        /// Largest step (s).
        max_s: f64,
    },
}

/// The step plan of a scenario.
#[derive(Debug, Clone, PartialEq)]
pub struct StepPlan {
    /// The policy.
    pub policy: Policy,
    /// The first step (s).
    pub initial_s: f64,
    /// The stiffest contact estimate behind `auto` (and the first adaptive step).
    pub stiffest: Option<StiffestContact>,
}

/// Largest speed along the scene's "up" that free fall over its height can produce, plus the
/// fastest initial, fed-in, belt or moving-part speed (m/s).
pub fn speed_bound(sc: &Scenario, world: &World) -> f64 {
    let g = vec3(sc.gravity_m_s2);
    let gmag = g.length();
    let up = if gmag > 0.0 { -g / gmag } else { Vec3::Z };
    let mut top = f64::NEG_INFINITY;
    let mut bottom = f64::INFINITY;
    let mut v0: f64 = 0.0;
    // The apples present now (at build: where the scenario placed them).
    for (a, &bh) in world.roster.apples().iter().zip(&world.apple_bodies) {
        let rb = &world.physics.bodies[bh];
        let h = up.dot(rb.translation());
        top = top.max(h);
        bottom = bottom.min(h - a.radius_m);
        v0 = v0.max(rb.linvel().length() + rb.angvel().length() * a.radius_m);
    }
    for s in sc.sources.iter().filter(|s| s.motion.is_none()) {
        let w = s.jitter_m.half_widths(g);
        let h = up.dot(vec3(s.position_m)) + (0..3).map(|c| up[c].abs() * w[c]).sum::<f64>();
        top = top.max(h);
        v0 = v0.max(vec3(s.velocity_m_s).length());
    }
    // A moving source: where and how fast its planned apples appear.
    if let Some((h, v)) = world.moving_feed_bounds(up) {
        top = top.max(h);
        v0 = v0.max(v);
    }
    let mut belt: f64 = 0.0;
    for (k, s) in sc.surfaces.iter().enumerate() {
        match s {
            SurfaceSpec::Plane(p) => {
                if vec3(p.normal).dot(up) > 0.5 {
                    bottom = bottom.min(up.dot(vec3(p.point_m)));
                }
                let _ = k;
            }
            SurfaceSpec::Conveyor(c) => belt = belt.max(c.belt_velocity_m_s.abs()),
            _ => {}
        }
    }
    for (s, &ch) in world.surface_colliders.iter().enumerate() {
        let shape_is_plane = world.physics.colliders[ch].shape().as_halfspace().is_some();
        if shape_is_plane {
            continue;
        }
        let aabb = world.physics.colliders[ch].compute_aabb();
        let _ = SurfaceId(s as u32);
        for c in aabb.vertices() {
            bottom = bottom.min(up.dot(c));
        }
    }
    let height = if top.is_finite() && bottom.is_finite() {
        (top - bottom).max(0.0)
    } else {
        0.0
    };
    // A moving part (a turning roller, a swinging flap) meets apples at its own speed too.
    v0 + (2.0 * gmag * height).sqrt() + belt.max(world.moving_speed_m_s())
}

/// The stiffest contact the scene can produce (see the module documentation).
pub fn stiffest_contact(sc: &Scenario, world: &World) -> Option<StiffestContact> {
    let v = speed_bound(sc, world).max(1e-3);
    let mats: Vec<(String, Material)> = sc
        .materials
        .iter()
        .filter_map(|(n, m)| {
            scenario::validate::material(n, m)
                .ok()
                .map(|x| (n.clone(), x))
        })
        .collect();
    let mat = |name: &str| mats.iter().find(|(n, _)| n == name).map(|(_, m)| *m);
    // The smallest apple of each material (the stiffest: m / k grows with R^2.5).
    let mut kinds: Vec<(String, f64, f64)> = Vec::new(); // material, radius, mass
    let mut consider =
        |material: &str, r: f64, m: f64| match kinds.iter_mut().find(|k| k.0 == material) {
            Some(k) if r < k.1 => *k = (material.to_string(), r, m),
            Some(_) => {}
            None => kinds.push((material.to_string(), r, m)),
        };
    let apple_count =
        world.roster.len() + sc.sources.iter().map(|s| s.count as usize).sum::<usize>();
    for a in world.roster.apples() {
        consider(&a.material, a.radius_m, a.mass_kg);
    }
    for s in &sc.sources {
        let d = match s.diameter_m {
            scenario::DiameterSpec::Fixed(d) => d,
            scenario::DiameterSpec::Distribution(x) => x.mean_m - 3.0 * x.spread_m.max(0.0),
        }
        .max(1e-3);
        let density = mat(&s.material).and_then(|m| m.density_kg_m3);
        let m = s
            .mass_kg
            .unwrap_or_else(|| sphere_mass(d, density.unwrap_or(0.0)));
        consider(&s.material, d / 2.0, m);
    }
    let surface_mats: Vec<String> = (0..world.layer.surface_count())
        .map(|s| {
            world
                .layer
                .surface_material_name(SurfaceId(s as u32))
                .to_string()
        })
        .collect();
    let mut best: Option<StiffestContact> = None;
    let mut offer = |t: f64, speed: f64, pair: String| {
        if t.is_finite() && best.as_ref().is_none_or(|b| t < b.contact_time_s) {
            best = Some(StiffestContact {
                contact_time_s: t,
                speed_m_s: speed,
                pair,
            });
        }
    };
    for (am, r, m) in &kinds {
        let Some(a) = mat(am) else { continue };
        for sm in &surface_mats {
            let Some(s) = mat(sm) else { continue };
            let k = normal::stiffness(effective_modulus(&a, &s), *r);
            let t = theory::elastic_impact(*m, v, k, *r).contact_time_s;
            offer(t, v, format!("apple of {} mm ({am}) on {sm}", 2000.0 * r));
        }
        // Apples meet apples only if there are two.
        let partners = if apple_count >= 2 {
            &kinds[..]
        } else {
            &[][..]
        };
        for (bm, r2, m2) in partners {
            let Some(b) = mat(bm) else { continue };
            let r_star = r * r2 / (r + r2);
            let k = normal::stiffness(effective_modulus(&a, &b), r_star);
            let t = theory::elastic_impact(theory::reduced_mass(*m, *m2), 2.0 * v, k, r_star)
                .contact_time_s;
            offer(
                t,
                2.0 * v,
                format!(
                    "apple of {} mm ({am}) on apple of {} mm ({bm})",
                    2000.0 * r,
                    2000.0 * r2
                ),
            );
        }
    }
    best
}

/// The step plan of a built scenario.
pub fn plan(sc: &Scenario, world: &World) -> StepPlan {
    let n = sc.steps_per_contact();
    let max_s = sc.max_step_s();
    let stiffest = if sc.fidelity == Fidelity::Rigid {
        None
    } else {
        stiffest_contact(sc, world)
    };
    let v = speed_bound(sc, world);
    // rapier finds surface pairs from the poses before the step: no apple may cross its margin in
    // one step (the adaptive step checks the actual speeds every step, see the layer).
    let motion_s = if v > 0.0 {
        0.5 * world.physics.integration_parameters.prediction_distance() / v
    } else {
        f64::INFINITY
    };
    let resolved = stiffest
        .as_ref()
        .map(|s| s.contact_time_s / n)
        .unwrap_or(f64::INFINITY)
        .min(max_s)
        .min(motion_s);
    match sc.time_step_s {
        TimeStep::Fixed(dt) => StepPlan {
            policy: Policy::Fixed(dt),
            initial_s: dt,
            stiffest,
        },
        TimeStep::Auto => StepPlan {
            policy: Policy::Fixed(resolved),
            initial_s: resolved,
            stiffest,
        },
        TimeStep::Adaptive if sc.fidelity == Fidelity::Rigid => StepPlan {
            policy: Policy::Fixed(resolved),
            initial_s: resolved,
            stiffest,
        },
        TimeStep::Adaptive => StepPlan {
            policy: Policy::Adaptive {
                steps_per_contact: n,
                max_s,
            },
            initial_s: resolved,
            stiffest,
        },
    }
}

/// The number of steps a run of `sc` will take under `plan`, estimated before it starts: a fixed
/// (or `auto`) step divides the duration; an adaptive run takes at least one largest step at a
/// time, and resolves any impact in `steps_per_contact` steps (one impact at least, when anything
/// can touch).
pub fn estimated_steps(sc: &Scenario, world: &World, plan: &StepPlan) -> f64 {
    match plan.policy {
        Policy::Fixed(dt) => sc.duration_s / dt,
        Policy::Adaptive {
            steps_per_contact,
            max_s,
        } => {
            let apples =
                world.roster.len() + sc.sources.iter().map(|s| s.count as usize).sum::<usize>();
            let can_touch = apples >= 2 || (apples >= 1 && !sc.surfaces.is_empty());
            (sc.duration_s / max_s).max(if can_touch { steps_per_contact } else { 0.0 })
        }
    }
}

/// Refuses a run whose estimated steps exceed `model.max_steps` before it starts, with the
/// estimate and the field to change (a step of 1e-300 s would otherwise run for ever).
pub fn check_steps(sc: &Scenario, world: &World, plan: &StepPlan) -> Result<(), ScenarioError> {
    let steps = estimated_steps(sc, world, plan);
    let max = sc.model.max_steps as f64;
    if steps.is_nan() || steps > max {
        let (field, how) = match (sc.time_step_s, plan.policy.clone()) {
            // A step under 10 ns resolves nothing a fruit does: the step is the mistake.
            (TimeStep::Fixed(dt), _) if dt >= 1e-8 => (
                "duration_s",
                format!("{} s of simulated time in steps of {dt:e} s", sc.duration_s),
            ),
            (TimeStep::Fixed(dt), _) => (
                "time_step_s",
                format!("{} s of simulated time in steps of {dt:e} s", sc.duration_s),
            ),
            (_, Policy::Fixed(dt)) if sc.steps_per_contact() > 1000.0 => (
                "accuracy",
                format!(
                    "{} steps per contact make the `auto` step {dt:e} s",
                    sc.steps_per_contact()
                ),
            ),
            (_, Policy::Fixed(dt)) => (
                "duration_s",
                format!(
                    "{} s of simulated time in `auto` steps of {dt:e} s",
                    sc.duration_s
                ),
            ),
            (_, Policy::Adaptive { .. }) if sc.steps_per_contact() > 1000.0 => (
                "accuracy",
                format!(
                    "{} steps per contact for every impact",
                    sc.steps_per_contact()
                ),
            ),
            (_, Policy::Adaptive { max_s, .. }) => (
                "duration_s",
                format!(
                    "{} s of simulated time in adaptive steps of at most {max_s:e} s",
                    sc.duration_s
                ),
            ),
        };
        return Err(ScenarioError::invalid(
            field,
            format!(
                "the run needs about {steps:.3e} steps ({how}), more than model.max_steps = {}; it is refused before it starts",
                sc.model.max_steps
            ),
        ));
    }
    Ok(())
}
