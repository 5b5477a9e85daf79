//! Sleeping: apples at rest stop costing anything (see [`super::SleepConfig`] for the rule).
//!
//! The layer decides, rapier executes: a sleeper is put to sleep in rapier (`RigidBody::sleep`,
//! so rapier does not integrate it) and woken with `wake_up`. Its contacts with other sleepers
//! and with fixed surfaces are frozen (not evaluated); it reports the contact force it carried
//! when it fell asleep. What wakes it is decided from the geometry in [`super::detect`].

use super::ContactLayer;
use crate::math::Vec3;
use rapier3d_f64::dynamics::RigidBodySet;

impl ContactLayer {
    /// Wakes apple `k` (in the layer and in rapier).
    pub(super) fn wake(&mut self, bodies: &mut RigidBodySet, k: usize) {
        if self.active[k] {
            return;
        }
        self.active[k] = true;
        self.asleep[k] = false;
        self.asleep_count -= 1;
        self.still_time[k] = 0.0;
        self.mean_force[k] = Vec3::NAN;
        self.awake_dirty = true;
        self.stats_wakeups += 1;
        if let Some(rb) = bodies.get_mut(self.apples[k].body) {
            rb.wake_up(true);
        }
    }

    /// Puts to sleep the apples that have been still long enough.
    pub(super) fn sleep_decisions(&mut self, bodies: &mut RigidBodySet, dt_s: f64) {
        let cfg = self.config.sleep;
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
            let m = self.apples[k].mass;
            let net = self.force[k] + self.gravity * m;
            // The mean runs while the apple is still (NaN: it starts again).
            let share = (4.0 * dt_s / cfg.time_s).min(1.0);
            let last = self.mean_force[k];
            let mean = if !self.still[k] || last.x.is_nan() {
                net
            } else {
                last + (net - last) * share
            };
            self.mean_force[k] = if self.still[k] { mean } else { Vec3::NAN };
            let limit = cfg.speed_m_s * m / cfg.time_s;
            let resting = self.count[k] > 0 && mean.length_squared() < limit * limit;
            if self.still[k] && !self.busy[k] && resting {
                self.still_time[k] += dt_s;
            } else {
                self.still_time[k] = 0.0;
            }
            if self.still_time[k] >= cfg.time_s {
                self.active[k] = false;
                self.asleep[k] = true;
                self.asleep_count += 1;
                self.awake_dirty = true;
                self.sleep_force[k] = self.force[k];
                self.vel[k] = Vec3::ZERO;
                self.angvel[k] = Vec3::ZERO;
                self.still[k] = true;
                self.stats_sleeps += 1;
                self.force[k] = Vec3::ZERO;
                self.torque[k] = Vec3::ZERO;
                self.loaded[k] = false;
                if let Some(rb) = bodies.get_mut(self.apples[k].body) {
                    rb.reset_forces(false);
                    rb.reset_torques(false);
                    rb.sleep();
                }
            }
        }
    }
}
