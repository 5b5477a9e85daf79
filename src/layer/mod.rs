//! The rapier layer: pair finding, our contact law applied as forces, contact records.
//!
//! A rapier user keeps their own pipeline and sets. They register which colliders are apples and
//! which are surfaces (with a material each), pass [`ContactLayer::hooks`] to the pipeline's
//! `step`, and call [`ContactLayer::apply_forces`] right before every step:
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
//! let (_, apple) = world.insert(
//!     RigidBodyBuilder::dynamic().translation(Vector::new(0.0, 0.0, 0.0401))
//!         .linvel(Vector::new(0.0, 0.0, -1.0)).can_sleep(false),
//!     ColliderBuilder::ball(0.04).mass(0.107),
//! );
//!
//! let mut layer = ContactLayer::new(LayerConfig::default());
//! let fruit = layer.add_material("apple", Material::from_shear(1.1e6, 0.18, Some(800.0)).unwrap());
//! let steel = layer.add_material("steel", Material::from_youngs(2.0736e11, 0.28, None).unwrap());
//! layer.set_default_coefficients(0.3, 1.0, 100.0);
//! layer.add_apple(&mut world.colliders, apple, fruit, "a1").unwrap();
//! layer.add_surface(&mut world.colliders, floor, SurfaceOptions::hertz("floor", steel)).unwrap();
//!
//! // One step with dt = 0 lets rapier list the pairs touching at the start.
//! let dt = world.integration_parameters.dt;
//! world.integration_parameters.dt = 0.0;
//! world.step_with_events(layer.hooks(), &());
//! world.integration_parameters.dt = dt;
//!
//! for step in 0..1500 {
//!     let t = step as f64 * dt;
//!     layer.apply_forces(&mut world.bodies, &world.colliders, &world.narrow_phase, t, dt).unwrap();
//!     world.step_with_events(layer.hooks(), &());
//! }
//! let bounce = &layer.finished_events()[0];
//! // 65.7 N by the closed form without gravity; gravity adds a little.
//! assert!((bounce.peak_force_n - 67.4).abs() < 0.1);
//! assert!(bounce.absorbed_energy_j.abs() < 1e-6, "elastic: no loss");
//! ```
//!
//! Why it is built this way (rapier-notes.md): forces are computed from the overlap at the
//! current poses (rapier's manifolds lag one step, which costs 4-6 % of the peak force at
//! dt = 1e-4); apple-apple pairs come from our own cell grid ([`grid`]) and never enter rapier's
//! narrow phase (collision groups), 8-32x cheaper; apple-surface pairs come from rapier's
//! broad phase, the surface geometry from the collider shapes ([`surface`]).

pub mod grid;
pub mod hooks;
pub mod surface;

use crate::contact::{self, theory, ContactKinematics, LawParts, Material, PairLaw};
use crate::math::{is_finite, Vec3};
use crate::record::events::{ContactEvent, ContactSample, Names, OpenContact, Party};
pub use hooks::{ContactHooks, Role};
use rapier3d_f64::dynamics::{RigidBodyHandle, RigidBodySet};
use rapier3d_f64::geometry::{ColliderHandle, ColliderSet, Group, InteractionGroups, NarrowPhase};
use rapier3d_f64::pipeline::ActiveHooks;
use std::collections::{BTreeMap, HashMap};
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
    /// The collider is registered twice.
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
/// and gravity; set it with [`ContactLayer::set_gravity`]) could not change its speed by
/// `speed_m_s` within `time_s`, and it touched no apple that was not still and no moving surface (a
/// belt, a moving body). A sleeper is not integrated (rapier's sleeping) and its
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

#[derive(Debug, Clone)]
struct AppleEntry {
    name: Arc<str>,
    collider: ColliderHandle,
    body: RigidBodyHandle,
    offset: Vec3,
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

/// State carried by a contact pair across steps.
#[derive(Debug, Clone)]
pub struct PairState {
    xi: Vec3,
    open: Option<Box<OpenContact>>,
    /// Force on body 1 at the last evaluation (reported for sleepers' frozen contacts).
    last_force: Vec3,
    /// Overlap at the last evaluation.
    last_u: f64,
    /// Overlap when one of the two fell asleep (NaN while both are awake).
    ref_u: f64,
}

impl Default for PairState {
    fn default() -> Self {
        Self {
            xi: Vec3::ZERO,
            open: None,
            last_force: Vec3::ZERO,
            last_u: 0.0,
            ref_u: f64::NAN,
        }
    }
}

#[derive(Debug, Clone)]
struct Slot {
    normal: Vec3,
    seen: bool,
    state: PairState,
}

#[derive(Debug, Clone, Copy)]
enum Other {
    /// Index into the neighbour list.
    Apple(usize),
    /// (apple, surface) key and slot index.
    Surface(u32, u32, usize),
}

/// Contacts per step from which the force pass runs in parallel (below that, rayon's overhead
/// outweighs the work). The results do not depend on it.
const PARALLEL_MIN_HITS: usize = 256;

/// One evaluated contact, ready to be added to the loads.
#[derive(Debug, Clone, Copy)]
struct HitOut {
    i: usize,
    j: Option<usize>,
    body2: Option<RigidBodyHandle>,
    /// Force on apple i (N).
    force: Vec3,
    point: Vec3,
    /// The leapfrog kick factor with adaptive steps.
    kick: Option<f64>,
    /// On a belt or a moving part: keeps the apple awake.
    moving_surface: bool,
    elastic_energy_j: f64,
    overlap_ratio: f64,
    /// The other party (for the slip samples).
    party: Party,
    /// Tangential slip speed at the contact point (m/s).
    slip_m_s: f64,
    /// Normal force (N).
    normal_force_n: f64,
}

/// The slip of one contact at the current poses, seen from one apple (an apple-apple contact
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

#[derive(Debug, Clone, Copy)]
struct Hit {
    i: u32,
    other: Other,
    normal: Vec3,
    overlap: f64,
    curvature2: f64,
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
    /// Role and index of registered colliders, indexed by the collider's arena index (a plain
    /// table: the candidate scan does two lookups per rapier pair every step).
    by_collider: Vec<Option<(ColliderHandle, Role, u32)>>,
    grid: grid::NeighborList<PairState>,
    surface_slots: BTreeMap<(u32, u32), Vec<Slot>>,
    // Per-step buffers.
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
    asleep: Vec<bool>,
    sleep_force: Vec<Vec3>,
    to_wake: Vec<u32>,
    stats_sleeps: u64,
    stats_wakeups: u64,
    hits: Vec<Hit>,
    slips: Vec<SlipSample>,
    scratch: Vec<SurfaceHit>,
    candidates: Vec<(u32, u32)>,
    finished: Vec<ContactEvent>,
    body_loads: Vec<(RigidBodyHandle, Vec3, Vec3)>,
    /// Adaptive steps only: contact force and torque per apple with each contact's leapfrog kick
    /// (see [`StepControl::gravity`]): what is handed to rapier.
    kicked_force: Vec<Vec3>,
    kicked_torque: Vec<Vec3>,
    /// Adaptive steps only: apples not yet stepped, whose first kick spans half a step.
    fresh: Vec<bool>,
    /// Force pass buffers (reused every step).
    states_buf: Vec<PairState>,
    outs_buf: Vec<Result<HitOut, LayerError>>,
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
            surface_slots: BTreeMap::new(),
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
            asleep: Vec::new(),
            sleep_force: Vec::new(),
            to_wake: Vec::new(),
            stats_sleeps: 0,
            stats_wakeups: 0,
            hits: Vec::new(),
            slips: Vec::new(),
            scratch: Vec::new(),
            candidates: Vec::new(),
            finished: Vec::new(),
            body_loads: Vec::new(),
            kicked_force: Vec::new(),
            kicked_torque: Vec::new(),
            fresh: Vec::new(),
            states_buf: Vec::new(),
            outs_buf: Vec::new(),
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
    /// enables the pair-filter hook.
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
        let mass = mp.mass();
        let inertia = mp.principal_inertia().x;
        if !(mass > 0.0 && inertia > 0.0) {
            return Err(LayerError::NotABall(name.to_string()));
        }
        if !self.config.passive {
            let g = self.config.apple_group;
            let old = co.collision_groups();
            co.set_collision_groups(InteractionGroups::new(g, old.filter & !g, old.test_mode));
            co.set_active_hooks(co.active_hooks() | ActiveHooks::FILTER_CONTACT_PAIRS);
        }
        let id = self.apples.len() as u32;
        self.apples.push(AppleEntry {
            name: name.into(),
            collider,
            body,
            offset,
            radius,
            material,
            mass,
            inv_tangential_mass: 1.0 / mass + radius * radius / inertia,
        });
        if !self.config.passive {
            self.hooks.set(collider, Role::Apple);
        }
        self.register(collider, Role::Apple, id);
        self.radius.push(radius);
        self.fresh.push(true);
        if self.apples.len() == 1 {
            // The skin is set by the first apple; the grid's cells follow the largest radius.
            self.grid = grid::NeighborList::new(self.config.grid_skin_ratio * radius);
        }
        Ok(AppleId(id))
    }

    /// Registers a surface collider (any body type). A Hertz surface gets the pair-filter hook so
    /// rapier leaves its apple contacts to the layer; a rigid one keeps rapier's response.
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

    /// The collider of an apple.
    pub fn apple_collider(&self, id: AppleId) -> ColliderHandle {
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

    /// The Verlet skin of the apple-apple list (m).
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

    /// Total contact force on an apple at the last [`apply_forces`](Self::apply_forces) (N).
    pub fn apple_contact_force(&self, id: AppleId) -> Vec3 {
        self.force.get(id.0 as usize).copied().unwrap_or(Vec3::ZERO)
    }

    /// Contact torque on an apple at the last step (N m).
    pub fn apple_contact_torque(&self, id: AppleId) -> Vec3 {
        self.torque
            .get(id.0 as usize)
            .copied()
            .unwrap_or(Vec3::ZERO)
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
        let mut out = Vec::new();
        for p in self.grid.pairs() {
            if let Some(o) = &p.state.open {
                out.push(o.snapshot(self.names_apple(p.i, p.j)));
            }
        }
        for (&(a, s), slots) in &self.surface_slots {
            for sl in slots {
                if let Some(o) = &sl.state.open {
                    out.push(o.snapshot(self.names_surface(a, s)));
                }
            }
        }
        out.sort_by(|x, y| {
            (x.a_index, party_key(x.b_party), x.t_start_s.to_bits()).cmp(&(
                y.a_index,
                party_key(y.b_party),
                y.t_start_s.to_bits(),
            ))
        });
        out
    }

    fn names_apple(&self, i: u32, j: u32) -> Names {
        Names {
            a: self.apples[i as usize].name.clone(),
            b: self.apples[j as usize].name.clone(),
            a_index: i,
            b_party: Party::Apple(j),
        }
    }

    fn names_surface(&self, a: u32, s: u32) -> Names {
        Names {
            a: self.apples[a as usize].name.clone(),
            b: self.surfaces[s as usize].name.clone(),
            a_index: a,
            b_party: Party::Surface(s),
        }
    }

    fn gather(&mut self, bodies: &RigidBodySet) -> Result<(), LayerError> {
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
        self.asleep.resize(n, false);
        self.sleep_force.resize(n, Vec3::ZERO);
        let still_speed = self.config.sleep.speed_m_s;
        for (k, a) in self.apples.iter().enumerate() {
            if self.asleep[k] {
                match bodies.get(a.body) {
                    // Still asleep in rapier: nothing moved, velocities are zero.
                    Some(rb) if rb.is_sleeping() => {
                        self.active[k] = false;
                        continue;
                    }
                    // Woken from outside (the user moved it): treat it as awake again.
                    _ => {
                        self.asleep[k] = false;
                        self.still_time[k] = 0.0;
                    }
                }
            }
            let Some(rb) = bodies.get(a.body) else {
                return Err(LayerError::NonFinite {
                    body: a.name.to_string(),
                    time_s: self.time_s,
                });
            };
            let c = rb.position().transform_point(a.offset);
            let v = rb.velocity_at_point(c);
            let w = rb.angvel();
            if !(is_finite(c) && is_finite(v) && is_finite(w)) {
                return Err(LayerError::NonFinite {
                    body: a.name.to_string(),
                    time_s: self.time_s,
                });
            }
            self.pos[k] = c;
            self.vel[k] = v;
            self.angvel[k] = w;
            self.active[k] = !self.asleep[k];
            self.still[k] = v.length() < still_speed && w.length() * a.radius < still_speed;
        }
        Ok(())
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
        narrow_phase: &NarrowPhase,
        time_s: f64,
        dt_s: f64,
    ) -> Result<(), LayerError> {
        let control = self.config.step_control.take();
        let r = self.step_forces(bodies, colliders, narrow_phase, time_s, dt_s);
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
        narrow_phase: &NarrowPhase,
        time_s: f64,
        dt_cap_s: f64,
        land_in_s: f64,
    ) -> Result<f64, LayerError> {
        self.land_in_s = land_in_s;
        let r = self.step_forces(bodies, colliders, narrow_phase, time_s, dt_cap_s);
        self.land_in_s = 0.0;
        r
    }

    fn step_forces(
        &mut self,
        bodies: &mut RigidBodySet,
        colliders: &ColliderSet,
        narrow_phase: &NarrowPhase,
        time_s: f64,
        dt_cap_s: f64,
    ) -> Result<f64, LayerError> {
        self.time_s = time_s;
        self.ensure_laws();
        self.gather(bodies)?;
        if self.config.passive {
            self.stats = StepStats {
                dt_limit_s: f64::INFINITY,
                ..StepStats::default()
            };
            return Ok(dt_cap_s);
        }
        // Touch and parting instants are interpolated within the step that led here.
        self.dt_back = self.last_dt.unwrap_or(dt_cap_s);
        let mut redone = false;
        loop {
            self.geometry_pass(bodies, colliders, narrow_phase, time_s, dt_cap_s);
            if self.to_wake.is_empty() || redone {
                break;
            }
            let woken = std::mem::take(&mut self.to_wake);
            for k in woken {
                self.wake(bodies, k as usize);
            }
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

        // Force pass, in the fixed order of `hits`.
        let hits = std::mem::take(&mut self.hits);
        let result = self.force_pass(&hits, bodies, colliders, time_s, dt_s);
        self.stats.contacts = hits.len();
        self.hits = hits;
        result?;
        self.add_frozen_forces();
        self.sleep_decisions(bodies, dt_s);

        // Hand the forces to rapier. `user_force` persists across steps, so reset every time.
        // With variable steps, the leapfrog kick (see `StepControl::gravity`).
        let (kick, gravity) = match self.config.step_control {
            Some(c) => ((self.dt_back + dt_s) / (2.0 * dt_s), c.gravity),
            None => (1.0, Vec3::ZERO),
        };
        for (k, a) in self.apples.iter().enumerate() {
            if !self.active[k] {
                continue;
            }
            if let Some(rb) = bodies.get_mut(a.body) {
                rb.reset_forces(false);
                rb.reset_torques(false);
                if self.config.step_control.is_none() {
                    rb.add_force(self.force[k], false);
                    rb.add_torque(self.torque[k], false);
                } else {
                    // Each contact carries its own kick (see `contact_force`); gravity's share.
                    // An apple's first step starts the leapfrog from its initial velocity: half
                    // a kick (measured: without it, a 6 mm drop on a belt in adaptive steps
                    // landed 4.6 % slow).
                    let kick = if std::mem::take(&mut self.fresh[k]) {
                        0.5
                    } else {
                        kick
                    };
                    rb.add_force(
                        self.kicked_force[k] + gravity * (a.mass * (kick - 1.0)),
                        false,
                    );
                    rb.add_torque(self.kicked_torque[k], false);
                }
            }
        }
        for (h, f, p) in self.body_loads.drain(..) {
            if let Some(rb) = bodies.get_mut(h) {
                if rb.is_dynamic() {
                    rb.add_force_at_point(f, p, true);
                }
            }
        }
        Ok(dt_s)
    }

    /// Finds every contact at the current poses (into `hits`), closes contacts that parted, and
    /// lists sleepers that must wake (into `to_wake`).
    fn geometry_pass(
        &mut self,
        bodies: &RigidBodySet,
        colliders: &ColliderSet,
        narrow_phase: &NarrowPhase,
        time_s: f64,
        dt_s: f64,
    ) {
        self.stats = StepStats {
            dt_limit_s: f64::INFINITY,
            ..StepStats::default()
        };
        let dt_back = self.dt_back;
        self.hits.clear();
        self.count.iter_mut().for_each(|c| *c = 0);
        // Apple-apple candidates from our grid; contacts dropped by a rebuild cannot have
        // overlapped (they are farther apart than the skin), close them where they are.
        let mut dropped_open = Vec::new();
        self.grid
            .update(&self.pos, &self.radius, &self.active, |p| {
                if p.state.open.is_some() {
                    dropped_open.push(p);
                }
            });
        for p in dropped_open {
            let (n, u) = self.apple_apple_geometry(p.i as usize, p.j as usize);
            let sep = (self.vel[p.i as usize] - self.vel[p.j as usize]).dot(n);
            let names = self.names_apple(p.i, p.j);
            let open = p.state.open.unwrap();
            self.finished
                .push(open.finish(time_s, dt_back, u, sep, names));
        }
        self.stats.apple_candidates = self.grid.pairs().len();
        let wake_ratio = self.config.sleep.wake_overlap_ratio;
        for k in 0..self.grid.pairs().len() {
            let (i, j) = {
                let p = &self.grid.pairs()[k];
                (p.i as usize, p.j as usize)
            };
            let (ai, aj) = (self.active[i], self.active[j]);
            if !ai && !aj {
                continue;
            }
            let (n, u) = self.apple_apple_geometry(i, j);
            let state = &mut self.grid.pairs_mut()[k].state;
            if ai != aj {
                // One sleeper: wake it if this contact starts, ends, or its overlap drifts.
                let sleeper = if ai { j } else { i };
                let starts = u > 0.0 && state.open.is_none();
                let ends = u <= 0.0 && state.open.is_some();
                if state.ref_u.is_nan() {
                    state.ref_u = state.last_u;
                }
                let drifts =
                    u > 0.0 && (u - state.ref_u).abs() > wake_ratio * state.ref_u.max(0.0) + 1e-9;
                if starts || ends || drifts {
                    self.to_wake.push(sleeper as u32);
                }
            } else {
                state.ref_u = f64::NAN;
            }
            state.last_u = u;
            if u <= 0.0 {
                if let Some(c) = self.config.step_control {
                    let closing = (self.vel[j] - self.vel[i]).dot(n);
                    // Relative acceleration of two apples: bounded by g (one supported, one
                    // falling); contact forces are not known yet at this point.
                    let accel = c.gravity.length();
                    if let Some(t_touch) = time_to_touch(-u, closing, accel, self.lookahead(&c)) {
                        // About to touch: resolve the impact (see `StepControl`).
                        let closing = closing + accel * t_touch;
                        let law = self.laws[self.apples[i].material.0 as usize
                            * self.materials.len()
                            + self.apples[j].material.0 as usize];
                        let (ri, rj) = (self.radius[i], self.radius[j]);
                        let r_star = ri * rj / (ri + rj);
                        let k = contact::normal::stiffness(law.e_star_pa, r_star);
                        let m_n = theory::reduced_mass(self.apples[i].mass, self.apples[j].mass);
                        let t_h = theory::elastic_impact(m_n, closing, k, r_star).contact_time_s;
                        let lim = t_touch + t_h / c.steps_per_contact;
                        self.stats.limit(lim, StepLimit::Approaching);
                    }
                }
            }
            let state = &mut self.grid.pairs_mut()[k].state;
            if u > 0.0 {
                if let Some(c) = self.config.step_control {
                    let rate = (self.vel[j] - self.vel[i]).dot(n);
                    let law = self.laws[self.apples[i].material.0 as usize * self.materials.len()
                        + self.apples[j].material.0 as usize];
                    let (ri, rj) = (self.radius[i], self.radius[j]);
                    let m_n = theory::reduced_mass(self.apples[i].mass, self.apples[j].mass);
                    let k = contact::normal::stiffness(law.e_star_pa, ri * rj / (ri + rj));
                    let (scale, start) = match state.open.as_mut() {
                        Some(o) => (
                            o.impact_scale(|v| impact_scale(m_n, k, v)),
                            o.start_time_s(),
                        ),
                        None => (impact_scale(m_n, k, rate), time_s),
                    };
                    let ke = if self.config.parts.energy_loss {
                        law.ke
                    } else {
                        1.0
                    };
                    let lim = contact_step_limit(&c, m_n, k, u, scale, rate, ke, time_s - start);
                    self.stats.limit(lim.0, lim.1);
                }
                self.hits.push(Hit {
                    i: i as u32,
                    other: Other::Apple(k),
                    normal: n,
                    overlap: u,
                    curvature2: 1.0 / self.radius[j],
                });
                self.count[i] += 1;
                self.count[j] += 1;
                continue;
            }
            let state = &mut self.grid.pairs_mut()[k].state;
            if state.open.is_some() {
                let sep = (self.vel[i] - self.vel[j]).dot(n);
                let open = state.open.take().unwrap();
                state.xi = Vec3::ZERO;
                state.last_force = Vec3::ZERO;
                let names = self.names_apple(i as u32, j as u32);
                self.finished
                    .push(open.finish(time_s, dt_back, u, sep, names));
            } else {
                state.xi = Vec3::ZERO;
                state.last_force = Vec3::ZERO;
            }
        }
        self.stats.apple_apple_contacts = self.hits.len();
        self.collect_surface_hits(bodies, colliders, narrow_phase, time_s, dt_s);
    }

    fn wake(&mut self, bodies: &mut RigidBodySet, k: usize) {
        if self.active[k] {
            return;
        }
        self.active[k] = true;
        self.asleep[k] = false;
        self.still_time[k] = 0.0;
        self.stats_wakeups += 1;
        if let Some(rb) = bodies.get_mut(self.apples[k].body) {
            rb.wake_up(true);
        }
    }

    /// A sleeper reports the contact force it carried when it fell asleep (its contacts are frozen;
    /// a change large enough to matter wakes it).
    fn add_frozen_forces(&mut self) {
        for k in 0..self.apples.len() {
            if self.asleep[k] {
                self.force[k] = self.sleep_force[k];
            }
        }
    }

    /// Puts to sleep the apples that have been still long enough (see [`SleepConfig`]).
    fn sleep_decisions(&mut self, bodies: &mut RigidBodySet, dt_s: f64) {
        let cfg = self.config.sleep;
        if !cfg.enabled {
            return;
        }
        for k in 0..self.apples.len() {
            if !self.active[k] {
                continue;
            }
            // Still, supported (touching something) and not accelerating: the net force would not
            // change its speed by the stillness threshold within the stillness time.
            let net = self.force[k] + self.gravity * self.apples[k].mass;
            let resting = self.count[k] > 0
                && net.length() * cfg.time_s < cfg.speed_m_s * self.apples[k].mass;
            if self.still[k] && !self.busy[k] && resting {
                self.still_time[k] += dt_s;
            } else {
                self.still_time[k] = 0.0;
            }
            if self.still_time[k] >= cfg.time_s {
                self.active[k] = false;
                self.asleep[k] = true;
                self.sleep_force[k] = self.force[k];
                self.vel[k] = Vec3::ZERO;
                self.angvel[k] = Vec3::ZERO;
                self.still[k] = true;
                self.stats_sleeps += 1;
                self.force[k] = Vec3::ZERO;
                self.torque[k] = Vec3::ZERO;
                if let Some(rb) = bodies.get_mut(self.apples[k].body) {
                    rb.reset_forces(false);
                    rb.reset_torques(false);
                    rb.sleep();
                }
            }
        }
    }

    /// How far ahead to look for contacts about to start: the coming step is at most the
    /// driver's largest and at most twice the last (the driver's growth limit).
    fn lookahead(&self, c: &StepControl) -> f64 {
        match self.last_dt {
            Some(dt) => c.lookahead_s.min(2.0 * dt),
            None => c.lookahead_s,
        }
    }

    /// With step control: no awake apple may move more than the pair-finding margins in one step.
    fn motion_limit(&mut self) {
        let Some(c) = self.config.step_control else {
            return;
        };
        let mut v_max: f64 = 0.0;
        for k in 0..self.apples.len() {
            if self.active[k] {
                // Centres only: spin moves no centre, and the margins are about centres.
                v_max = v_max.max(self.vel[k].length());
            }
        }
        // The grid's skin is known once apples exist (sources may add the first ones late).
        // Two apples closing at up to 2 v_max must not cross the skin of the list unseen in one
        // step: each may move half the skin.
        let reach = c.max_displacement_m.min(0.5 * self.grid.skin_m());
        if v_max > 0.0 && reach > 0.0 {
            self.stats.limit(reach / v_max, StepLimit::Motion);
        }
    }

    /// Work done so far by the normal forces of the contacts still open (J): the energy the
    /// contacts hold or have lost so far (see `OpenContact::work_so_far_j`).
    pub fn open_contact_work_j(&self) -> f64 {
        let mut w = 0.0;
        for p in self.grid.pairs() {
            if let Some(o) = &p.state.open {
                w += o.work_so_far_j();
            }
        }
        for slots in self.surface_slots.values() {
            for sl in slots {
                if let Some(o) = &sl.state.open {
                    w += o.work_so_far_j();
                }
            }
        }
        w
    }

    /// Number of apples asleep now.
    pub fn sleeping_count(&self) -> usize {
        self.asleep.iter().filter(|&&a| a).count()
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

    fn apple_apple_geometry(&self, i: usize, j: usize) -> (Vec3, f64) {
        let d = self.pos[i] - self.pos[j];
        let dist = d.length();
        let u = self.radius[i] + self.radius[j] - dist;
        let n = if dist > 0.0 { d / dist } else { Vec3::Z };
        (n, u)
    }

    fn collect_surface_hits(
        &mut self,
        bodies: &RigidBodySet,
        colliders: &ColliderSet,
        narrow_phase: &NarrowPhase,
        time_s: f64,
        dt_s: f64,
    ) {
        let dt_back = self.dt_back;
        let control = self.config.step_control;
        let horizon = control.map_or(0.0, |c| self.lookahead(&c));
        self.candidates.clear();
        for pair in narrow_phase.contact_pairs() {
            match (self.lookup(pair.collider1), self.lookup(pair.collider2)) {
                (Some((Role::Apple, a)), Some((Role::HertzSurface, s)))
                | (Some((Role::HertzSurface, s)), Some((Role::Apple, a)))
                    // A sleeper's surface contacts are frozen: no need to look at them.
                    if self.active[a as usize] =>
                {
                    self.candidates.push((a, s))
                }
                _ => {}
            }
        }
        self.candidates.sort_unstable();
        self.candidates.dedup();
        for (&(a, _), slots) in self.surface_slots.iter_mut() {
            // Slots of sleepers stay as they are (frozen); the others must be seen again.
            let keep = !self.active[a as usize];
            for s in slots.iter_mut() {
                s.seen = keep;
            }
        }
        let candidates = std::mem::take(&mut self.candidates);
        for &(a, s) in &candidates {
            let ai = a as usize;
            let surf = &self.surfaces[s as usize];
            let Some(co) = colliders.get(surf.collider) else {
                continue;
            };
            let ahead = control.map_or(dt_s, |c| self.lookahead(&c).max(dt_s));
            let margin = 2.0 * self.vel[ai].length() * ahead + 1e-9;
            self.scratch.clear();
            surface::surface_hits(
                &surf.shape,
                co,
                self.pos[ai],
                self.radius[ai],
                margin,
                &mut self.scratch,
            );
            if self.scratch.is_empty() {
                continue;
            }
            let slots = self.surface_slots.entry((a, s)).or_default();
            for hit in &self.scratch {
                // Match the hit to the slot with the closest normal (one per smooth region).
                let mut best: Option<(usize, f64)> = None;
                for (k, sl) in slots.iter().enumerate() {
                    if sl.seen {
                        continue;
                    }
                    let c = sl.normal.dot(hit.normal);
                    if c > surface::MESH_MERGE_COS && best.is_none_or(|b| c > b.1) {
                        best = Some((k, c));
                    }
                }
                if hit.overlap_m <= 0.0 {
                    if let Some(c) = control {
                        // About to touch: resolve the impact (see `StepControl`).
                        let v_s =
                            surface_point_velocity(bodies, colliders, surf.collider, self.pos[ai]);
                        let closing = (v_s - self.vel[ai]).dot(hit.normal);
                        // Gravity towards the surface closes the gap within the step too.
                        let accel = (-c.gravity.dot(hit.normal)).max(0.0);
                        if let Some(t_touch) =
                            time_to_touch(-hit.overlap_m, closing, accel, horizon)
                        {
                            let closing = closing + accel * t_touch;
                            let r_star = contact::normal::effective_radius(
                                1.0 / self.radius[ai],
                                hit.curvature_1_m,
                            );
                            if let Some(r_star) = r_star {
                                let law = self.laws[self.apples[ai].material.0 as usize
                                    * self.materials.len()
                                    + surf.material.0 as usize];
                                let k = contact::normal::stiffness(law.e_star_pa, r_star);
                                let t_h = theory::elastic_impact(
                                    self.apples[ai].mass,
                                    closing,
                                    k,
                                    r_star,
                                )
                                .contact_time_s;
                                let lim = t_touch + t_h / c.steps_per_contact;
                                self.stats.limit(lim, StepLimit::Approaching);
                            }
                        }
                    }
                }
                let k = match best {
                    Some((k, _)) => k,
                    None => {
                        if hit.overlap_m <= 0.0 {
                            continue;
                        }
                        slots.push(Slot {
                            normal: hit.normal,
                            seen: false,
                            state: PairState::default(),
                        });
                        slots.len() - 1
                    }
                };
                let sl = &mut slots[k];
                sl.seen = true;
                sl.normal = hit.normal;
                if hit.overlap_m > 0.0 {
                    if let Some(c) = control {
                        let v_s =
                            surface_point_velocity(bodies, colliders, surf.collider, self.pos[ai]);
                        let rate = (v_s - self.vel[ai]).dot(hit.normal);
                        if let Some(r_star) = contact::normal::effective_radius(
                            1.0 / self.radius[ai],
                            hit.curvature_1_m,
                        ) {
                            let law = self.laws[self.apples[ai].material.0 as usize
                                * self.materials.len()
                                + surf.material.0 as usize];
                            let kk = contact::normal::stiffness(law.e_star_pa, r_star);
                            let m_n = self.apples[ai].mass;
                            let (scale, start) = match sl.state.open.as_mut() {
                                Some(o) => (
                                    o.impact_scale(|v| impact_scale(m_n, kk, v)),
                                    o.start_time_s(),
                                ),
                                None => (impact_scale(m_n, kk, rate), time_s),
                            };
                            let ke = if self.config.parts.energy_loss {
                                law.ke
                            } else {
                                1.0
                            };
                            let lim = contact_step_limit(
                                &c,
                                m_n,
                                kk,
                                hit.overlap_m,
                                scale,
                                rate,
                                ke,
                                time_s - start,
                            );
                            self.stats.limit(lim.0, lim.1);
                        }
                    }
                    self.hits.push(Hit {
                        i: a,
                        other: Other::Surface(a, s, k),
                        normal: hit.normal,
                        overlap: hit.overlap_m,
                        curvature2: hit.curvature_1_m,
                    });
                    self.count[ai] += 1;
                } else if let Some(open) = sl.state.open.take() {
                    let v_surf =
                        surface_point_velocity(bodies, colliders, surf.collider, self.pos[ai]);
                    let sep = (self.vel[ai] - v_surf).dot(hit.normal);
                    let names = Names {
                        a: self.apples[ai].name.clone(),
                        b: surf.name.clone(),
                        a_index: a,
                        b_party: Party::Surface(s),
                    };
                    self.finished
                        .push(open.finish(time_s, dt_back, hit.overlap_m, sep, names));
                    sl.state.xi = Vec3::ZERO;
                }
            }
        }
        self.candidates = candidates;
        // Slots not seen this step: the apple left the surface's neighbourhood.
        let mut closed = Vec::new();
        self.surface_slots.retain(|&(a, s), slots| {
            slots.retain_mut(|sl| {
                if sl.seen {
                    return true;
                }
                if let Some(open) = sl.state.open.take() {
                    closed.push((a, s, open));
                }
                false
            });
            !slots.is_empty()
        });
        for (a, s, open) in closed {
            let names = self.names_surface(a, s);
            let ai = a as usize;
            let sep = self.vel[ai].length();
            self.finished
                .push(open.finish(time_s, dt_back, 0.0, sep, names));
        }
    }

    /// Evaluates one contact at the current poses: the contact law, the guards and the contact
    /// record. Reads the layer and writes only the contact's own `state`, so contacts can be
    /// evaluated in parallel; [`apply_hit`](Self::apply_hit) then adds the results in a fixed
    /// order (bit-identical sums whatever the thread count).
    #[allow(clippy::too_many_arguments)]
    fn evaluate_hit(
        &self,
        h: &Hit,
        state: &mut PairState,
        bodies: &RigidBodySet,
        colliders: &ColliderSet,
        time_s: f64,
        dt_s: f64,
    ) -> Result<HitOut, LayerError> {
        let mut moving_surface = false;
        let i = h.i as usize;
        let ai = &self.apples[i];
        let n_mat = self.materials.len();
        let (law, j_apple, other_mat, surf_idx) = match h.other {
            Other::Apple(k) => {
                let j = self.grid.pairs()[k].j as usize;
                let m2 = self.apples[j].material;
                (
                    self.laws[ai.material.0 as usize * n_mat + m2.0 as usize],
                    Some(j),
                    m2,
                    None,
                )
            }
            Other::Surface(_, s, _) => {
                let m2 = self.surfaces[s as usize].material;
                (
                    self.laws[ai.material.0 as usize * n_mat + m2.0 as usize],
                    None,
                    m2,
                    Some(s as usize),
                )
            }
        };
        let _ = other_mat;
        let n = h.normal;
        let u = h.overlap;
        let Some(r_star) = contact::normal::effective_radius(1.0 / self.radius[i], h.curvature2)
        else {
            let other = match (j_apple, surf_idx) {
                (Some(j), _) => self.apples[j].name.to_string(),
                (_, Some(s)) => self.surfaces[s].name.to_string(),
                _ => String::new(),
            };
            return Err(LayerError::Conforming {
                apple: ai.name.to_string(),
                surface: other,
                apple_radius_m: self.radius[i],
                surface_radius_m: if h.curvature2 != 0.0 {
                    -1.0 / h.curvature2
                } else {
                    f64::INFINITY
                },
            });
        };
        let c = contact::geometry::contact_point(self.pos[i], self.radius[i], n, u, law.share1);
        let v1 = self.vel[i] + self.angvel[i].cross(c - self.pos[i]);
        let (v2, inv_t2, inv_n2, body2) = match (j_apple, surf_idx) {
            (Some(j), _) => (
                self.vel[j] + self.angvel[j].cross(c - self.pos[j]),
                self.apples[j].inv_tangential_mass,
                1.0 / self.apples[j].mass,
                None,
            ),
            (_, Some(s)) => {
                let surf = &self.surfaces[s];
                let co = colliders.get(surf.collider);
                let parent = co.and_then(|c| c.parent());
                let moving_parent = parent
                    .and_then(|p| bodies.get(p))
                    .is_some_and(|rb| !rb.is_fixed());
                if moving_parent || surf.belt_local != Vec3::ZERO {
                    // An apple on a belt or a moving part must stay awake.
                    moving_surface = true;
                }
                let (vb, inv_m, dyn_body) = match parent.and_then(|p| bodies.get(p).map(|b| (p, b)))
                {
                    Some((p, rb)) if !rb.is_fixed() => {
                        let inv = if rb.is_dynamic() && rb.mass() > 0.0 {
                            1.0 / rb.mass()
                        } else {
                            0.0
                        };
                        (rb.velocity_at_point(c), inv, rb.is_dynamic().then_some(p))
                    }
                    _ => (Vec3::ZERO, 0.0, None),
                };
                let mut belt = Vec3::ZERO;
                if surf.belt_local != Vec3::ZERO {
                    if let Some(co) = co {
                        let b = co.position().rotation * surf.belt_local;
                        belt = b - n * b.dot(n);
                    }
                }
                (vb + belt, inv_m, inv_m, dyn_body)
            }
            _ => unreachable!(),
        };
        let rel = v1 - v2;
        let inv_t = ai.inv_tangential_mass + inv_t2;
        let share_count = match j_apple {
            Some(j) => self.count[i].max(self.count[j]),
            None => self.count[i],
        }
        .max(1) as f64;
        let m_n = 1.0 / (1.0 / ai.mass + inv_n2);
        let kin = ContactKinematics {
            normal: n,
            overlap_m: u,
            r_star_m: r_star,
            rel_velocity: rel,
            tangential_mass_kg: 1.0 / inv_t,
            normal_mass_kg: m_n,
            resting: false,
        };
        let relax = self.config.tangential_relaxation / share_count;
        let parts = self.config.parts;
        let hist_cap = self.config.force_history_cap;
        let guard = self.config.guard;
        let r_min = match j_apple {
            Some(j) => self.radius[i].min(self.radius[j]),
            None => self.radius[i],
        };
        let names = match h.other {
            Other::Apple(k) => {
                let p = &self.grid.pairs()[k];
                self.names_apple(p.i, p.j)
            }
            Other::Surface(a, s, _) => self.names_surface(a, s),
        };
        // Resting once its impact is over: older than 1.2 times eq. 12's contact time at its
        // approach speed, (1 + 1/sqrt(ke)) / 2 elastic contact times (physics.md section 3).
        let k_n = contact::normal::stiffness(law.e_star_pa, r_star);
        let resting = state.open.as_mut().is_some_and(|o| {
            let (t_h, _) = o.impact_scale(|v| impact_scale(m_n, k_n, v));
            let ke = if parts.energy_loss { law.ke } else { 1.0 };
            time_s - o.start_time_s() > 1.2 * t_h * 0.5 * (1.0 + 1.0 / ke.max(1e-4).sqrt())
        });
        let kin = ContactKinematics { resting, ..kin };
        let resp = contact::evaluate(&law, parts, &kin, &mut state.xi, relax, dt_s);
        state.last_force = resp.force_on_1;
        if !(resp.normal_force_n.is_finite() && is_finite(resp.force_on_1)) {
            return Err(LayerError::NonFinite {
                body: names.a.to_string(),
                time_s,
            });
        }
        let ratio = u / r_min;
        if ratio > guard.max_overlap_ratio {
            return Err(LayerError::Unstable {
                a: names.a.to_string(),
                b: names.b.to_string(),
                time_s,
                what: format!(
                    "overlap {:.4} mm is {:.1} % of the radius, beyond the {:.0} % limit (Hertz needs u << R): the bodies pass through each other or the step is far too large",
                    u * 1e3,
                    100.0 * ratio,
                    100.0 * guard.max_overlap_ratio
                ),
                suggested_dt_s: None,
            });
        }
        if state.open.is_none() {
            // Stability guard: the elastic contact time at this approach speed must span enough
            // steps (physics.md section 10).
            let v_app = resp.overlap_rate_m_s;
            if v_app > 0.0 && guard.min_steps_per_impact > 0.0 {
                let m_n = 1.0 / (1.0 / ai.mass + inv_n2);
                let k = contact::normal::stiffness(law.e_star_pa, r_star);
                let t_h = theory::elastic_impact(m_n, v_app, k, r_star).contact_time_s;
                let steps = t_h / dt_s;
                if steps < guard.min_steps_per_impact * (1.0 - 1e-6) {
                    let dt_ok = t_h / guard.min_steps_per_impact;
                    return Err(LayerError::Unstable {
                        a: names.a.to_string(),
                        b: names.b.to_string(),
                        time_s,
                        what: format!(
                            "impact at {v_app:.4} m/s lasts {:.4} ms, only {steps:.1} steps of {dt_s:e} s (need >= {}); use time_step_s <= {dt_ok:.3e}",
                            t_h * 1e3,
                            guard.min_steps_per_impact
                        ),
                        suggested_dt_s: Some(dt_ok),
                    });
                }
            }
            let mut open =
                OpenContact::begin(time_s, self.dt_back, u, resp.overlap_rate_m_s, hist_cap);
            if let (Some(c), None) = (self.config.step_control, j_apple) {
                // Rapier's velocities are staggered half a step behind the poses: at long steps
                // the velocity that carried the apple in is the one of mid-step, not of the touch.
                // Add gravity's share from mid-step to touch (two apples fall alike: no share).
                let since_touch = time_s - open.start_time_s();
                let a_n = -c.gravity.dot(n);
                let v = resp.overlap_rate_m_s + a_n * (0.5 * self.dt_back - since_touch);
                open.set_approach_speed(v.max(0.0));
            }
            state.open = Some(Box::new(open));
        }
        // The backward span of this force's kick (see the leapfrog kick below).
        let kick_back = match (self.config.step_control, state.open.as_ref()) {
            (Some(_), Some(o)) => self.dt_back.min((time_s - o.start_time_s()).max(0.0)),
            _ => self.dt_back,
        };
        let point = c + resp.patch_shift;
        if let Some(open) = state.open.as_mut() {
            open.observe(&ContactSample {
                time_s,
                dt_s,
                dt_back_s: self.dt_back,
                kick_back_s: kick_back,
                overlap_m: u,
                force_n: resp.normal_force_n,
                contact_radius_m: resp.contact_radius_m,
                pressure_pa: resp.mean_pressure_pa,
                point,
            });
        }
        let f = resp.force_on_1;
        // Leapfrog kick with variable steps (see `StepControl::gravity`): the force at this pose
        // stands for the impulse from h_back/2 before to h/2 after it. A contact that began within
        // the last step has pushed only since its touch, so its backward share is its age, not
        // h_back (measured: a 6.8 ms step before a belt landing kicked the first contact force
        // 7.3 times, peak 14 N instead of 22 N).
        let kick = self
            .config
            .step_control
            .map(|_| (kick_back + dt_s) / (2.0 * dt_s));
        let k = contact::normal::stiffness(law.e_star_pa, r_star);
        let party = match (j_apple, surf_idx) {
            (Some(j), _) => Party::Apple(j as u32),
            (_, Some(s)) => Party::Surface(s as u32),
            _ => unreachable!(),
        };
        Ok(HitOut {
            i,
            j: j_apple,
            body2,
            force: f,
            point,
            kick,
            moving_surface,
            elastic_energy_j: contact::normal::elastic_energy(k, u),
            overlap_ratio: ratio,
            party,
            slip_m_s: (rel - n * rel.dot(n)).length(),
            normal_force_n: resp.normal_force_n,
        })
    }

    /// Adds one evaluated contact to the apples' loads (see [`evaluate_hit`](Self::evaluate_hit)).
    fn apply_hit(&mut self, o: &HitOut) {
        let HitOut {
            i,
            j: j_apple,
            body2,
            force: f,
            point,
            kick,
            ..
        } = *o;
        if o.moving_surface {
            self.busy[i] = true;
        }
        if let Some(j) = j_apple {
            // A neighbour that is not still keeps an apple awake.
            if !self.still[j] {
                self.busy[i] = true;
            }
            if !self.still[i] {
                self.busy[j] = true;
            }
        }
        self.force[i] += f;
        self.torque[i] += (point - self.pos[i]).cross(f);
        if let Some(j) = j_apple {
            self.force[j] -= f;
            self.torque[j] += (point - self.pos[j]).cross(-f);
        }
        let load = match kick {
            Some(kick) => {
                let fk = f * kick;
                self.kicked_force[i] += fk;
                self.kicked_torque[i] += (point - self.pos[i]).cross(fk);
                if let Some(j) = j_apple {
                    self.kicked_force[j] -= fk;
                    self.kicked_torque[j] += (point - self.pos[j]).cross(-fk);
                }
                -fk
            }
            None => -f,
        };
        if let Some(b) = body2 {
            self.body_loads.push((b, load, point));
        }
        self.stats.elastic_energy_j += o.elastic_energy_j;
        self.stats.max_overlap_ratio = self.stats.max_overlap_ratio.max(o.overlap_ratio);
        if self.config.record_slips {
            let sample = SlipSample {
                apple: i as u32,
                other: o.party,
                slip_m_s: o.slip_m_s,
                normal_force_n: o.normal_force_n,
                point,
            };
            self.slips.push(sample);
            if let Some(j) = j_apple {
                self.slips.push(SlipSample {
                    apple: j as u32,
                    other: Party::Apple(i as u32),
                    ..sample
                });
            }
        }
    }

    /// The state of the contact a hit belongs to.
    fn state_of(&mut self, h: &Hit) -> &mut PairState {
        match h.other {
            Other::Apple(k) => &mut self.grid.pairs_mut()[k].state,
            Other::Surface(a, s, slot) => {
                &mut self
                    .surface_slots
                    .get_mut(&(a, s))
                    .expect("slot exists for a surface hit")[slot]
                    .state
            }
        }
    }

    /// The force pass: every hit evaluated (in parallel on rayon's current pool when there are
    /// enough of them), then applied in the order of `hits`.
    fn force_pass(
        &mut self,
        hits: &[Hit],
        bodies: &RigidBodySet,
        colliders: &ColliderSet,
        time_s: f64,
        dt_s: f64,
    ) -> Result<(), LayerError> {
        self.slips.clear();
        // Each contact's state is moved out for the evaluation, so the layer itself is only read.
        let mut states = std::mem::take(&mut self.states_buf);
        states.clear();
        for h in hits {
            states.push(std::mem::take(self.state_of(h)));
        }
        let mut outs = std::mem::take(&mut self.outs_buf);
        outs.clear();
        let parallel = hits.len() >= PARALLEL_MIN_HITS && rayon::current_num_threads() > 1;
        {
            let this = &*self;
            let eval = |(h, st): (&Hit, &mut PairState)| {
                this.evaluate_hit(h, st, bodies, colliders, time_s, dt_s)
            };
            if parallel {
                use rayon::prelude::*;
                hits.par_iter()
                    .zip(states.par_iter_mut())
                    .with_min_len(64)
                    .map(eval)
                    .collect_into_vec(&mut outs);
            } else {
                outs.extend(hits.iter().zip(states.iter_mut()).map(eval));
            }
        }
        for (h, st) in hits.iter().zip(states.drain(..)) {
            *self.state_of(h) = st;
        }
        self.states_buf = states;
        let mut result = Ok(());
        for o in outs.drain(..) {
            match o {
                Ok(o) => self.apply_hit(&o),
                Err(e) => {
                    result = Err(e);
                    break;
                }
            }
        }
        self.outs_buf = outs;
        result
    }
}

/// Time until a gap closes, if within `horizon` (s): the smallest h > 0 with
/// (closing + accel h) h >= gap. Rapier's symplectic Euler moves a body by its kicked velocity
/// v + a h over the whole step, so a step planned from the current closing speed alone overshoots
/// the touch (measured: a 6.9 ms step onto a belt started the contact at half its peak overlap).
fn time_to_touch(gap: f64, closing: f64, accel: f64, horizon: f64) -> Option<f64> {
    let gap = gap.max(0.0);
    if (closing + accel * horizon) * horizon < gap {
        return None;
    }
    // Stable root of accel h^2 + closing h - gap = 0 (accel >= 0; the test above guarantees a
    // root in (0, horizon]).
    let disc = (closing * closing + 4.0 * accel * gap).sqrt();
    let h = if closing >= 0.0 {
        2.0 * gap / (closing + disc)
    } else {
        (disc - closing) / (2.0 * accel)
    };
    (h.is_finite() && closing + accel * h > 0.0).then_some(h)
}

/// Elastic contact time and maximum overlap of an impact at approach speed `v` (zeros for v <= 0).
fn impact_scale(m_n: f64, k: f64, v: f64) -> (f64, f64) {
    if v > 0.0 {
        let u = (5.0 * m_n * v * v / (4.0 * k)).powf(0.4);
        (2.0 * theory::HERTZ_TIME_INTEGRAL * u / v, u)
    } else {
        (0.0, 0.0)
    }
}

/// With step control: the longest step that resolves a contact in progress (see
/// [`StepControl`]). `u` overlap, `impact` = (contact time, max overlap) of its impact at the
/// approach speed (see [`impact_scale`]), `rate` current du/dt (> 0 approaching), `unloading_ke`
/// the eq. 12 ke of the pair (1 when elastic), `age` time since first touch. An impact (younger
/// than 1.2 times eq. 12's contact time, (1 + 1/sqrt(ke)) / 2 elastic ones) gets N steps per
/// contact time of an impact reaching max(u, u_max), and while it separates N steps per contact
/// time of its softer unloading curve (ke k); a resting contact after that gets
/// N/4 (at least 4) per contact time at max(u, u_max(s)): its normal oscillation, which needs
/// resolving only for stability (omega dt = 4 / steps; explicit stepping is stable below 2).
#[allow(clippy::too_many_arguments)]
fn contact_step_limit(
    c: &StepControl,
    m_n: f64,
    k: f64,
    u: f64,
    impact: (f64, f64),
    rate: f64,
    unloading_ke: f64,
    age: f64,
) -> (f64, StepLimit) {
    let (t_a, u_a) = impact;
    let s = rate.abs();
    // An impact lasts (1 + 1/sqrt(ke)) / 2 elastic contact times with eq. 12 (physics.md section
    // 3); 20 % more covers the lower speeds' longer contacts.
    let window = 1.2 * t_a * 0.5 * (1.0 + 1.0 / unloading_ke.max(1e-4).sqrt());
    if age < window {
        let mut t = if u > u_a {
            theory::contact_time_at_overlap(m_n, k, u)
        } else {
            t_a
        };
        if rate < 0.0 && unloading_ke < 1.0 {
            // Separating: eq. 12 unloads along ke times the Hertz curve, a contact of stiffness
            // ke k, whose time scale is 1 / sqrt(ke) longer; N steps of that scale resolve it.
            t /= unloading_ke.max(1e-4).sqrt();
        }
        return (t / c.steps_per_contact, StepLimit::Impact);
    }
    // u_max(s) > u  <=>  5 m s^2 / (4 k) > u^(5/2): compared without powers.
    let u_eff = if 1.25 * m_n * s * s / k > u * u * u.sqrt() {
        impact_scale(m_n, k, s).1
    } else {
        u
    };
    (
        theory::contact_time_at_overlap(m_n, k, u_eff) / (0.25 * c.steps_per_contact).max(4.0),
        StepLimit::Resting,
    )
}

fn party_key(p: Party) -> (u8, u32) {
    match p {
        Party::Apple(j) => (0, j),
        Party::Surface(s) => (1, s),
    }
}

fn surface_point_velocity(
    bodies: &RigidBodySet,
    colliders: &ColliderSet,
    collider: ColliderHandle,
    point: Vec3,
) -> Vec3 {
    colliders
        .get(collider)
        .and_then(|c| c.parent())
        .and_then(|p| bodies.get(p))
        .map(|rb| rb.velocity_at_point(point))
        .unwrap_or(Vec3::ZERO)
}
