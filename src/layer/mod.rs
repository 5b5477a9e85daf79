//! The rapier layer: pair finding, our contact law applied as forces, contact records.
//!
//! A rapier user keeps their own pipeline and sets. They register which rigid bodies are apples
//! (a collider-less body with its radius, or a ball collider) and which colliders are surfaces
//! (with a material each), pass [`ContactLayer::hooks`] to the pipeline's `step`, and call
//! [`ContactLayer::apply_forces`] right before every step:
//!
//! ```
//! use applesim::layer::{ContactLayer, LayerConfig, SurfaceOptions};
//! use applesim::contact::Material;
//! use rapier3d_f64::prelude::*;
//!
//! let mut world = PhysicsWorld::new();
//! world.gravity = Vector::new(0.0, 0.0, -9.81);
//! world.integration_parameters.num_solver_iterations = 1; // exact symplectic Euler
//! world.integration_parameters.max_ccd_substeps = 0;
//! world.integration_parameters.dt = 1e-5;
//!
//! let floor = world.colliders.insert(ColliderBuilder::new(SharedShape::halfspace(Vector::Z)));
//! // An apple: a rigid body with the mass properties of a 0.107 kg ball of radius 40 mm. It needs
//! // no collider: the layer finds its contacts (a ball collider works too, see `add_apple`).
//! let apple = world.bodies.insert(
//!     RigidBodyBuilder::dynamic().translation(Vector::new(0.0, 0.0, 0.0401))
//!         .linvel(Vector::new(0.0, 0.0, -1.0))
//!         .additional_mass_properties(MassProperties::new(
//!             Vector::ZERO, 0.107, Vector::splat(0.4 * 0.107 * 0.04 * 0.04)))
//!         .gyroscopic_forces_enabled(false) // zero for a sphere: skip the work
//!         .can_sleep(false),
//! );
//!
//! let mut layer = ContactLayer::new(LayerConfig::default());
//! let fruit = layer.add_material("apple", Material::from_shear(1.1e6, 0.18, Some(800.0)).unwrap());
//! let steel = layer.add_material("steel", Material::from_youngs(2.0736e11, 0.28, None).unwrap());
//! layer.set_default_coefficients(0.3, 1.0, 100.0);
//! layer.add_apple_body(&world.bodies, apple, 0.04, fruit, "a1").unwrap();
//! layer.add_surface(&mut world.colliders, floor, SurfaceOptions::hertz("floor", steel)).unwrap();
//!
//! let dt = world.integration_parameters.dt;
//! for step in 0..1500 {
//!     let t = step as f64 * dt;
//!     layer.apply_forces(&mut world.bodies, &world.colliders, &world.islands, t, dt).unwrap();
//!     world.step_with_events(layer.hooks(), &());
//! }
//! let bounce = &layer.finished_events()[0];
//! // 65.7 N by the closed form without gravity; gravity adds a little.
//! assert!((bounce.peak_force_n - 67.4).abs() < 0.1);
//! assert!(bounce.absorbed_energy_j.abs() < 1e-6, "elastic: no loss");
//! ```
//!
//! Why it is built this way (rapier-notes.md, docs/performance.md):
//!
//! - forces come from the overlap at the current poses (rapier's manifolds lag one step, which
//!   costs 4-6 % of the peak force at dt = 1e-4);
//! - apple-apple pairs come from our own cell grid ([`grid`]) and never reach rapier, 8-32x
//!   cheaper than its narrow phase;
//! - apples need no collider: when its Verlet list is rebuilt, the layer lists the surfaces within
//!   the skin of each apple from the colliders' bounding boxes and shapes ([`surface`] computes
//!   the geometry at the current poses), so rapier keeps no per-apple collider up to date;
//! - contacts live in a slab (`contacts`) that the force pass walks in a fixed order, in
//!   parallel when there are enough of them, with bit-identical sums for any thread count.
//!
//! The layer is a facade over parts that each own one kind of state and the methods that change
//! it, in the order a step uses them:
//!
//! | part | owns |
//! |---|---|
//! | `registry` | materials, pair laws, apples, surfaces, the handle tables (rapier's `Coarena`) |
//! | `clock` | the [`StepRequest`] of the coming step, the step that led here, first steps |
//! | `frame` | per apple: pose and motion at the current poses, contact count; the summed loads |
//! | `sleep` | who sleeps, the awake list, stillness times, wake-ups |
//! | `scene` | each surface's pose and motion this step |
//! | `detect` | the grid, the surface candidates: which contacts exist now, which ended |
//! | `contacts` | the contact slab (state of each open contact) |
//! | `kernel` | the force pass: the law per contact, loads summed in slot order |
//! | `outputs` | finished contacts, slips, the step's figures |

mod adaptive;
mod bodies;
mod clock;
mod config;
mod contacts;
mod detect;
mod error;
mod frame;
pub mod grid;
mod hooks;
mod kernel;
mod outputs;
mod queries;
mod registry;
mod scene;
mod sleep;
pub mod stage_clock;
pub mod surface;

pub use bodies::{BodyRef, BodySets};
pub use clock::{growth_cap, land, StepLimit, StepRequest};
pub use config::{
    Coefficients, Guard, LayerConfig, Padding, SleepConfig, StepControl, SurfaceOptions,
};
pub use detect::PARALLEL_MIN_CANDIDATE_APPLES;
pub use error::LayerError;
pub use hooks::{ContactHooks, Role};
pub use outputs::{SlipSample, StepStats};
pub use registry::{AppleId, MaterialId, SurfaceId};
pub use surface::{SurfaceHit, SurfaceShape};

use crate::contact::spheroid::Spheroid;
use crate::contact::Material;
use crate::record::events::{ContactEvent, Names, OpenContact, Party};
use clock::StepClock;
use contacts::ContactStore;
use detect::{Detection, Parts};
use frame::{Frame, Loads};
use kernel::{Inputs, Kernel};
use outputs::Outputs;
use rapier3d_f64::dynamics::{IslandManager, RigidBodySet};
use rapier3d_f64::geometry::{ColliderHandle, ColliderSet};
use registry::Registry;
use sleep::Sleep;
use stage_clock::{Clock, Stage};

/// The Hertz contact layer. See the module documentation for how to attach it to a world.
#[derive(Debug)]
pub struct ContactLayer {
    config: LayerConfig,
    registry: Registry,
    clock: StepClock,
    frame: Frame,
    loads: Loads,
    sleep: Sleep,
    detection: Detection,
    contacts: ContactStore,
    kernel: Kernel,
    out: Outputs,
}

impl ContactLayer {
    /// A layer with no materials, apples or surfaces.
    pub fn new(config: LayerConfig) -> Self {
        Self {
            config,
            registry: Registry::new(),
            clock: StepClock::default(),
            frame: Frame::default(),
            loads: Loads::default(),
            sleep: Sleep::new(),
            detection: Detection::new(),
            contacts: ContactStore::default(),
            kernel: Kernel::default(),
            out: Outputs::default(),
        }
    }

    /// The configuration.
    pub fn config(&self) -> &LayerConfig {
        &self.config
    }

    /// The hooks to pass to rapier's `step`.
    pub fn hooks(&self) -> &ContactHooks {
        &self.registry.hooks
    }

    // Registration.

    /// Registers a material.
    pub fn add_material(&mut self, name: &str, material: Material) -> MaterialId {
        self.registry.add_material(name, material)
    }

    /// Friction, ke and lambda for every pair without its own setting.
    pub fn set_default_coefficients(&mut self, friction: f64, ke: f64, lambda_s_m: f64) {
        self.registry
            .set_default_coefficients(Coefficients::paper(friction, ke, lambda_s_m));
    }

    /// The coefficients and sub-models of every pair without its own setting.
    pub fn set_default_pair_law(&mut self, c: Coefficients) {
        self.registry.set_default_coefficients(c);
    }

    /// Friction, ke and lambda for one pair of materials (either order).
    pub fn set_pair_coefficients(&mut self, a: MaterialId, b: MaterialId, c: Coefficients) {
        self.registry.set_pair_coefficients(a, b, c);
    }

    /// The coefficients in force for a pair of materials.
    pub fn coefficients(&self, a: MaterialId, b: MaterialId) -> Coefficients {
        self.registry.coefficients(a, b)
    }

    /// Registers a ball collider on a dynamic body as an apple. Sets its collision groups so
    /// that apple-apple pairs never enter rapier's narrow phase (the layer finds them), and
    /// enables the pair-filter hook (rapier's response to Hertz surfaces is switched off).
    ///
    /// An apple needs a collider only when rapier itself must touch it (a surface with rapier's
    /// own `rigid` contact); otherwise [`add_apple_body`](Self::add_apple_body) is cheaper:
    /// rapier then keeps no collider of it up to date.
    pub fn add_apple(
        &mut self,
        colliders: &mut ColliderSet,
        collider: ColliderHandle,
        material: MaterialId,
        name: &str,
    ) -> Result<AppleId, LayerError> {
        let id = self
            .registry
            .add_apple(colliders, collider, material, name, &self.config)?;
        self.apple_added(id);
        Ok(id)
    }

    /// Registers a dynamic rigid body without a collider as an apple: a ball of `radius_m`
    /// centred on the body's centre of mass, with the body's mass and (isotropic) inertia, from
    /// its mass properties as built (`additional_mass_properties`) or as rapier computed them.
    ///
    /// `body` is a handle in `bodies`: a bare handle for rapier's own set, or a [`BodyRef`] into
    /// an apple set (then `bodies` is that set; see [`BodySets`] and [`Self::step_in`]).
    pub fn add_apple_body(
        &mut self,
        bodies: &RigidBodySet,
        body: impl Into<BodyRef>,
        radius_m: f64,
        material: MaterialId,
        name: &str,
    ) -> Result<AppleId, LayerError> {
        let id = self
            .registry
            .add_apple_body(bodies, body.into(), radius_m, material, name)?;
        self.apple_added(id);
        Ok(id)
    }

    /// Registers a dynamic rigid body without a collider as a spheroidal apple: equatorial
    /// radius `shape.a`, polar half-height `shape.c` along the body's own z axis, centred on its
    /// centre of mass (docs/shape.md). Give the body the spheroid's principal inertia
    /// ([`Spheroid::principal_inertia`]) and enable its gyroscopic forces (a spheroid's are not
    /// zero). A sphere (a = c) is the same as [`add_apple_body`](Self::add_apple_body), and
    /// `body` may lie in an apple set as there.
    pub fn add_spheroid_body(
        &mut self,
        bodies: &RigidBodySet,
        body: impl Into<BodyRef>,
        shape: Spheroid,
        material: MaterialId,
        name: &str,
    ) -> Result<AppleId, LayerError> {
        let id = self
            .registry
            .add_spheroid_body(bodies, body.into(), shape, material, name)?;
        self.apple_added(id);
        Ok(id)
    }

    fn apple_added(&mut self, id: AppleId) {
        let radius = self.registry.apples[id.0 as usize].radius;
        self.frame.radius.push(radius);
        self.clock.first_step.push(true);
        self.sleep.apple_added();
        self.detection.apple_added(
            self.registry.apples.len(),
            radius,
            self.config.grid_skin_ratio,
        );
    }

    /// Registers a surface collider (any body type). A Hertz surface gets the pair-filter hook so
    /// rapier leaves its contacts with apple colliders to the layer; a rigid one keeps rapier's
    /// response (apples that must touch it need a ball collider, see [`add_apple`](Self::add_apple)).
    pub fn add_surface(
        &mut self,
        colliders: &mut ColliderSet,
        collider: ColliderHandle,
        options: SurfaceOptions,
    ) -> Result<SurfaceId, LayerError> {
        let id = self
            .registry
            .add_surface(colliders, collider, options, self.config.passive)?;
        self.detection.surface_added();
        Ok(id)
    }

    /// Takes an apple out of the run (it left the scene): from the next step on it touches no
    /// surface and no apple, wherever its body is, and its open contacts end at that step. The
    /// caller stops its body (`World::take_out` disables it in rapier and parks it far away).
    pub fn take_out_apple(&mut self, id: AppleId) {
        self.detection.retire(id.0 as usize);
        self.sleep.forget_ride(id.0 as usize);
    }

    /// Checks that no apple can meet a concave surface tighter than itself (conforming contact).
    pub fn check_conformity(&self) -> Result<(), LayerError> {
        self.registry.check_conformity()
    }

    // Stepping.

    /// Computes every modelled contact at the current poses and sets the apples' forces and
    /// torques for a step of `dt_s` (replacing whatever the layer set before). Call it right
    /// before each `step`, with the time of the current poses. Returns the step to take: `dt_s`,
    /// unless the layer was built with [`LayerConfig::step_control`] (then see [`Self::step`]).
    pub fn apply_forces(
        &mut self,
        bodies: &mut RigidBodySet,
        colliders: &ColliderSet,
        islands: &IslandManager,
        time_s: f64,
        dt_s: f64,
    ) -> Result<f64, LayerError> {
        self.step(
            bodies,
            colliders,
            islands,
            &StepRequest::fixed(time_s, dt_s),
        )
    }

    /// Computes every modelled contact at the current poses, chooses the coming step under the
    /// driver's `request` (with [`LayerConfig::step_control`]: the longest that resolves the
    /// contacts in progress and those about to start, at most `request.dt_s`, landed; without:
    /// `request.dt_s`), sets the apples' forces and torques for it and returns it. Pass the
    /// returned step to rapier.
    ///
    /// Sleeping apples (see [`SleepConfig`]) are not touched; contacts between two sleepers or
    /// between a sleeper and a fixed surface are not evaluated. Wake-ups are decided from the
    /// geometry before any force is computed, so a woken apple gets all its contacts this step.
    pub fn step(
        &mut self,
        bodies: &mut RigidBodySet,
        colliders: &ColliderSet,
        islands: &IslandManager,
        request: &StepRequest,
    ) -> Result<f64, LayerError> {
        self.step_in(BodySets::one(bodies, islands), colliders, request)
    }

    /// [`Self::step`] with the apples' bodies spread over several sets: rapier's own (with the
    /// surfaces) and apple sets, worlds of collider-less apples that the caller steps
    /// concurrently with rapier's own after this call (each with the same gravity and
    /// integration parameters; `World::advance` does it). See [`BodySets`] for why this changes
    /// no result.
    pub fn step_in(
        &mut self,
        mut bodies: BodySets,
        colliders: &ColliderSet,
        request: &StepRequest,
    ) -> Result<f64, LayerError> {
        let bodies = &mut bodies;
        self.clock.begin(request);
        self.registry.ensure_laws();
        let timer = Clock::start();
        self.gather(bodies)?;
        timer.stop(Stage::Read);
        if self.config.passive {
            self.out.stats = StepStats::fresh();
            return Ok(request.dt_s);
        }
        self.detection
            .observe_surfaces(bodies.main, colliders, &self.registry, &mut self.sleep);
        let timer = Clock::start();
        self.wake_requested(bodies);
        let mut redone = false;
        loop {
            let mut parts = Parts {
                registry: &self.registry,
                config: &self.config,
                clock: &self.clock,
                frame: &mut self.frame,
                sleep: &mut self.sleep,
                contacts: &mut self.contacts,
                out: &mut self.out,
            };
            self.detection.detect(&mut parts, colliders, request.dt_s);
            if !self.sleep.wakes_pending() || redone {
                break;
            }
            self.wake_requested(bodies);
            redone = true;
        }
        self.sleep.clear_wakes();
        timer.stop(Stage::Detect);
        let control = self.config.step_control;
        let dt_s = match control {
            Some(c) => {
                let limit = adaptive::motion_limit(
                    &c,
                    self.sleep.awake(),
                    &self.frame.vel,
                    self.detection.skin_m(),
                );
                if let Some(limit) = limit {
                    self.out.stats.limit(limit, StepLimit::Motion);
                }
                let parts = adaptive::surface_motion_limit(
                    &c,
                    self.detection.surface_speed_m_s,
                    self.detection.skin_m(),
                );
                if let Some(limit) = parts {
                    self.out.stats.limit(limit, StepLimit::Motion);
                }
                self.out.stats.dt_set_by_limit = self.out.stats.dt_limit_s < request.dt_s;
                request.choose(self.out.stats.dt_limit_s)
            }
            None => request.dt_s,
        };
        let timer = Clock::start();
        self.kernel.run(
            Inputs {
                registry: &self.registry,
                frame: &self.frame,
                surf_now: &self.detection.surf_now,
                config: &self.config,
                clock: &self.clock,
                slab_shares: &self.detection.slab_shares,
            },
            &mut self.contacts,
            self.detection.epoch,
            &mut self.loads,
            &mut self.out,
            dt_s,
        )?;
        timer.stop(Stage::Law);
        let timer = Clock::start();
        self.sleep.decide(
            &self.config.sleep,
            self.config.gravity,
            bodies,
            &self.registry.apples,
            &mut self.frame,
            &mut self.loads,
            dt_s,
            self.clock.time_s,
        );
        timer.stop(Stage::Sleep);
        let timer = Clock::start();
        let kick = (self.clock.dt_back + dt_s) / (2.0 * dt_s);
        self.loads.hand_to_rapier(
            bodies,
            &self.registry.apples,
            self.sleep.awake(),
            |k| self.sleep.is_asleep(k) || self.sleep.ride(k).is_some(),
            control,
            kick,
            self.config.gravity,
            &mut self.clock.first_step,
        );
        timer.stop(Stage::Handoff);
        Ok(dt_s)
    }

    /// Reads the awake apples' current state from rapier. A sleeper costs nothing here: one that
    /// rapier woke (the user moved it, or gave it an impulse with `wake_up`) shows up in rapier's
    /// active set and is taken as awake again.
    fn gather(&mut self, bodies: &BodySets) -> Result<(), LayerError> {
        let n = self.registry.apples.len();
        self.frame.begin(n);
        self.loads.begin(n, self.config.step_control.is_some());
        self.sleep.grow(n);
        self.sleep.notice_rapier_wakeups(bodies, &self.registry);
        self.refresh_awake();
        let sleep = &self.sleep;
        self.frame.read(
            bodies,
            &self.registry.apples,
            sleep.awake(),
            sleep.riding_count(),
            |k| sleep.riding_count() > 0 && sleep.ride(k).is_some(),
            self.config.sleep.speed_m_s,
            self.clock.time_s,
        )?;
        self.sleep.place_riders(&mut self.frame, self.clock.time_s);
        Ok(())
    }

    fn wake_requested(&mut self, bodies: &mut BodySets) {
        self.sleep
            .wake_requested(bodies, &self.registry.apples, self.clock.time_s);
        self.refresh_awake();
    }

    fn refresh_awake(&mut self) {
        if self.sleep.refresh_awake() {
            self.detection.awake_changed();
        }
    }

    /// Resets the user forces the layer set on other dynamic bodies (call before
    /// `apply_forces` if surfaces ride on dynamic bodies: the reaction forces accumulate).
    pub fn reset_surface_body_forces(&self, bodies: &mut RigidBodySet, colliders: &ColliderSet) {
        for s in &self.registry.surfaces {
            if let Some(parent) = colliders.get(s.collider).and_then(|c| c.parent()) {
                if let Some(rb) = bodies.get_mut(parent) {
                    if rb.is_dynamic() {
                        rb.reset_forces(false);
                        rb.reset_torques(false);
                    }
                }
            }
        }
    }
}

/// Tests: runs `f` on a rayon pool of `threads` (what a layer step does on one thread and on
/// several).
#[cfg(test)]
pub(crate) fn on_pool<R: Send>(threads: usize, f: impl FnOnce() -> R + Send) -> R {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("a thread pool")
        .install(f)
}
