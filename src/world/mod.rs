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
//! rapier would spend a sixth of its step computing it. A spheroidal apple (issue 29) has two
//! moments, so its body has them on ([`World::add_apple`]).

pub mod free_roller;
pub mod mesh;
pub mod motion;
pub mod roster;
mod surface_specs;
pub mod surfaces;
pub mod zones;

use crate::contact::Material;
use crate::contact::{LawParts, SubModels};
use crate::layer::stage_clock::{Clock, Stage};
use crate::layer::{
    AppleId, BodyRef, BodySets, Coefficients, ContactLayer, Guard, LayerConfig, LayerError,
    MaterialId, SleepConfig, StepControl, StepRequest, SurfaceId,
};
use crate::math::{vec3, Vec3};
use crate::scenario::{self, AppleSpec, ContactModel, Fidelity, Scenario, ScenarioError, TimeStep};
use rapier3d_f64::math::Pose;
use rapier3d_f64::prelude::*;
pub use roster::{apple_mass, sphere_mass, Origin, Roster, RosterApple};
use serde::Serialize;
use std::collections::{BTreeMap, VecDeque};
use std::path::Path;
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
    /// rapier's sets, pipeline and parameters: the surfaces' bodies and colliders, and the apples
    /// of body set 0.
    pub physics: PhysicsWorld,
    /// Apple sets: worlds of collider-less apples only, stepped concurrently with `physics` (see
    /// [`World::advance`] and [`crate::layer::BodySets`]). Empty on one thread.
    apple_sets: Vec<PhysicsWorld>,
    /// The apples the scene starts with (the split's plan; see [`Self::split_apples`]).
    initial_apples: usize,
    /// The contact layer.
    pub layer: ContactLayer,
    /// Rigid body of each apple (its set and handle), in layer order (listed, generated, then fed
    /// in). Read a body with [`World::apple_body`].
    pub apple_bodies: Vec<BodyRef>,
    /// Every apple in the world, in layer order: name, material, radius, mass, origin.
    pub roster: Roster,
    /// Collider of each surface part, in layer order.
    pub surface_colliders: Vec<ColliderHandle>,
    /// Frame of each surface part in which positions along it are measured, if it has a running
    /// direction ([`surfaces::SurfacePart::along`]).
    pub surface_frames: Vec<Option<rapier3d_f64::math::Pose>>,
    /// Whether apples carry ball colliders (only when rapier itself must touch them).
    apple_colliders: bool,
    /// The bins' inner boxes, in scenario order (where apples end and when they entered).
    pub bins: Vec<BinBox>,
    /// The kinematic body of each moving surface spec, its motion, and its free roller's index
    /// in `free_rollers` if it turns freely.
    movers: Vec<(RigidBodyHandle, motion::Motion, Option<usize>)>,
    /// The free-turning rollers: the one owner of their spin ([`free_roller`]).
    free_rollers: Vec<free_roller::FreeRoller>,
    /// Largest speed of any moving part's surface over its profile (m/s).
    moving_speed_m_s: f64,
    /// Time of the current poses (s), set by the driver ([`World::set_time`]).
    time_s: f64,
    materials: BTreeMap<String, (MaterialId, Material)>,
    /// Emissions still to come, in order of planned time.
    pending: VecDeque<Feed>,
    /// What each source fed in so far and what held it up (in scenario order).
    feeds: Vec<SourceFeed>,
    /// Per apple, where it left the scene if it was taken out of the run.
    taken_out: Vec<Option<Vec3>>,
    /// Each source's motion (scenario order), `None` for a fixed source.
    source_motions: Vec<Option<motion::Motion>>,
    /// Per apple (layer order), when and where it was fed in, if a source fed it.
    fed_entries: Vec<Option<FedEntry>>,
}

/// When and where a source fed an apple in: `summary.json` `apples[].fed` (issue 31). A moving
/// source's apple appears where the source is at that time, with its velocity added; one that
/// waited for its spot appears later than planned, where the source is then.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FedEntry {
    /// The source's name.
    pub source: String,
    /// Planned time of entry (s): `start_s + k / rate_per_s`.
    pub planned_s: f64,
    /// Time it entered (s): later than planned if it waited for its spot.
    pub time_s: f64,
    /// Its centre when it entered (m).
    pub position_m: [f64; 3],
    /// Its velocity when it entered (m/s): the source's `velocity_m_s` (turned with the source)
    /// plus the source's own velocity at that point.
    pub velocity_m_s: [f64; 3],
}

/// The inside of a bin: where an apple counts as in it (its centre inside the box bounded by
/// the floor's top face and the walls' inner faces, up to the walls' height).
#[derive(Debug, Clone, PartialEq)]
pub struct BinBox {
    /// The bin's name (its walls are `NAME/floor`, `NAME/x_min`, ...).
    pub name: String,
    /// Centre of the floor's top face, and the bin's orientation.
    pub frame: Pose,
    /// Inside length (x), width (y) and wall height (z) (m).
    pub inner_size_m: [f64; 3],
    /// The motion that carries the bin, if it moves (a bin filler lowers it): `frame` is its
    /// pose at t = 0 with every offset zero.
    pub motion: Option<motion::Motion>,
}

impl BinBox {
    /// The bin's frame at time `t_s` (where its motion has it then).
    pub fn frame_at(&self, t_s: f64) -> Pose {
        match &self.motion {
            Some(m) => m.carry(t_s) * self.frame,
            None => self.frame,
        }
    }

    /// A point in the bin's frame at time `t_s`: x, y from the floor's centre, z up from the
    /// floor's top face.
    pub fn local(&self, p: Vec3, t_s: f64) -> Vec3 {
        self.frame_at(t_s).inverse_transform_point(p)
    }

    /// Whether the point `p` (an apple's centre) is inside the bin at time `t_s`.
    pub fn contains(&self, p: Vec3, t_s: f64) -> bool {
        let q = self.local(p, t_s);
        let [lx, ly, h] = self.inner_size_m;
        q.x.abs() <= lx / 2.0 && q.y.abs() <= ly / 2.0 && q.z >= 0.0 && q.z <= h
    }
}

/// One planned emission of a source.
#[derive(Debug, Clone)]
struct Feed {
    /// Planned time (s).
    time_s: f64,
    /// Index in `sources`.
    source: usize,
    apple: AppleSpec,
    /// What first held it up (`apple 'feed-3'`), if its spot was taken when it was due.
    blocker: Option<String>,
}

/// What a source fed in and what held it up: the `sources` section of `summary.json`.
///
/// An apple whose spot is taken when its time comes waits (and the source's later apples wait
/// behind it, so that the order of the feed is kept); the waiting is counted in apples and
/// seconds, with what took the spot, because a line designer reads it as "the feed is faster
/// than the line clears it".
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct SourceFeed {
    /// The source's name.
    pub name: String,
    /// Apples it was to feed (`count`).
    pub count: usize,
    /// Apples fed in.
    pub fed: usize,
    /// Apples whose time had not come when the run ended (never fed in).
    pub not_due: usize,
    /// Apples due but still waiting for their spot at the end (never fed in).
    pub still_waiting: usize,
    /// Apples that waited for their spot (fed in late, or still waiting at the end).
    pub waited: usize,
    /// Their waits together (s): entry (or the end) less planned time.
    pub wait_total_s: f64,
    /// The longest wait (s).
    pub wait_longest_s: f64,
    /// What took the spot, with the apples each held up, most first.
    pub blocked_by: Vec<Blocker>,
}

/// Something that took a source's spot.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Blocker {
    /// `apple 'NAME'` or `surface 'NAME'`.
    pub what: String,
    /// Apples of the source it held up.
    pub apples: usize,
}

impl SourceFeed {
    /// Counts one apple's wait of `wait_s` caused by `blocker`.
    fn count_wait(&mut self, wait_s: f64, blocker: &str) {
        self.waited += 1;
        self.wait_total_s += wait_s;
        self.wait_longest_s = self.wait_longest_s.max(wait_s);
        match self.blocked_by.iter_mut().find(|b| b.what == blocker) {
            Some(b) => b.apples += 1,
            None => self.blocked_by.push(Blocker {
                what: blocker.to_string(),
                apples: 1,
            }),
        }
    }
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
            twisting: c.twisting.model(),
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
    let rule = sl.rule(sc.accuracy);
    // Adaptive steps: the layer chooses each step (rigid fidelity: rapier's own contacts, a
    // fixed step). No apple may cross half of rapier's prediction distance in one step.
    let step_control = (sc.time_step_s == TimeStep::Adaptive && !rigid).then(|| StepControl {
        steps_per_contact: sc.steps_per_contact(),
        max_displacement_m: 0.5 * ip.prediction_distance(),
    });
    let config = LayerConfig {
        force_history_cap: if sc.force_history().is_kept() {
            FORCE_HISTORY_CAP
        } else {
            0
        },
        force_history_span: match sc.force_history() {
            crate::scenario::ForceHistory::Full => crate::record::events::HistorySpan::Whole,
            _ => crate::record::events::HistorySpan::Impact,
        },
        history_dashpot_bound: sc.model.history_dashpot_bound,
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
            carried: sl.carried,
            speed_m_s: rule.speed_m_s,
            time_s: rule.time_s,
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
        apple_sets: Vec::new(),
        initial_apples: 0,
        layer,
        apple_bodies: Vec::new(),
        roster: Roster::default(),
        surface_colliders: Vec::new(),
        surface_frames: Vec::new(),
        bins: bins(sc)?,
        materials,
        pending: VecDeque::new(),
        feeds: sc
            .sources
            .iter()
            .map(|s| SourceFeed {
                name: s.name.clone(),
                count: s.count as usize,
                ..SourceFeed::default()
            })
            .collect(),
        taken_out: Vec::new(),
        source_motions: sc
            .sources
            .iter()
            .map(|s| motion::Motion::of_source(s.motion.as_ref()))
            .collect(),
        fed_entries: Vec::new(),
        movers: Vec::new(),
        free_rollers: Vec::new(),
        moving_speed_m_s: 0.0,
        time_s: 0.0,
        apple_colliders: rigid
            || sc
                .surfaces
                .iter()
                .any(|s| s.contact_model() == ContactModel::Rigid),
    };

    world.add_surface_specs(sc, base_dir)?;
    // A bin moves with its floor's body.
    for b in 0..world.bins.len() {
        let floor = format!("{}/floor", world.bins[b].name);
        let k = (0..world.surface_colliders.len())
            .find(|&k| world.layer.surface_name(SurfaceId(k as u32)) == floor);
        world.bins[b].motion = k
            .and_then(|k| world.surface_motion(k))
            .map(|(m, _)| m.clone());
    }
    let plan = roster::plan(sc)?;
    world.split_apples(
        plan.initial.len(),
        plan.feeds.len(),
        rayon::current_num_threads(),
    );
    for (a, origin) in &plan.initial {
        world.add_apple(a, *origin)?;
    }
    world.layer.check_conformity()?;
    check_initial_surface_overlaps(sc, &plan.initial, &world)?;
    world.pending = plan
        .feeds
        .into_iter()
        .map(|(time_s, source, apple)| Feed {
            time_s,
            source,
            apple,
            blocker: None,
        })
        .collect();
    check_spawn_points(sc, &world)?;

    // Apples with colliders (rapier's own contact with rigid surfaces): a step of length zero runs
    // rapier's collision detection only, so the rigid contacts touching at t = 0 are known before
    // the first step. The layer needs none of it: it finds its contacts itself.
    if world.apple_colliders {
        world.refresh_pairs();
    }
    Ok(world)
}

/// The rigid-body set `set` of a world (0: rapier's own; see [`BodyRef`]).
fn body_set<'a>(
    physics: &'a PhysicsWorld,
    apple_sets: &'a [PhysicsWorld],
    set: u32,
) -> &'a RigidBodySet {
    match set {
        0 => &physics.bodies,
        s => &apple_sets[s as usize - 1].bodies,
    }
}

/// The fewest apples in a scene for its apples to be split over body sets. Chosen equal to the
/// neighbour scan's parallel threshold, not measured on its own: a small scene gains little from
/// a second set and pays a fork and join per step (docs/performance.md, "Two threads: rapier's
/// step split over body sets").
pub const APPLE_SETS_MIN_APPLES: usize = 256;

/// The fewest awake apples (rapier's active bodies: sleepers and riders are not) for the body
/// sets to be stepped concurrently; below, one after the other. A region costs the pool's wake-up
/// (15-21 us on the 2-core VM, docs/performance.md) and rapier's step of ~100 bodies costs less:
/// measured on the 1000-apple line's middle window (about 120 awake, 900 riding), two threads
/// were slower than one there before. The same figure as the other regions' thresholds.
pub const APPLE_SETS_PARALLEL_MIN_AWAKE: usize = 256;

/// Fed apples per run of one body set (see [`World::split_apples`]): a few cache lines of each
/// of the layer's per-apple arrays. Not tuned.
pub const FED_RUN: usize = 64;

impl World {
    /// Spreads the apples to come over `threads` body sets (rapier's own and `threads - 1`
    /// apple sets) in runs of consecutive apple indices: the `initial` apples in one run per set
    /// (the first `initial / threads` in set 0, and so on), the `fed` ones in runs of
    /// [`FED_RUN`] dealt in turn (the apples in a line at one time are a window of the fed
    /// ones). This when the scene has at least [`APPLE_SETS_MIN_APPLES`] apples in all, more
    /// than one thread, and no apple needs a collider (rapier's own contact with a rigid surface
    /// is in rapier's own set). Which set an apple is in changes no bit of any result
    /// ([`crate::layer::BodySets`]).
    pub fn split_apples(&mut self, initial: usize, fed: usize, threads: usize) {
        self.initial_apples = initial;
        let apples = initial + fed;
        let sets = if apples >= APPLE_SETS_MIN_APPLES && !self.apple_colliders {
            threads.max(1)
        } else {
            1
        };
        self.apple_sets = (1..sets)
            .map(|_| {
                let mut w = PhysicsWorld::new();
                w.gravity = self.physics.gravity;
                w.integration_parameters = self.physics.integration_parameters;
                w
            })
            .collect();
    }

    /// How many body sets hold apples (1: rapier's own only).
    pub fn body_set_count(&self) -> usize {
        1 + self.apple_sets.len()
    }

    /// The set the next apple goes into: consecutive apples share a set. A thread then reads,
    /// examines and hands forces to mostly the apples it stepped (the frame's arrays, the pair
    /// list and the contacts are in apple order), not every other apple of the other thread's
    /// cache (docs/performance.md, "Two threads: the serial stages", item 3).
    fn next_apple_set(&self) -> u32 {
        let sets = self.body_set_count();
        let (k, initial) = (self.apple_bodies.len(), self.initial_apples);
        let set = if k < initial {
            k * sets / initial
        } else {
            (k - initial) / FED_RUN % sets
        };
        set as u32
    }

    /// The rigid-body set `set` (0: rapier's own; see [`BodyRef`]).
    fn body_set_mut(&mut self, set: u32) -> &mut RigidBodySet {
        match set {
            0 => &mut self.physics.bodies,
            s => &mut self.apple_sets[s as usize - 1].bodies,
        }
    }

    /// Apple `k`'s rigid body (layer order).
    pub fn apple_body(&self, k: usize) -> &RigidBody {
        let r = self.apple_bodies[k];
        &body_set(&self.physics, &self.apple_sets, r.set)[r.handle]
    }

    /// Apple `k`'s rigid body, mutably (rapier marks it modified).
    pub fn apple_body_mut(&mut self, k: usize) -> Option<&mut RigidBody> {
        let r = self.apple_bodies[k];
        self.body_set_mut(r.set).get_mut(r.handle)
    }

    /// The layer's force pass at the current poses ([`ContactLayer::step_in`]) over every body
    /// set: returns the step to take, for [`World::advance`].
    pub fn force_pass(&mut self, request: &StepRequest) -> Result<f64, LayerError> {
        let sets = BodySets {
            main: &mut self.physics.bodies,
            islands: &self.physics.islands,
            apple_sets: &mut self.apple_sets,
        };
        self.layer.step_in(sets, &self.physics.colliders, request)
    }

    /// The name of a body that rapier quarantined (its state went non-finite) in any set: an
    /// apple's name, or rapier's handle of another body.
    pub fn quarantined(&self) -> Option<String> {
        let sets = std::iter::once(&self.physics).chain(&self.apple_sets);
        for (s, w) in sets.enumerate() {
            if let Some(&handle) = w.quarantine().bodies().first() {
                let r = BodyRef {
                    set: s as u32,
                    handle,
                };
                return Some(
                    self.apple_bodies
                        .iter()
                        .position(|&b| b == r)
                        .map(|k| self.layer.apple_name(AppleId(k as u32)).to_string())
                        .unwrap_or_else(|| format!("{handle:?}")),
                );
            }
        }
        None
    }

    /// Advances rapier by `dt_s`: the step the layer answered the force pass with (the forces it
    /// set are for that step). The step is set here, every step; the world has no step of its
    /// own.
    pub fn advance(&mut self, dt_s: f64) {
        if dt_s > 0.0 {
            // Each moving part to its pose at the end of the step: rapier moves it there and
            // gives it the velocity that does so.
            let t = self.time_s + dt_s;
            for (b, m, free) in &self.movers {
                let Some(rb) = self.physics.bodies.get_mut(*b) else {
                    continue;
                };
                let pose = match free {
                    Some(k) => {
                        // Its spin from the torques of the force pass just done.
                        let f = &mut self.free_rollers[*k];
                        let torque = f.torque_n_m(self.layer.surface_reactions(), rb.translation());
                        f.turn(torque, dt_s);
                        m.pose_spun(t, f.angle_rad())
                    }
                    None => m.pose(t),
                };
                rb.set_next_kinematic_position(pose);
            }
        }
        self.physics.integration_parameters.dt = dt_s;
        let hooks = self.layer.hooks();
        let timer = Clock::start();
        if self.apple_sets.is_empty() {
            self.physics.step_with_events(hooks, &());
            timer.stop(Stage::Rapier);
            return;
        }
        // The apple sets in step with rapier's own world, each on rayon's pool: they hold only
        // collider-less apples, which touch nothing in rapier.
        for w in &mut self.apple_sets {
            w.integration_parameters = self.physics.integration_parameters;
            w.gravity = self.physics.gravity;
        }
        let (main, sets) = (&mut self.physics, &mut self.apple_sets);
        if self.layer.awake_count() >= APPLE_SETS_PARALLEL_MIN_AWAKE {
            rayon::join(
                || main.step_with_events(hooks, &()),
                || {
                    use rayon::prelude::*;
                    sets.par_iter_mut()
                        .for_each(|w| w.step_with_events(&(), &()));
                },
            );
        } else {
            // Few bodies to integrate (a line whose apples mostly ride or sleep): the sets one
            // after the other, the same bits, without a region's wake-up.
            main.step_with_events(hooks, &());
            for w in sets.iter_mut() {
                w.step_with_events(&(), &());
            }
        }
        timer.stop(Stage::Rapier);
    }

    /// The motion of the body that carries surface part `k` (layer order), and the part's pose
    /// on that body, if the part moves: its pose at time t is `motion.pose(t) * on_body`. The
    /// ParaView output draws moving parts from it ([`crate::output::vtk`]).
    pub fn surface_motion(&self, k: usize) -> Option<(&motion::Motion, Pose)> {
        let co = self
            .physics
            .colliders
            .get(*self.surface_colliders.get(k)?)?;
        let body = co.parent()?;
        let on_body = *co.position_wrt_parent()?;
        let (_, m, _) = self.movers.iter().find(|(b, _, _)| *b == body)?;
        Some((m, on_body))
    }

    /// The free-turning rollers' rates and angles now.
    pub fn free_rollers(&self) -> Vec<free_roller::FreeRollerState> {
        self.free_rollers.iter().map(|f| f.state()).collect()
    }

    /// The first free-turning roller whose spin ran away, if one did
    /// ([`free_roller::FreeRoller::runaway`]).
    pub fn runaway_roller(&self) -> Option<free_roller::RollerRunaway> {
        self.free_rollers.iter().find_map(|f| f.runaway())
    }

    /// Whether the scene has a free-turning roller (then the run writes `rollers.csv`).
    pub fn has_free_rollers(&self) -> bool {
        !self.free_rollers.is_empty()
    }

    /// The free-turning rollers' spins now, into `out` (cleared first; scenario order): what
    /// the driver copies at each output sample ([`free_roller::RollerSample`]).
    pub fn sample_free_rollers(&self, out: &mut Vec<free_roller::RollerSample>) {
        out.clear();
        out.extend(self.free_rollers.iter().map(|f| f.sample()));
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

    /// Whether the run has spheroidal apples: in the world now, or among the feeds to come.
    pub fn has_spheroids(&self) -> bool {
        self.layer.has_spheroids() || self.pending.iter().any(|f| f.apple.is_spheroid())
    }

    /// Runs rapier's collision detection without moving anything (a step of length zero).
    pub fn refresh_pairs(&mut self) {
        let dt = self.physics.integration_parameters.dt;
        self.advance(0.0);
        self.physics.integration_parameters.dt = dt;
    }

    /// Inserts an apple (a dynamic body, a ball or a spheroid), registers it with the layer and
    /// enters it in the roster.
    ///
    /// A spheroid (a height other than its diameter, issue 29) is a body with the spheroid's
    /// principal inertia about its own axes and gyroscopic forces on (w x I w is not zero for
    /// unequal moments), registered with [`ContactLayer::add_spheroid_body`]; a sphere takes
    /// the sphere's code unchanged. A `rotation` turns either from the start (a sphere's turn
    /// moves only what is marked on it: the damage sites of issue 26).
    pub fn add_apple(&mut self, a: &AppleSpec, origin: Origin) -> Result<AppleId, BuildError> {
        let (mid, m) = self.materials[&a.material];
        let entry = roster::entry(a, m.density_kg_m3, origin);
        let (mass, radius) = (entry.mass_kg, entry.radius_m);
        let field = origin.field();
        let mut body = RigidBodyBuilder::dynamic()
            .translation(vec3(a.position_m))
            .linvel(vec3(a.velocity_m_s))
            .angvel(vec3(a.angular_velocity_rad_s))
            .gyroscopic_forces_enabled(false)
            // The layer decides when an apple sleeps (rapier's own rule is too coarse).
            .can_sleep(false);
        if a.rotation.is_some() {
            // The whole pose, not `rotation` (a scaled axis that would round the quaternion).
            body = body.pose(Pose::from_parts(vec3(a.position_m), a.orientation(&field)?));
        }
        if a.is_spheroid() {
            if self.apple_colliders {
                // Validation refuses this first (`spheroids_with_balls`); a library caller
                // that skipped it is told here.
                return Err(ScenarioError::invalid(
                    format!("{field}.height_m"),
                    format!(
                        "apple '{}' is a spheroid, and this scene gives apples rapier's ball colliders (the rigid fidelity or a rigid surface): rapier has no spheroid shape",
                        a.name
                    ),
                )
                .into());
            }
            let shape = a.spheroid();
            let (ieq, iax) = shape.principal_inertia(mass);
            let set = self.next_apple_set();
            let bodies = self.body_set_mut(set);
            let handle = bodies.insert(
                body.gyroscopic_forces_enabled(true)
                    .additional_mass_properties(MassProperties::new(
                        Vector::ZERO,
                        mass,
                        Vector::new(ieq, ieq, iax),
                    )),
            );
            let r = BodyRef { set, handle };
            self.apple_bodies.push(r);
            let bodies = body_set(&self.physics, &self.apple_sets, set);
            let id = self
                .layer
                .add_spheroid_body(bodies, r, shape, mid, &a.name)?;
            self.roster.push(entry);
            return Ok(id);
        }
        let id = if self.apple_colliders {
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
            self.apple_bodies.push(bh.into());
            self.layer
                .add_apple(&mut self.physics.colliders, ch, mid, &a.name)?
        } else {
            let inertia = 0.4 * mass * radius * radius;
            let set = self.next_apple_set();
            let handle = self
                .body_set_mut(set)
                .insert(body.additional_mass_properties(MassProperties::new(
                    Vector::ZERO,
                    mass,
                    Vector::splat(inertia),
                )));
            let r = BodyRef { set, handle };
            self.apple_bodies.push(r);
            let bodies = body_set(&self.physics, &self.apple_sets, set);
            self.layer.add_apple_body(bodies, r, radius, mid, &a.name)?
        };
        self.roster.push(entry);
        Ok(id)
    }

    /// Feeds in the apples of sources whose time has come (at time `t`). An apple whose spot is
    /// still taken waits for it to clear (it and the ones after it from the same source are
    /// postponed, in order); what took the spot is remembered for the report. Returns how many
    /// appeared.
    pub fn emit_due(&mut self, t: f64) -> Result<usize, BuildError> {
        let mut emitted = 0;
        // Sources held up in this call, with what holds them.
        let mut blocked: Vec<(usize, String)> = Vec::new();
        let mut kept = VecDeque::new();
        while let Some(front) = self.pending.front() {
            if front.time_s > t + 1e-12 {
                break;
            }
            let mut f = self.pending.pop_front().expect("front exists");
            // Where the source puts it now (a moving source has moved on while it waited).
            let apple = self.placed(&f, t);
            let held = match blocked.iter().find(|(s, _)| *s == f.source) {
                Some((_, by)) => Some(by.clone()),
                None => self.spot_taken_by(&apple).inspect(|by| {
                    blocked.push((f.source, by.clone()));
                }),
            };
            if let Some(by) = held {
                f.blocker.get_or_insert(by);
                kept.push_back(f);
                continue;
            }
            let id = self.add_apple(
                &apple,
                Origin::Fed {
                    source: f.source,
                    time_s: f.time_s,
                },
            )?;
            let k = id.0 as usize;
            if self.fed_entries.len() <= k {
                self.fed_entries.resize(k + 1, None);
            }
            self.fed_entries[k] = Some(FedEntry {
                source: self.feeds[f.source].name.clone(),
                planned_s: f.time_s,
                time_s: t,
                position_m: apple.position_m,
                velocity_m_s: apple.velocity_m_s,
            });
            let feed = &mut self.feeds[f.source];
            feed.fed += 1;
            if let Some(by) = &f.blocker {
                feed.count_wait(t - f.time_s, by);
            }
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

    /// What each source fed in and what held it up, for a run that ended at `end_s`: the apples
    /// still pending are counted as still waiting (their spot was taken when they were due) or
    /// not due (their time had not come).
    pub fn source_feeds(&self, end_s: f64) -> Vec<SourceFeed> {
        let mut out = self.feeds.clone();
        for f in &self.pending {
            let feed = &mut out[f.source];
            match &f.blocker {
                Some(by) => {
                    feed.still_waiting += 1;
                    feed.count_wait((end_s - f.time_s).max(0.0), by);
                }
                None => feed.not_due += 1,
            }
        }
        for feed in &mut out {
            // Most apples held up first; ties in order of appearance (a stable sort).
            feed.blocked_by.sort_by_key(|b| std::cmp::Reverse(b.apples));
        }
        out
    }

    /// The first planned emission after time `t_s` (an adaptive run's steps land on it, so that
    /// an apple appears at its planned time, not up to a step later); `None` when none is left.
    /// Emissions held up by a taken spot (due already) wait at the front of the queue, which is
    /// in time order after them.
    pub fn next_emission_after(&self, t_s: f64) -> Option<f64> {
        self.pending
            .iter()
            .map(|f| f.time_s)
            .find(|&e| e > t_s + 1e-12)
    }

    /// Emissions still to come.
    pub fn pending_emissions(&self) -> usize {
        self.pending.len()
    }

    /// When and where apple `k` (layer order) was fed in, if a source fed it.
    pub fn fed_entry(&self, k: usize) -> Option<&FedEntry> {
        self.fed_entries.get(k).and_then(Option::as_ref)
    }

    /// The motion of source `k` (scenario order), if it moves.
    pub fn source_motion(&self, k: usize) -> Option<&motion::Motion> {
        self.source_motions.get(k).and_then(Option::as_ref)
    }

    /// A planned apple as its source puts it at time `t_s`: where the source's motion carries
    /// its spot then, with the source's velocity there added ([`motion::Motion::spawn`]); as
    /// planned for a fixed source.
    fn placed(&self, f: &Feed, t_s: f64) -> AppleSpec {
        place(self.source_motion(f.source), &f.apple, t_s)
    }

    /// The highest point along `up` a moving source's planned apples appear at (their centres
    /// at their planned times), and the fastest of them (m/s): `None` without a moving source.
    /// The step planner's speed bound takes them (`sim::timestep::speed_bound`).
    pub fn moving_feed_bounds(&self, up: Vec3) -> Option<(f64, f64)> {
        self.pending
            .iter()
            .filter(|f| self.source_motion(f.source).is_some())
            .map(|f| {
                let a = self.placed(f, f.time_s);
                (up.dot(vec3(a.position_m)), vec3(a.velocity_m_s).length())
            })
            .reduce(|a, b| (a.0.max(b.0), a.1.max(b.1)))
    }

    /// The point that stands to surface part `s` as it is now (its collider's pose) as `p`
    /// stands to it at time `t_s`: `p` itself for a fixed part, `p` carried back by the part's
    /// motion from `t_s` to the current time for a moving one (a roller's own turn is left out:
    /// it is round). Overlaps with a part at any time are so found without moving it.
    fn at_part_now(&self, s: usize, p: Vec3, t_s: f64) -> Vec3 {
        match self.surface_motion(s) {
            Some((m, _)) => {
                let back = m.pose_spun(self.time_s, 0.0) * m.pose_spun(t_s, 0.0).inverse();
                back.transform_point(p)
            }
            None => p,
        }
    }

    /// Whether surface part `s` moves (it rides a body with a motion).
    fn part_moves(&self, s: usize) -> bool {
        self.surface_motion(s).is_some()
    }

    /// What takes the spot of a due apple: another apple it would overlap, or a surface it would
    /// sink into deeper than an apple may be placed ([`MAX_INITIAL_SURFACE_OVERLAP_RATIO`]; a
    /// static surface cannot, the spawn points were checked when the world was built, but a
    /// library user may move one).
    ///
    /// A spheroid takes its bounding ball here (its orientation is random, and the spawn points
    /// were checked with the bounding ball of the source's largest apple).
    fn spot_taken_by(&self, a: &AppleSpec) -> Option<String> {
        let p = vec3(a.position_m);
        let r = a.bounding_radius_m();
        for k in 0..self.apple_bodies.len() {
            let id = AppleId(k as u32);
            // A rider sleeps in rapier where it began to ride: the layer carries it.
            let q = match self.layer.rider_motion(id, self.time_s) {
                Some((c, _)) => c,
                None => self.apple_body(k).translation(),
            };
            if (q - p).length() < r + self.layer.apple_radius(id) {
                return Some(format!("apple '{}'", self.layer.apple_name(id)));
            }
        }
        let mut hits = Vec::new();
        for (s, &ch) in self.surface_colliders.iter().enumerate() {
            if let Some(co) = self.physics.colliders.get(ch) {
                hits.clear();
                let id = SurfaceId(s as u32);
                crate::layer::surface::surface_hits(
                    self.layer.surface_shape(id),
                    co,
                    p,
                    r,
                    0.0,
                    &mut hits,
                );
                if hits
                    .iter()
                    .any(|h| h.overlap_m > MAX_INITIAL_SURFACE_OVERLAP_RATIO * r)
                {
                    return Some(format!("surface '{}'", self.layer.surface_name(id)));
                }
            }
        }
        None
    }

    /// The height (along `up`, a unit vector against gravity) of the lowest point of every
    /// surface, read from the colliders now (a library user may move or remove them): `None`
    /// when there is no surface, or one reaches down without end (a plane that is not level).
    /// An apple more than its diameter below it has nothing left to land on.
    pub fn lowest_surface_height(&self, up: Vec3) -> Option<f64> {
        let mut lowest = f64::INFINITY;
        for &ch in &self.surface_colliders {
            let Some(co) = self.physics.colliders.get(ch) else {
                continue;
            };
            let h = match co.shape().as_halfspace() {
                Some(hs) => {
                    let n = co.rotation() * hs.normal;
                    if n.dot(up) > 1.0 - 1e-9 {
                        co.translation().dot(up)
                    } else {
                        return None;
                    }
                }
                None => {
                    let b = co.compute_aabb();
                    let (lo, hi) = (b.mins, b.maxs);
                    let mut h = f64::INFINITY;
                    for c in 0..8 {
                        let corner = Vec3::new(
                            if c & 1 == 0 { lo.x } else { hi.x },
                            if c & 2 == 0 { lo.y } else { hi.y },
                            if c & 4 == 0 { lo.z } else { hi.z },
                        );
                        h = h.min(corner.dot(up));
                    }
                    h
                }
            };
            if !h.is_finite() {
                return None;
            }
            lowest = lowest.min(h);
        }
        lowest.is_finite().then_some(lowest)
    }

    /// Takes apple `k` out of the simulation (it left the scene at `at`): rapier no longer moves
    /// it, the layer no longer looks for its contacts ([`ContactLayer::take_out_apple`]), and it
    /// is parked far from everything, each apple at its own spot; [`Self::shown_position`] still gives `at`, the place where it left. An
    /// apple falling for ever would otherwise cost steps for nothing (an adaptive run shortens
    /// its steps so that no apple moves more than half of rapier's prediction distance per step,
    /// which a fast fall makes tiny), and one frozen where it left would be an obstacle hanging
    /// in the air for the apples that follow it.
    pub fn take_out(&mut self, k: usize, at: Vec3) {
        if self.taken_out.len() <= k {
            self.taken_out.resize(k + 1, None);
        }
        let parked = self.taken_out.iter().filter(|x| x.is_some()).count();
        self.taken_out[k] = Some(at);
        // The layer forgets it: a parking spot may lie inside a surface (every spot below an
        // upward plane does), which once failed the run with an overlap of 100 km.
        self.layer.take_out_apple(AppleId(k as u32));
        if let Some(rb) = self.apple_body_mut(k) {
            rb.set_linvel(Vec3::ZERO, false);
            rb.set_angvel(Vec3::ZERO, false);
            // Apples are at most 1 m wide (the diameter range): 3 m apart never touch, and
            // PARKING_M below the origin is beyond any scene (positions are at most 1e4 m).
            let spot = Vec3::new(3.0 * parked as f64, 0.0, -PARKING_M);
            rb.set_translation(spot, false);
            rb.set_enabled(false);
        }
    }

    /// Where to show apple `k`: the place where it left the scene when it was taken out
    /// ([`Self::take_out`]), else `None` (its body's own position).
    pub fn shown_position(&self, k: usize) -> Option<Vec3> {
        self.taken_out.get(k).copied().flatten()
    }
}

/// How far below the origin apples taken out of the run are parked (m).
const PARKING_M: f64 = 1e5;

/// The inner boxes of the scenario's bins.
fn bins(sc: &Scenario) -> Result<Vec<BinBox>, ScenarioError> {
    let mut out = Vec::new();
    for (k, s) in sc.surfaces.iter().enumerate() {
        if let scenario::SurfaceSpec::Bin(b) = s {
            let rotation = scenario::surfaces::rotation_of(&b.rotation, &format!("surfaces[{k}]"))?;
            out.push(BinBox {
                name: b.name.clone(),
                frame: Pose::from_parts(vec3(b.position_m), rotation),
                inner_size_m: b.inner_size_m,
                motion: None,
            });
        }
    }
    Ok(out)
}

/// A planned apple (placed where its source is at rest) as a source with motion `m` puts it at
/// time `t_s` ([`motion::Motion::spawn`]); unchanged for a fixed source.
fn place(m: Option<&motion::Motion>, a: &AppleSpec, t_s: f64) -> AppleSpec {
    let Some(m) = m else { return a.clone() };
    let (p, v) = m.spawn(t_s, vec3(a.position_m), vec3(a.velocity_m_s));
    AppleSpec {
        position_m: p.to_array(),
        velocity_m_s: v.to_array(),
        ..a.clone()
    }
}

/// The deepest overlap of a ball of radius `r` centred at `p` with any surface part where the
/// parts are at time `t_s` (moving ones where their motion has them then): (overlap, part).
fn deepest_overlap(
    world: &World,
    p: Vec3,
    r: f64,
    t_s: f64,
    hits: &mut Vec<crate::layer::surface::SurfaceHit>,
) -> Option<(f64, SurfaceId)> {
    let mut worst: Option<(f64, SurfaceId)> = None;
    for (s, &ch) in world.surface_colliders.iter().enumerate() {
        let Some(co) = world.physics.colliders.get(ch) else {
            continue;
        };
        let id = SurfaceId(s as u32);
        hits.clear();
        let q = world.at_part_now(s, p, t_s);
        crate::layer::surface::surface_hits(world.layer.surface_shape(id), co, q, r, 0.0, hits);
        for h in hits.iter() {
            if worst.is_none_or(|w| h.overlap_m > w.0) {
                worst = Some((h.overlap_m, id));
            }
        }
    }
    worst
}

/// The field a spot of source `k` that lies in a surface at `t_s` is refused by: its `motion`
/// (`.translation` or `.rotation` when it has only that) when the motion has carried the spot
/// away from `position_m` then, else `position_m`.
fn spot_field(
    k: usize,
    src: &scenario::SourceSpec,
    m: Option<&motion::Motion>,
    t_s: f64,
) -> String {
    let p = vec3(src.position_m);
    let moved = m.is_some_and(|m| (m.carry(t_s).transform_point(p) - p).length() > 1e-9);
    match (&src.motion, moved) {
        (Some(ms), true) => match (&ms.translation, &ms.rotation) {
            (Some(_), None) => format!("sources[{k}].motion.translation"),
            (None, Some(_)) => format!("sources[{k}].motion.rotation"),
            _ => format!("sources[{k}].motion"),
        },
        _ => format!("sources[{k}].position_m"),
    }
}

/// A source whose spawn point overlaps a surface could never feed an apple (each would wait for
/// its spot for ever): refused before the run, naming the source and the surface. Checked where
/// the scenario alone decides it (issue 31), with the source and the surfaces where they are at
/// the time (moving ones where their motion has them then):
///
/// 1. the spawn region at the source's first spawn time (`start_s`): `position_m` plus every
///    jitter offset, with the source's largest diameter, probed at its centre, corners, edge and
///    face centres (exact for planes and for flat faces, whose overlap is largest at a corner of
///    the region);
/// 2. when the source or a surface moves, every planned apple at its planned time, where its
///    source puts it then: a spot a moving surface sweeps through, or a moving source carried
///    into a surface, is refused naming the apple and the time;
/// 3. with `model.scene_bounds`, every planned apple of a moving source inside the box.
///
/// An overlap up to [`MAX_INITIAL_SURFACE_OVERLAP_RATIO`] of the radius is allowed, as for an
/// apple placed at the start. The field named is `position_m` (or the source's `motion` when it
/// has carried the spot there), or `jitter_m` when only a jittered spot lies in the surface.
/// A spot taken by an apple is not decided by the scenario alone: the apple waits for it.
fn check_spawn_points(sc: &Scenario, world: &World) -> Result<(), ScenarioError> {
    let mut hits = Vec::new();
    let g = vec3(sc.gravity_m_s2);
    let surface_at = |s: SurfaceId| {
        let name = world.layer.surface_name(s);
        if world.part_moves(s.0 as usize) {
            format!("surface '{name}' (where its motion has it then)")
        } else {
            format!("surface '{name}'")
        }
    };
    for (k, src) in sc.sources.iter().enumerate() {
        let m = world.source_motion(k);
        let t0 = src.start_s;
        let d = src.diameter_m.max_m();
        // Its apples are turned at random: the largest's bounding ball (a sphere's own).
        let r = 0.5 * scenario::AspectSpec::bounding_diameter_m(src.aspect.as_ref(), d);
        let allowed = MAX_INITIAL_SURFACE_OVERLAP_RATIO * r;
        let spot = |o: Vec3| match m {
            Some(m) => m.carry(t0).transform_point(vec3(src.position_m) + o),
            None => vec3(src.position_m) + o,
        };
        // The centre names position_m (or the motion); a corner of the jitter region only,
        // jitter_m.
        let centre = spot(Vec3::ZERO);
        let mut found = deepest_overlap(world, centre, r, t0, &mut hits)
            .filter(|w| w.0 > allowed)
            .map(|(u, s)| (u, s, centre, true));
        if found.is_none() && !src.jitter_m.is_zero() {
            for ox in [0.0, -1.0, 1.0] {
                for oy in [0.0, -1.0, 1.0] {
                    for oz in [0.0, -1.0, 1.0] {
                        let p = spot(src.jitter_m.offset([ox, oy, oz], g));
                        if let Some((u, s)) = deepest_overlap(world, p, r, t0, &mut hits) {
                            if u > allowed && found.is_none_or(|f| u > f.0) {
                                found = Some((u, s, p, false));
                            }
                        }
                    }
                }
            }
        }
        let Some((u, s, p, at_centre)) = found else {
            continue;
        };
        let surface = surface_at(s);
        let at = format!("[{}, {}, {}] m", short(p.x), short(p.y), short(p.z));
        // Both sides of the overlap named: the surface as its scenario entry places it, and the
        // source's largest apple (sources[k].diameter_m).
        let placed = sc
            .surface_fields_of(world.layer.surface_name(s))
            .map_or_else(String::new, |f| format!(" ({f})"));
        let size = if 2.0 * r > d {
            format!(
                "the bounding ball of its largest apple, however it turns, by sources[{k}].diameter_m and aspect: {} m",
                short(2.0 * r)
            )
        } else {
            format!(
                "an apple of its largest diameter, sources[{k}].diameter_m: {} m",
                short(d)
            )
        };
        let moving = m.is_some() || world.part_moves(s.0 as usize);
        let when = if moving {
            format!(" at its first spawn time, t = {} s", short(t0))
        } else {
            String::new()
        };
        return Err(if at_centre {
            ScenarioError::invalid(
                spot_field(k, src, m, t0),
                format!(
                    "the spawn point of source '{}' overlaps {surface}{placed} by {:.1} mm ({size}, centred at {at}{when}): none of its apples could be fed in; move position_m at least that far clear of the surface",
                    src.name,
                    u * 1e3,
                ),
            )
        } else {
            ScenarioError::invalid(
                format!("sources[{k}].jitter_m"),
                format!(
                    "the spawn region of source '{}' (position_m +- jitter_m) overlaps {surface}{placed} by {:.1} mm ({size}, centred at {at}{when}): apples placed there could not be fed in; reduce jitter_m or move position_m clear of the surface",
                    src.name,
                    u * 1e3,
                ),
            )
        });
    }
    // Every planned apple at its time, when something moves.
    let any_part_moves = (0..world.surface_colliders.len()).any(|s| world.part_moves(s));
    let any_source_moves = world.source_motions.iter().any(Option::is_some);
    if !(any_part_moves || any_source_moves) {
        return Ok(());
    }
    for f in &world.pending {
        let k = f.source;
        let src = &sc.sources[k];
        let m = world.source_motion(k);
        if m.is_none() && !any_part_moves {
            continue;
        }
        let t = f.time_s;
        let a = place(m, &f.apple, t);
        let p = vec3(a.position_m);
        let at = format!("[{}, {}, {}] m", short(p.x), short(p.y), short(p.z));
        if let (Some(b), Some(_)) = (&sc.model.scene_bounds, m) {
            if !b.contains(a.position_m) {
                return Err(ScenarioError::invalid(
                    spot_field(k, src, m, t),
                    format!(
                        "apple '{}' of source '{}' would appear at t = {} s at {at}, outside model.scene_bounds: the source's motion carries its spot out of the scene; keep it inside",
                        a.name,
                        src.name,
                        short(t)
                    ),
                ));
            }
        }
        let r = a.bounding_radius_m();
        let allowed = MAX_INITIAL_SURFACE_OVERLAP_RATIO * r;
        let Some((u, s)) = deepest_overlap(world, p, r, t, &mut hits).filter(|w| w.0 > allowed)
        else {
            continue;
        };
        // The jitter is to blame when the spot without it is clear.
        let unjittered = match m {
            Some(m) => m.carry(t).transform_point(vec3(src.position_m)),
            None => vec3(src.position_m),
        };
        let centre_in =
            deepest_overlap(world, unjittered, r, t, &mut hits).is_some_and(|w| w.0 > allowed);
        let (field, fix) = if !centre_in {
            (
                format!("sources[{k}].jitter_m"),
                "reduce jitter_m or move position_m clear of the surface".to_string(),
            )
        } else {
            let field = spot_field(k, src, m, t);
            let fix = if field.ends_with("position_m") {
                format!(
                    "move position_m out of the path of surface '{}', or feed at other times (start_s, rate_per_s)",
                    world.layer.surface_name(s)
                )
            } else {
                "change the motion so that the source keeps clear of the surface".to_string()
            };
            (field, fix)
        };
        return Err(ScenarioError::invalid(
            field,
            format!(
                "apple '{}' of source '{}' would appear at t = {} s at {at}{}, {:.1} mm inside {}: it could not be fed in then; {fix}",
                a.name,
                src.name,
                short(t),
                if m.is_some() {
                    " (where the source's motion carries it then)"
                } else {
                    ""
                },
                u * 1e3,
                surface_at(s),
            ),
        ));
    }
    Ok(())
}

/// A coordinate as a person writes it: 6 significant digits, no trailing zeros
/// (0.8420000000000001 -> 0.842).
fn short(x: f64) -> String {
    format!("{x:.5e}")
        .parse::<f64>()
        .map(|y| y.to_string())
        .unwrap_or_else(|_| x.to_string())
}

fn check_initial_surface_overlaps(
    sc: &Scenario,
    apples: &[(AppleSpec, Origin)],
    world: &World,
) -> Result<(), ScenarioError> {
    let mut hits = Vec::new();
    for (k, (a, _)) in apples.iter().enumerate() {
        if a.is_spheroid() {
            spheroid_surface_overlap(sc, k, a, world, &mut hits)?;
            continue;
        }
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
                let id = SurfaceId(s as u32);
                return Err(starts_inside(
                    sc,
                    world,
                    field,
                    a,
                    id,
                    h.overlap_m,
                    "radius",
                ));
            }
        }
    }
    Ok(())
}

/// [`check_initial_surface_overlaps`] for spheroid `k`: its overlap with each surface as the
/// layer computes it (`layer::surface::spheroid_hits`, exact on every surface kind). Allowed:
/// [`MAX_INITIAL_SURFACE_OVERLAP_RATIO`] of its smaller radius.
fn spheroid_surface_overlap(
    sc: &Scenario,
    k: usize,
    a: &AppleSpec,
    world: &World,
    hits: &mut Vec<crate::layer::surface::SurfaceHit>,
) -> Result<(), ScenarioError> {
    let shape = a.spheroid();
    let field = sc.initial_apple_field(k);
    // Checked by validation; read again for a library caller that skipped it.
    let turned = a.orientation(&field)?;
    let allowed = MAX_INITIAL_SURFACE_OVERLAP_RATIO * shape.a.min(shape.c);
    let mut extra = Vec::new();
    let mut scratch = crate::layer::surface::SpheroidScratch::default();
    for (s, &ch) in world.surface_colliders.iter().enumerate() {
        let Some(co) = world.physics.colliders.get(ch) else {
            continue;
        };
        hits.clear();
        extra.clear();
        let id = SurfaceId(s as u32);
        crate::layer::surface::spheroid_hits(
            world.layer.surface_shape(id),
            co,
            vec3(a.position_m),
            &turned,
            &shape,
            0.0,
            hits,
            &mut extra,
            &mut scratch,
        );
        let deepest = hits
            .iter()
            .map(|h| h.overlap_m)
            .fold(f64::NEG_INFINITY, f64::max);
        if deepest > allowed {
            let what = "smaller radius, as turned";
            return Err(starts_inside(sc, world, field, a, id, deepest, what));
        }
    }
    Ok(())
}

/// The refusal of an apple that starts `depth_m` inside surface `id`, more than the allowed share
/// of its `radius` (as the message names it).
fn starts_inside(
    sc: &Scenario,
    world: &World,
    field: String,
    a: &AppleSpec,
    id: SurfaceId,
    depth_m: f64,
    radius: &str,
) -> ScenarioError {
    let part = world.layer.surface_name(id);
    let placed = sc
        .surface_fields_of(part)
        .map_or_else(String::new, |f| format!(" ({f})"));
    ScenarioError::invalid(
        field,
        format!(
            "apple '{}' starts {:.4} mm inside surface '{part}'{placed} (more than {} % of its {radius}): place it on or above the surface",
            a.name,
            depth_m * 1e3,
            MAX_INITIAL_SURFACE_OVERLAP_RATIO * 100.0
        ),
    )
}
