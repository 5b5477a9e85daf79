//! The run driver: steps a built world through a scenario, feeding samples to a sink and
//! collecting contact events; refuses a run that went wrong instead of returning it.
//!
//! The stability guard: the layer refuses non-finite state, overlaps beyond
//! `model.max_overlap_ratio` of the radius and impacts resolved in fewer steps than the accuracy
//! needs (naming the pair and the step that would work); the driver refuses rapier's quarantine,
//! a total energy that rises in a scene with no energy input (`model.energy_tolerance`), and runs
//! that would take more than `model.max_steps` steps.

pub mod fate;
pub mod keep_awake;
pub mod slip_roll;
pub mod timestep;

use crate::layer::{AppleId, LayerError, StepRequest};
use crate::math::arr3;
use crate::record::events::{ContactEvent, FinishedContact, Party};
use crate::record::series::{AppleState, SampleSink, ShapeState};
use crate::record::transitions::{self, Transition, TransitionSummary};
use crate::scenario::Scenario;
use crate::world::{self, BuildError, World};
use serde::Serialize;
use slip_roll::Detector;
use std::collections::BTreeMap;
use std::path::Path;
use std::time::Instant;
use thiserror::Error;

/// Errors of a run.
#[derive(Debug, Error)]
pub enum SimError {
    /// The world could not be built.
    #[error(transparent)]
    Build(#[from] BuildError),
    /// The layer refused to go on (a registration or geometry error).
    #[error(transparent)]
    Layer(#[from] LayerError),
    /// The stability guard stopped the run (non-finite state, an overlap beyond the limit, an
    /// impact in too few steps); `field` is the scenario field to change (the step, or the
    /// accuracy that sets it).
    #[error("{field}: {error}")]
    Guard {
        /// The scenario field to change.
        field: &'static str,
        /// What the layer saw.
        error: LayerError,
    },
    /// rapier quarantined a body whose state went non-finite.
    #[error(
        "{field}: non-finite state of '{body}' at t = {} s (rapier quarantined it): the run blew up", crate::math::secs(*time_s)
    )]
    Quarantine {
        /// The scenario field to change.
        field: &'static str,
        /// Body name.
        body: String,
        /// Simulated time.
        time_s: f64,
    },
    /// The sample sink failed (disk full, ...).
    #[error("writing samples: {0}")]
    Io(#[from] std::io::Error),
    /// The total energy rose in a scene with no energy input: the run is going wrong.
    #[error("{field}: unstable at t = {} s: the total energy rose by {rise_percent:.2} % above what the scene started with (limit {limit_percent} %), in a scene with no energy input; the fastest apple is '{apple}'. Use a smaller time_step_s (or \"time_step_s\": \"auto\")", crate::math::secs(*time_s))]
    EnergyRise {
        /// The scenario field to change.
        field: &'static str,
        /// Simulated time.
        time_s: f64,
        /// Rise above the budget (%).
        rise_percent: f64,
        /// Allowed rise (%).
        limit_percent: f64,
        /// The fastest apple then.
        apple: String,
    },
    /// A free-turning roller's spin ran away (not finite, or its surface faster than any speed
    /// of fruit handling): its update is unstable at this step (docs/physics.md 12.5).
    #[error("{field}: the spin of the free-turning roller '{roller}' ran away at t = {} s: {spin_rad_s:e} rad/s, a surface speed of {surface_speed_m_s:e} m/s (beyond |v| <= 100 m/s, or not finite): its explicit update from the contacts' friction is unstable with {inertia_kg_m2:e} kg m^2 at this step; give a larger moment of inertia or a shorter step", crate::math::secs(*time_s))]
    RollerRunaway {
        /// The JSON path of the roller's moment of inertia.
        field: String,
        /// The roller.
        roller: String,
        /// Simulated time.
        time_s: f64,
        /// Its rate then (rad/s).
        spin_rad_s: f64,
        /// Its surface speed then (m/s).
        surface_speed_m_s: f64,
        /// Its moment of inertia (kg m^2).
        inertia_kg_m2: f64,
    },
    /// The run would take too many steps.
    #[error("model.max_steps: the run needs more than model.max_steps = {max_steps} steps (at t = {} s of {} s with steps of {dt_s:e} s): use a larger time_step_s, \"auto\" or \"adaptive\", or raise model.max_steps", crate::math::secs(*time_s), crate::math::secs(*duration_s))]
    TooManySteps {
        /// The limit.
        max_steps: u64,
        /// Time reached.
        time_s: f64,
        /// Scenario duration.
        duration_s: f64,
        /// The step in use.
        dt_s: f64,
    },
}

/// Final state of one apple.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AppleFinal {
    /// Name.
    pub name: String,
    /// Diameter (m): a spheroid's equatorial one.
    pub diameter_m: f64,
    /// A spheroid's height along its own axis (m); absent for a sphere.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub height_m: Option<f64>,
    /// A spheroid's orientation at the end, a unit quaternion [w, x, y, z] (its frame to the
    /// world's); absent for a sphere.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub final_orientation: Option<[f64; 4]>,
    /// Mass (kg).
    pub mass_kg: f64,
    /// Centre at the end (m).
    pub final_position_m: [f64; 3],
    /// Centre velocity at the end (m/s).
    pub final_velocity_m_s: [f64; 3],
    /// Angular velocity at the end (rad/s).
    pub final_angular_velocity_rad_s: [f64; 3],
    /// Largest normal force of any contact of this apple (N).
    pub peak_force_n: f64,
    /// Largest mean contact pressure of any contact of this apple (Pa).
    pub peak_pressure_pa: f64,
    /// Number of contact events of this apple.
    pub contacts: usize,
    /// Where it ended: in a bin, on a surface, out of the scene, still moving.
    pub fate: fate::Fate,
    /// When and where its source fed it in (fed apples only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fed: Option<crate::world::FedEntry>,
}

/// Everything a run produced.
#[derive(Debug, Clone)]
pub struct RunResult {
    /// Steps taken.
    pub steps: u64,
    /// Time step (s): the fixed step, or the mean step of an adaptive run.
    pub time_step_s: f64,
    /// How the run stepped: `fixed`, `auto` or `adaptive`.
    pub step_policy: &'static str,
    /// Shortest and longest step taken (s).
    pub step_range_s: [f64; 2],
    /// The stiffest contact behind `auto`, if estimated.
    pub stiffest_contact: Option<timestep::StiffestContact>,
    /// The fidelity level and what it cannot tell.
    pub fidelity_limits: &'static str,
    /// Simulated time (s).
    pub simulated_time_s: f64,
    /// Wall-clock time of the stepping loop (s): a measurement, the only non-deterministic output.
    pub wall_time_s: f64,
    /// Contact events in order of start (then apple, then other party); open ones have no end.
    pub events: Vec<ContactEvent>,
    /// Final state per apple (layer order).
    pub apples: Vec<AppleFinal>,
    /// Every apple of the run in layer order: name, material, radius, mass, where it came from.
    pub roster: crate::world::Roster,
    /// Where in the line a point lies at a given time (bins, parts): the audit places
    /// apple-apple hits by it.
    pub zones: crate::world::zones::Zones,
    /// Slip/roll transitions in order of time (empty when the detector is off).
    pub transitions: Vec<Transition>,
    /// The transitions section of the summary (`None` when the detector is off).
    pub transition_summary: Option<TransitionSummary>,
    /// Things the user should know that did not stop the run.
    pub warnings: Vec<String>,
    /// The line's end: apples per fate, throughput per bin, what each source fed.
    pub line: fate::LineEnd,
    /// Key results as flat, unit-suffixed numbers (one row of a batch table): every feature that
    /// produces a headline figure adds its keys here. Only finite values.
    pub metrics: BTreeMap<String, f64>,
    /// What each virtual instrumented sphere (`apples[].probe`) recorded, in the order listed.
    pub probes: Vec<ProbeRecord>,
}

/// What one virtual instrumented sphere recorded.
#[derive(Debug, Clone)]
pub struct ProbeRecord {
    /// The probe apple's name.
    pub apple: String,
    /// Its index in the layer (and in [`RunResult::apples`]).
    pub index: u32,
    /// Its mass (kg).
    pub mass_kg: f64,
    /// How it sampled.
    pub spec: crate::record::probe::ProbeSpec,
    /// The kept samples (time s, reading g): windows around the impacts.
    pub trace: Vec<(f64, f64)>,
    /// The impacts as the device reports them.
    pub impacts: Vec<crate::record::probe::ProbeImpact>,
}

/// The headline figures of a run (see [`RunResult::metrics`]): of the fruit, the contacts of a
/// virtual instrumented sphere left out (`fruit(e)` false; the probe's figures are its own,
/// `probe.NAME.*`).
pub fn base_metrics(
    events: &[ContactEvent],
    apples: &[AppleFinal],
    fruit: &dyn Fn(&ContactEvent) -> bool,
) -> BTreeMap<String, f64> {
    let mut m = BTreeMap::new();
    let events: Vec<&ContactEvent> = events.iter().filter(|e| fruit(e)).collect();
    m.insert("contact_events".into(), events.len() as f64);
    let max = |it: &mut dyn Iterator<Item = f64>| it.fold(f64::NAN, f64::max);
    m.insert(
        "max_peak_force_n".into(),
        max(&mut events.iter().map(|e| e.peak_force_n)),
    );
    m.insert(
        "max_pressure_pa".into(),
        max(&mut events.iter().map(|e| e.max_pressure_pa)),
    );
    m.insert(
        "max_overlap_m".into(),
        max(&mut events.iter().map(|e| e.max_overlap_m)),
    );
    let durations: Vec<f64> = events.iter().filter_map(|e| e.duration_s).collect();
    m.insert(
        "max_contact_duration_s".into(),
        max(&mut durations.iter().copied()),
    );
    if !durations.is_empty() {
        m.insert(
            "mean_contact_duration_s".into(),
            durations.iter().sum::<f64>() / durations.len() as f64,
        );
    }
    let speeds: Vec<f64> = apples
        .iter()
        .map(|a| crate::math::vec3(a.final_velocity_m_s).length())
        .collect();
    m.insert(
        "max_final_speed_m_s".into(),
        max(&mut speeds.iter().copied()),
    );
    if !speeds.is_empty() {
        m.insert(
            "mean_final_speed_m_s".into(),
            speeds.iter().sum::<f64>() / speeds.len() as f64,
        );
    }
    m.retain(|_, v| v.is_finite());
    m
}

/// What a step that has output samples inside it starts from ([`Simulation::interpolated_states`]).
struct StepStart {
    apples: Vec<AppleState>,
    rollers: Vec<crate::world::free_roller::RollerSample>,
}

/// A running simulation.
pub struct Simulation {
    world: World,
    /// The scenario field that sets the step (named by the stability guard's refusals).
    step_field: &'static str,
    plan: timestep::StepPlan,
    step_policy: &'static str,
    fidelity_limits: &'static str,
    duration_s: f64,
    sample_interval_s: f64,
    time_s: f64,
    dt_prev: f64,
    dt_range: [f64; 2],
    step: u64,
    max_steps: u64,
    next_sample: u64,
    /// Contacts that ended, kept compact until the run's end (see [`FinishedContact`]).
    events: Vec<FinishedContact>,
    /// Warnings of pads that bottomed out (docs/physics.md section 13), in the order they did.
    pad_warnings: Vec<String>,
    /// Warnings the scenario alone gives (an exactly symmetric feed), added at the end.
    scenario_warnings: Vec<String>,
    states: Vec<AppleState>,
    /// The free-turning rollers' spins at the last sample (copied from the world, their owner;
    /// empty in a scene without them).
    rollers: Vec<crate::world::free_roller::RollerSample>,
    gravity: crate::math::Vec3,
    energy: Option<EnergyGuard>,
    detector: Option<Detector>,
    /// The virtual instrumented spheres: (apple, recorder).
    probes: Vec<(AppleId, crate::record::probe::ProbeRecorder)>,
    /// Bin entries and apples leaving the scene, seen at the output samples.
    tracker: fate::Tracker,
    /// The pool's other threads polling for work while the run steps (split scenes only).
    keep_awake: keep_awake::KeepAwake,
}

/// Watches the total energy of a scene without energy input (no belt, no moving body).
struct EnergyGuard {
    budget_j: f64,
    scale_j: f64,
    tolerance: f64,
    counted_apples: usize,
    /// The largest speed the scene can produce (m/s): each apple's share of the scale is
    /// 1/2 m v_bound^2, the energy it could carry.
    v_bound: f64,
}

impl Simulation {
    /// Builds the world of a validated scenario and plans its steps.
    pub fn new(sc: &Scenario, base_dir: &Path) -> Result<Self, SimError> {
        // Memory and output were estimated when the scenario was validated; the steps need the
        // plan. Refused with the estimate before anything is stepped.
        let world = world::build(sc, base_dir)?;
        let plan = timestep::plan(sc, &world);
        timestep::check_free_rollers(sc, &world, &plan).map_err(BuildError::from)?;
        timestep::check_tunnelling(sc, &world, &plan).map_err(BuildError::from)?;
        timestep::check_steps(sc, &world, &plan).map_err(BuildError::from)?;
        let v_bound = timestep::speed_bound(sc, &world).max(0.01);
        let belt_or_moving = sc.surfaces.iter().any(|s| s.is_moving());
        let energy = (!belt_or_moving && sc.fidelity != crate::scenario::Fidelity::Rigid)
            .then_some({
                EnergyGuard {
                    budget_j: f64::NAN,
                    scale_j: 0.0,
                    tolerance: sc.model.energy_tolerance,
                    counted_apples: 0,
                    v_bound: 0.0,
                }
            });
        let step_policy = match sc.time_step_s {
            crate::scenario::TimeStep::Fixed(_) => "fixed",
            crate::scenario::TimeStep::Auto => "auto",
            crate::scenario::TimeStep::Adaptive
                if matches!(plan.policy, timestep::Policy::Fixed(_)) =>
            {
                "auto"
            }
            crate::scenario::TimeStep::Adaptive => "adaptive",
        };
        Ok(Self {
            step_field: match sc.time_step_s {
                crate::scenario::TimeStep::Fixed(_) => "time_step_s",
                _ => "accuracy",
            },
            dt_prev: plan.initial_s,
            plan,
            step_policy,
            fidelity_limits: sc.fidelity.limits(),
            duration_s: sc.duration_s,
            sample_interval_s: sc.sample_interval_s(),
            time_s: 0.0,
            dt_range: [f64::INFINITY, 0.0],
            step: 0,
            max_steps: sc.model.max_steps,
            next_sample: 0,
            events: Vec::new(),
            pad_warnings: Vec::new(),
            scenario_warnings: crate::scenario::generators::symmetric_feed_warnings(
                &sc.sources,
                sc.gravity_m_s2,
            ),
            states: Vec::new(),
            rollers: Vec::new(),
            gravity: crate::math::vec3(sc.gravity_m_s2),
            energy: energy.map(|e| EnergyGuard { v_bound, ..e }),
            detector: (sc.output.transitions.enabled && !world.layer.config().passive)
                .then(|| Detector::new(sc.output.transitions, world.surface_frames.clone())),
            probes: sc
                .apples
                .iter()
                .filter_map(|a| {
                    let spec = a.probe?;
                    // Listed apples come first in the layer, in their order; found by name to
                    // be independent of that.
                    let id = (0..world.layer.apple_count())
                        .map(|k| AppleId(k as u32))
                        .find(|&id| world.layer.apple_name(id) == a.name)?;
                    let m = world.layer.apple_mass(id);
                    Some((id, crate::record::probe::ProbeRecorder::new(spec, m)))
                })
                .collect(),
            tracker: fate::Tracker::new(sc),
            keep_awake: keep_awake::KeepAwake::default(),
            world,
        })
    }

    /// The world (rapier sets and the layer).
    pub fn world(&self) -> &World {
        &self.world
    }

    /// Mutable world, for callers that drive or inspect it themselves.
    pub fn world_mut(&mut self) -> &mut World {
        &mut self.world
    }

    /// The step plan.
    pub fn plan(&self) -> &timestep::StepPlan {
        &self.plan
    }

    /// Time of the current poses (s).
    pub fn time_s(&self) -> f64 {
        self.time_s
    }

    /// Steps a fixed-step run takes (for an adaptive run: the steps at its first step length).
    pub fn steps_total(&self) -> u64 {
        (self.duration_s / self.plan.initial_s).round().max(1.0) as u64
    }

    /// Steps taken so far.
    pub fn steps_done(&self) -> u64 {
        self.step
    }

    /// Whether the run has reached its duration.
    pub fn done(&self) -> bool {
        match self.plan.policy {
            timestep::Policy::Fixed(_) => self.step >= self.steps_total(),
            timestep::Policy::Adaptive { .. } => self.time_s >= self.duration_s * (1.0 - 1e-12),
        }
    }

    /// Current states of the apples (contact forces of the last force pass).
    pub fn apple_states(&mut self) -> &[AppleState] {
        self.refresh_states();
        &self.states
    }

    fn refresh_states(&mut self) {
        let layer = &self.world.layer;
        self.states.clear();
        for k in 0..self.world.apple_bodies.len() {
            let id = AppleId(k as u32);
            let rb = self.world.apple_body(k);
            // A rider sleeps in rapier where it began to ride: the layer carries it.
            let (position, velocity) = match layer.rider_motion(id, self.time_s) {
                Some((c, v)) => (c, v),
                None => (
                    self.world.shown_position(k).unwrap_or(rb.translation()),
                    rb.linvel(),
                ),
            };
            self.states.push(AppleState {
                index: k as u32,
                name: layer.apple_name(id).into(),
                position,
                velocity,
                angular_velocity: rb.angvel(),
                contact_force: layer.apple_contact_force(id),
                slip_speed: self.detector.as_ref().map(|d| d.current_slip(k)),
                diameter_m: match layer.apple_shape(id) {
                    Some(sh) => 2.0 * sh.a,
                    None => 2.0 * layer.apple_radius(id),
                },
                shape: layer.apple_shape(id).map(|sh| ShapeState {
                    height_m: 2.0 * sh.c,
                    rotation: *rb.rotation(),
                }),
                mass_kg: layer.apple_mass(id),
            });
        }
    }

    /// A refusal of the layer as a run error: the stability guard's (non-finite state, an
    /// overlap beyond the limit, an impact in too few steps) names the field that sets the step.
    fn guard(&self, e: LayerError) -> SimError {
        match e {
            // `auto` and `adaptive` steps are set by the accuracy and capped by max_time_step_s:
            // the step that would work is given as that cap.
            LayerError::Unstable {
                a,
                b,
                time_s,
                what,
                suggested_dt_s: Some(dt),
            } if self.step_field != "time_step_s" => SimError::Guard {
                field: self.step_field,
                error: LayerError::Unstable {
                    a,
                    b,
                    time_s,
                    what: match what.split_once("; use time_step_s <=") {
                        Some((head, _)) => format!(
                            "{head}; use max_time_step_s <= {dt:.3e} (the {} step's cap) or a higher accuracy",
                            self.step_policy
                        ),
                        None => what,
                    },
                    suggested_dt_s: Some(dt),
                },
            },
            LayerError::Unstable { .. } | LayerError::NonFinite { .. } => SimError::Guard {
                field: self.step_field,
                error: e,
            },
            other => SimError::Layer(other),
        }
    }

    /// The time left to the next instant a step must land on: the end, or a source's next
    /// emission (an apple appears at its planned time: without it an adaptive step of up to
    /// 10 ms fed it that much later, 4 mm behind on a 0.4 m/s belt). Steps do not land on the
    /// output samples: a sample between two steps is interpolated
    /// ([`Self::interpolated_states`]), so that the output's sampling never changes the run
    /// (issue 31: landing on every sample shortened a step each time and, the pour being
    /// chaotic, moved every figure).
    fn land_in_s(&self) -> f64 {
        let end = self.duration_s - self.time_s;
        match self.world.next_emission_after(self.time_s) {
            Some(e) if e - self.time_s < end => e - self.time_s,
            _ => end,
        }
    }

    /// The time of the next output sample, k times the interval rounded to 12 significant
    /// digits: the decimal time a user reads (10.6 s, not 10.600000000000001), the same double
    /// whichever interval reaches it, so that runs sampled at 0.1 s and at 0.02 s interpolate the
    /// same state at 10.6 s, to the bit.
    fn next_sample_s(&self) -> f64 {
        let t = self.next_sample as f64 * self.sample_interval_s;
        format!("{t:.11e}").parse().unwrap_or(t)
    }

    /// Whether an output sample falls strictly inside the step from `t0` to `t1` (an adaptive
    /// run; a sample on a step's end is taken at that step, as the first and the last are).
    fn sample_inside(&self, t0: f64, t1: f64) -> bool {
        let ts = self.next_sample_s();
        matches!(self.plan.policy, timestep::Policy::Adaptive { .. })
            && ts > t0
            && ts < t1 - 1e-9 * self.sample_interval_s
            && ts < self.duration_s
    }

    /// What the coming step is asked to be: the fixed step, or for an adaptive run at most the
    /// largest step and twice the last one, landing exactly on the end
    /// ([`StepRequest::adaptive`]). After the last step (`closing`), the request that closes the
    /// contacts at the final poses: a step as long as the last.
    fn request(&self, closing: bool) -> StepRequest {
        let t = self.time_s;
        let last = (self.step > 0).then_some(self.dt_prev);
        match self.plan.policy {
            timestep::Policy::Fixed(dt) => StepRequest::fixed(t, dt),
            timestep::Policy::Adaptive { max_s, .. } if closing => StepRequest {
                time_s: t,
                dt_s: self.dt_prev,
                max_dt_s: max_s,
                last_dt_s: last,
                land_in_s: Some(self.land_in_s()).filter(|&l| l > 0.0),
            },
            timestep::Policy::Adaptive { max_s, .. } => {
                StepRequest::adaptive(t, max_s, last, self.plan.initial_s, self.land_in_s())
            }
        }
    }

    /// Computes the forces at the current poses for the coming step and returns its length.
    fn force_pass(&mut self, request: &StepRequest) -> Result<f64, LayerError> {
        let w = &mut self.world;
        let dt = w.force_pass(request)?;
        self.events.extend(
            w.layer
                .take_finished_events()
                .into_iter()
                .map(FinishedContact::from),
        );
        self.pad_warnings.extend(w.layer.take_pad_warnings());
        if let Some(d) = self.detector.as_mut() {
            d.observe(request.time_s, &w.layer);
        }
        for (id, p) in &mut self.probes {
            p.observe(request.time_s, w.layer.apple_contact_force(*id).length());
        }
        Ok(dt)
    }

    fn sample_due(&self) -> bool {
        match self.plan.policy {
            timestep::Policy::Fixed(dt) => {
                let stride = (self.sample_interval_s / dt).round().max(1.0) as u64;
                self.step % stride == 0
            }
            timestep::Policy::Adaptive { .. } => {
                let next_sample_t = self.next_sample_s();
                self.time_s >= next_sample_t - 1e-9 * self.sample_interval_s
            }
        }
    }

    /// Feeds in due apples, computes forces at the current poses, samples if due, and advances
    /// one step.
    pub fn step(&mut self, sink: &mut dyn SampleSink) -> Result<(), SimError> {
        if self.step >= self.max_steps {
            return Err(SimError::TooManySteps {
                max_steps: self.max_steps,
                time_s: self.time_s,
                duration_s: self.duration_s,
                dt_s: self.dt_prev,
            });
        }
        if self.world.body_set_count() > 1
            && self.world.layer.stats().contacts >= keep_awake::MIN_CONTACTS
        {
            self.keep_awake.ensure();
        } else {
            self.keep_awake.release();
        }
        let t = self.time_s;
        self.world.emit_due(t)?;
        let dt = self
            .force_pass(&self.request(false))
            .map_err(|e| self.guard(e))?;
        let due = self.sample_due();
        if due {
            self.emit_sample(sink)?;
            self.next_sample += 1;
            self.check_energy()?;
            self.track(self.time_s);
        }
        // Samples inside this step are interpolated after it, from the states at its start.
        let inside = self.sample_inside(t, t + dt);
        if !due && (inside || self.step % 1000 == 0) {
            self.refresh_states();
            self.check_energy()?;
        }
        let start = inside.then(|| self.start_of_step());
        let w = &mut self.world;
        w.advance(dt);
        if let Some(name) = w.quarantined() {
            return Err(SimError::Quarantine {
                field: self.step_field,
                body: name,
                time_s: self.time_s,
            });
        }
        if let Some(r) = self.world.runaway_roller() {
            return Err(SimError::RollerRunaway {
                field: r.field,
                roller: r.roller,
                time_s: self.time_s,
                spin_rad_s: r.spin_rad_s,
                surface_speed_m_s: r.surface_speed_m_s,
                inertia_kg_m2: r.inertia_kg_m2,
            });
        }
        self.step += 1;
        self.dt_prev = dt;
        self.dt_range = [self.dt_range[0].min(dt), self.dt_range[1].max(dt)];
        self.time_s = match self.plan.policy {
            timestep::Policy::Fixed(d) => self.step as f64 * d,
            timestep::Policy::Adaptive { .. } => {
                let t = self.time_s + dt;
                // Snap onto the end.
                if (t - self.duration_s).abs() < 1e-9 * self.duration_s {
                    self.duration_s
                } else {
                    t
                }
            }
        };
        self.world.set_time(self.time_s);
        if let Some(start) = start {
            while self.sample_inside(t, self.time_s) {
                let ts = self.next_sample_s();
                self.interpolated_states(&start, (ts - t) / dt);
                self.emit_states(ts, sink)?;
                self.next_sample += 1;
                self.track(ts);
            }
        }
        Ok(())
    }

    /// The states at the start of a step that has output samples inside it: the apples' (their
    /// contact forces and slip those acting over the step) and the free rollers' angles.
    fn start_of_step(&mut self) -> StepStart {
        if self.world.has_free_rollers() {
            self.world.sample_free_rollers(&mut self.rollers);
        }
        StepStart {
            apples: self.states.clone(),
            rollers: self.rollers.clone(),
        }
    }

    /// The states at a fraction `f` of the step just taken: each position on the straight line
    /// from the step's start to its end (symplectic Euler moves a body at its new velocity over
    /// the whole step); the velocities likewise between the step's start and end, so that a
    /// sample inside a step reads as one on a step would (each body's velocity of the half step
    /// before, as bodies.csv has always given it) and a fit to sampled velocities is not jittered
    /// by where the samples fall in their steps; the contact forces and slip those computed at
    /// the step's start, which acted over it; a free roller's angle and rate likewise.
    fn interpolated_states(&mut self, start: &StepStart, f: f64) {
        self.refresh_states();
        let lerp = |a: crate::math::Vec3, b: crate::math::Vec3| a + (b - a) * f;
        for (s, s0) in self.states.iter_mut().zip(&start.apples) {
            s.position = lerp(s0.position, s.position);
            s.velocity = lerp(s0.velocity, s.velocity);
            s.angular_velocity = lerp(s0.angular_velocity, s.angular_velocity);
            if let (Some(sh), Some(sh0)) = (s.shape.as_mut(), s0.shape.as_ref()) {
                sh.rotation = sh0.rotation.slerp(sh.rotation, f);
            }
            s.contact_force = s0.contact_force;
            s.slip_speed = s0.slip_speed;
        }
        if self.world.has_free_rollers() {
            self.world.sample_free_rollers(&mut self.rollers);
            for (r, r0) in self.rollers.iter_mut().zip(&start.rollers) {
                r.angle_rad = r0.angle_rad + (r.angle_rad - r0.angle_rad) * f;
                r.spin_rad_s = r0.spin_rad_s + (r.spin_rad_s - r0.spin_rad_s) * f;
                r.surface_speed_m_s =
                    r0.surface_speed_m_s + (r.surface_speed_m_s - r0.surface_speed_m_s) * f;
            }
        }
    }

    /// One output sample: the apples' states, then (in a scene that has them) the free-turning
    /// rollers' spins at the same time, copied from the world that owns them.
    fn emit_sample(&mut self, sink: &mut dyn SampleSink) -> std::io::Result<()> {
        self.refresh_states();
        if self.world.has_free_rollers() {
            self.world.sample_free_rollers(&mut self.rollers);
        }
        self.emit_states(self.time_s, sink)
    }

    /// Writes the states held (apples, and free rollers in a scene that has them) as the
    /// sample at `t`.
    fn emit_states(&mut self, t: f64, sink: &mut dyn SampleSink) -> std::io::Result<()> {
        sink.sample(t, &self.states)?;
        if self.world.has_free_rollers() {
            sink.sample_rollers(t, &self.rollers)?;
        }
        Ok(())
    }

    /// Looks at the apples just sampled: bin entries, and apples that left the scene, which are
    /// taken out of the run ([`fate`]).
    fn track(&mut self, t: f64) {
        for k in self.tracker.observe(t, &self.states, &self.world) {
            let at = self.states[k].position;
            self.world.take_out(k, at);
        }
    }

    /// Total mechanical energy (J) with the velocities taken at the poses' time (symplectic
    /// Euler stores the velocity of the half step before: v + a dt / 2 is the one at the pose),
    /// and the energy of apples fed in since the last call added to the budget.
    fn check_energy(&mut self) -> Result<(), SimError> {
        let step_field = self.step_field;
        let Some(guard) = self.energy.as_mut() else {
            return Ok(());
        };
        let layer = &self.world.layer;
        let g = self.gravity;
        let half = 0.5 * self.dt_prev;
        // Energy in the contacts: the work their normal forces did so far (not the Hertz elastic
        // energy, which eq. 12 does not store when it loads below the Hertz curve).
        let mut total = layer.open_contact_work_j();
        let mut fed = 0.0;
        let mut fed_scale = 0.0;
        let mut fastest = (0.0, 0usize);
        let first = guard.budget_j.is_nan();
        for (k, s) in self.states.iter().enumerate() {
            let id = AppleId(k as u32);
            let m = layer.apple_mass(id);
            let r = layer.apple_radius(id);
            let inertia = 0.4 * m * r * r;
            let asleep = layer.is_asleep(id);
            let (v, w) = if asleep {
                (s.velocity, s.angular_velocity)
            } else {
                (
                    s.velocity + (s.contact_force / m + g) * half,
                    s.angular_velocity + layer.apple_contact_torque(id) / inertia * half,
                )
            };
            let e = 0.5 * m * v.length_squared() + 0.5 * inertia * w.length_squared()
                - m * g.dot(s.position);
            total += e;
            if k >= guard.counted_apples {
                // Apples fed in (or all of them at the first check): their energy enters the
                // budget, the energy they could carry the scale.
                fed += e;
                fed_scale += 0.5 * m * guard.v_bound * guard.v_bound;
            }
            if v.length() > fastest.0 {
                fastest = (v.length(), k);
            }
        }
        guard.counted_apples = self.states.len();
        guard.scale_j += fed_scale;
        if first {
            guard.budget_j = total;
            guard.scale_j = guard.scale_j.max(1e-12);
            return Ok(());
        }
        guard.budget_j += fed;
        let rise = (total - guard.budget_j) / guard.scale_j;
        if rise > guard.tolerance {
            return Err(SimError::EnergyRise {
                field: step_field,
                time_s: self.time_s,
                rise_percent: 100.0 * rise,
                limit_percent: 100.0 * guard.tolerance,
                apple: self.states[fastest.1].name.to_string(),
            });
        }
        Ok(())
    }

    /// Runs to the end of the scenario. `progress` is called now and then with the fraction done.
    pub fn run(
        mut self,
        sink: &mut dyn SampleSink,
        progress: &mut dyn FnMut(f64),
    ) -> Result<RunResult, SimError> {
        let start = Instant::now();
        let mut last_report = 0.0;
        while !self.done() {
            self.step(sink)?;
            let f = self.time_s / self.duration_s;
            if f - last_report >= 0.005 {
                last_report = f;
                progress(f);
            }
        }
        // The final poses: close contacts that parted in the last step, sample the end state.
        self.force_pass(&self.request(true))
            .map_err(|e| self.guard(e))?;
        self.emit_sample(sink)?;
        self.check_energy()?;
        self.track(self.time_s);
        let wall = start.elapsed().as_secs_f64();
        Ok(self.finish(wall))
    }

    fn finish(mut self, wall_time_s: f64) -> RunResult {
        let layer = &self.world.layer;
        let finished = std::mem::take(&mut self.events);
        let mut events: Vec<ContactEvent> = Vec::with_capacity(finished.len());
        events.extend(finished.into_iter().map(|f| {
            let names = layer.names(f.a_index(), f.b_party());
            f.into_event(names)
        }));
        events.extend(self.world.layer.open_events());
        events.sort_by(|x, y| {
            x.t_start_s
                .total_cmp(&y.t_start_s)
                .then(x.a_index.cmp(&y.a_index))
                .then(party_order(x.b_party).cmp(&party_order(y.b_party)))
        });
        let n = self.world.apple_bodies.len();
        let mut peak = vec![0.0f64; n];
        let mut peak_p = vec![0.0f64; n];
        let mut count = vec![0usize; n];
        for e in &events {
            let mut touch = |k: usize| {
                peak[k] = peak[k].max(e.peak_force_n);
                peak_p[k] = peak_p[k].max(e.max_pressure_pa);
                count[k] += 1;
            };
            touch(e.a_index as usize);
            if let Party::Apple(j) = e.b_party {
                touch(j as usize);
            }
        }
        let feeds = self.world.source_feeds(self.time_s);
        let tracker = self.tracker;
        let (fates, mut line) =
            tracker.finish(self.time_s, &self.states, &self.world, &events, feeds);
        line.free_rollers = self.world.free_rollers();
        let apples: Vec<AppleFinal> = self
            .states
            .iter()
            .zip(fates)
            .enumerate()
            .map(|(k, (s, fate))| AppleFinal {
                name: s.name.to_string(),
                diameter_m: s.diameter_m,
                height_m: s.shape.map(|sh| sh.height_m),
                final_orientation: s.shape.map(|sh| {
                    let q = sh.rotation;
                    [q.w, q.x, q.y, q.z]
                }),
                mass_kg: s.mass_kg,
                final_position_m: arr3(s.position),
                final_velocity_m_s: arr3(s.velocity),
                final_angular_velocity_rad_s: arr3(s.angular_velocity),
                peak_force_n: peak[k],
                peak_pressure_pa: peak_p[k],
                contacts: count[k],
                fate,
                fed: self.world.fed_entry(k).cloned(),
            })
            .collect();
        let mut warnings = std::mem::take(&mut self.scenario_warnings);
        warnings.extend(fate::warnings(&apples, &line, self.time_s));
        warnings.append(&mut self.pad_warnings);
        let worst = events.iter().map(|e| (e.max_overlap_m, e)).fold(
            None::<(f64, &ContactEvent)>,
            |acc, x| match acc {
                Some(a) if a.0 >= x.0 => Some(a),
                _ => Some(x),
            },
        );
        if let Some((u, e)) = worst {
            let r = self.world.layer.apple_radius(AppleId(e.a_index));
            if u > 0.1 * r {
                warnings.push(format!(
                    "contact '{}' - '{}' reached an overlap of {:.1} % of the radius: Hertz theory assumes u << R, treat its forces as indicative",
                    e.a, e.b, 100.0 * u / r
                ));
            }
        }
        let roster = &self.world.roster;
        let is_probe = |k: u32| roster.apples().get(k as usize).is_some_and(|a| a.probe);
        let fruit = |e: &ContactEvent| {
            !is_probe(e.a_index) && !matches!(e.b_party, Party::Apple(j) if is_probe(j))
        };
        let fruit_apples: Vec<AppleFinal> = apples
            .iter()
            .enumerate()
            .filter(|(k, _)| !is_probe(*k as u32))
            .map(|(_, a)| a.clone())
            .collect();
        let mut metrics = base_metrics(&events, &fruit_apples, &fruit);
        let probes: Vec<ProbeRecord> = std::mem::take(&mut self.probes)
            .into_iter()
            .map(|(id, p)| {
                let spec = *p.spec();
                let (trace, impacts) = p.finish();
                ProbeRecord {
                    apple: self.world.layer.apple_name(id).to_string(),
                    index: id.0,
                    mass_kg: self.world.layer.apple_mass(id),
                    spec,
                    trace,
                    impacts,
                }
            })
            .collect();
        for p in &probes {
            let key = |what: &str| format!("probe.{}.{what}", p.apple);
            metrics.insert(key("impacts"), p.impacts.len() as f64);
            let max = |f: fn(&crate::record::probe::ProbeImpact) -> f64| {
                p.impacts.iter().map(f).fold(f64::NAN, f64::max)
            };
            for (what, v) in [
                ("max_peak_g", max(|i| i.peak_g)),
                ("max_velocity_change_m_s", max(|i| i.velocity_change_m_s)),
            ] {
                if v.is_finite() {
                    metrics.insert(key(what), v);
                }
            }
        }
        metrics.extend(line.metrics());
        let (transitions, transition_summary) = match self.detector.take() {
            Some(d) => {
                let (t, s) = d.finish();
                metrics.extend(transitions::metrics(&s));
                (t, Some(s))
            }
            None => (Vec::new(), None),
        };
        RunResult {
            metrics,
            transitions,
            transition_summary,
            steps: self.step,
            time_step_s: if self.step > 0 {
                self.time_s / self.step as f64
            } else {
                self.plan.initial_s
            },
            step_policy: self.step_policy,
            step_range_s: self.dt_range,
            stiffest_contact: self.plan.stiffest.clone(),
            fidelity_limits: self.fidelity_limits,
            simulated_time_s: self.time_s,
            wall_time_s,
            events,
            apples,
            zones: crate::world::zones::Zones::of(&self.world),
            roster: std::mem::take(&mut self.world.roster),
            warnings,
            probes,
            line,
        }
    }
}

fn party_order(p: Party) -> (u8, u32) {
    match p {
        Party::Apple(j) => (0, j),
        Party::Surface(s) => (1, s),
    }
}

/// Runs a validated scenario to the end.
pub fn run(
    sc: &Scenario,
    base_dir: &Path,
    sink: &mut dyn SampleSink,
) -> Result<RunResult, SimError> {
    Simulation::new(sc, base_dir)?.run(sink, &mut |_| {})
}
