//! The force pass: the contact law for every contact seen at the current poses, then the loads
//! of each apple summed in a fixed order.
//!
//! Each contact is evaluated from the layer's per-step arrays (read only) and writes only its own
//! state; its force is added to the loads in slab order. On one thread the two happen together;
//! on several, blocks of contacts are evaluated in parallel into an output per slot (each thread
//! first its own share of the slab, then the others'), and the calling thread adds each finished
//! block to the loads in slab order while the others evaluate on, so the sums are bit-identical
//! whatever the thread count and take no serial pass of their own.

use super::clock::StepClock;
use super::config::LayerConfig;
use super::contacts::{Contact, ContactStore};
use super::frame::{Frame, Loads};
use super::grid::NONE;
use super::outputs::{Outputs, PadBottom, SlipSample};
use super::registry::Registry;
use super::scene::SurfaceNow;
use super::LayerError;
use crate::contact::{self, theory, ContactConstants, ContactKinematics};
use crate::math::{is_finite, Vec3};
use crate::record::events::{ContactSample, OpenContact, Party, Rotation};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Mutex;

/// Contacts per step from which the force pass runs in parallel (below that, rayon's overhead
/// outweighs the work). The results do not depend on it.
const PARALLEL_MIN_CONTACTS: usize = 256;

/// Slots per block of the parallel force pass (see [`Kernel::run`]).
const SUM_BLOCK: usize = 128;

/// A block of slots of the parallel force pass: its contacts, their outputs and stamps, and the
/// first error its evaluation met (the index in the block, the error).
struct Block<'a> {
    slots: &'a mut [Contact],
    outs: &'a mut [ContactOut],
    stamps: &'a [u64],
    error: Option<(usize, Box<LayerError>)>,
}

/// Marks a block of the parallel force pass evaluated when dropped.
struct Done<'a>(&'a AtomicBool);

impl Drop for Done<'_> {
    fn drop(&mut self) {
        self.0.store(true, Ordering::Release);
    }
}

/// What the evaluation of one contact hands to the sums.
#[derive(Debug, Clone, Copy)]
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
    /// Rolling- and twisting-resistance torque on apple `i` (N m); the other body gets the
    /// opposite.
    torque: Vec3,
    /// A pad bottomed out under this contact for the first time this step: which limit, and the
    /// pad's compression there.
    pad_bottomed: Option<(contact::padding::PadLimit, f64)>,
    /// The contact's apple `i` and other body, so that the sums read the output alone (not the
    /// contact, which stays with the thread that examines and evaluates it).
    i: u32,
    other: Party,
}

impl Default for ContactOut {
    fn default() -> Self {
        Self {
            force: Vec3::ZERO,
            point: Vec3::ZERO,
            kick: 0.0,
            normal_force_n: 0.0,
            slip_m_s: 0.0,
            elastic_energy_j: 0.0,
            overlap_ratio: 0.0,
            torque: Vec3::ZERO,
            pad_bottomed: None,
            i: 0,
            other: Party::Apple(0),
        }
    }
}

/// Everything one contact's evaluation reads (all of it shared, none of it written): the
/// registry, the frame, the surfaces as seen this step and the settings, plus the step.
struct Ctx<'a> {
    registry: &'a Registry,
    frame: &'a Frame,
    surf_now: &'a [SurfaceNow],
    config: &'a LayerConfig,
    /// `relaxation / (n dt)`: the kill rate of a bound shared by n contacts (0 and 1: the
    /// whole), n < 32.
    kill_rate_by_count: [f64; 32],
    /// `bound * (1 / (n dt))`, n < 32 (0 and 1: the whole): the largest gamma_t / m_t of a
    /// `history` dashpot shared by n contacts (`ContactKinematics::history_damping_limit_1_s`).
    history_limit_by_count: [f64; 32],
    time_s: f64,
    dt_s: f64,
    dt_back: f64,
}

/// The sums the force pass writes.
struct Sums<'a> {
    loads: &'a mut Loads,
    out: &'a mut Outputs,
}

impl Ctx<'_> {
    fn name_of(&self, p: Party) -> String {
        self.registry.name_of(p).to_string()
    }

    /// Evaluates one contact at the current poses: the contact law, the guards and the contact
    /// record.
    fn evaluate(&self, c: &mut Contact) -> Result<ContactOut, Box<LayerError>> {
        let i = c.i as usize;
        let ai = &self.registry.apples[i];
        let (pi, ri) = (self.frame.pos[i], self.frame.radius[i]);
        let n = c.normal;
        let u = c.overlap_m;
        // NaN (not computed yet) never equals: computed at the first evaluation.
        if c.consts_curvature != c.curvature2 {
            match c.shaped {
                // A spheroid's R_k moves as it turns: only what depends on it, every step.
                Some(sh) if !c.consts_curvature.is_nan() && c.consts.pad.is_none() => {
                    self.reshape(c, sh)?
                }
                _ => self.prepare(c)?,
            }
        }
        let law = &self.registry.laws()[c.law as usize];
        let k = &c.consts;
        let point = match &c.shaped {
            Some(sh) => pi + sh.arm + n * (u * law.share1),
            None => contact::geometry::contact_point(pi, ri, n, u, law.share1),
        };
        let v1 = self.frame.vel[i] + self.frame.angvel[i].cross(point - pi);
        // The other body's surface point (belt included), how many contacts share the rate
        // bounds, and the smaller radius.
        let (v2, shared) = match c.other {
            Party::Apple(j) => {
                let j = j as usize;
                (
                    self.frame.vel[j] + self.frame.angvel[j].cross(point - self.frame.pos[j]),
                    self.frame.count[i].max(self.frame.count[j]),
                )
            }
            Party::Surface(s) => {
                let now = &self.surf_now[s as usize];
                let belt = now.belt - n * now.belt.dot(n);
                (now.velocity_at(point) + belt, self.frame.count[i])
            }
        };
        let ke = if self.config.parts.energy_loss {
            law.ke
        } else {
            1.0
        };
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
                    o.set_impact_deadline(c.resting_from_s);
                }
                time_s > c.resting_from_s
            }
            None => false,
        };
        let rel_velocity = v1 - v2;
        let rate = -rel_velocity.dot(n);
        // The free relative acceleration of the overlap (everything but this contact's force:
        // gravity, the other contacts' loads), from the last step: its change of rate plus what
        // this contact's own force took off it. Before a step is known: gravity onto a surface,
        // nothing between two apples (they fall alike).
        // Impacts keep the paper's law as validated (their step mean counts the contact's own
        // force alone: the free acceleration is negligible beside it); resting contacts, which
        // carry the load, take it into account.
        let free_accel = match c.record.as_ref() {
            _ if !resting => 0.0,
            Some(o) if c.prev_rate.is_finite() && self.dt_back > 0.0 => {
                (rate - c.prev_rate) / self.dt_back + o.last_force_n() * k.inv_normal_mass
            }
            _ => match c.other {
                Party::Apple(_) => 0.0,
                Party::Surface(_) => -self.config.gravity.dot(n),
            },
        };
        c.prev_rate = rate;
        let (kill_rate, history_limit) = match (
            self.kill_rate_by_count.get(usize::from(shared)),
            self.history_limit_by_count.get(usize::from(shared)),
        ) {
            (Some(&r), Some(&h)) => (r, h),
            _ => {
                let n_dt = f64::from(shared) * self.dt_s;
                (
                    self.config.tangential_relaxation / n_dt,
                    self.config.history_dashpot_bound * (1.0 / n_dt),
                )
            }
        };
        let kin = ContactKinematics {
            normal: n,
            overlap_m: u,
            rel_velocity,
            resting,
            free_accel,
            history_damping_limit_1_s: history_limit,
        };
        let resp = contact::evaluate(
            law,
            self.config.parts,
            k,
            &kin,
            &mut c.xi,
            kill_rate,
            self.dt_s,
        );
        // Rolling and twisting resistance (pure couples), only for the pairs that have them.
        let rolling = law.models.rolling != contact::RollingModel::None;
        let twisting =
            law.models.twisting != contact::TwistingModel::None && self.config.parts.friction;
        let torque = if !rolling && !twisting {
            Vec3::ZERO
        } else {
            let w2 = match c.other {
                Party::Apple(j) => self.frame.angvel[j as usize],
                Party::Surface(s) => self.surf_now[s as usize].ang,
            };
            let w_rel = self.frame.angvel[i] - w2;
            let roll = if rolling {
                contact::rolling_torque(
                    law,
                    k,
                    n,
                    w_rel,
                    &resp,
                    &mut c.rolling,
                    kill_rate,
                    self.dt_s,
                )
            } else {
                Vec3::ZERO
            };
            if twisting {
                roll + contact::twisting_torque(law, k, n, w_rel, &resp, kill_rate)
            } else {
                roll
            }
        };
        if !(resp.normal_force_n.is_finite() && is_finite(resp.force_on_1)) {
            return Err(Box::new(LayerError::NonFinite {
                body: ai.name.to_string(),
                time_s,
            }));
        }
        let ratio = u * c.inv_r_min;
        if ratio > self.config.guard.max_overlap_ratio {
            return Err(Box::new(LayerError::Unstable {
                a: ai.name.to_string(),
                b: self.name_of(c.other),
                time_s,
                what: format!(
                    "overlap {:.4} mm is {:.1} % of the radius, beyond the {:.0} % limit (Hertz needs u << R): the bodies pass through each other or the step is far too large",
                    u * 1e3,
                    100.0 * ratio,
                    100.0 * self.config.guard.max_overlap_ratio
                ),
                suggested_dt_s: None,
            }));
        }
        if c.record.is_none() {
            c.record = Some(self.begin(c, k, &resp)?);
        }
        // Warned once per contact.
        // A pad's limits, each warned once per contact (the further one may follow the first).
        let pad_bottomed = match (resp.pad_bottomed, &k.pad) {
            (true, Some(pad)) => pad
                .limit_at(u)
                .filter(|(l, _)| c.pad_limit.is_none_or(|seen| *l > seen)),
            _ => None,
        };
        if let Some((l, _)) = pad_bottomed {
            c.pad_limit = Some(l);
        }
        // The backward span of this force's kick (see the leapfrog kick below).
        let kick_back = match (self.config.step_control, c.record.as_ref()) {
            (Some(_), Some(o)) => self.dt_back.min((time_s - o.start_time_s()).max(0.0)),
            _ => self.dt_back,
        };
        let point = point + resp.patch_shift;
        if let Some(open) = c.record.as_mut() {
            // A pad's shares of the deformation and of the loss change as it is squeezed
            // (contact::share); the others' were set when the contact opened.
            if let Some(pad) = &k.pad {
                let (ind, energy) = pad.apple_shares(u);
                open.set_shares(ind, energy);
            }
            open.observe(&ContactSample {
                time_s,
                dt_s: self.dt_s,
                dt_back_s: self.dt_back,
                kick_back_s: kick_back,
                overlap_m: u,
                force_n: resp.normal_force_n,
                contact_radius_m: resp.area_radius_m,
                pressure_pa: resp.mean_pressure_pa,
                point,
                normal: n,
                normal_velocities: [
                    self.frame.vel[i].dot(n),
                    match c.other {
                        Party::Apple(j) => self.frame.vel[j as usize].dot(n),
                        // A belt moves along its own plane; a moving part (a kinematic body) may
                        // move along the normal too.
                        Party::Surface(s) => {
                            let now = &self.surf_now[s as usize];
                            if now.moving {
                                now.velocity_at(point).dot(n)
                            } else {
                                0.0
                            }
                        }
                    },
                ],
            });
            if open.peak_raised() {
                open.place_peak([
                    self.frame.rot[i],
                    match c.other {
                        Party::Apple(j) => self.frame.rot[j as usize],
                        Party::Surface(_) => Rotation::IDENTITY,
                    },
                ]);
            }
        }
        // Leapfrog kick with variable steps (see `StepControl::gravity`): the force at this pose
        // stands for the impulse from h_back/2 before to h/2 after it. A contact that began within
        // the last step has pushed only since its touch, so its backward share is its age, not
        // h_back (measured: a 6.8 ms step before a belt landing kicked the first contact force
        // 7.3 times, peak 14 N instead of 22 N).
        let kick = match self.config.step_control {
            Some(_) => (kick_back + self.dt_s) / (2.0 * self.dt_s),
            None => 1.0,
        };
        Ok(ContactOut {
            force: resp.force_on_1,
            point,
            kick,
            normal_force_n: resp.normal_force_n,
            slip_m_s: if self.config.record_slips {
                resp.slip_velocity.length()
            } else {
                0.0
            },
            elastic_energy_j: resp.elastic_energy_j,
            overlap_ratio: ratio,
            torque,
            pad_bottomed,
            i: c.i,
            other: c.other,
        })
    }

    /// The constants of a contact's law, once (and again if its curvature changes).
    fn prepare(&self, c: &mut Contact) -> Result<(), Box<LayerError>> {
        let i = c.i as usize;
        let ai = &self.registry.apples[i];
        let ri = self.frame.radius[i];
        let mut pad = None;
        // A spheroid's levers: its contact point's distance from its centre.
        let (lever1, lever2) = match &c.shaped {
            Some(sh) => (sh.arm.length(), sh.lever2_m),
            None => (ri, f64::NAN),
        };
        let (m2, inv_t2, inv_n2, r_min, inv_i2, inv_spin2) = match c.other {
            Party::Apple(j) => {
                let aj = &self.registry.apples[j as usize];
                let l2 = if lever2.is_nan() { aj.radius } else { lever2 };
                (
                    aj.material,
                    aj.inv_tangential_mass,
                    1.0 / aj.mass,
                    ri.min(self.frame.radius[j as usize]),
                    1.0 / (aj.inertia + aj.mass * l2 * l2),
                    1.0 / aj.inertia,
                )
            }
            Party::Surface(s) => {
                let inv = self.surf_now[s as usize].inv_mass;
                let surf = &self.registry.surfaces[s as usize];
                // A padded surface: the apple touches the pad (its law: friction, damping), the
                // substrate below.
                pad = surf.padding.map(|p| (p, surf.material));
                (
                    surf.padding.map_or(surf.material, |p| p.material),
                    inv + surf.turned_by_contacts.unwrap_or(0.0),
                    inv,
                    ri,
                    0.0,
                    0.0,
                )
            }
        };
        let r_star = match &c.shaped {
            Some(sh) => Some(sh.r_star_m).filter(|r| r.is_finite()),
            None => contact::normal::effective_radius(1.0 / ri, c.curvature2),
        };
        let Some(r_star) = r_star else {
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
        c.law = self.registry.law_index(ai.material, m2) as u32;
        c.consts = ContactConstants::new(
            &self.registry.laws()[c.law as usize],
            r_star,
            1.0 / (1.0 / ai.mass + inv_n2),
            1.0 / (ai.inv_tangential_mass + inv_t2),
        );
        // Moments about the contact point, I + m R^2 (LIGGGHTS epsd).
        c.consts.rolling_inertia_kg_m2 =
            1.0 / (1.0 / (ai.inertia + ai.mass * lever1 * lever1) + inv_i2);
        c.consts.spin_inertia_kg_m2 = 1.0 / (1.0 / ai.inertia + inv_spin2);
        if let Some(sh) = &c.shaped {
            // The true ellipse's area, pi a b = pi R_a u.
            c.consts.area_scale = (sh.area_radius_m / r_star).sqrt();
        } else if let Party::Surface(s) = c.other {
            // A roller's side (the only surface hit with a positive curvature on a cylinder):
            // the true area of the ellipse, pi a b = pi R_a u, for the recorded area and pressure.
            let rr = self.surf_now[s as usize].cylinder_radius_m;
            if let (Some(rr), true) = (rr, c.curvature2 > 0.0) {
                let h = contact::elliptic::sphere_on_cylinder(ri, rr);
                c.consts.area_scale = (h.area_radius_m / h.stiffness_radius_m).sqrt();
            }
        }
        c.consts.pad = pad.map(|(p, substrate)| {
            // The substrate's loss factor, or the apple-pad pair's own (contact::share).
            let law = &self.registry.laws()[c.law as usize];
            let [eta_apple, eta_pad] = law.loss_factors;
            let substrate = self.registry.material(substrate);
            let eta_sub = substrate
                .loss_factor
                .unwrap_or(contact::share::pair_loss_factor(law.ke.sqrt()));
            Box::new(contact::padding::PadConstants::new(
                self.registry.material(ai.material),
                self.registry.material(p.material),
                substrate,
                p.thickness_m,
                r_star,
                [eta_apple, eta_pad, eta_sub],
            ))
        });
        c.consts_curvature = c.curvature2;
        c.inv_r_min = 1.0 / c.shaped.map_or(r_min, |sh| sh.r_min_m);
        Ok(())
    }

    /// A spheroid contact's constants after its R_k changed (the apple turned): stiffness and
    /// the ellipse's area scale, as [`Self::prepare`] makes them. The rest (the law, the masses,
    /// the moments about the contact point with the lever of its first step) stays.
    fn reshape(&self, c: &mut Contact, sh: super::contacts::Shaped) -> Result<(), Box<LayerError>> {
        if !sh.r_star_m.is_finite() {
            // Conforming now: prepare refuses it, naming the pair.
            return self.prepare(c);
        }
        let law = &self.registry.laws()[c.law as usize];
        let sqrt_r_star = sh.r_star_m.sqrt();
        c.consts.r_star_m = sh.r_star_m;
        c.consts.sqrt_r_star = sqrt_r_star;
        c.consts.stiffness = 4.0 / 3.0 * law.e_star_pa * sqrt_r_star;
        c.consts.area_scale = (sh.area_radius_m / sh.r_star_m).sqrt();
        c.consts_curvature = c.curvature2;
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
        if v_app > 0.0 && self.config.guard.min_steps_per_impact > 0.0 {
            let t_h = theory::elastic_impact(k.normal_mass_kg, v_app, k.stiffness, k.r_star_m)
                .contact_time_s;
            let steps = t_h / self.dt_s;
            if steps < self.config.guard.min_steps_per_impact * (1.0 - 1e-6) {
                let dt_ok = t_h / self.config.guard.min_steps_per_impact;
                return Err(Box::new(LayerError::Unstable {
                    a: self.registry.apples[c.i as usize].name.to_string(),
                    b: self.name_of(c.other),
                    time_s: self.time_s,
                    what: format!(
                        "impact at {v_app:.4} m/s lasts {:.4} ms, only {steps:.1} steps of {:e} s (need >= {}); use time_step_s <= {dt_ok:.3e}",
                        t_h * 1e3,
                        self.dt_s,
                        self.config.guard.min_steps_per_impact
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
            self.config.force_history_cap,
            self.config.force_history_span,
        );
        // The apple's shares of the deformation and of the loss (contact::share): the pair
        // law's, once (a pad's are set pose by pose).
        let law = &self.registry.laws()[c.law as usize];
        open.set_shares(law.share1, law.energy_share1);
        if let (Some(_), Party::Surface(_)) = (self.config.step_control, c.other) {
            // Rapier's velocities are staggered half a step behind the poses: at long steps the
            // velocity that carried the apple in is the one of mid-step, not of the touch. Add
            // gravity's share from mid-step to touch (two apples fall alike: no share).
            let since_touch = self.time_s - open.start_time_s();
            let a_n = -self.config.gravity.dot(c.normal);
            let v = v_app + a_n * (0.5 * self.dt_back - since_touch);
            open.set_approach_speed(v.max(0.0));
        }
        Ok(open)
    }

    /// Adds one evaluated contact to the loads of its bodies.
    #[inline(always)]
    fn add_load(&self, sums: &mut Sums, i: u32, other: Party, o: &ContactOut) {
        let loads = &mut *sums.loads;
        let ii = i as usize;
        let (f, point) = (o.force, o.point);
        let arm_i = point - self.frame.pos[ii];
        loads.force[ii] += f;
        loads.torque[ii] += arm_i.cross(f);
        let control = self.config.step_control.is_some();
        let fk = f * o.kick;
        if control {
            loads.kicked_force[ii] += fk;
            loads.kicked_torque[ii] += arm_i.cross(fk);
        }
        let couple = o.torque != Vec3::ZERO;
        if couple {
            loads.torque[ii] += o.torque;
            if control {
                loads.kicked_torque[ii] += o.torque * o.kick;
            }
        }
        match other {
            Party::Apple(j) => {
                let j = j as usize;
                // A neighbour that is not still keeps an apple awake.
                if !self.frame.still[j] {
                    loads.busy[ii] = true;
                }
                if !self.frame.still[ii] {
                    loads.busy[j] = true;
                }
                let arm_j = point - self.frame.pos[j];
                loads.force[j] -= f;
                loads.torque[j] -= arm_j.cross(f);
                if control {
                    loads.kicked_force[j] -= fk;
                    loads.kicked_torque[j] -= arm_j.cross(fk);
                }
                if couple {
                    loads.torque[j] -= o.torque;
                    if control {
                        loads.kicked_torque[j] -= o.torque * o.kick;
                    }
                }
            }
            Party::Surface(s) => {
                let now = &self.surf_now[s as usize];
                if now.moving {
                    // On a belt or a moving part: the apple stays awake.
                    loads.busy[ii] = true;
                }
                if let Some(limit) = o.pad_bottomed {
                    sums.out.pad_bottoms.push(PadBottom {
                        apple: i,
                        surface: s,
                        time_s: self.time_s,
                        limit,
                    });
                }
                if let Some(b) = now.dynamic_body {
                    loads.body_loads.push((b, -fk, point));
                }
                if self.registry.surfaces[s as usize]
                    .turned_by_contacts
                    .is_some()
                {
                    loads
                        .surface_reactions
                        .push((super::SurfaceId(s), -fk, point));
                }
            }
        }
        sums.out.stats.elastic_energy_j += o.elastic_energy_j;
        sums.out.stats.max_overlap_ratio = sums.out.stats.max_overlap_ratio.max(o.overlap_ratio);
        if self.config.record_slips {
            let sample = SlipSample {
                apple: i,
                other,
                slip_m_s: o.slip_m_s,
                normal_force_n: o.normal_force_n,
                point,
            };
            sums.out.slips.push(sample);
            if let Party::Apple(j) = other {
                sums.out.slips.push(SlipSample {
                    apple: j,
                    other: Party::Apple(i),
                    ..sample
                });
            }
        }
    }
}

/// What the force pass reads: the registry, the frame, the surfaces as seen this step, the
/// settings and the clock.
pub(super) struct Inputs<'a> {
    pub registry: &'a Registry,
    pub frame: &'a Frame,
    pub surf_now: &'a [SurfaceNow],
    pub config: &'a LayerConfig,
    pub clock: &'a StepClock,
    /// Detection's split of the slab among its runs of pairs
    /// ([`super::detect::Detection::slab_shares`]; empty: none).
    pub slab_shares: &'a [u32],
}

/// The force pass and its scratch: one output per contact slot, for the parallel evaluation.
#[derive(Debug, Default)]
pub(super) struct Kernel {
    outs: Vec<ContactOut>,
}

impl Kernel {
    /// Every contact seen by this step's detection (stamped `epoch`) evaluated and added to the
    /// loads in slot order (evaluated in parallel on rayon's current pool when there are enough
    /// of them).
    pub fn run(
        &mut self,
        inputs: Inputs,
        contacts: &mut ContactStore,
        epoch: u64,
        loads: &mut Loads,
        out: &mut Outputs,
        dt_s: f64,
    ) -> Result<(), LayerError> {
        out.slips.clear();
        let relaxation = inputs.config.tangential_relaxation;
        let slab_shares = inputs.slab_shares;
        let ctx = Ctx {
            registry: inputs.registry,
            frame: inputs.frame,
            surf_now: inputs.surf_now,
            config: inputs.config,
            kill_rate_by_count: std::array::from_fn(|n| relaxation / (n.max(1) as f64 * dt_s)),
            history_limit_by_count: std::array::from_fn(|n| {
                inputs.config.history_dashpot_bound * (1.0 / (n.max(1) as f64 * dt_s))
            }),
            time_s: inputs.clock.time_s,
            dt_s,
            dt_back: inputs.clock.dt_back,
        };
        let parallel =
            out.stats.contacts >= PARALLEL_MIN_CONTACTS && rayon::current_num_threads() > 1;
        let mut sums = Sums { loads, out };
        let (slots, stamps) = contacts.slots_and_stamps();
        if !parallel {
            for (c, &stamp) in slots.iter_mut().zip(stamps) {
                if stamp == epoch {
                    let o = ctx.evaluate(c).map_err(|e| *e)?;
                    ctx.add_load(&mut sums, c.i, c.other, &o);
                }
            }
            return Ok(());
        }
        self.outs.resize(slots.len(), ContactOut::default());
        // Blocks of slots, evaluated on rayon's pool in any order, each by one thread; this
        // thread also adds them to the loads in block (slot) order as soon as each is done, so
        // the serial sums run while the other threads are still evaluating.
        let blocks: Vec<Mutex<Block>> = slots
            .chunks_mut(SUM_BLOCK)
            .zip(self.outs.chunks_mut(SUM_BLOCK))
            .zip(stamps.chunks(SUM_BLOCK))
            .map(|((slots, outs), stamps)| {
                Mutex::new(Block {
                    slots,
                    outs,
                    stamps,
                    error: None,
                })
            })
            .collect();
        let done: Vec<AtomicBool> = blocks.iter().map(|_| AtomicBool::new(false)).collect();
        // Each thread first takes the blocks of its own share of the slab, then helps with the
        // others'. Its share is the contacts its run of pairs just examined, and the stepping
        // thread's also the surfaces' contacts, which it found (`share_ranges`): a contact is
        // evaluated on the core that wrote its geometry, and the sums below read only the
        // outputs, not the contacts. In the 2-core VM's slow spells, reading a line the other
        // core wrote costs about 25 ns more, and the pair stage took 113-122 us a step instead
        // of 50-59 with the contacts read across (docs/performance.md, "Eleventh session").
        let shares = rayon::current_num_threads();
        let ranges: Vec<(usize, AtomicUsize, usize)> =
            share_ranges(slab_shares, shares, blocks.len())
                .into_iter()
                .map(|(owner, start, end)| (owner, AtomicUsize::new(start), end))
                .collect();
        let claim = |me: usize| {
            let mine = ranges.iter().filter(|r| r.0 == me);
            let others = (1..shares).flat_map(|q| {
                let p = (me + q) % shares;
                ranges.iter().filter(move |r| r.0 == p)
            });
            mine.chain(others).find_map(|(_, next, end)| {
                let b = next.fetch_add(1, Ordering::Relaxed);
                (b < *end).then_some(b)
            })
        };
        let claim = &claim;
        let evaluate = |b: usize| {
            let mut guard = blocks[b].lock().expect("no panic holds it");
            // Done when the evaluation ends, by a panic too (the block's lock is then poisoned,
            // and the summing thread's `lock` passes the panic on instead of waiting for ever).
            let _done = Done(&done[b]);
            let block = &mut *guard;
            for (k, ((c, o), &stamp)) in block
                .slots
                .iter_mut()
                .zip(block.outs.iter_mut())
                .zip(block.stamps)
                .enumerate()
            {
                if stamp == epoch {
                    match ctx.evaluate(c) {
                        Ok(r) => *o = r,
                        // The first error of the block (its lowest slot) is the one reported.
                        Err(e) => {
                            if block.error.is_none() {
                                block.error = Some((k, e));
                            }
                        }
                    }
                }
            }
        };
        let mut first_error = None;
        rayon::scope(|scope| {
            for helper in 1..shares {
                scope.spawn(move |_| {
                    while let Some(b) = claim(helper) {
                        evaluate(b);
                    }
                });
            }
            let mut summed = 0;
            while summed < blocks.len() && first_error.is_none() {
                if done[summed].load(Ordering::Acquire) {
                    let mut guard = blocks[summed].lock().expect("no panic holds it");
                    let block = &mut *guard;
                    // The contacts before the first error (slot order) count; it is returned.
                    let end = block.error.as_ref().map_or(block.slots.len(), |e| e.0);
                    for (o, &stamp) in block.outs[..end].iter().zip(block.stamps) {
                        if stamp == epoch {
                            ctx.add_load(&mut sums, o.i, o.other, o);
                        }
                    }
                    first_error = block.error.take().map(|e| e.1);
                    summed += 1;
                } else if let Some(b) = claim(0) {
                    evaluate(b);
                } else {
                    // Another thread is evaluating the next block.
                    std::hint::spin_loop();
                }
            }
            // After an error no block is evaluated any more.
            for (_, next, end) in &ranges {
                next.store(*end, Ordering::Relaxed);
            }
        });
        if let Some(e) = first_error {
            return Err(*e);
        }
        Ok(())
    }
}

/// The parallel force pass's shares of the slab's `n_blocks` blocks among `shares` threads, as
/// (thread, first block, end block) ranges, each thread's in slab order: from detection's split
/// `split` ([`super::detect::Detection::slab_shares`]: each run's first slot, [`NONE`] for a run
/// without contacts, then the end of the pairs' contacts) run r's contacts go to thread r and the
/// contacts after the pairs' (the surfaces') to thread 0; without a split of `shares + 1` entries,
/// equal parts. Slots are rounded to the nearest block boundary and the split made increasing, so
/// that any split covers every block once (a contact that started between two rebuilds sits in a
/// free slot anywhere: it is evaluated, on whichever thread its block falls to).
pub(super) fn share_ranges(
    split: &[u32],
    shares: usize,
    n_blocks: usize,
) -> Vec<(usize, usize, usize)> {
    if split.len() != shares + 1 || shares < 2 {
        return (0..shares.max(1))
            .map(|p| {
                (
                    p,
                    p * n_blocks / shares.max(1),
                    (p + 1) * n_blocks / shares.max(1),
                )
            })
            .collect();
    }
    let mut at = Vec::with_capacity(shares + 1);
    for &slot in split {
        let last = at.last().copied().unwrap_or(0);
        let b = if slot == NONE {
            last
        } else {
            ((slot as usize + SUM_BLOCK / 2) / SUM_BLOCK).min(n_blocks)
        };
        at.push(b.max(last));
    }
    let mut ranges = vec![(0, 0, at[1])];
    ranges.extend((1..shares).map(|p| (p, at[p], at[p + 1])));
    ranges.push((0, at[shares], n_blocks));
    ranges
}

#[cfg(test)]
mod tests {
    use super::super::{ContactLayer, LayerError, StepRequest};
    use crate::contact::Material;
    use crate::math::Vec3;
    use rapier3d_f64::dynamics::{IslandManager, RigidBodyBuilder, RigidBodySet};
    use rapier3d_f64::geometry::ColliderSet;
    use rapier3d_f64::parry::mass_properties::MassProperties;

    /// One step of 1000 touching apples in a lattice (about 2 700 contacts, the parallel pass)
    /// where two pairs far apart in the contact list overlap beyond the guard's limit, and the
    /// `nan_apples` move at a NaN speed, on a pool of `threads`: the step's error.
    fn bad_step_on(threads: usize, nan_apples: &[usize]) -> LayerError {
        super::super::on_pool(threads, || {
            let mut bodies = RigidBodySet::new();
            let colliders = ColliderSet::new();
            let islands = IslandManager::new();
            let mut layer = ContactLayer::new(Default::default());
            let fruit = layer.add_material(
                "apple",
                Material::from_shear(1.1e6, 0.18, Some(800.0)).unwrap(),
            );
            layer.set_default_coefficients(0.5, 0.09, 1000.0);
            let r = 0.04;
            let m = 800.0 * 4.0 / 3.0 * std::f64::consts::PI * r * r * r;
            for k in 0..1000 {
                let cell = Vec3::new((k % 10) as f64, (k / 10 % 10) as f64, (k / 100) as f64);
                // Touching neighbours (0.5 mm overlap); apples 901 and 21 sink into 900 and 20.
                let mut pos = cell * 0.0795;
                if k == 901 || k == 21 {
                    pos.x -= 0.05;
                }
                let speed = if nan_apples.contains(&k) {
                    f64::NAN
                } else {
                    0.0
                };
                let body = bodies.insert(
                    RigidBodyBuilder::dynamic()
                        .translation(pos)
                        .linvel(Vec3::new(speed, 0.0, 0.0))
                        .additional_mass_properties(MassProperties::new(
                            Vec3::ZERO,
                            m,
                            Vec3::splat(0.4 * m * r * r),
                        )),
                );
                layer
                    .add_apple_body(&bodies, body, r, fruit, &format!("a{k}"))
                    .unwrap();
            }
            layer
                .step(
                    &mut bodies,
                    &colliders,
                    &islands,
                    &StepRequest::fixed(0.0, 1e-4),
                )
                .expect_err("two pairs overlap beyond the limit")
        })
    }

    /// Every split detection can hand over gives shares that cover each block of the slab once
    /// (so every contact is evaluated once, and the sums in slot order give the same bits), and
    /// a split of a reordered slab gives each run's contacts to its thread, the surfaces' to the
    /// stepping thread.
    #[test]
    fn the_slab_is_shared_as_detection_split_it_and_covered_once() {
        use super::{share_ranges, NONE, SUM_BLOCK};
        // A split measured on the eq. 12 pile: 23 blocks, run 1's contacts from slot 1302, the
        // pairs' to 2500.
        assert_eq!(
            share_ranges(&[0, 1302, 2500], 2, 23),
            vec![(0, 0, 10), (1, 10, 20), (0, 20, 23)]
        );
        assert_eq!(share_ranges(&[], 2, 10), vec![(0, 0, 5), (1, 5, 10)]);
        let odd: [&[u32]; 7] = [
            &[0, NONE, 900],
            &[0, 900, 100],
            &[0, 5000, 9000],
            &[0, NONE, NONE, NONE],
            &[0, 300, 200, 700],
            &[
                0,
                2 * SUM_BLOCK as u32,
                4 * SUM_BLOCK as u32,
                6 * SUM_BLOCK as u32,
            ],
            &[0, 1, 2],
        ];
        for split in odd {
            for shares in [2, 3] {
                for n_blocks in [0, 1, 7, 23] {
                    let ranges = share_ranges(split, shares, n_blocks);
                    let mut seen = vec![0; n_blocks];
                    for &(owner, start, end) in &ranges {
                        assert!(owner < shares && start <= end && end <= n_blocks);
                        (start..end).for_each(|b| seen[b] += 1);
                    }
                    assert!(
                        seen.iter().all(|&k| k == 1),
                        "{split:?}, {shares} shares, {n_blocks} blocks: {ranges:?}"
                    );
                }
            }
        }
    }

    /// The parallel force pass reports the error of the lowest slot, as the serial one does.
    #[test]
    fn the_parallel_pass_reports_the_first_error_in_slot_order() {
        let one = format!("{:?}", bad_step_on(1, &[]));
        assert!(one.contains("a20") && one.contains("a21"), "{one}");
        assert_eq!(one, format!("{:?}", bad_step_on(2, &[])));
    }

    /// The parallel read of the bodies reports the first non-finite apple in apple order, as
    /// the serial one does (apples 700 and 300 in different chunks).
    #[test]
    fn the_parallel_read_reports_the_first_non_finite_apple() {
        let one = format!("{:?}", bad_step_on(1, &[700, 300]));
        assert!(one.contains("NonFinite") && one.contains("a300"), "{one}");
        assert_eq!(one, format!("{:?}", bad_step_on(2, &[700, 300])));
    }
}
