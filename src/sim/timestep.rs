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
    for (k, a) in world.roster.apples().iter().enumerate() {
        let rb = world.apple_body(k);
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
        // A spheroid's stiffest contact: its largest radius of curvature (docs/shape.md).
        let r = match a.height_m {
            Some(_) => a.spheroid().stiffest_radius(),
            None => a.radius_m,
        };
        consider(&a.material, r, a.mass_kg);
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
        // Spheroids fed with an aspect: the stiffest radius of curvature the aspects can give,
        // and the lightest of them (a flatter apple of the same diameter is lighter by its
        // aspect, and a lighter apple's contact is shorter).
        let (r, m) = match &s.aspect {
            Some(x) if !x.is_sphere() => {
                let ratio = [x.min(), x.max()]
                    .into_iter()
                    .map(crate::contact::spheroid::Spheroid::stiffest_radius_ratio)
                    .fold(1.0, f64::max);
                let lighter = if s.mass_kg.is_none() {
                    x.min().min(1.0)
                } else {
                    1.0
                };
                (ratio * d / 2.0, m * lighter)
            }
            _ => (d / 2.0, m),
        };
        consider(&s.material, r, m);
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
    // A light free-turning roller's spin needs its own step (see `RollerStability`); never
    // below the shortest step there is (`check_free_rollers` refuses such a roller).
    let roller_s = free_roller_stability(sc, world)
        .iter()
        .map(|r| r.max_step_s.max(scenario::ranges::TIME_STEP.min))
        .fold(f64::INFINITY, f64::min);
    let resolved = stiffest
        .as_ref()
        .map(|s| s.contact_time_s / n)
        .unwrap_or(f64::INFINITY)
        .min(max_s)
        .min(motion_s)
        .min(roller_s);
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
                format!(
                    "{} s of simulated time in steps of time_step_s = {dt:e} s",
                    sc.duration_s
                ),
            ),
            (TimeStep::Fixed(dt), _) => (
                "time_step_s",
                format!(
                    "duration_s = {} s of simulated time in steps of {dt:e} s",
                    sc.duration_s
                ),
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

/// The longest step at which a free-turning roller's spin stays stable, and the lightest roller
/// that is stable at a given step (docs/physics.md section 12.5, "Stability of the spin").
///
/// The roller's rate w is updated explicitly from the friction its contacts put on it,
/// I dw/dt = R_r F_t, and the friction of a sticking contact is a spring on the slip,
/// F_t = -k_t xi - gamma_t s with xi' = s, k_t = 8 G* a (Mindlin). The slip s of the apple's and
/// the roller's surfaces changes by F_t (1/m_a + R_r^2/I) per unit time, 1/m_a = 7 / (2 m) for a
/// solid ball: the contact is an oscillator of mass m_t = 1 / (7/(2 m) + R_r^2 / I), stepped
/// like the apples (symplectic Euler). With a = k_t h^2 / m_t and b = gamma_t h / m_t, one step
/// maps (xi, s) by a matrix whose characteristic polynomial is z^2 - (2 - a - b) z + (1 - b);
/// both roots lie inside the unit circle iff 0 < b < 2 and a + 2 b < 4 (Jury). A light roller
/// makes m_t ~ I / R_r^2 small and a large: the spin rings and grows without bound (the Coulomb
/// cap only bounds it at a chatter of mu P h / m_t per step: 1e-11 kg m^2 at 1e-5 s spun at
/// 217,000 rad/s). Required here with a margin of two: a + 2 b <= 2. The Mindlin dashpot is a
/// share of the velocity-kill rate, gamma_t = 0.5 m_t / h (b = 0.5 for a lone contact), so
/// a <= 1: h <= sqrt(m_t / k_t). LIGGGHTS's `history` dashpot gamma_t = 2 sqrt(5/6) |beta|
/// sqrt(k_t m) does not scale with m_t: h <= (sqrt(gamma_t^2 + 2 k_t m_t) - gamma_t) / k_t.
/// k_t is taken at the largest contact radius the scene can produce on the roller: the impact
/// at the scene's largest speed ([`speed_bound`]) or the apple's weight, whichever presses more.
#[derive(Debug, Clone, PartialEq)]
pub struct RollerStability {
    /// The JSON path of the roller's moment of inertia
    /// (`surfaces[k].free_turning.moment_of_inertia_kg_m2`).
    pub field: String,
    /// The roller (a bed's rollers are alike: its first, `NAME/0`).
    pub roller: String,
    /// Its moment of inertia (kg m^2).
    pub inertia_kg_m2: f64,
    /// The apple whose contact is the stiffest for it (a description).
    pub apple: String,
    /// The stick spring's stiffness k_t at the largest contact radius (N/m).
    pub stiffness_n_m: f64,
    /// The longest stable step with this inertia (s).
    pub max_step_s: f64,
    /// The `history` model's dashpot gamma_t (N s/m), `None` for Mindlin.
    history: Option<f64>,
    apple_inv_mass: f64,
    radius_m: f64,
}

impl RollerStability {
    /// The lightest moment of inertia stable at step `h` (kg m^2); infinite when no roller is
    /// (the apple's own tangential mass is then too light for the step).
    pub fn min_inertia_kg_m2(&self, h: f64) -> f64 {
        let k = self.stiffness_n_m;
        let m_t = match self.history {
            None => k * h * h,
            Some(gamma) => 0.5 * (k * h * h + 2.0 * gamma * h),
        };
        let inv = 1.0 / m_t - self.apple_inv_mass;
        if inv > 0.0 {
            self.radius_m * self.radius_m / inv
        } else {
            f64::INFINITY
        }
    }
}

/// The longest stable step of a contact oscillator of mass `m_t` and stiffness `k` (see
/// [`RollerStability`]): `gamma` the history dashpot, `None` for Mindlin.
fn stable_step(k: f64, m_t: f64, history: Option<f64>) -> f64 {
    match history {
        None => (m_t / k).sqrt(),
        Some(gamma) => ((gamma * gamma + 2.0 * k * m_t).sqrt() - gamma) / k,
    }
}

/// The spin stability of every free-turning roller of the scene (one per roller or bed spec),
/// from the apples it can meet: the roster's and the sources' (their smallest and largest).
pub fn free_roller_stability(sc: &Scenario, world: &World) -> Vec<RollerStability> {
    let mut out = Vec::new();
    if sc.fidelity == Fidelity::Rigid {
        return out;
    }
    let v = speed_bound(sc, world).max(1e-3);
    let g = vec3(sc.gravity_m_s2).length();
    let mat = |name: &str| {
        sc.materials
            .get(name)
            .and_then(|m| scenario::validate::material(name, m).ok())
    };
    // The apples a roller can meet: (material, radius, mass, description).
    let mut apples: Vec<(String, f64, f64, String)> = Vec::new();
    let mut consider = |material: &str, r: f64, m: f64, what: String| {
        if !apples
            .iter()
            .any(|a| a.0 == material && a.1 == r && a.2 == m)
        {
            apples.push((material.to_string(), r, m, what));
        }
    };
    // Per material, the largest apple and the lightest one (k_t grows with both radius and
    // mass, m_t shrinks with the mass).
    // (material, its largest apple, its lightest apple), each (radius, mass, description).
    type Pick = (f64, f64, String);
    let mut extremes: Vec<(String, Pick, Pick)> = Vec::new();
    for a in world.roster.apples() {
        let what = format!("apple '{}'", a.name);
        match extremes.iter_mut().find(|e| e.0 == a.material) {
            Some(e) => {
                if a.radius_m > e.1 .0 {
                    e.1 = (a.radius_m, a.mass_kg, what.clone());
                }
                if a.mass_kg < e.2 .1 {
                    e.2 = (a.radius_m, a.mass_kg, what);
                }
            }
            None => extremes.push((
                a.material.clone(),
                (a.radius_m, a.mass_kg, what.clone()),
                (a.radius_m, a.mass_kg, what),
            )),
        }
    }
    for (material, big, light) in extremes {
        consider(&material, big.0, big.1, big.2);
        consider(&material, light.0, light.1, light.2);
    }
    for s in &sc.sources {
        let density = mat(&s.material)
            .and_then(|m| m.density_kg_m3)
            .unwrap_or(0.0);
        for d in [s.diameter_m.min_m().max(1e-3), s.diameter_m.max_m()] {
            let m = s.mass_kg.unwrap_or_else(|| sphere_mass(d, density));
            consider(
                &s.material,
                d / 2.0,
                m,
                format!("the apples of source '{}'", s.name),
            );
        }
    }
    for (k, spec) in sc.surfaces.iter().enumerate() {
        let (roller, name) = match spec {
            SurfaceSpec::Roller(r) => (r.clone(), r.name.clone()),
            SurfaceSpec::RollerBed(b) => (b.roller(0), b.roller(0).name),
            _ => continue,
        };
        let Some(ft) = &roller.free_turning else {
            continue;
        };
        if roller.contact_model == scenario::ContactModel::Rigid {
            continue;
        }
        let Some(rm) = mat(&roller.material) else {
            continue;
        };
        let (i, rr) = (ft.moment_of_inertia_kg_m2, roller.radius_m);
        let mut worst: Option<RollerStability> = None;
        for (am, ra, m, what) in &apples {
            let Some(a) = mat(am) else { continue };
            let c = sc.pair_law(am, &roller.material);
            if c.friction <= 0.0 || !(m.is_finite() && *m > 0.0) {
                continue;
            }
            let law = crate::contact::PairLaw::new(
                &a,
                &rm,
                c.friction,
                c.ke.unwrap_or(1.0),
                c.lambda_s_m.unwrap_or(0.0),
            )
            .with_models(crate::world::coefficients(&c).models);
            let r_star = crate::contact::elliptic::sphere_on_cylinder(*ra, rr).stiffness_radius_m;
            let kn = normal::stiffness(law.e_star_pa, r_star);
            let u_impact = theory::elastic_impact(*m, v, kn, r_star).max_overlap_m;
            let u_rest = (m * g / kn).powf(2.0 / 3.0);
            let u = u_impact.max(u_rest);
            let k_t =
                crate::contact::friction::mindlin_stiffness(law.g_star_pa, (r_star * u).sqrt());
            let apple_inv = 3.5 / m;
            let m_t = 1.0 / (apple_inv + rr * rr / i);
            let history =
                (law.models.tangential == crate::contact::TangentialModel::History).then(|| {
                    2.0 * crate::contact::damping::SQRT_FIVE_SIXTHS
                        * law.beta.abs()
                        * (k_t * m).sqrt()
                });
            let h = stable_step(k_t, m_t, history);
            if h.is_finite() && worst.as_ref().is_none_or(|w| h < w.max_step_s) {
                worst = Some(RollerStability {
                    field: format!("surfaces[{k}].free_turning.moment_of_inertia_kg_m2"),
                    roller: name.clone(),
                    inertia_kg_m2: i,
                    apple: what.clone(),
                    stiffness_n_m: k_t,
                    max_step_s: h,
                    history,
                    apple_inv_mass: apple_inv,
                    radius_m: rr,
                });
            }
        }
        out.extend(worst);
    }
    out
}

/// Refuses, before the run, a free-turning roller too light for the step the run would take
/// (see [`RollerStability`]): a fixed `time_step_s` longer than its stable step, or a stable step
/// under the shortest step there is (1e-9 s) whatever the policy. `auto` takes the roller's
/// stable step when it is shorter ([`plan`]); `adaptive` shortens its steps on the roller's
/// contacts (the layer's stick limit counts the roller's inertia).
pub fn check_free_rollers(
    sc: &Scenario,
    world: &World,
    plan: &StepPlan,
) -> Result<(), ScenarioError> {
    let floor = scenario::ranges::TIME_STEP.min;
    for r in free_roller_stability(sc, world) {
        let dt = match sc.time_step_s {
            TimeStep::Fixed(dt) => dt,
            _ => plan.initial_s.max(floor),
        };
        let fixed = matches!(sc.time_step_s, TimeStep::Fixed(_));
        if (fixed && dt > r.max_step_s * (1.0 + 1e-9)) || r.max_step_s < floor {
            let how = if fixed && r.max_step_s >= floor {
                format!(", or time_step_s <= {:e} s", round_down(r.max_step_s))
            } else {
                String::new()
            };
            return Err(ScenarioError::invalid(
                r.field.clone(),
                format!(
                    "{} kg m^2 is too light for the roller '{}' at a step of {dt:e} s: its spin, updated from the friction of its contact with {} (stick stiffness k_t = {} N/m), is stable only for steps up to {:e} s (k_t h^2 / m_t <= 1 with the Mindlin dashpot, m_t = 1 / (7/(2 m) + R_r^2 / I); docs/physics.md 12.5); give at least {:e} kg m^2{how}",
                    scenario::ranges::num(r.inertia_kg_m2),
                    r.roller,
                    r.apple,
                    scenario::ranges::num3(r.stiffness_n_m),
                    round_down(r.max_step_s),
                    round_up(r.min_inertia_kg_m2(dt)),
                ),
            ));
        }
    }
    Ok(())
}

/// The thinnest part of the scene an apple can pass through: (its name, its thickness in m).
/// A box, a belt, a flat chute, a bin's walls and a roller have a thickness (a roller its
/// diameter); a mesh and a trough are shells of none. Planes (half-spaces) cannot be passed
/// through, and rapier's own `rigid` surfaces are not the layer's.
pub fn thinnest_part(sc: &Scenario) -> Option<(String, f64)> {
    use crate::world::surfaces::DEFAULT_THICKNESS_M;
    let mut thinnest: Option<(String, f64)> = None;
    for s in &sc.surfaces {
        if s.contact_model() == scenario::ContactModel::Rigid {
            continue;
        }
        let t = match s {
            SurfaceSpec::Plane(_) => continue,
            SurfaceSpec::Box(b) => b.size_m.iter().copied().fold(f64::INFINITY, f64::min),
            SurfaceSpec::Conveyor(c) => c.size_m.iter().copied().fold(f64::INFINITY, f64::min),
            SurfaceSpec::Chute(c) => match c.profile {
                scenario::surfaces::ChuteProfile::Flat => c
                    .thickness_m
                    .unwrap_or(DEFAULT_THICKNESS_M)
                    .min(c.width_m.unwrap_or(f64::INFINITY))
                    .min(c.length_m),
                scenario::surfaces::ChuteProfile::Trough => 0.0,
            },
            SurfaceSpec::Bin(b) => b.wall_thickness_m.unwrap_or(DEFAULT_THICKNESS_M),
            SurfaceSpec::Mesh(_) => 0.0,
            SurfaceSpec::Roller(r) => 2.0 * r.radius_m.min(r.length_m / 2.0),
            SurfaceSpec::RollerBed(b) => 2.0 * b.radius_m.min(b.length_m / 2.0),
        };
        if thinnest.as_ref().is_none_or(|x| t < x.1) {
            thinnest = Some((s.name().to_string(), t));
        }
    }
    thinnest
}

/// Refuses, before the run, a fixed step long enough for an apple to pass through the thinnest
/// part unseen (tunnelling). The layer sees a contact only at the poses of each step: an apple
/// of radius R closing on a part of thickness T at speed v moves v h per step, and once its
/// centre is past the part's middle the contact pushes it out on the far side. With
/// v h <= R + T/2 some step finds it touching on the near side, where the guards of the run
/// (the overlap limit, the steps per impact) take over. v is the largest closing speed the scene
/// can produce ([`speed_bound`]: the fastest apple, free fall over the scene's height, the
/// fastest belt or moving part); R the smallest apple's radius. The step named as the one that
/// works is the shorter of that bound and the step that resolves the stiffest impact in
/// the required steps (which the run would demand next). `auto` and `adaptive` steps keep every
/// apple within half of rapier's prediction distance per step, far below this.
pub fn check_tunnelling(
    sc: &Scenario,
    world: &World,
    plan: &StepPlan,
) -> Result<(), ScenarioError> {
    let TimeStep::Fixed(dt) = sc.time_step_s else {
        return Ok(());
    };
    if sc.fidelity == Fidelity::Rigid {
        return Ok(());
    }
    let Some((part, thickness)) = thinnest_part(sc) else {
        return Ok(());
    };
    let mut r_min = world
        .roster
        .apples()
        .iter()
        .map(|a| a.radius_m)
        .fold(f64::INFINITY, f64::min);
    for s in &sc.sources {
        r_min = r_min.min(0.5 * s.diameter_m.min_m().max(1e-3));
    }
    if !r_min.is_finite() {
        return Ok(());
    }
    let v = speed_bound(sc, world);
    let reach = r_min + 0.5 * thickness;
    if v * dt <= reach {
        return Ok(());
    }
    let tunnel_s = reach / v;
    let resolve_s = plan.stiffest.as_ref().map_or(f64::INFINITY, |s| {
        s.contact_time_s / sc.required_steps_per_impact().max(1.0)
    });
    let ok = round_down(tunnel_s.min(resolve_s));
    Err(ScenarioError::invalid(
        "time_step_s",
        format!(
            "{dt:e} s lets apples pass through parts unseen: the scene can close on '{part}' ({} mm thick) at up to {} m/s, {} mm in one step, more than an apple's radius ({} mm) and half the part; use time_step_s <= {ok:e} s (or \"auto\")",
            scenario::ranges::num3(thickness * 1e3),
            scenario::ranges::num3(v),
            scenario::ranges::num3(v * dt * 1e3),
            scenario::ranges::num3(r_min * 1e3),
        ),
    ))
}

/// `x` rounded down to 4 significant digits: a step stated as the one that works must not be
/// printed a hair above it (5.9576e-4 printed 5.958e-4 gave an impact 9.99995 steps).
fn round_down(x: f64) -> f64 {
    if !(x.is_finite() && x > 0.0) {
        return x;
    }
    let scale = 10f64.powi(3 - x.log10().floor() as i32);
    let y = (x * scale).floor() / scale;
    // The division may land a hair above the digits; keep it at or below x.
    if y > x {
        ((x * scale).floor() - 1.0) / scale
    } else {
        y
    }
}

/// `x` rounded up to 4 significant digits (a smallest value stated must be enough).
fn round_up(x: f64) -> f64 {
    if !(x.is_finite() && x > 0.0) {
        return x;
    }
    let scale = 10f64.powi(3 - x.log10().floor() as i32);
    let y = (x * scale).ceil() / scale;
    if y < x {
        ((x * scale).ceil() + 1.0) / scale
    } else {
        y
    }
}
