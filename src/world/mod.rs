//! World building: a validated scenario becomes rapier bodies and colliders, registered with a
//! [`ContactLayer`].
//!
//! Integration settings follow rapier-notes.md: `num_solver_iterations = 1` makes rapier's step
//! exact symplectic Euler (the default 4 weights the force term by (N+1)/(2N) and gains energy);
//! CCD is off (contacts are resolved by the force law over many steps, never by CCD clamping);
//! apples never sleep by rapier's own rule (the layer puts them to sleep, see `layer::sleep`).
//!
//! An apple is a rigid body with the mass properties of a solid ball and no collider: the layer
//! finds all its contacts, so a collider would only cost rapier an update per apple per step
//! (docs/performance.md). Apples get a ball collider only when rapier itself must touch them: a
//! surface with rapier's own contact (`"contact_model": "rigid"`) or the `rigid` fidelity.
//! Gyroscopic forces are off: for a ball's isotropic inertia the term w x (I w) is zero, and
//! rapier would spend a sixth of its step computing it.

pub mod mesh;
pub mod motion;
pub mod roster;
pub mod surfaces;

use crate::contact::Material;
use crate::contact::{LawParts, SubModels};
use crate::layer::{
    AppleId, Coefficients, ContactLayer, Guard, LayerConfig, LayerError, MaterialId, SleepConfig,
    StepControl, SurfaceId, SurfaceOptions,
};
use crate::math::vec3;
use crate::scenario::{self, AppleSpec, ContactModel, Fidelity, Scenario, ScenarioError, TimeStep};
use rapier3d_f64::prelude::*;
pub use roster::{apple_mass, sphere_mass, Origin, Roster, RosterApple};
use std::collections::{BTreeMap, VecDeque};
use std::path::Path;
use surfaces::SurfacePart;
use thiserror::Error;

/// Largest initial overlap of an apple with a surface, as a fraction of its radius: an apple may
/// be placed at its resting sag (about 0.3 % of R for the paper's apple), not deeper.
pub const MAX_INITIAL_SURFACE_OVERLAP_RATIO: f64 = 0.01;

/// Collision group of apple colliders (when a scene needs them).
const APPLE_GROUP: Group = Group::GROUP_32;

/// Collision group of the surfaces whose contacts the layer computes.
const HERTZ_SURFACE_GROUP: Group = Group::GROUP_31;

/// Samples of force history kept per contact when the scenario asks for histories.
pub const FORCE_HISTORY_CAP: usize = 4096;

/// Errors while building the world.
#[derive(Debug, Error)]
pub enum BuildError {
    /// A scenario mistake found while building (it names the field).
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    /// A layer registration error.
    #[error(transparent)]
    Layer(#[from] LayerError),
}

/// The rapier world plus our layer, ready to step.
pub struct World {
    /// rapier's sets, pipeline and parameters.
    pub physics: PhysicsWorld,
    /// The contact layer.
    pub layer: ContactLayer,
    /// Rigid body of each apple, in layer order (listed, generated, then fed in).
    pub apple_bodies: Vec<RigidBodyHandle>,
    /// Every apple in the world, in layer order: name, material, radius, mass, origin.
    pub roster: Roster,
    /// Collider of each surface part, in layer order.
    pub surface_colliders: Vec<ColliderHandle>,
    /// Frame of each surface part in which positions along it are measured, if it has a running
    /// direction ([`surfaces::SurfacePart::along`]).
    pub surface_frames: Vec<Option<rapier3d_f64::math::Pose>>,
    /// Whether apples carry ball colliders (only when rapier itself must touch them).
    apple_colliders: bool,
    /// The kinematic body of each moving surface spec and its motion.
    movers: Vec<(RigidBodyHandle, motion::Motion)>,
    /// Largest speed of any moving part's surface over its profile (m/s).
    moving_speed_m_s: f64,
    /// Time of the current poses (s), set by the driver ([`World::set_time`]).
    time_s: f64,
    materials: BTreeMap<String, (MaterialId, Material)>,
    /// Emissions still to come: (planned time, source index, apple), in order.
    pending: VecDeque<(f64, usize, AppleSpec)>,
    postponed: u64,
}

/// The layer's coefficients and sub-models of a pair's contact law (validated: the eq. 12
/// dampings have ke and lambda, the viscoelastic one a restitution).
pub fn coefficients(c: &scenario::ContactSpec) -> Coefficients {
    Coefficients {
        friction: c.friction,
        ke: c.ke.unwrap_or(1.0),
        lambda_s_m: c.lambda_s_m.unwrap_or(0.0),
        models: SubModels {
            damping: c.damping.model(),
            restitution: c.restitution.unwrap_or(f64::NAN),
            tangential: c.tangential.model(),
            rolling: c.rolling.model(),
            rolling_friction: c.rolling_friction,
            rolling_damping: c.rolling_damping,
        },
    }
}

/// Builds the world of a validated scenario. `base_dir` is where relative asset paths (meshes)
/// are resolved.
pub fn build(sc: &Scenario, base_dir: &Path) -> Result<World, BuildError> {
    let mut physics = PhysicsWorld::new();
    physics.gravity = vec3(sc.gravity_m_s2);
    // The step itself is set by the driver before every step (sim::timestep plans it).
    let ip = &mut physics.integration_parameters;
    let rigid = sc.fidelity == Fidelity::Rigid;
    if rigid {
        // rapier's own contacts: its default solver iterations and CCD, for large steps.
        ip.num_solver_iterations = 4;
    } else {
        ip.num_solver_iterations = 1;
        ip.max_ccd_substeps = 0;
    }

    let sl = &sc.model.sleep;
    // Adaptive steps: the layer chooses each step (rigid fidelity: rapier's own contacts, a
    // fixed step). No apple may cross half of rapier's prediction distance in one step.
    let step_control = (sc.time_step_s == TimeStep::Adaptive && !rigid).then(|| StepControl {
        steps_per_contact: sc.steps_per_contact(),
        max_displacement_m: 0.5 * ip.prediction_distance(),
    });
    let config = LayerConfig {
        force_history_cap: if sc.output.force_history {
            FORCE_HISTORY_CAP
        } else {
            0
        },
        guard: Guard {
            max_overlap_ratio: sc.model.max_overlap_ratio,
            min_steps_per_impact: sc.required_steps_per_impact(),
        },
        parts: LawParts {
            energy_loss: sc.fidelity != Fidelity::Hertz,
            friction: true,
            patch_shift: sc.fidelity == Fidelity::Full,
        },
        passive: rigid,
        step_control,
        gravity: vec3(sc.gravity_m_s2),
        record_slips: sc.output.transitions.enabled,
        sleep: SleepConfig {
            enabled: sl.enabled,
            speed_m_s: sl.speed_m_s,
            time_s: sl.time_s,
            ..SleepConfig::default()
        },
        ..LayerConfig::default()
    };
    let mut layer = ContactLayer::new(config);
    let mut materials = BTreeMap::new();
    for (name, spec) in &sc.materials {
        let m = scenario::validate::material(name, spec)?;
        materials.insert(name.clone(), (layer.add_material(name, m), m));
    }
    layer.set_default_pair_law(coefficients(&sc.contact));
    for p in &sc.pairs {
        let a = materials[&p.materials[0]].0;
        let b = materials[&p.materials[1]].0;
        layer.set_pair_coefficients(a, b, coefficients(&p.over(&sc.contact)));
    }
    let mut world = World {
        physics,
        layer,
        apple_bodies: Vec::new(),
        roster: Roster::default(),
        surface_colliders: Vec::new(),
        surface_frames: Vec::new(),
        materials,
        pending: VecDeque::new(),
        postponed: 0,
        movers: Vec::new(),
        moving_speed_m_s: 0.0,
        time_s: 0.0,
        apple_colliders: rigid
            || sc
                .surfaces
                .iter()
                .any(|s| s.contact_model() == ContactModel::Rigid),
    };

    // An apple material for rigid surfaces' coefficients: the first apple's, or any source's.
    let apple_material = sc
        .apples
        .first()
        .map(|a| a.material.clone())
        .or_else(|| sc.sources.first().map(|s| s.material.clone()));
    for (k, s) in sc.surfaces.iter().enumerate() {
        let field = format!("surfaces[{k}]");
        // A moving part rides a kinematic body placed at its rest pose, moving at its initial
        // velocity (rapier derives the velocity from the poses only once it steps).
        let mover = motion::Motion::of(s).map(|m| {
            let (lin, ang) = m.velocity(0.0);
            let body = RigidBodyBuilder::kinematic_position_based()
                .pose(m.rest_pose())
                .linvel(lin)
                .angvel(ang)
                .build();
            (world.physics.bodies.insert(body), m)
        });
        for part in surfaces::parts(s, &field, base_dir)? {
            let parent = mover.as_ref().map(|(b, m)| (*b, m.rest_pose()));
            world.add_surface(part, apple_material.as_deref(), parent)?;
        }
        if let Some((b, m)) = mover {
            // The farthest point of its colliders from the body's origin.
            let origin = m.rest_pose().translation;
            let reach = world.physics.bodies[b]
                .colliders()
                .iter()
                .filter_map(|&c| world.physics.colliders.get(c))
                .map(|c| {
                    let bs = c.shape().compute_local_bounding_sphere();
                    (c.position() * bs.center - origin).length() + bs.radius
                })
                .filter(|r| r.is_finite())
                .fold(0.0, f64::max);
            world.moving_speed_m_s = world.moving_speed_m_s.max(m.max_speed_m_s(reach));
            world.movers.push((b, m));
        }
    }
    let plan = roster::plan(sc)?;
    for (a, origin) in &plan.initial {
        world.add_apple(a, *origin)?;
    }
    world.layer.check_conformity()?;
    check_initial_surface_overlaps(sc, &plan.initial, &world)?;
    world.pending = plan.feeds.into();

    // Apples with colliders (rapier's own contact with rigid surfaces): a step of length zero runs
    // rapier's collision detection only, so the rigid contacts touching at t = 0 are known before
    // the first step. The layer needs none of it: it finds its contacts itself.
    if world.apple_colliders {
        world.refresh_pairs();
    }
    Ok(world)
}

impl World {
    /// Advances rapier by `dt_s`: the step the layer answered the force pass with (the forces it
    /// set are for that step). The step is set here, every step; the world has no step of its
    /// own.
    pub fn advance(&mut self, dt_s: f64) {
        if dt_s > 0.0 {
            // Each moving part to its pose at the end of the step: rapier moves it there and
            // gives it the velocity that does so.
            let t = self.time_s + dt_s;
            for (b, m) in &self.movers {
                if let Some(rb) = self.physics.bodies.get_mut(*b) {
                    rb.set_next_kinematic_position(m.pose(t));
                }
            }
        }
        self.physics.integration_parameters.dt = dt_s;
        self.physics.step_with_events(self.layer.hooks(), &());
    }

    /// Sets the time of the current poses (s): the driver's clock, from which the next step's
    /// poses of moving parts are computed ([`World::advance`]).
    pub fn set_time(&mut self, time_s: f64) {
        self.time_s = time_s;
    }

    /// The largest speed of a moving part's surface over its whole profile (m/s; 0 without
    /// moving parts).
    pub fn moving_speed_m_s(&self) -> f64 {
        self.moving_speed_m_s
    }

    /// Runs rapier's collision detection without moving anything (a step of length zero).
    pub fn refresh_pairs(&mut self) {
        let dt = self.physics.integration_parameters.dt;
        self.advance(0.0);
        self.physics.integration_parameters.dt = dt;
    }

    fn add_surface(
        &mut self,
        part: SurfacePart,
        apple_material: Option<&str>,
        parent: Option<(RigidBodyHandle, rapier3d_f64::math::Pose)>,
    ) -> Result<(), BuildError> {
        let (mid, _) = self.materials[&part.material];
        let rigid = part.model == ContactModel::Rigid || self.layer.config().passive;
        let mut collider = part.collider;
        let along = part.along;
        if rigid {
            // rapier's own response: friction and restitution of the apple-surface pair.
            let c = match apple_material {
                Some(am) => self.layer.coefficients(self.materials[am].0, mid),
                None => self.layer.coefficients(mid, mid),
            };
            collider = collider
                .friction(c.friction)
                .restitution(c.ke.sqrt())
                .friction_combine_rule(CoefficientCombineRule::Max)
                .restitution_combine_rule(CoefficientCombineRule::Max);
        }
        if !rigid {
            // Out of the way of the apple colliders of scenes that have them (the layer owns
            // these contacts).
            collider = collider.collision_groups(InteractionGroups::new(
                HERTZ_SURFACE_GROUP,
                Group::ALL,
                InteractionTestMode::And,
            ));
        }
        let ch = match parent {
            Some((body, rest)) => {
                // Attached at its scenario pose relative to the body's rest pose, massless (the
                // body's centre of mass stays at its origin).
                let at = rest.inverse() * collider.position;
                collider = collider.position(at).density(0.0);
                let set = &mut self.physics;
                set.colliders
                    .insert_with_parent(collider, body, &mut set.bodies)
            }
            None => self.physics.colliders.insert(collider),
        };
        self.layer.add_surface(
            &mut self.physics.colliders,
            ch,
            SurfaceOptions {
                name: part.name,
                material: mid,
                shape: part.shape,
                belt_velocity_local: part.belt_local,
                rigid,
            },
        )?;
        self.surface_colliders.push(ch);
        self.surface_frames.push(along);
        Ok(())
    }

    /// Inserts an apple (a dynamic ball), registers it with the layer and enters
    /// it in the roster.
    pub fn add_apple(&mut self, a: &AppleSpec, origin: Origin) -> Result<AppleId, BuildError> {
        let (mid, m) = self.materials[&a.material];
        let entry = roster::entry(a, m.density_kg_m3, origin);
        let (mass, radius) = (entry.mass_kg, entry.radius_m);
        let body = RigidBodyBuilder::dynamic()
            .translation(vec3(a.position_m))
            .linvel(vec3(a.velocity_m_s))
            .angvel(vec3(a.angular_velocity_rad_s))
            .gyroscopic_forces_enabled(false)
            // The layer decides when an apple sleeps (rapier's own rule is too coarse).
            .can_sleep(false);
        let id =
            if self.apple_colliders {
                let c = self.layer.coefficients(mid, mid);
                let ball = ColliderBuilder::ball(radius).mass(mass);
                let ball = if self.layer.config().passive {
                    // rapier's own contacts between apples (the `rigid` fidelity).
                    ball.friction(c.friction).restitution(c.ke.sqrt())
                } else {
                    // Touches only the rigid surfaces; the layer handles the rest.
                    ball.friction(0.0)
                        .restitution(0.0)
                        .collision_groups(InteractionGroups::new(
                            APPLE_GROUP,
                            Group::ALL & !APPLE_GROUP & !HERTZ_SURFACE_GROUP,
                            InteractionTestMode::And,
                        ))
                };
                let (bh, ch) = self.physics.insert(body, ball);
                self.apple_bodies.push(bh);
                self.layer
                    .add_apple(&mut self.physics.colliders, ch, mid, &a.name)?
            } else {
                let inertia = 0.4 * mass * radius * radius;
                let bh = self.physics.bodies.insert(body.additional_mass_properties(
                    MassProperties::new(Vector::ZERO, mass, Vector::splat(inertia)),
                ));
                self.apple_bodies.push(bh);
                self.layer
                    .add_apple_body(&self.physics.bodies, bh, radius, mid, &a.name)?
            };
        self.roster.push(entry);
        Ok(id)
    }

    /// Feeds in the apples of sources whose time has come (at time `t`). An apple whose spot is
    /// still taken waits for it to clear (it and the ones after it from the same source are
    /// postponed, in order). Returns how many appeared.
    pub fn emit_due(&mut self, t: f64) -> Result<usize, BuildError> {
        let mut emitted = 0;
        let mut blocked_sources: Vec<usize> = Vec::new();
        let mut kept = VecDeque::new();
        while let Some(front) = self.pending.front() {
            if front.0 > t + 1e-12 {
                break;
            }
            let (when, src, a) = self.pending.pop_front().unwrap();
            if blocked_sources.contains(&src) || !self.spot_is_free(&a) {
                if !blocked_sources.contains(&src) {
                    blocked_sources.push(src);
                    self.postponed += 1;
                }
                kept.push_back((when, src, a));
                continue;
            }
            self.add_apple(
                &a,
                Origin::Fed {
                    source: src,
                    time_s: when,
                },
            )?;
            emitted += 1;
        }
        while let Some(x) = kept.pop_back() {
            self.pending.push_front(x);
        }
        if emitted > 0 && self.apple_colliders {
            // New apple colliders: let rapier find their rigid-surface pairs before the next step.
            self.refresh_pairs();
        }
        Ok(emitted)
    }

    /// Emissions postponed because the spot was taken.
    pub fn postponed_emissions(&self) -> u64 {
        self.postponed
    }

    /// Emissions still to come.
    pub fn pending_emissions(&self) -> usize {
        self.pending.len()
    }

    fn spot_is_free(&self, a: &AppleSpec) -> bool {
        let p = vec3(a.position_m);
        let r = a.diameter_m / 2.0;
        for (k, &bh) in self.apple_bodies.iter().enumerate() {
            let q = self.physics.bodies[bh].translation();
            let rr = self.layer.apple_radius(AppleId(k as u32));
            if (q - p).length() < r + rr {
                return false;
            }
        }
        let mut hits = Vec::new();
        for (s, &ch) in self.surface_colliders.iter().enumerate() {
            if let Some(co) = self.physics.colliders.get(ch) {
                hits.clear();
                let shape = self.layer.surface_shape(SurfaceId(s as u32));
                crate::layer::surface::surface_hits(shape, co, p, r, 0.0, &mut hits);
                if hits.iter().any(|h| h.overlap_m > 0.0) {
                    return false;
                }
            }
        }
        true
    }
}

fn check_initial_surface_overlaps(
    sc: &Scenario,
    apples: &[(AppleSpec, Origin)],
    world: &World,
) -> Result<(), ScenarioError> {
    let mut hits = Vec::new();
    for (k, (a, _)) in apples.iter().enumerate() {
        let r = a.diameter_m / 2.0;
        for (s, &ch) in world.surface_colliders.iter().enumerate() {
            let Some(co) = world.physics.colliders.get(ch) else {
                continue;
            };
            hits.clear();
            let shape = world.layer.surface_shape(SurfaceId(s as u32));
            crate::layer::surface::surface_hits(shape, co, vec3(a.position_m), r, 0.0, &mut hits);
            if let Some(h) = hits
                .iter()
                .find(|h| h.overlap_m > MAX_INITIAL_SURFACE_OVERLAP_RATIO * r)
            {
                let field = sc.initial_apple_field(k);
                return Err(ScenarioError::invalid(
                    field,
                    format!(
                        "apple '{}' starts {:.4} mm inside surface '{}' (more than {} % of its radius): place it on or above the surface",
                        a.name,
                        h.overlap_m * 1e3,
                        world.layer.surface_name(SurfaceId(s as u32)),
                        MAX_INITIAL_SURFACE_OVERLAP_RATIO * 100.0
                    ),
                ));
            }
        }
    }
    Ok(())
}
