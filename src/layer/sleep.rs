//! Sleeping: apples at rest stop costing anything (see [`super::SleepConfig`] for the rule).
//!
//! The layer decides, rapier executes: a sleeper is put to sleep in rapier (`RigidBody::sleep`,
//! so rapier does not integrate it) and woken with `wake_up`. Its contacts with other sleepers
//! and with fixed surfaces are frozen (not evaluated); it reports the contact force it carried
//! when it fell asleep. What wakes it is decided from the geometry in [`super::detect`], or by
//! rapier (a body the user moved or pushed shows up in rapier's active set).
//!
//! This module owns every piece of sleep state; the rest of the layer reads it (the awake list,
//! who sleeps) and asks for wake-ups ([`Sleep::request_wake`]).

use super::config::SleepConfig;
use super::frame::{Frame, Loads};
use super::registry::{AppleEntry, Registry};
use crate::math::Vec3;
use rapier3d_f64::dynamics::{IslandManager, RigidBodySet};

/// The sleep state of every apple.
#[derive(Debug)]
pub(super) struct Sleep {
    asleep: Vec<bool>,
    /// The apples awake now, in increasing order (see [`Self::refresh_awake`]).
    awake: Vec<u32>,
    /// How many apples sleep.
    asleep_count: usize,
    /// The awake set changed: `awake` must be listed again.
    dirty: bool,
    /// Time each apple has been still and supported (s).
    still_time: Vec<f64>,
    /// Running mean of the net force while still (NaN: starts again).
    mean_force: Vec<Vec3>,
    /// A spheroid's running mean of the contact torque about its centre while still (NaN:
    /// starts again; spheres do not use it).
    mean_torque: Vec<Vec3>,
    /// The contact force a sleeper carried when it fell asleep.
    sleep_force: Vec<Vec3>,
    /// Sleepers to wake before the next detection.
    to_wake: Vec<u32>,
}

impl Sleep {
    pub fn new() -> Self {
        Self {
            asleep: Vec::new(),
            awake: Vec::new(),
            asleep_count: 0,
            dirty: true,
            still_time: Vec::new(),
            mean_force: Vec::new(),
            mean_torque: Vec::new(),
            sleep_force: Vec::new(),
            to_wake: Vec::new(),
        }
    }

    /// A new apple was registered: it starts awake.
    pub fn apple_added(&mut self) {
        self.dirty = true;
    }

    /// Sizes the state for `n` apples (new ones awake).
    pub fn grow(&mut self, n: usize) {
        self.still_time.resize(n, 0.0);
        self.mean_force.resize(n, Vec3::NAN);
        self.mean_torque.resize(n, Vec3::NAN);
        self.asleep.resize(n, false);
        self.sleep_force.resize(n, Vec3::ZERO);
    }

    /// The awake apples, in increasing order.
    #[inline]
    pub fn awake(&self) -> &[u32] {
        &self.awake
    }

    /// Per apple: asleep.
    #[inline]
    pub fn asleep(&self) -> &[bool] {
        &self.asleep
    }

    /// Whether apple `k` sleeps.
    #[inline]
    pub fn is_asleep(&self, k: usize) -> bool {
        self.asleep.get(k).copied().unwrap_or(false)
    }

    /// How many apples sleep.
    pub fn asleep_count(&self) -> usize {
        self.asleep_count
    }

    /// The contact force a sleeper carried when it fell asleep.
    pub fn sleep_force(&self, k: usize) -> Vec3 {
        self.sleep_force[k]
    }

    /// Asks for apple `k` to be woken before the next detection.
    #[inline]
    pub fn request_wake(&mut self, k: u32) {
        self.to_wake.push(k);
    }

    /// Whether wake-ups are pending.
    pub fn wakes_pending(&self) -> bool {
        !self.to_wake.is_empty()
    }

    /// Drops pending wake-ups (the detection pass was redone once already).
    pub fn clear_wakes(&mut self) {
        self.to_wake.clear();
    }

    /// Whether some apple sleeps (the awake list is shorter than the apples).
    fn sleeping_any(&self, n: usize) -> bool {
        self.awake.len() < n || self.dirty
    }

    /// Sleepers that rapier woke (the user moved one, or gave it an impulse with `wake_up`) show
    /// up in rapier's active set: they are awake again. Costs nothing when nobody sleeps.
    pub fn notice_rapier_wakeups(&mut self, islands: &IslandManager, registry: &Registry) {
        if !self.sleeping_any(registry.apples.len()) {
            return;
        }
        for h in islands.active_bodies() {
            if let Some(k) = registry.apple_of(h) {
                if self.asleep[k] {
                    self.asleep[k] = false;
                    self.asleep_count -= 1;
                    self.still_time[k] = 0.0;
                    self.mean_force[k] = Vec3::NAN;
                    self.mean_torque[k] = Vec3::NAN;
                    self.dirty = true;
                }
            }
        }
    }

    /// Lists the awake apples again after sleeps and wake-ups. Returns whether the list changed
    /// (whoever keeps lists built on it must rebuild them).
    pub fn refresh_awake(&mut self) -> bool {
        if !self.dirty {
            return false;
        }
        self.dirty = false;
        self.awake.clear();
        for (k, &a) in self.asleep.iter().enumerate() {
            if !a {
                self.awake.push(k as u32);
            }
        }
        true
    }

    /// Wakes the apples asked for (in the layer and in rapier).
    pub fn wake_requested(&mut self, bodies: &mut RigidBodySet, apples: &[AppleEntry]) {
        for k in std::mem::take(&mut self.to_wake) {
            let k = k as usize;
            if !self.asleep[k] {
                continue;
            }
            self.asleep[k] = false;
            self.asleep_count -= 1;
            self.still_time[k] = 0.0;
            self.mean_force[k] = Vec3::NAN;
            self.mean_torque[k] = Vec3::NAN;
            self.dirty = true;
            if let Some(rb) = bodies.get_mut(apples[k].body) {
                rb.wake_up(true);
            }
        }
    }

    /// Puts to sleep the apples that have been still long enough (the rule of [`SleepConfig`];
    /// `gravity` enters the net force).
    #[allow(clippy::too_many_arguments)]
    pub fn decide(
        &mut self,
        cfg: &SleepConfig,
        gravity: Vec3,
        bodies: &mut RigidBodySet,
        apples: &[AppleEntry],
        frame: &mut Frame,
        loads: &mut Loads,
        dt_s: f64,
    ) {
        if !cfg.enabled {
            return;
        }
        for i in 0..self.awake.len() {
            let k = self.awake[i] as usize;
            // Still, supported (touching something) and not accelerating: the net force would not
            // change its speed by the stillness threshold within the stillness time. The force is
            // a running mean over a quarter of the stillness time: an apple held in a pile
            // vibrates (its contact forces swing around their balance at the contacts' own
            // frequencies, hundreds of hertz) while its mean force is nil, and the rule is about
            // the mean (measured on the 1000-apple pile: with the instantaneous force, ~300 still
            // apples stayed awake for 0.7 s after the pile had come to rest).
            let m = apples[k].mass;
            let net = loads.force[k] + gravity * m;
            // The mean runs while the apple is still (NaN: it starts again).
            let share = (4.0 * dt_s / cfg.time_s).min(1.0);
            let last = self.mean_force[k];
            let still = frame.still[k];
            let mean = if !still || last.x.is_nan() {
                net
            } else {
                last + (net - last) * share
            };
            self.mean_force[k] = if still { mean } else { Vec3::NAN };
            let limit = cfg.speed_m_s * m / cfg.time_s;
            let mut resting = frame.count[k] > 0 && mean.length_squared() < limit * limit;
            if apples[k].shape.is_some() {
                // A spheroid tilted off its resting pose is still at the turns of its rocking,
                // with a torque that would set it turning again: the mean torque must not change
                // |w| R by the threshold within the stillness time either (a sphere's contacts
                // leave it no such torque at rest; its rule is unchanged).
                let last = self.mean_torque[k];
                let tau = loads.torque[k];
                let mean_t = if !still || last.x.is_nan() {
                    tau
                } else {
                    last + (tau - last) * share
                };
                self.mean_torque[k] = if still { mean_t } else { Vec3::NAN };
                let a = &apples[k];
                let limit_t = cfg.speed_m_s * a.inertia / (a.radius * cfg.time_s);
                resting &= mean_t.length_squared() < limit_t * limit_t;
            }
            if still && !loads.busy[k] && resting {
                self.still_time[k] += dt_s;
            } else {
                self.still_time[k] = 0.0;
            }
            if self.still_time[k] >= cfg.time_s {
                self.asleep[k] = true;
                self.asleep_count += 1;
                self.dirty = true;
                self.sleep_force[k] = loads.force[k];
                frame.vel[k] = Vec3::ZERO;
                frame.angvel[k] = Vec3::ZERO;
                frame.still[k] = true;
                loads.force[k] = Vec3::ZERO;
                loads.torque[k] = Vec3::ZERO;
                loads.loaded[k] = false;
                if let Some(rb) = bodies.get_mut(apples[k].body) {
                    rb.reset_forces(false);
                    rb.reset_torques(false);
                    rb.sleep();
                }
            }
        }
    }
}
