//! Sleeping: apples at rest stop costing anything (see [`super::SleepConfig`] for the rule).
//!
//! The layer decides, rapier executes: a sleeper is put to sleep in rapier (`RigidBody::sleep`,
//! so rapier does not integrate it) and woken with `wake_up`. Its contacts with other sleepers
//! and with fixed surfaces are frozen (not evaluated); it reports the contact force it carried
//! when it fell asleep. What wakes it is decided from the geometry in [`super::detect`], or by
//! rapier (a body the user moved or pushed shows up in rapier's active set).
//!
//! An apple at rest on a running belt is at rest in the belt's frame: by the same rule (still,
//! supported, no net force, for the stillness time) *in that frame*, with the belt as its only
//! contact, it **rides** the belt ([`Ride`]): rapier carries it as a kinematic body at the belt's
//! velocity (an exact motion: a belt runs at constant velocity, and an apple at rest on it moves
//! with it), its contact is frozen (not evaluated; it reports the force it carried), and it stays
//! on the awake list, so that pair finding, the step control and detection see it move. It is
//! woken, dynamic again at the belt's velocity, the step anything else comes within the search
//! margin of it (an apple or another surface), its belt contact's overlap drifts at all (by 1e-6
//! of itself: the belt's end), or the belt changes. A line's belts carry most of its apples, and a rider costs rapier's
//! kinematic update and its detection, not its contact law (docs/performance.md, "A line at
//! scale").
//!
//! This module owns every piece of sleep state; the rest of the layer reads it (the awake list,
//! who sleeps, who rides) and asks for wake-ups ([`Sleep::request_wake`]).

use super::bodies::BodySets;
use super::config::SleepConfig;
use super::frame::{Frame, Loads};
use super::registry::{AppleEntry, Registry};
use crate::math::Vec3;

/// An apple riding a running belt (see the module's doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Ride {
    /// The belt (surface index).
    pub surface: u32,
    /// The belt's velocity, the apple's (m/s).
    pub velocity: Vec3,
    /// Where its centre was when it began to ride (m), and when (s).
    pub from: Vec3,
    pub since_s: f64,
    /// Until when it rides over its belt's box face well inside the edges, where its one hit
    /// cannot change and detection need not query it (s): NaN until detection first looks
    /// ([`super::surface::time_over_a_box_face`]), -inf when it does not ride over a box face.
    pub face_until_s: f64,
}

impl Ride {
    /// Its centre at time `t_s`: carried at the belt's velocity.
    #[inline]
    pub fn centre_at(&self, t_s: f64) -> Vec3 {
        self.from + self.velocity * (t_s - self.since_s)
    }
}

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
    /// Sleepers (and riders) to wake before the next detection.
    to_wake: Vec<u32>,
    /// Per apple: the belt it rides.
    riding: Vec<Option<Ride>>,
    /// How many apples ride.
    riding_count: usize,
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
            riding: Vec::new(),
            riding_count: 0,
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
        self.riding.resize(n, None);
    }

    /// The belt apple `k` rides, if it does.
    #[inline]
    pub fn ride(&self, k: usize) -> Option<Ride> {
        self.riding.get(k).copied().flatten()
    }

    /// [`Self::ride`], not copied.
    #[inline]
    pub fn ride_ref(&self, k: usize) -> Option<&Ride> {
        self.riding.get(k).and_then(Option::as_ref)
    }

    /// Sets until when rider `k` rides over its belt's face (see [`Ride::face_until_s`]).
    pub fn set_face_until(&mut self, k: usize, t_s: f64) {
        if let Some(r) = self.riding.get_mut(k).and_then(Option::as_mut) {
            r.face_until_s = t_s;
        }
    }

    /// How many apples ride a belt.
    pub fn riding_count(&self) -> usize {
        self.riding_count
    }

    /// Apple `k` left the run: it rides no more (its body is parked by the caller).
    pub fn forget_ride(&mut self, k: usize) {
        if let Some(Some(_)) = self.riding.get(k) {
            self.riding[k] = None;
            self.riding_count -= 1;
        }
    }

    /// Apple `k` starts being still from nothing (woken, or begun to ride).
    fn restart_stillness(&mut self, k: usize) {
        self.still_time[k] = 0.0;
        self.mean_force[k] = Vec3::NAN;
        self.mean_torque[k] = Vec3::NAN;
    }

    /// The riders' centres and velocities at time `t_s` into the frame (rapier does not move
    /// them: they sleep in it while they ride).
    pub fn place_riders(&self, frame: &mut Frame, t_s: f64) {
        if self.riding_count == 0 {
            return;
        }
        for &k in &self.awake {
            let k = k as usize;
            if let Some(ride) = self.riding[k] {
                frame.pos[k] = ride.centre_at(t_s);
                frame.vel[k] = ride.velocity;
                frame.angvel[k] = Vec3::ZERO;
                frame.still[k] = false;
            }
        }
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

    /// The contact force a sleeper (or a rider) carried when it fell asleep (began to ride).
    pub fn sleep_force(&self, k: usize) -> Vec3 {
        self.sleep_force[k]
    }

    /// Asks for apple `k` to be woken before the next detection.
    #[inline]
    pub fn request_wake(&mut self, k: u32) {
        self.to_wake.push(k);
    }

    /// Puts apple `k` to sleep where it is, with no rule asked (tests: sleepers beside awake
    /// apples).
    #[cfg(test)]
    pub fn put_to_sleep(&mut self, k: usize) {
        if !self.asleep[k] {
            self.asleep[k] = true;
            self.asleep_count += 1;
            self.dirty = true;
        }
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
    pub fn notice_rapier_wakeups(&mut self, bodies: &BodySets, registry: &Registry) {
        if !self.sleeping_any(registry.apples.len()) && self.riding_count == 0 {
            return;
        }
        for h in bodies.active() {
            if let Some(k) = registry.apple_of(h) {
                if self.riding[k].is_some() {
                    // A rider rapier woke (the user touched its body): it rides no more.
                    self.to_wake.push(k as u32);
                    continue;
                }
                if self.asleep[k] {
                    self.asleep[k] = false;
                    self.asleep_count -= 1;
                    self.restart_stillness(k);
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

    /// Wakes the apples asked for (in the layer and in rapier); `t_s` is the time of the
    /// current poses (where a rider is put back into rapier).
    pub fn wake_requested(&mut self, bodies: &mut BodySets, apples: &[AppleEntry], t_s: f64) {
        for k in std::mem::take(&mut self.to_wake) {
            let k = k as usize;
            if let Some(ride) = self.riding[k].take() {
                // Awake in rapier again, where the belt has carried it, at the belt's velocity;
                // its contact is evaluated again from this step's detection on.
                self.riding_count -= 1;
                self.restart_stillness(k);
                if let Some(rb) = bodies.get_mut(apples[k].body) {
                    let a = &apples[k];
                    let rot = *rb.rotation();
                    rb.set_translation(ride.centre_at(t_s) - rot * a.offset, false);
                    rb.set_linvel(ride.velocity, false);
                    rb.set_angvel(Vec3::ZERO, false);
                    rb.wake_up(true);
                }
                continue;
            }
            if !self.asleep[k] {
                continue;
            }
            self.asleep[k] = false;
            self.asleep_count -= 1;
            self.restart_stillness(k);
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
        bodies: &mut BodySets,
        apples: &[AppleEntry],
        frame: &mut Frame,
        loads: &mut Loads,
        dt_s: f64,
        t_s: f64,
    ) {
        if !cfg.enabled {
            return;
        }
        let still2 = cfg.speed_m_s * cfg.speed_m_s;
        for i in 0..self.awake.len() {
            let k = self.awake[i] as usize;
            if self.riding[k].is_some() {
                continue;
            }
            // One contact, with a running belt: the rule below holds in the belt's frame (an
            // inertial frame: the net force is the same), and its end is a ride.
            let belt = match frame.carrier[k] {
                Some((s, v)) if cfg.carried && frame.count[k] == 1 && !frame.still[k] => {
                    let (dv, w) = (frame.vel[k] - v, frame.angvel[k]);
                    let r = apples[k].radius;
                    (dv.length_squared() < still2 && w.length_squared() * r * r < still2)
                        .then_some((s, v))
                }
                _ => None,
            };
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
            let still = frame.still[k] || belt.is_some();
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
            // A rider's belt keeps it busy (a moving surface), and it touches nothing else.
            if still && (!loads.busy[k] || belt.is_some()) && resting {
                self.still_time[k] += dt_s;
            } else {
                self.still_time[k] = 0.0;
            }
            if self.still_time[k] >= cfg.time_s {
                if let Some((surface, velocity)) = belt {
                    self.riding[k] = Some(Ride {
                        surface,
                        velocity,
                        from: frame.pos[k],
                        since_s: t_s,
                        face_until_s: f64::NAN,
                    });
                    self.riding_count += 1;
                    self.restart_stillness(k);
                    // The layer carries it (`place_riders`).
                    self.freeze(k, velocity, bodies, apples, frame, loads);
                    continue;
                }
                self.asleep[k] = true;
                self.asleep_count += 1;
                self.dirty = true;
                frame.still[k] = true;
                self.freeze(k, Vec3::ZERO, bodies, apples, frame, loads);
            }
        }
    }

    /// Stops evaluating apple `k` (it falls asleep, or begins to ride a belt): it keeps the
    /// contact force it carries, moves at `velocity` without turning, and rapier holds its body
    /// asleep with no force on it.
    fn freeze(
        &mut self,
        k: usize,
        velocity: Vec3,
        bodies: &mut BodySets,
        apples: &[AppleEntry],
        frame: &mut Frame,
        loads: &mut Loads,
    ) {
        self.sleep_force[k] = loads.force[k];
        frame.vel[k] = velocity;
        frame.angvel[k] = Vec3::ZERO;
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
