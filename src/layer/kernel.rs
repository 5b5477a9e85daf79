//! The force pass: the contact law for every contact seen at the current poses, then the loads
//! of each apple summed in a fixed order.
//!
//! Each contact is evaluated from the layer's per-step arrays (read only) and writes only its own
//! state; its force is added to the loads in slab order. On one thread the two happen together;
//! on several, the contacts are evaluated in parallel into an output per slot and the loads are
//! summed afterwards, still in slab order, so the sums are bit-identical whatever the thread
//! count.

use super::contacts::Contact;
use super::{
    AppleEntry, ContactLayer, Guard, LayerError, SlipSample, StepControl, StepStats, SurfaceEntry,
    SurfaceNow, PARALLEL_MIN_CONTACTS,
};
use crate::contact::{self, theory, ContactConstants, ContactKinematics, LawParts, PairLaw};
use crate::math::{is_finite, Vec3};
use crate::record::events::{ContactSample, OpenContact, Party};
use rapier3d_f64::dynamics::RigidBodyHandle;
use std::sync::Mutex;

/// What the evaluation of one contact hands to the sums.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct ContactOut {
    /// Force on apple `i` (N); the other body gets the opposite.
    force: Vec3,
    /// Point of application (m, world).
    point: Vec3,
    /// The leapfrog kick factor with adaptive steps (1 with a fixed step).
    kick: f64,
    /// Normal force (N).
    normal_force_n: f64,
    /// Tangential slip speed at the contact point (m/s).
    slip_m_s: f64,
    /// Elastic energy 2/5 k u^(5/2) (J).
    elastic_energy_j: f64,
    /// Overlap over the smaller radius.
    overlap_ratio: f64,
}

/// Everything one contact's evaluation reads (all of it shared, none of it written).
struct Ctx<'a> {
    pos: &'a [Vec3],
    vel: &'a [Vec3],
    angvel: &'a [Vec3],
    radius: &'a [f64],
    count: &'a [u16],
    still: &'a [bool],
    apples: &'a [AppleEntry],
    surfaces: &'a [SurfaceEntry],
    surf_now: &'a [SurfaceNow],
    laws: &'a [PairLaw],
    n_mat: usize,
    parts: LawParts,
    relaxation: f64,
    /// `relaxation / (n dt)`: the kill rate of a bound shared by n contacts (0 and 1: the
    /// whole), n < 32.
    kill_rate_by_count: [f64; 32],
    guard: Guard,
    history_cap: usize,
    control: Option<StepControl>,
    record_slips: bool,
    time_s: f64,
    dt_s: f64,
    dt_back: f64,
}

/// The sums the force pass writes.
struct Loads<'a> {
    force: &'a mut [Vec3],
    torque: &'a mut [Vec3],
    kicked_force: &'a mut [Vec3],
    kicked_torque: &'a mut [Vec3],
    busy: &'a mut [bool],
    body_loads: &'a mut Vec<(RigidBodyHandle, Vec3, Vec3)>,
    slips: &'a mut Vec<SlipSample>,
    stats: &'a mut StepStats,
}

impl Ctx<'_> {
    fn name_of(&self, p: Party) -> String {
        match p {
            Party::Apple(j) => self.apples[j as usize].name.to_string(),
            Party::Surface(s) => self.surfaces[s as usize].name.to_string(),
        }
    }

    /// Evaluates one contact at the current poses: the contact law, the guards and the contact
    /// record.
    fn evaluate(&self, c: &mut Contact) -> Result<ContactOut, Box<LayerError>> {
        let i = c.i as usize;
        let ai = &self.apples[i];
        let (pi, ri) = (self.pos[i], self.radius[i]);
        let n = c.normal;
        let u = c.overlap_m;
        // NaN (not computed yet) never equals: computed at the first evaluation.
        if c.consts_curvature != c.curvature2 {
            self.prepare(c)?;
        }
        let law = &self.laws[c.law as usize];
        let k = c.consts;
        let point = contact::geometry::contact_point(pi, ri, n, u, law.share1);
        let v1 = self.vel[i] + self.angvel[i].cross(point - pi);
        // The other body's surface point (belt included), how many contacts share the rate
        // bounds, and the smaller radius.
        let (v2, shared) = match c.other {
            Party::Apple(j) => {
                let j = j as usize;
                (
                    self.vel[j] + self.angvel[j].cross(point - self.pos[j]),
                    self.count[i].max(self.count[j]),
                )
            }
            Party::Surface(s) => {
                let now = &self.surf_now[s as usize];
                let belt = now.belt - n * now.belt.dot(n);
                (now.velocity_at(point) + belt, self.count[i])
            }
        };
        let ke = if self.parts.energy_loss { law.ke } else { 1.0 };
        let time_s = self.time_s;
        // Resting once its impact is over: older than 1.2 times eq. 12's contact time at its
        // approach speed, (1 + 1/sqrt(ke)) / 2 elastic contact times (physics.md section 3).
        let resting = match c.record.as_mut() {
            Some(o) => {
                if c.resting_from_s.is_nan() {
                    let (m_n, k_n) = (k.normal_mass_kg, k.stiffness);
                    let (t_h, _) = o.impact_scale(|v| super::adaptive::impact_scale(m_n, k_n, v));
                    c.resting_from_s =
                        o.start_time_s() + 1.2 * t_h * 0.5 * (1.0 + 1.0 / ke.max(1e-4).sqrt());
                }
                time_s > c.resting_from_s
            }
            None => false,
        };
        let kin = ContactKinematics {
            normal: n,
            overlap_m: u,
            rel_velocity: v1 - v2,
            resting,
        };
        let kill_rate = match self.kill_rate_by_count.get(usize::from(shared)) {
            Some(&r) => r,
            None => self.relaxation / (f64::from(shared) * self.dt_s),
        };
        let resp = contact::evaluate(law, self.parts, &k, &kin, &mut c.xi, kill_rate, self.dt_s);
        if !(resp.normal_force_n.is_finite() && is_finite(resp.force_on_1)) {
            return Err(Box::new(LayerError::NonFinite {
                body: ai.name.to_string(),
                time_s,
            }));
        }
        let ratio = u * c.inv_r_min;
        if ratio > self.guard.max_overlap_ratio {
            return Err(Box::new(LayerError::Unstable {
                a: ai.name.to_string(),
                b: self.name_of(c.other),
                time_s,
                what: format!(
                    "overlap {:.4} mm is {:.1} % of the radius, beyond the {:.0} % limit (Hertz needs u << R): the bodies pass through each other or the step is far too large",
                    u * 1e3,
                    100.0 * ratio,
                    100.0 * self.guard.max_overlap_ratio
                ),
                suggested_dt_s: None,
            }));
        }
        if c.record.is_none() {
            c.record = Some(self.begin(c, &k, &resp)?);
        }
        // The backward span of this force's kick (see the leapfrog kick below).
        let kick_back = match (self.control, c.record.as_ref()) {
            (Some(_), Some(o)) => self.dt_back.min((time_s - o.start_time_s()).max(0.0)),
            _ => self.dt_back,
        };
        let point = point + resp.patch_shift;
        if let Some(open) = c.record.as_mut() {
            open.observe(&ContactSample {
                time_s,
                dt_s: self.dt_s,
                dt_back_s: self.dt_back,
                kick_back_s: kick_back,
                overlap_m: u,
                force_n: resp.normal_force_n,
                contact_radius_m: resp.contact_radius_m,
                pressure_pa: resp.mean_pressure_pa,
                point,
            });
        }
        // Leapfrog kick with variable steps (see `StepControl::gravity`): the force at this pose
        // stands for the impulse from h_back/2 before to h/2 after it. A contact that began within
        // the last step has pushed only since its touch, so its backward share is its age, not
        // h_back (measured: a 6.8 ms step before a belt landing kicked the first contact force
        // 7.3 times, peak 14 N instead of 22 N).
        let kick = match self.control {
            Some(_) => (kick_back + self.dt_s) / (2.0 * self.dt_s),
            None => 1.0,
        };
        Ok(ContactOut {
            force: resp.force_on_1,
            point,
            kick,
            normal_force_n: resp.normal_force_n,
            slip_m_s: if self.record_slips {
                resp.slip_velocity.length()
            } else {
                0.0
            },
            elastic_energy_j: resp.elastic_energy_j,
            overlap_ratio: ratio,
        })
    }

    /// The constants of a contact's law, once (and again if its curvature changes).
    fn prepare(&self, c: &mut Contact) -> Result<(), Box<LayerError>> {
        let i = c.i as usize;
        let ai = &self.apples[i];
        let ri = self.radius[i];
        let (m2, inv_t2, inv_n2, r_min) = match c.other {
            Party::Apple(j) => {
                let aj = &self.apples[j as usize];
                (
                    aj.material,
                    aj.inv_tangential_mass,
                    1.0 / aj.mass,
                    ri.min(self.radius[j as usize]),
                )
            }
            Party::Surface(s) => {
                let inv = self.surf_now[s as usize].inv_mass;
                (self.surfaces[s as usize].material, inv, inv, ri)
            }
        };
        let Some(r_star) = contact::normal::effective_radius(1.0 / ri, c.curvature2) else {
            return Err(Box::new(LayerError::Conforming {
                apple: ai.name.to_string(),
                surface: self.name_of(c.other),
                apple_radius_m: ri,
                surface_radius_m: if c.curvature2 != 0.0 {
                    -1.0 / c.curvature2
                } else {
                    f64::INFINITY
                },
            }));
        };
        c.law = (ai.material.0 as usize * self.n_mat + m2.0 as usize) as u32;
        c.consts = ContactConstants::new(
            &self.laws[c.law as usize],
            r_star,
            1.0 / (1.0 / ai.mass + inv_n2),
            1.0 / (ai.inv_tangential_mass + inv_t2),
        );
        c.consts_curvature = c.curvature2;
        c.inv_r_min = 1.0 / r_min;
        Ok(())
    }

    /// Opens the record of a contact at its first evaluation, after the stability guard: the
    /// elastic contact time at this approach speed must span enough steps (physics.md
    /// section 10).
    fn begin(
        &self,
        c: &Contact,
        k: &ContactConstants,
        resp: &contact::ContactResponse,
    ) -> Result<OpenContact, Box<LayerError>> {
        let v_app = resp.overlap_rate_m_s;
        if v_app > 0.0 && self.guard.min_steps_per_impact > 0.0 {
            let t_h = theory::elastic_impact(k.normal_mass_kg, v_app, k.stiffness, k.r_star_m)
                .contact_time_s;
            let steps = t_h / self.dt_s;
            if steps < self.guard.min_steps_per_impact * (1.0 - 1e-6) {
                let dt_ok = t_h / self.guard.min_steps_per_impact;
                return Err(Box::new(LayerError::Unstable {
                    a: self.apples[c.i as usize].name.to_string(),
                    b: self.name_of(c.other),
                    time_s: self.time_s,
                    what: format!(
                        "impact at {v_app:.4} m/s lasts {:.4} ms, only {steps:.1} steps of {:e} s (need >= {}); use time_step_s <= {dt_ok:.3e}",
                        t_h * 1e3,
                        self.dt_s,
                        self.guard.min_steps_per_impact
                    ),
                    suggested_dt_s: Some(dt_ok),
                }));
            }
        }
        let mut open = OpenContact::begin(
            self.time_s,
            self.dt_back,
            c.overlap_m,
            v_app,
            self.history_cap,
        );
        if let (Some(ctl), Party::Surface(_)) = (self.control, c.other) {
            // Rapier's velocities are staggered half a step behind the poses: at long steps the
            // velocity that carried the apple in is the one of mid-step, not of the touch. Add
            // gravity's share from mid-step to touch (two apples fall alike: no share).
            let since_touch = self.time_s - open.start_time_s();
            let a_n = -ctl.gravity.dot(c.normal);
            let v = v_app + a_n * (0.5 * self.dt_back - since_touch);
            open.set_approach_speed(v.max(0.0));
        }
        Ok(open)
    }

    /// Adds one evaluated contact to the loads of its bodies.
    #[inline]
    fn add_load(&self, loads: &mut Loads, i: u32, other: Party, o: &ContactOut) {
        let ii = i as usize;
        let (f, point) = (o.force, o.point);
        let arm_i = point - self.pos[ii];
        loads.force[ii] += f;
        loads.torque[ii] += arm_i.cross(f);
        let control = self.control.is_some();
        let fk = f * o.kick;
        if control {
            loads.kicked_force[ii] += fk;
            loads.kicked_torque[ii] += arm_i.cross(fk);
        }
        match other {
            Party::Apple(j) => {
                let j = j as usize;
                // A neighbour that is not still keeps an apple awake.
                if !self.still[j] {
                    loads.busy[ii] = true;
                }
                if !self.still[ii] {
                    loads.busy[j] = true;
                }
                let arm_j = point - self.pos[j];
                loads.force[j] -= f;
                loads.torque[j] -= arm_j.cross(f);
                if control {
                    loads.kicked_force[j] -= fk;
                    loads.kicked_torque[j] -= arm_j.cross(fk);
                }
            }
            Party::Surface(s) => {
                let now = &self.surf_now[s as usize];
                if now.moving {
                    // On a belt or a moving part: the apple stays awake.
                    loads.busy[ii] = true;
                }
                if let Some(b) = now.dynamic_body {
                    loads.body_loads.push((b, -fk, point));
                }
            }
        }
        loads.stats.elastic_energy_j += o.elastic_energy_j;
        loads.stats.max_overlap_ratio = loads.stats.max_overlap_ratio.max(o.overlap_ratio);
        if self.record_slips {
            let sample = SlipSample {
                apple: i,
                other,
                slip_m_s: o.slip_m_s,
                normal_force_n: o.normal_force_n,
                point,
            };
            loads.slips.push(sample);
            if let Party::Apple(j) = other {
                loads.slips.push(SlipSample {
                    apple: j,
                    other: Party::Apple(i),
                    ..sample
                });
            }
        }
    }
}

impl ContactLayer {
    /// The force pass: every contact seen by this step's detection evaluated and added to the
    /// loads in slot order (evaluated in parallel on rayon's current pool when there are enough
    /// of them).
    pub(super) fn force_pass(&mut self, time_s: f64, dt_s: f64) -> Result<(), LayerError> {
        self.slips.clear();
        let epoch = self.epoch;
        let ctx = Ctx {
            pos: &self.pos,
            vel: &self.vel,
            angvel: &self.angvel,
            radius: &self.radius,
            count: &self.count,
            still: &self.still,
            apples: &self.apples,
            surfaces: &self.surfaces,
            surf_now: &self.surf_now,
            laws: &self.laws,
            n_mat: self.materials.len(),
            parts: self.config.parts,
            relaxation: self.config.tangential_relaxation,
            kill_rate_by_count: std::array::from_fn(|n| {
                self.config.tangential_relaxation / (n.max(1) as f64 * dt_s)
            }),
            guard: self.config.guard,
            history_cap: self.config.force_history_cap,
            control: self.config.step_control,
            record_slips: self.config.record_slips,
            time_s,
            dt_s,
            dt_back: self.dt_back,
        };
        let mut loads = Loads {
            force: &mut self.force,
            torque: &mut self.torque,
            kicked_force: &mut self.kicked_force,
            kicked_torque: &mut self.kicked_torque,
            busy: &mut self.busy,
            body_loads: &mut self.body_loads,
            slips: &mut self.slips,
            stats: &mut self.stats,
        };
        let (contacts, stamps) = self.contacts.slots_and_stamps();
        let parallel =
            loads.stats.contacts >= PARALLEL_MIN_CONTACTS && rayon::current_num_threads() > 1;
        if !parallel {
            for (c, &stamp) in contacts.iter_mut().zip(stamps) {
                if stamp == epoch {
                    let o = ctx.evaluate(c).map_err(|e| *e)?;
                    ctx.add_load(&mut loads, c.i, c.other, &o);
                }
            }
            return Ok(());
        }
        use rayon::prelude::*;
        self.outs.resize(contacts.len(), ContactOut::default());
        // The error of the lowest slot wins, whatever the thread count.
        let errors = Mutex::new(Vec::new());
        contacts
            .par_iter_mut()
            .zip(self.outs.par_iter_mut())
            .zip(stamps.par_iter())
            .enumerate()
            .with_min_len(64)
            .for_each(|(k, ((c, o), &stamp))| {
                if stamp == epoch {
                    match ctx.evaluate(c) {
                        Ok(r) => *o = r,
                        Err(e) => errors.lock().expect("no panic holds it").push((k, e)),
                    }
                }
            });
        let first_error = errors
            .into_inner()
            .expect("no panic holds it")
            .into_iter()
            .min_by_key(|e: &(usize, Box<LayerError>)| e.0);
        if let Some((_, e)) = first_error {
            return Err(*e);
        }
        for ((c, o), &stamp) in contacts.iter().zip(&self.outs).zip(stamps) {
            if stamp == epoch {
                ctx.add_load(&mut loads, c.i, c.other, o);
            }
        }
        Ok(())
    }
}
