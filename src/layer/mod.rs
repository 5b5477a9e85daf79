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
//! - contacts live in a slab ([`contacts`]) that the force pass walks in a fixed order, in
//!   parallel when there are enough of them, with bit-identical sums for any thread count.

mod adaptive;
pub mod contacts;
mod detect;
pub mod grid;
pub mod hooks;
mod kernel;
mod sleep;
pub mod surface;

use crate::contact::{self, LawParts, Material, PairLaw};
use crate::math::{is_finite, Vec3};
use crate::record::events::{ContactEvent, Names, OpenContact, Party};
use contacts::ContactStore;
pub use hooks::{ContactHooks, Role};
use rapier3d_f64::dynamics::{IslandManager, RigidBodyHandle, RigidBodySet};
use rapier3d_f64::geometry::{ColliderHandle, ColliderSet, Group, InteractionGroups};
use rapier3d_f64::math::Pose;
use rapier3d_f64::pipeline::ActiveHooks;
use std::collections::HashMap;
use std::sync::Arc;
pub use surface::{SurfaceHit, SurfaceShape};
use thiserror::Error;

/// Index of a material registered with [`ContactLayer::add_material`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct MaterialId(pub u16);

/// Index of an apple in the layer (registration order).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct AppleId(pub u32);

/// Index of a surface in the layer (registration order).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct SurfaceId(pub u32);

/// Errors of the layer: registration mistakes and runs that went wrong.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum LayerError {
    /// The collider handle is not in the collider set.
    #[error("collider {0:?} is not in the collider set")]
    UnknownCollider(ColliderHandle),
    /// An apple collider must be a ball attached to a dynamic body.
    #[error("apple '{0}': its collider must be a ball attached to a dynamic rigid body")]
    NotABall(String),
    /// A collider-less apple body must be dynamic, with a mass, an inertia and a positive radius.
    #[error("apple '{0}': its rigid body must be dynamic, with a positive mass and inertia (set them with additional_mass_properties), and its radius positive")]
    NoMass(String),
    /// The collider (or body) is registered twice.
    #[error("collider of '{0}' is already registered with the layer")]
    Duplicate(String),
    /// A concave surface tighter than the apple: Hertz theory has no answer (K1 + K2 <= 0).
    #[error("apple '{apple}' (radius {apple_radius_m} m) cannot touch concave surface '{surface}' of radius {surface_radius_m} m: conforming contact (K1 + K2 <= 0) is outside Hertz theory; make the surface radius larger than the apple's")]
    Conforming {
        /// Apple name.
        apple: String,
        /// Surface name.
        surface: String,
        /// Apple radius.
        apple_radius_m: f64,
        /// Surface radius.
        surface_radius_m: f64,
    },
    /// A body's state went non-finite.
    #[error("non-finite state of '{body}' at t = {time_s} s: the run blew up (the time step is too large for the stiffest contact, or a force is unbounded)")]
    NonFinite {
        /// Body name.
        body: String,
        /// Simulated time.
        time_s: f64,
    },
    /// The stability guard stopped the run.
    #[error("unstable at t = {time_s} s, contact '{a}' - '{b}': {what}")]
    Unstable {
        /// First body.
        a: String,
        /// Second body.
        b: String,
        /// Simulated time.
        time_s: f64,
        /// What was seen and what would work.
        what: String,
        /// A time step that would resolve this contact, when the cause is the step.
        suggested_dt_s: Option<f64>,
    },
}

/// Limits beyond which the layer refuses to go on (physics.md section 10).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Guard {
    /// Largest overlap as a fraction of the smaller radius (Hertz needs u << R).
    pub max_overlap_ratio: f64,
    /// Fewest steps an impact may be resolved in: the Hertz contact time at the approach speed
    /// over dt. 10 steps give about 1 % error in the peak force (physics.md section 10).
    pub min_steps_per_impact: f64,
}

impl Default for Guard {
    fn default() -> Self {
        Self {
            max_overlap_ratio: 0.5,
            min_steps_per_impact: 10.0,
        }
    }
}

/// When apples at rest stop being simulated, and what wakes them.
///
/// An awake apple counts as *still* when |v| and |w| R are both below `speed_m_s`; it falls
/// asleep after `time_s` of stillness during which it touched something, its net force (contacts
/// and gravity; set it with [`ContactLayer::set_gravity`]), averaged over the last quarter of
/// `time_s`, could not change its speed by `speed_m_s` within `time_s`, and it touched no apple
/// that was not still and no moving surface (a belt, a moving body). The force is averaged because
/// an apple held in a pile vibrates at its contacts' frequencies while its mean force is nil. A
/// sleeper is not integrated (rapier's sleeping) and its
/// contacts with other sleepers and fixed surfaces are frozen, not evaluated. It wakes when a
/// contact with an awake apple starts or ends, or when the overlap of such a contact moves by
/// more than `wake_overlap_ratio` of its value at the time of sleeping (the neighbour pushes
/// harder or lets go). Waking cascades: a woken apple that moves shifts its own contacts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SleepConfig {
    /// Whether apples may sleep at all.
    pub enabled: bool,
    /// Stillness threshold (m/s).
    pub speed_m_s: f64,
    /// Stillness time before sleeping (s).
    pub time_s: f64,
    /// Relative change of a contact's overlap that wakes a sleeper.
    pub wake_overlap_ratio: f64,
}

impl Default for SleepConfig {
    fn default() -> Self {
        Self {
            enabled: true,
            speed_m_s: 0.005,
            time_s: 0.2,
            wake_overlap_ratio: 0.05,
        }
    }
}

/// What an adaptive driver asks of the layer: every force pass also computes the longest next
/// step that resolves the contacts in progress and those about to start with
/// `steps_per_contact` steps (see [`StepStats::dt_limit_s`]):
///
/// - a contact in progress at overlap u, that started at approach speed v_a: the elastic contact
///   time of an impact reaching max(u, u_max(v_a)), over N (for a resting contact that is the time
///   scale of its normal oscillation, so resting contacts allow long steps);
/// - a pair closing at speed v_c with gap g: g / v_c + t_H(v_c) / N (it may touch within the
///   step, but not go deeper than one resolved step);
/// - no awake apple may move more than `max_displacement_m` (the pair-finding margins).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepControl {
    /// Steps per elastic contact time.
    pub steps_per_contact: f64,
    /// How far ahead to look for contacts about to start (s): the largest step the driver takes
    /// (the layer looks at most twice its last step ahead: the driver never more than doubles it).
    pub lookahead_s: f64,
    /// Largest displacement of an apple in one step allowed by rapier's pair finding (m); the
    /// layer also keeps it within half its own grid skin.
    pub max_displacement_m: f64,
    /// Gravity (m/s^2): when the step changes from h_k-1 to h_k, the velocity kick of pose k must
    /// span (h_k-1 + h_k) / 2, the time between the staggered velocities (leapfrog with variable
    /// steps); rapier kicks by F h_k, so the layer scales every force by (h_k-1 + h_k) / (2 h_k) and
    /// adds gravity's share. Without it, a step change during an impact creates or destroys energy
    /// (measured: +2 % at the first step change of a 1.4 m/s drop).
    pub gravity: Vec3,
}

/// Settings of the layer.
#[derive(Debug, Clone, PartialEq)]
pub struct LayerConfig {
    /// Which parts of the contact law are on.
    pub parts: LawParts,
    /// Bound of the rate-dependent forces as a fraction of the velocity-kill rate m_eff / dt,
    /// shared among an apple's contacts: the tangential dashpot (see [`contact::friction`]) and
    /// the rate part of eq. 12 (see [`contact::damping::hysteresis_force`]). 0.5 removes at most
    /// half the relative velocity per step, which keeps explicit stepping stable.
    pub tangential_relaxation: f64,
    /// Verlet skin of the apple-apple list as a fraction of the largest apple radius.
    pub grid_skin_ratio: f64,
    /// Samples of force history kept per contact (0: none); long contacts are decimated.
    pub force_history_cap: usize,
    /// Stability guard.
    pub guard: Guard,
    /// The collision group that marks apples; apple-apple pairs are excluded from rapier with it.
    pub apple_group: Group,
    /// Sleeping of apples at rest.
    pub sleep: SleepConfig,
    /// `true` leaves every contact to rapier (the `rigid` fidelity): the layer only keeps names.
    pub passive: bool,
    /// Step control for adaptive stepping.
    pub step_control: Option<StepControl>,
    /// Keep each step's slip of every evaluated contact ([`ContactLayer::slips`]) for the
    /// slip/roll detector ([`crate::record::transitions`]).
    pub record_slips: bool,
}

impl Default for LayerConfig {
    fn default() -> Self {
        Self {
            parts: LawParts::default(),
            tangential_relaxation: 0.5,
            grid_skin_ratio: 0.25,
            force_history_cap: 0,
            guard: Guard::default(),
            apple_group: Group::GROUP_32,
            sleep: SleepConfig::default(),
            passive: false,
            step_control: None,
            record_slips: false,
        }
    }
}

/// Registration options of a surface.
#[derive(Debug, Clone, PartialEq)]
pub struct SurfaceOptions {
    /// Name used in records.
    pub name: String,
    /// Material.
    pub material: MaterialId,
    /// Geometry source.
    pub shape: SurfaceShape,
    /// Belt velocity in the collider's local frame (m/s): enters the friction slip; the
    /// collider itself does not move.
    pub belt_velocity_local: Vec3,
    /// Whether rapier's own contact handles this surface (no forces recorded).
    pub rigid: bool,
}

impl SurfaceOptions {
    /// A Hertz surface with the collider's own shape.
    pub fn hertz(name: &str, material: MaterialId) -> Self {
        Self {
            name: name.to_string(),
            material,
            shape: SurfaceShape::FromCollider,
            belt_velocity_local: Vec3::ZERO,
            rigid: false,
        }
    }
}

/// Contact coefficients of a pair of materials.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coefficients {
    /// Coulomb friction.
    pub friction: f64,
    /// Eq. 12 ke.
    pub ke: f64,
    /// Eq. 12 lambda (s/m).
    pub lambda_s_m: f64,
}

/// gives one sample for each of its apples).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SlipSample {
    /// The apple.
    pub apple: u32,
    /// What it touches.
    pub other: Party,
    /// Tangential slip speed of the apple's surface point over the other surface at the contact
    /// point, belt velocity included (m/s): |s_t| of physics.md section 5.
    pub slip_m_s: f64,
    /// Normal force (N).
    pub normal_force_n: f64,
    /// Contact point (m, world).
    pub point: Vec3,
}

/// What limited an adaptive step.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, PartialOrd, Ord)]
pub enum StepLimit {
    /// Nothing in the layer: the driver's cap (largest step, output samples, end).
    #[default]
    None,
    /// An impact in progress.
    Impact,
    /// A resting contact's normal oscillation.
    Resting,
    /// A pair about to touch.
    Approaching,
    /// The pair-finding margins (an apple moving fast).
    Motion,
}

/// Per-step figures of the layer.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StepStats {
    /// Contacts with overlap this step.
    pub contacts: usize,
    /// Apple-apple contacts.
    pub apple_apple_contacts: usize,
    /// Candidate apple-apple pairs in the neighbour list.
    pub apple_candidates: usize,
    /// Elastic energy stored in the contacts, sum of 2/5 k u^(5/2) (J).
    pub elastic_energy_j: f64,
    /// Largest overlap over the smaller radius.
    pub max_overlap_ratio: f64,
    /// With [`LayerConfig::step_control`]: the longest next step that resolves every contact in
    /// progress or about to start (s); infinite when nothing limits it.
    pub dt_limit_s: f64,
    /// What set `dt_limit_s`.
    pub dt_limit_reason: StepLimit,
}

impl StepStats {
    fn limit(&mut self, dt: f64, why: StepLimit) {
        if dt < self.dt_limit_s {
            self.dt_limit_s = dt;
            self.dt_limit_reason = why;
        }
    }
}

/// An apple as the layer knows it.
#[derive(Debug, Clone)]
struct AppleEntry {
    name: Arc<str>,
    /// The apple's ball collider, if it has one (rapier needs it only for rigid surfaces).
    collider: Option<ColliderHandle>,
    body: RigidBodyHandle,
    /// Centre of the ball in the body's frame.
    offset: Vec3,
    /// The ball is centred on the body's centre of mass: its centre is the body's translation
    /// when `offset` is zero, and its velocity the body's linear velocity.
    centred: bool,
    radius: f64,
    material: MaterialId,
    mass: f64,
    /// 1/m + r^2/I: inverse mass of the surface point in a tangential direction.
    inv_tangential_mass: f64,
}

#[derive(Debug, Clone)]
struct SurfaceEntry {
    name: Arc<str>,
    collider: ColliderHandle,
    material: MaterialId,
    shape: SurfaceShape,
    belt_local: Vec3,
    rigid: bool,
}

/// What the layer reads of a surface once per step (the few surfaces, not every contact, go to
/// rapier's sets).
#[derive(Debug, Clone)]
struct SurfaceNow {
    /// The collider still exists.
    exists: bool,
    /// Its pose at the last step (change detection).
    pose: Pose,
    /// Its pose at the last rebuild of the candidate lists (how far it may have moved since).
    pose_at_build: Pose,
    /// Radius of a sphere around the collider's origin containing its shape (m; infinite for a
    /// half-space): bounds how far a rotation moves its points.
    extent_m: f64,
    /// Moved or removed since the last step: wakes the sleepers near it.
    changed: bool,
    /// The parent body is not fixed, or the surface is a running belt: apples on it stay awake.
    moving: bool,
    /// Velocity field of the parent body: linear velocity, angular velocity, centre of mass.
    lin: Vec3,
    ang: Vec3,
    com: Vec3,
    /// Inverse mass of a dynamic parent (0 for fixed or kinematic ones).
    inv_mass: f64,
    /// A dynamic parent receives the reaction forces.
    dynamic_body: Option<RigidBodyHandle>,
    /// Belt velocity in world axes (m/s).
    belt: Vec3,
    /// A plane (a half-space collider with the collider's own shape): its world normal and
    /// n . point, so that its contacts need no shape dispatch.
    plane: Option<(Vec3, f64)>,
}

impl SurfaceNow {
    fn new() -> Self {
        Self {
            exists: false,
            pose: Pose::IDENTITY,
            pose_at_build: Pose::IDENTITY,
            extent_m: f64::INFINITY,
            changed: false,
            moving: false,
            lin: Vec3::ZERO,
            ang: Vec3::ZERO,
            com: Vec3::ZERO,
            inv_mass: 0.0,
            dynamic_body: None,
            belt: Vec3::ZERO,
            plane: None,
        }
    }

    /// Velocity of the surface's material point at `p` (belt excluded).
    fn velocity_at(&self, p: Vec3) -> Vec3 {
        self.lin + self.ang.cross(p - self.com)
    }

    /// The hits of an apple (centre, radius) with this surface, keeping those with overlap
    /// > -margin (see [`surface::surface_hits`]); planes without the shape dispatch.
    fn hits(
        &self,
        surf: &SurfaceEntry,
        colliders: &ColliderSet,
        centre: Vec3,
        radius: f64,
        margin: f64,
        out: &mut Vec<SurfaceHit>,
    ) {
        if let Some((n, d)) = self.plane {
            let u = radius - (centre.dot(n) - d);
            if u > -margin {
                out.push(SurfaceHit {
                    normal: n,
                    overlap_m: u,
                    curvature_1_m: 0.0,
                });
            }
        } else if let Some(co) = colliders.get(surf.collider) {
            surface::surface_hits(&surf.shape, co, centre, radius, margin, out);
        }
    }
}

/// A surface near an apple: listed at the last rebuild (closer than the skin), with the chain of
/// its open contacts (see [`Contact::next`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct SurfaceCandidate {
    apple: u32,
    surface: u32,
    first: u32,
}

/// Contacts per step from which the force pass runs in parallel (below that, rayon's overhead
/// outweighs the work). The results do not depend on it.
const PARALLEL_MIN_CONTACTS: usize = 256;

/// The Hertz contact layer. See the module documentation for how to attach it to a world.
#[derive(Debug)]
pub struct ContactLayer {
    config: LayerConfig,
    hooks: ContactHooks,
    materials: Vec<(String, Material)>,
    default_coeffs: Coefficients,
    pair_coeffs: HashMap<(MaterialId, MaterialId), Coefficients>,
    laws: Vec<PairLaw>,
    laws_dirty: bool,
    apples: Vec<AppleEntry>,
    surfaces: Vec<SurfaceEntry>,
    /// Role and index of registered colliders, indexed by the collider's arena index.
    by_collider: Vec<Option<(ColliderHandle, Role, u32)>>,
    grid: grid::NeighborList,
    /// Surfaces near each apple, sorted by (apple, surface).
    candidates: Vec<SurfaceCandidate>,
    rebuild_candidates: bool,
    contacts: ContactStore,
    surf_now: Vec<SurfaceNow>,
    /// The detection pass counter (see [`ContactStore::stamp`]); passes count from 2.
    epoch: u64,
    /// The apples awake now, in increasing order (see `refresh_awake`).
    awake: Vec<u32>,
    /// How many apples sleep.
    asleep_count: usize,
    /// The awake set changed: `awake` and `pair_scan` must be listed again.
    awake_dirty: bool,
    /// Indices of the pairs with an awake apple, when some apples sleep (`None`: all pairs).
    pair_scan: Option<Vec<u32>>,
    /// `candidates[cand_start[k]..cand_start[k + 1]]` are apple k's surface candidates.
    cand_start: Vec<u32>,
    /// Apple of each registered rigid body, by the body's arena index (rapier's wake-ups).
    apple_of_body: Vec<Option<(RigidBodyHandle, u32)>>,
    // Per apple, per step.
    pos: Vec<Vec3>,
    vel: Vec<Vec3>,
    angvel: Vec<Vec3>,
    radius: Vec<f64>,
    active: Vec<bool>,
    force: Vec<Vec3>,
    torque: Vec<Vec3>,
    count: Vec<u16>,
    still: Vec<bool>,
    busy: Vec<bool>,
    still_time: Vec<f64>,
    /// Running mean of the net force while still (see `sleep`).
    mean_force: Vec<Vec3>,
    asleep: Vec<bool>,
    sleep_force: Vec<Vec3>,
    /// The layer left a non-zero force or torque on the body at the last step (so a zero one now
    /// must be written: rapier keeps user forces).
    loaded: Vec<bool>,
    to_wake: Vec<u32>,
    stats_sleeps: u64,
    stats_wakeups: u64,
    slips: Vec<SlipSample>,
    scratch: Vec<SurfaceHit>,
    chain: Vec<u32>,
    finished: Vec<ContactEvent>,
    body_loads: Vec<(RigidBodyHandle, Vec3, Vec3)>,
    /// Adaptive steps only: contact force and torque per apple with each contact's leapfrog kick
    /// (see [`StepControl::gravity`]): what is handed to rapier.
    kicked_force: Vec<Vec3>,
    kicked_torque: Vec<Vec3>,
    /// Adaptive steps only: apples not yet stepped, whose first kick spans half a step.
    fresh: Vec<bool>,
    /// Output of the force pass, one per contact slot.
    outs: Vec<kernel::ContactOut>,
    stats: StepStats,
    time_s: f64,
    last_dt: Option<f64>,
    dt_back: f64,
    gravity: Vec3,
    land_in_s: f64,
}

impl ContactLayer {
    /// A layer with no materials, apples or surfaces.
    pub fn new(config: LayerConfig) -> Self {
        Self {
            grid: grid::NeighborList::new(0.0),
            config,
            hooks: ContactHooks::default(),
            materials: Vec::new(),
            default_coeffs: Coefficients {
                friction: 0.0,
                ke: 1.0,
                lambda_s_m: 0.0,
            },
            pair_coeffs: HashMap::new(),
            laws: Vec::new(),
            laws_dirty: true,
            apples: Vec::new(),
            surfaces: Vec::new(),
            by_collider: Vec::new(),
            candidates: Vec::new(),
            rebuild_candidates: true,
            contacts: ContactStore::default(),
            surf_now: Vec::new(),
            epoch: 1,
            awake: Vec::new(),
            asleep_count: 0,
            awake_dirty: true,
            pair_scan: None,
            cand_start: Vec::new(),
            apple_of_body: Vec::new(),
            pos: Vec::new(),
            vel: Vec::new(),
            angvel: Vec::new(),
            radius: Vec::new(),
            active: Vec::new(),
            force: Vec::new(),
            torque: Vec::new(),
            count: Vec::new(),
            still: Vec::new(),
            busy: Vec::new(),
            still_time: Vec::new(),
            mean_force: Vec::new(),
            asleep: Vec::new(),
            sleep_force: Vec::new(),
            loaded: Vec::new(),
            to_wake: Vec::new(),
            stats_sleeps: 0,
            stats_wakeups: 0,
            slips: Vec::new(),
            scratch: Vec::new(),
            chain: Vec::new(),
            finished: Vec::new(),
            body_loads: Vec::new(),
            kicked_force: Vec::new(),
            kicked_torque: Vec::new(),
            fresh: Vec::new(),
            outs: Vec::new(),
            stats: StepStats::default(),
            time_s: 0.0,
            last_dt: None,
            dt_back: 0.0,
            gravity: Vec3::ZERO,
            land_in_s: 0.0,
        }
    }

    /// The configuration.
    pub fn config(&self) -> &LayerConfig {
        &self.config
    }

    /// Sets gravity (m/s^2): the sleep rule checks that an apple's net force is small.
    pub fn set_gravity(&mut self, gravity: Vec3) {
        self.gravity = gravity;
    }

    /// Sets (or clears) the step control of an adaptive driver.
    pub fn set_step_control(&mut self, control: Option<StepControl>) {
        self.config.step_control = control;
    }

    /// The hooks to pass to rapier's `step`.
    pub fn hooks(&self) -> &ContactHooks {
        &self.hooks
    }

    /// Registers a material.
    pub fn add_material(&mut self, name: &str, material: Material) -> MaterialId {
        self.materials.push((name.to_string(), material));
        self.laws_dirty = true;
        MaterialId((self.materials.len() - 1) as u16)
    }

    /// Friction, ke and lambda for every pair without its own setting.
    pub fn set_default_coefficients(&mut self, friction: f64, ke: f64, lambda_s_m: f64) {
        self.default_coeffs = Coefficients {
            friction,
            ke,
            lambda_s_m,
        };
        self.laws_dirty = true;
    }

    /// Friction, ke and lambda for one pair of materials (either order).
    pub fn set_pair_coefficients(&mut self, a: MaterialId, b: MaterialId, c: Coefficients) {
        self.pair_coeffs.insert((a.min(b), a.max(b)), c);
        self.laws_dirty = true;
    }

    /// The coefficients in force for a pair of materials.
    pub fn coefficients(&self, a: MaterialId, b: MaterialId) -> Coefficients {
        *self
            .pair_coeffs
            .get(&(a.min(b), a.max(b)))
            .unwrap_or(&self.default_coeffs)
    }

    /// The law for (apple material, other material).
    pub fn pair_law(&mut self, apple: MaterialId, other: MaterialId) -> PairLaw {
        self.ensure_laws();
        self.laws[apple.0 as usize * self.materials.len() + other.0 as usize]
    }

    fn ensure_laws(&mut self) {
        if !self.laws_dirty {
            return;
        }
        let n = self.materials.len();
        self.laws.clear();
        for a in 0..n {
            for b in 0..n {
                let c = self.coefficients(MaterialId(a as u16), MaterialId(b as u16));
                self.laws.push(PairLaw::new(
                    &self.materials[a].1,
                    &self.materials[b].1,
                    c.friction,
                    c.ke,
                    c.lambda_s_m,
                ));
            }
        }
        self.laws_dirty = false;
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
        if self.lookup(collider).is_some() {
            return Err(LayerError::Duplicate(name.to_string()));
        }
        let co = colliders
            .get_mut(collider)
            .ok_or(LayerError::UnknownCollider(collider))?;
        let radius = co
            .shape()
            .as_ball()
            .map(|b| b.radius)
            .ok_or_else(|| LayerError::NotABall(name.to_string()))?;
        let body = co
            .parent()
            .ok_or_else(|| LayerError::NotABall(name.to_string()))?;
        let offset = co
            .position_wrt_parent()
            .map(|p| p.translation)
            .unwrap_or(Vec3::ZERO);
        let mp = co.mass_properties();
        let (mass, inertia) = (mp.mass(), mp.principal_inertia().x);
        if !(mass > 0.0 && inertia > 0.0) {
            return Err(LayerError::NotABall(name.to_string()));
        }
        if !self.config.passive {
            let g = self.config.apple_group;
            let old = co.collision_groups();
            co.set_collision_groups(InteractionGroups::new(g, old.filter & !g, old.test_mode));
            co.set_active_hooks(co.active_hooks() | ActiveHooks::FILTER_CONTACT_PAIRS);
            self.hooks.set(collider, Role::Apple);
        }
        let id = self.push_apple(AppleEntry {
            name: name.into(),
            collider: Some(collider),
            body,
            offset,
            centred: false,
            radius,
            material,
            mass,
            inv_tangential_mass: 1.0 / mass + radius * radius / inertia,
        });
        self.register(collider, Role::Apple, id.0);
        Ok(id)
    }

    /// Registers a dynamic rigid body without a collider as an apple: a ball of `radius_m`
    /// centred on the body's centre of mass, with the body's mass and (isotropic) inertia, from
    /// its mass properties as built (`additional_mass_properties`) or as rapier computed them.
    pub fn add_apple_body(
        &mut self,
        bodies: &RigidBodySet,
        body: RigidBodyHandle,
        radius_m: f64,
        material: MaterialId,
        name: &str,
    ) -> Result<AppleId, LayerError> {
        if self.apple_of(body).is_some() {
            return Err(LayerError::Duplicate(name.to_string()));
        }
        let rb = bodies
            .get(body)
            .ok_or_else(|| LayerError::NoMass(name.to_string()))?;
        let mprops = rb.mass_properties();
        let mut mp = mprops.local_mprops;
        if mp.mass() <= 0.0 {
            // Not computed by rapier yet (the body was just built): its additional properties.
            if let Some(rapier3d_f64::dynamics::RigidBodyAdditionalMassProps::MassProps(m)) =
                mprops.additional_local_mprops.as_deref()
            {
                mp = *m;
            }
        }
        let (mass, inertia) = (mp.mass(), mp.principal_inertia().x);
        if !(rb.is_dynamic() && mass > 0.0 && inertia > 0.0 && radius_m > 0.0) {
            return Err(LayerError::NoMass(name.to_string()));
        }
        Ok(self.push_apple(AppleEntry {
            name: name.into(),
            collider: None,
            body,
            offset: mp.local_com,
            centred: true,
            radius: radius_m,
            material,
            mass,
            inv_tangential_mass: 1.0 / mass + radius_m * radius_m / inertia,
        }))
    }

    fn push_apple(&mut self, entry: AppleEntry) -> AppleId {
        let id = self.apples.len() as u32;
        let radius = entry.radius;
        let b = entry.body.into_raw_parts().0 as usize;
        if self.apple_of_body.len() <= b {
            self.apple_of_body.resize(b + 1, None);
        }
        self.apple_of_body[b] = Some((entry.body, id));
        self.awake_dirty = true;
        self.apples.push(entry);
        self.radius.push(radius);
        self.fresh.push(true);
        if self.apples.len() == 1 {
            // The skin is set by the first apple; the grid's cells follow the largest radius.
            self.grid = grid::NeighborList::new(self.config.grid_skin_ratio * radius);
        }
        AppleId(id)
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
        if self.lookup(collider).is_some() {
            return Err(LayerError::Duplicate(options.name));
        }
        let co = colliders
            .get_mut(collider)
            .ok_or(LayerError::UnknownCollider(collider))?;
        if !self.config.passive {
            co.set_active_hooks(co.active_hooks() | ActiveHooks::FILTER_CONTACT_PAIRS);
        }
        let role = if options.rigid || self.config.passive {
            Role::RigidSurface
        } else {
            Role::HertzSurface
        };
        let id = self.surfaces.len() as u32;
        self.surfaces.push(SurfaceEntry {
            name: options.name.into(),
            collider,
            material: options.material,
            shape: options.shape,
            belt_local: options.belt_velocity_local,
            rigid: options.rigid,
        });
        self.surf_now.push(SurfaceNow::new());
        self.rebuild_candidates = true;
        self.hooks.set(collider, role);
        self.register(collider, role, id);
        Ok(SurfaceId(id))
    }

    fn register(&mut self, h: ColliderHandle, role: Role, id: u32) {
        let k = h.into_raw_parts().0 as usize;
        if self.by_collider.len() <= k {
            self.by_collider.resize(k + 1, None);
        }
        self.by_collider[k] = Some((h, role, id));
    }

    /// The apple of a rigid body, if it is one.
    fn apple_of(&self, h: RigidBodyHandle) -> Option<usize> {
        match self.apple_of_body.get(h.into_raw_parts().0 as usize) {
            Some(Some((stored, k))) if *stored == h => Some(*k as usize),
            _ => None,
        }
    }

    fn lookup(&self, h: ColliderHandle) -> Option<(Role, u32)> {
        match self.by_collider.get(h.into_raw_parts().0 as usize) {
            Some(Some((stored, role, id))) if *stored == h => Some((*role, *id)),
            _ => None,
        }
    }

    /// Checks that no apple can meet a concave surface tighter than itself (conforming contact).
    pub fn check_conformity(&self) -> Result<(), LayerError> {
        for s in &self.surfaces {
            if let SurfaceShape::Trough { radius_m, .. } = s.shape {
                for a in &self.apples {
                    if contact::normal::effective_radius(1.0 / a.radius, -1.0 / radius_m).is_none()
                    {
                        return Err(LayerError::Conforming {
                            apple: a.name.to_string(),
                            surface: s.name.to_string(),
                            apple_radius_m: a.radius,
                            surface_radius_m: radius_m,
                        });
                    }
                }
            }
        }
        Ok(())
    }

    /// Number of apples.
    pub fn apple_count(&self) -> usize {
        self.apples.len()
    }

    /// Name of an apple.
    pub fn apple_name(&self, id: AppleId) -> &str {
        &self.apples[id.0 as usize].name
    }

    /// The ball collider of an apple, if it has one.
    pub fn apple_collider(&self, id: AppleId) -> Option<ColliderHandle> {
        self.apples[id.0 as usize].collider
    }

    /// The rigid body of an apple.
    pub fn apple_body(&self, id: AppleId) -> RigidBodyHandle {
        self.apples[id.0 as usize].body
    }

    /// Radius of an apple (m).
    pub fn apple_radius(&self, id: AppleId) -> f64 {
        self.apples[id.0 as usize].radius
    }

    /// Mass of an apple (kg).
    pub fn apple_mass(&self, id: AppleId) -> f64 {
        self.apples[id.0 as usize].mass
    }

    /// Name of a surface.
    pub fn surface_name(&self, id: SurfaceId) -> &str {
        &self.surfaces[id.0 as usize].name
    }

    /// Number of surfaces.
    pub fn surface_count(&self) -> usize {
        self.surfaces.len()
    }

    /// The Verlet skin of the pair lists (m).
    pub fn grid_skin_m(&self) -> f64 {
        self.grid.skin_m()
    }

    /// Name of a surface's material.
    pub fn surface_material_name(&self, id: SurfaceId) -> &str {
        &self.materials[self.surfaces[id.0 as usize].material.0 as usize].0
    }

    /// How a surface's geometry is computed.
    pub fn surface_shape(&self, id: SurfaceId) -> &SurfaceShape {
        &self.surfaces[id.0 as usize].shape
    }

    /// Whether rapier's own contact handles the surface.
    pub fn surface_is_rigid(&self, id: SurfaceId) -> bool {
        self.surfaces[id.0 as usize].rigid
    }

    /// Total contact force on an apple at the last [`apply_forces`](Self::apply_forces) (N); for
    /// a sleeper, the force it carried when it fell asleep (its contacts are frozen).
    pub fn apple_contact_force(&self, id: AppleId) -> Vec3 {
        let k = id.0 as usize;
        if self.asleep.get(k).copied().unwrap_or(false) {
            return self.sleep_force[k];
        }
        self.force.get(k).copied().unwrap_or(Vec3::ZERO)
    }

    /// Contact torque on an apple at the last step (N m); zero for a sleeper.
    pub fn apple_contact_torque(&self, id: AppleId) -> Vec3 {
        let k = id.0 as usize;
        if self.asleep.get(k).copied().unwrap_or(false) {
            return Vec3::ZERO;
        }
        self.torque.get(k).copied().unwrap_or(Vec3::ZERO)
    }

    /// The apple-apple candidate pairs of the neighbour list (i < j, sorted), and how many times
    /// the list was rebuilt.
    pub fn neighbor_pairs(&self) -> (Vec<(u32, u32)>, u64) {
        (
            self.grid.pairs().iter().map(|p| (p.i, p.j)).collect(),
            self.grid.rebuilds(),
        )
    }

    /// Figures of the last step.
    pub fn stats(&self) -> StepStats {
        self.stats
    }

    /// Contacts that ended so far, in the order they ended.
    pub fn finished_events(&self) -> &[ContactEvent] {
        &self.finished
    }

    /// Takes the finished events out of the layer.
    pub fn take_finished_events(&mut self) -> Vec<ContactEvent> {
        std::mem::take(&mut self.finished)
    }

    /// The contacts still open, as events with no end (sorted by apple, then other party).
    pub fn open_events(&self) -> Vec<ContactEvent> {
        let mut out: Vec<ContactEvent> = self
            .contacts
            .iter()
            .filter_map(|c| {
                let o = c.record.as_ref()?;
                Some(o.snapshot(self.names(c.i, c.other)))
            })
            .collect();
        out.sort_by(|x, y| {
            (x.a_index, party_key(x.b_party), x.t_start_s.to_bits()).cmp(&(
                y.a_index,
                party_key(y.b_party),
                y.t_start_s.to_bits(),
            ))
        });
        out
    }

    /// Who a contact is about (the names of an event's parties).
    pub fn names(&self, i: u32, other: Party) -> Names {
        Names {
            a: self.apples[i as usize].name.clone(),
            b: match other {
                Party::Apple(j) => self.apples[j as usize].name.clone(),
                Party::Surface(s) => self.surfaces[s as usize].name.clone(),
            },
            a_index: i,
            b_party: other,
        }
    }

    /// Work done so far by the normal forces of the contacts still open (J): the energy the
    /// contacts hold or have lost so far (see `OpenContact::work_so_far_j`).
    pub fn open_contact_work_j(&self) -> f64 {
        self.contacts
            .iter()
            .filter_map(|c| c.record.as_ref())
            .map(OpenContact::work_so_far_j)
            .sum()
    }

    /// Number of apples asleep now.
    pub fn sleeping_count(&self) -> usize {
        self.asleep_count
    }

    /// Number of apples awake now.
    pub fn awake_count(&self) -> usize {
        self.apples.len() - self.asleep_count
    }

    /// Open contacts, sleepers' frozen ones included: (all, apple-apple).
    pub fn contact_counts(&self) -> (usize, usize) {
        self.contacts.iter().fold((0, 0), |(all, aa), c| {
            (
                all + 1,
                aa + usize::from(matches!(c.other, Party::Apple(_))),
            )
        })
    }

    /// Whether an apple is asleep.
    pub fn is_asleep(&self, id: AppleId) -> bool {
        self.asleep.get(id.0 as usize).copied().unwrap_or(false)
    }

    /// The slip of every contact evaluated at the last force pass, in a fixed order (needs
    /// [`LayerConfig::record_slips`]). Contacts of sleeping apples are not evaluated.
    pub fn slips(&self) -> &[SlipSample] {
        &self.slips
    }

    /// Centre, velocity and angular velocity of an apple as the last force pass saw them.
    pub fn apple_motion(&self, id: AppleId) -> (Vec3, Vec3, Vec3) {
        let k = id.0 as usize;
        (self.pos[k], self.vel[k], self.angvel[k])
    }

    /// Total sleeps and wake-ups so far.
    pub fn sleep_counts(&self) -> (u64, u64) {
        (self.stats_sleeps, self.stats_wakeups)
    }

    /// Resets the user forces the layer set on other dynamic bodies (call before
    /// `apply_forces` if surfaces ride on dynamic bodies).
    pub fn reset_surface_body_forces(&self, bodies: &mut RigidBodySet, colliders: &ColliderSet) {
        for s in &self.surfaces {
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

    /// Reads the awake apples' current state from rapier. A sleeper costs nothing here: one that
    /// rapier woke (the user moved it, or gave it an impulse with `wake_up`) shows up in rapier's
    /// active set and is taken as awake again.
    fn gather(&mut self, bodies: &RigidBodySet, islands: &IslandManager) -> Result<(), LayerError> {
        let n = self.apples.len();
        self.pos.resize(n, Vec3::ZERO);
        self.vel.resize(n, Vec3::ZERO);
        self.angvel.resize(n, Vec3::ZERO);
        self.active.resize(n, true);
        self.force.clear();
        self.force.resize(n, Vec3::ZERO);
        self.torque.clear();
        self.torque.resize(n, Vec3::ZERO);
        if self.config.step_control.is_some() {
            self.kicked_force.clear();
            self.kicked_force.resize(n, Vec3::ZERO);
            self.kicked_torque.clear();
            self.kicked_torque.resize(n, Vec3::ZERO);
        }
        self.count.clear();
        self.count.resize(n, 0);
        self.still.resize(n, false);
        self.busy.clear();
        self.busy.resize(n, false);
        self.still_time.resize(n, 0.0);
        self.mean_force.resize(n, Vec3::NAN);
        self.asleep.resize(n, false);
        self.sleep_force.resize(n, Vec3::ZERO);
        self.loaded.resize(n, false);
        if self.sleeping_any() {
            for h in islands.active_bodies() {
                if let Some(k) = self.apple_of(h) {
                    if self.asleep[k] {
                        self.asleep[k] = false;
                        self.asleep_count -= 1;
                        self.active[k] = true;
                        self.still_time[k] = 0.0;
                        self.mean_force[k] = Vec3::NAN;
                        self.awake_dirty = true;
                    }
                }
            }
        }
        self.refresh_awake();
        let still2 = self.config.sleep.speed_m_s * self.config.sleep.speed_m_s;
        for &k in &self.awake {
            let k = k as usize;
            let a = &self.apples[k];
            let Some(rb) = bodies.get(a.body) else {
                return Err(LayerError::NonFinite {
                    body: a.name.to_string(),
                    time_s: self.time_s,
                });
            };
            let pose = rb.position();
            let c = if a.offset == Vec3::ZERO {
                pose.translation
            } else {
                pose.transform_point(a.offset)
            };
            let w = rb.angvel();
            let v = if a.centred {
                rb.linvel()
            } else {
                rb.linvel() + w.cross(c - rb.center_of_mass())
            };
            if !(is_finite(c) && is_finite(v) && is_finite(w)) {
                return Err(LayerError::NonFinite {
                    body: a.name.to_string(),
                    time_s: self.time_s,
                });
            }
            self.pos[k] = c;
            self.vel[k] = v;
            self.angvel[k] = w;
            self.still[k] =
                v.length_squared() < still2 && w.length_squared() * a.radius * a.radius < still2;
        }
        Ok(())
    }

    /// Whether some apple sleeps (the awake list is shorter than the apples).
    fn sleeping_any(&self) -> bool {
        self.awake.len() < self.apples.len() || self.awake_dirty
    }

    /// Lists the awake apples again after sleeps and wake-ups, and the pairs to scan with them.
    fn refresh_awake(&mut self) {
        if !self.awake_dirty {
            return;
        }
        self.awake_dirty = false;
        self.awake.clear();
        for (k, &a) in self.asleep.iter().enumerate() {
            self.active[k] = !a;
            if !a {
                self.awake.push(k as u32);
            }
        }
        self.pair_scan = None;
    }

    /// Computes every modelled contact at the current poses and sets the apples' forces and
    /// torques for the coming step (replacing whatever the layer set before). Call it right
    /// before each `step`, with the time of the current poses and the step about to be taken.
    ///
    /// Sleeping apples (see [`SleepConfig`]) are not touched; contacts between two sleepers or
    /// between a sleeper and a fixed surface are not evaluated. Wake-ups are decided from the
    /// geometry before any force is computed, so a woken apple gets all its contacts this step.
    pub fn apply_forces(
        &mut self,
        bodies: &mut RigidBodySet,
        colliders: &ColliderSet,
        islands: &IslandManager,
        time_s: f64,
        dt_s: f64,
    ) -> Result<(), LayerError> {
        let control = self.config.step_control.take();
        let r = self.step_forces(bodies, colliders, islands, time_s, dt_s);
        self.config.step_control = control;
        r.map(|_| ())
    }

    /// Like [`apply_forces`](Self::apply_forces) for an adaptive driver (with
    /// [`LayerConfig::step_control`] set): finds the contacts at the current poses, chooses the
    /// coming step, at most `dt_cap_s`, that resolves them (see [`StepControl`]), applies the
    /// forces for it and returns it. Pass the returned step to rapier. `land_in_s`, if positive,
    /// is the time left to a point the driver must land on exactly (an output sample, the end):
    /// the step is then shortened to divide it evenly, never leaving a sliver.
    pub fn apply_forces_adaptive(
        &mut self,
        bodies: &mut RigidBodySet,
        colliders: &ColliderSet,
        islands: &IslandManager,
        time_s: f64,
        dt_cap_s: f64,
        land_in_s: f64,
    ) -> Result<f64, LayerError> {
        self.land_in_s = land_in_s;
        let r = self.step_forces(bodies, colliders, islands, time_s, dt_cap_s);
        self.land_in_s = 0.0;
        r
    }

    fn step_forces(
        &mut self,
        bodies: &mut RigidBodySet,
        colliders: &ColliderSet,
        islands: &IslandManager,
        time_s: f64,
        dt_cap_s: f64,
    ) -> Result<f64, LayerError> {
        self.time_s = time_s;
        self.ensure_laws();
        self.gather(bodies, islands)?;
        if self.config.passive {
            self.stats = StepStats {
                dt_limit_s: f64::INFINITY,
                ..StepStats::default()
            };
            return Ok(dt_cap_s);
        }
        // Touch and parting instants are interpolated within the step that led here.
        self.dt_back = self.last_dt.unwrap_or(dt_cap_s);
        self.observe_surfaces(bodies, colliders);
        for k in std::mem::take(&mut self.to_wake) {
            self.wake(bodies, k as usize);
        }
        self.refresh_awake();
        let mut redone = false;
        loop {
            self.detect(colliders, time_s, dt_cap_s);
            if self.to_wake.is_empty() || redone {
                break;
            }
            for k in std::mem::take(&mut self.to_wake) {
                self.wake(bodies, k as usize);
            }
            self.refresh_awake();
            redone = true;
        }
        self.to_wake.clear();
        self.motion_limit();
        let dt_s = if self.config.step_control.is_some() {
            let dt = dt_cap_s.min(self.stats.dt_limit_s);
            if self.land_in_s > 0.0 {
                self.land_in_s / (self.land_in_s / dt).ceil()
            } else {
                dt
            }
        } else {
            dt_cap_s
        };
        self.last_dt = Some(dt_s);

        self.force_pass(time_s, dt_s)?;
        self.sleep_decisions(bodies, dt_s);
        self.hand_to_rapier(bodies, dt_s);
        Ok(dt_s)
    }

    /// Hands the forces to rapier. `user_force` persists across steps, so whatever the layer left
    /// on a body is replaced; a body that had no load and gets none is not touched (rapier then
    /// has no change of it to process). With variable steps, the leapfrog kick (see
    /// [`StepControl::gravity`]).
    fn hand_to_rapier(&mut self, bodies: &mut RigidBodySet, dt_s: f64) {
        let control = self.config.step_control;
        let (kick, gravity) = match control {
            Some(c) => ((self.dt_back + dt_s) / (2.0 * dt_s), c.gravity),
            None => (1.0, Vec3::ZERO),
        };
        for &k in &self.awake {
            let k = k as usize;
            if !self.active[k] {
                // Fell asleep in this pass.
                continue;
            }
            let a = &self.apples[k];
            let (f, t) = match control {
                None => (self.force[k], self.torque[k]),
                Some(_) => {
                    // Each contact carries its own kick (see `kernel`); gravity's share. An
                    // apple's first step starts the leapfrog from its initial velocity: half a
                    // kick (measured: without it, a 6 mm drop on a belt in adaptive steps landed
                    // 4.6 % slow).
                    let kick = if std::mem::take(&mut self.fresh[k]) {
                        0.5
                    } else {
                        kick
                    };
                    (
                        self.kicked_force[k] + gravity * (a.mass * (kick - 1.0)),
                        self.kicked_torque[k],
                    )
                }
            };
            let load = f != Vec3::ZERO || t != Vec3::ZERO;
            if !load && !self.loaded[k] {
                continue;
            }
            self.loaded[k] = load;
            if let Some(rb) = bodies.get_mut(a.body) {
                rb.reset_forces(false);
                rb.reset_torques(false);
                rb.add_force(f, false);
                rb.add_torque(t, false);
            }
        }
        for (h, f, p) in self.body_loads.drain(..) {
            if let Some(rb) = bodies.get_mut(h) {
                if rb.is_dynamic() {
                    rb.add_force_at_point(f, p, true);
                }
            }
        }
    }

    /// With step control: no awake apple may move more than the pair-finding margins in one step.
    fn motion_limit(&mut self) {
        let Some(c) = self.config.step_control else {
            return;
        };
        let mut v_max: f64 = 0.0;
        for &k in &self.awake {
            // Centres only: spin moves no centre, and the margins are about centres.
            v_max = v_max.max(self.vel[k as usize].length());
        }
        // The grid's skin is known once apples exist (sources may add the first ones late).
        // Two apples closing at up to 2 v_max must not cross the skin of the list unseen in one
        // step: each may move half the skin.
        let reach = c.max_displacement_m.min(0.5 * self.grid.skin_m());
        if v_max > 0.0 && reach > 0.0 {
            self.stats.limit(reach / v_max, StepLimit::Motion);
        }
    }
}

/// How far ahead to look for contacts about to start: the coming step is at most the driver's
/// largest and at most twice the last (the driver's growth limit).
fn lookahead(last_dt: Option<f64>, c: &StepControl) -> f64 {
    match last_dt {
        Some(dt) => c.lookahead_s.min(2.0 * dt),
        None => c.lookahead_s,
    }
}

fn party_key(p: Party) -> (u8, u32) {
    match p {
        Party::Apple(j) => (0, j),
        Party::Surface(s) => (1, s),
    }
}
