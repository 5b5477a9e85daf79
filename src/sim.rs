//! The run driver: steps a built world through a scenario, feeding samples to a sink and
//! collecting contact events; refuses a run that went wrong instead of returning it.

use crate::layer::{AppleId, LayerError};
use crate::math::arr3;
use crate::record::events::{ContactEvent, Party};
use crate::record::series::{AppleState, SampleSink};
use crate::scenario::Scenario;
use crate::world::{self, BuildError, World};
use serde::Serialize;
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
    /// The layer refused to go on (non-finite state, stability guard).
    #[error(transparent)]
    Layer(#[from] LayerError),
    /// rapier quarantined a body whose state went non-finite.
    #[error(
        "non-finite state of '{body}' at t = {time_s} s (rapier quarantined it): the run blew up"
    )]
    Quarantine {
        /// Body name.
        body: String,
        /// Simulated time.
        time_s: f64,
    },
    /// The sample sink failed (disk full, ...).
    #[error("writing samples: {0}")]
    Io(#[from] std::io::Error),
}

/// Final state of one apple.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AppleFinal {
    /// Name.
    pub name: String,
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
}

/// Everything a run produced.
#[derive(Debug, Clone)]
pub struct RunResult {
    /// Steps taken.
    pub steps: u64,
    /// Time step (s).
    pub time_step_s: f64,
    /// Simulated time (s).
    pub simulated_time_s: f64,
    /// Wall-clock time of the stepping loop (s): a measurement, the only non-deterministic output.
    pub wall_time_s: f64,
    /// Contact events in order of start (then apple, then other party); open ones have no end.
    pub events: Vec<ContactEvent>,
    /// Final state per apple.
    pub apples: Vec<AppleFinal>,
    /// Things the user should know that did not stop the run.
    pub warnings: Vec<String>,
    /// Key results as flat, unit-suffixed numbers (one row of a batch table): every feature that
    /// produces a headline figure adds its keys here. Only finite values.
    pub metrics: BTreeMap<String, f64>,
}

/// The headline figures of a run (see [`RunResult::metrics`]).
pub fn base_metrics(events: &[ContactEvent], apples: &[AppleFinal]) -> BTreeMap<String, f64> {
    let mut m = BTreeMap::new();
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

/// A running simulation.
pub struct Simulation {
    world: World,
    dt: f64,
    steps_total: u64,
    step: u64,
    stride: u64,
    events: Vec<ContactEvent>,
    states: Vec<AppleState>,
}

impl Simulation {
    /// Builds the world of a validated scenario.
    pub fn new(sc: &Scenario, base_dir: &Path) -> Result<Self, SimError> {
        let world = world::build(sc, base_dir)?;
        let dt = sc.time_step_s;
        let steps_total = (sc.duration_s / dt).round().max(1.0) as u64;
        let stride = (sc.output.sample_interval_s / dt).round().max(1.0) as u64;
        Ok(Self {
            world,
            dt,
            steps_total,
            step: 0,
            stride,
            events: Vec::new(),
            states: Vec::new(),
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

    /// Time of the current poses (s).
    pub fn time_s(&self) -> f64 {
        self.step as f64 * self.dt
    }

    /// Steps the scenario asks for.
    pub fn steps_total(&self) -> u64 {
        self.steps_total
    }

    /// Steps taken so far.
    pub fn steps_done(&self) -> u64 {
        self.step
    }

    /// Current states of the apples (contact forces of the last force pass).
    pub fn apple_states(&mut self) -> &[AppleState] {
        self.refresh_states();
        &self.states
    }

    fn refresh_states(&mut self) {
        let layer = &self.world.layer;
        self.states.clear();
        for (k, &bh) in self.world.apple_bodies.iter().enumerate() {
            let id = AppleId(k as u32);
            let rb = &self.world.physics.bodies[bh];
            self.states.push(AppleState {
                index: k as u32,
                name: layer.apple_name(id).into(),
                position: rb.translation(),
                velocity: rb.linvel(),
                angular_velocity: rb.angvel(),
                contact_force: layer.apple_contact_force(id),
            });
        }
    }

    fn force_pass(&mut self) -> Result<(), LayerError> {
        let t = self.time_s();
        let w = &mut self.world;
        w.layer.apply_forces(
            &mut w.physics.bodies,
            &w.physics.colliders,
            &w.physics.narrow_phase,
            t,
            self.dt,
        )?;
        self.events.extend(w.layer.take_finished_events());
        Ok(())
    }

    /// Feeds in due apples, computes forces at the current poses, samples if due, and advances
    /// one step.
    pub fn step(&mut self, sink: &mut dyn SampleSink) -> Result<(), SimError> {
        let t = self.time_s();
        self.world.emit_due(t)?;
        self.force_pass()?;
        if self.step % self.stride == 0 {
            self.refresh_states();
            sink.sample(self.time_s(), &self.states)?;
        }
        let w = &mut self.world;
        w.physics.step_with_events(w.layer.hooks(), &());
        if let Some(&bh) = w.physics.quarantine().bodies().first() {
            let name = w
                .apple_bodies
                .iter()
                .position(|&b| b == bh)
                .map(|k| w.layer.apple_name(AppleId(k as u32)).to_string())
                .unwrap_or_else(|| format!("{bh:?}"));
            return Err(SimError::Quarantine {
                body: name,
                time_s: self.time_s(),
            });
        }
        self.step += 1;
        Ok(())
    }

    /// Runs to the end of the scenario. `progress` is called now and then with the fraction done.
    pub fn run(
        mut self,
        sink: &mut dyn SampleSink,
        progress: &mut dyn FnMut(f64),
    ) -> Result<RunResult, SimError> {
        let start = Instant::now();
        let report_every = (self.steps_total / 200).max(1);
        while self.step < self.steps_total {
            self.step(sink)?;
            if self.step % report_every == 0 {
                progress(self.step as f64 / self.steps_total as f64);
            }
        }
        // The final poses: close contacts that parted in the last step, sample the end state.
        self.force_pass()?;
        self.refresh_states();
        sink.sample(self.time_s(), &self.states)?;
        let wall = start.elapsed().as_secs_f64();
        Ok(self.finish(wall))
    }

    fn finish(mut self, wall_time_s: f64) -> RunResult {
        let mut events = std::mem::take(&mut self.events);
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
        let apples: Vec<AppleFinal> = self
            .states
            .iter()
            .enumerate()
            .map(|(k, s)| AppleFinal {
                name: s.name.to_string(),
                final_position_m: arr3(s.position),
                final_velocity_m_s: arr3(s.velocity),
                final_angular_velocity_rad_s: arr3(s.angular_velocity),
                peak_force_n: peak[k],
                peak_pressure_pa: peak_p[k],
                contacts: count[k],
            })
            .collect();
        let mut warnings = Vec::new();
        let postponed = self.world.postponed_emissions();
        if postponed > 0 {
            warnings.push(format!(
                "{postponed} fed-in apples waited for their spot to clear (the source emits faster than apples leave it)"
            ));
        }
        let pending = self.world.pending_emissions();
        if pending > 0 {
            warnings.push(format!(
                "{pending} apples of the sources were never fed in: the run ended first"
            ));
        }
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
        let metrics = base_metrics(&events, &apples);
        RunResult {
            metrics,
            steps: self.step,
            time_step_s: self.dt,
            simulated_time_s: self.time_s(),
            wall_time_s,
            events,
            apples,
            warnings,
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
