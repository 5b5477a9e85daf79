//! Contact events: one per contact from first touch to separation (issue 2 item 6).
//!
//! The layer feeds an [`OpenContact`] with the state at every step the bodies overlap and closes it
//! when they part. Touch and separation instants are interpolated between steps: with rapier's
//! symplectic Euler (one solver iteration) the velocity stored with a pose is the one that carried
//! the body there, constant over the step, so the overlap is linear in time across the crossing and
//! t_touch = t - u / (du/dt) is exact for the discrete trajectory (physics.md section 10).

use crate::math::{arr3, Vec3};
use serde::Serialize;
use std::sync::Arc;

/// The other party of a contact.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case", tag = "kind", content = "index")]
pub enum Party {
    /// Another apple (its index in the layer).
    Apple(u32),
    /// A surface (its index in the layer).
    Surface(u32),
}

impl Party {
    /// Sort key of the other parties of one apple's contacts: apples first, then surfaces, each
    /// by index (the order of events and records in every output).
    pub fn order(self) -> (u8, u32) {
        match self {
            Party::Apple(j) => (0, j),
            Party::Surface(s) => (1, s),
        }
    }
}

/// A finished (or, at the end of a run, still open) contact.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ContactEvent {
    /// Name of the apple.
    pub a: Arc<str>,
    /// Name of the other body (apple or surface).
    pub b: Arc<str>,
    /// Index of apple `a` in the layer.
    #[serde(skip)]
    pub a_index: u32,
    /// The other party.
    #[serde(skip)]
    pub b_party: Party,
    /// First touch (s), interpolated between steps.
    pub t_start_s: f64,
    /// Separation (s), interpolated; `None` while the contact is still open at the end.
    pub t_end_s: Option<f64>,
    /// t_end - t_start (s).
    pub duration_s: Option<f64>,
    /// Largest normal force seen at a step (N).
    pub peak_force_n: f64,
    /// Time of that step (s).
    pub t_peak_s: f64,
    /// Normal impulse, sum of P dt over the contact (N s): exactly the momentum it transferred.
    pub impulse_n_s: f64,
    /// Largest overlap u (m).
    pub max_overlap_m: f64,
    /// Largest contact radius a = sqrt(R* u) (m); on a roller's elliptical contact the radius
    /// of the circle of its true area, sqrt(a b).
    pub max_contact_radius_m: f64,
    /// Largest mean contact pressure P / (true contact area) (Pa).
    pub max_pressure_pa: f64,
    /// Normal approach speed at first touch (m/s).
    pub approach_speed_m_s: f64,
    /// Normal separation speed at separation (m/s); `None` while open.
    pub separation_speed_m_s: Option<f64>,
    /// separation / approach speed; `None` while open or for contacts that start at rest.
    pub restitution: Option<f64>,
    /// Work absorbed by the normal force over the contact, sum of P du (J): the hysteresis loss.
    pub absorbed_energy_j: f64,
    /// Apple `a`'s part of `absorbed_energy_j` (J): the loss pose by pose times its share
    /// ([`crate::contact::share`]); the other body took the rest.
    pub a_absorbed_energy_j: f64,
    /// Number of steps with overlap.
    pub steps: u64,
    /// Contact point at the peak force (m, world).
    pub contact_point_m: [f64; 3],
    /// The impact the contact starts with (`None` for a contact that starts at rest).
    pub impact: Option<ImpactPulse>,
    /// The load carried once the impact is over, or from the start of a contact that starts
    /// at rest (`None` when the contact ends with its impact).
    pub resting: Option<RestingLoad>,
    /// Force history (time s, normal force N), when recorded; decimated evenly if long.
    #[serde(skip)]
    pub history: Option<Vec<(f64, f64)>>,
    /// The end of the span the history was kept over (s) when the contact went on after it
    /// ([`HistorySpan::Impact`]: the impact pulse and as much again); `None` when the history
    /// holds the whole contact (or there is none).
    #[serde(skip)]
    pub history_cut_s: Option<f64>,
}

/// Which part of a contact its force history covers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum HistorySpan {
    /// The whole contact (decimated evenly to the cap).
    #[default]
    Whole,
    /// The impact pulse and as much again after it ([`IMPACT_HISTORY_SPAN`]); nothing of a
    /// contact that starts at rest. What the pulse fit, the force chart (its default window ends
    /// 20 % after the last pulse) and the viewer's curves (the pulse and as much again) use, without
    /// the seconds of resting force that made up most of `forces.csv` in a bin fill.
    Impact,
}

/// A kept impact history runs from the touch to this many times the impact pulse's duration
/// ([`HistorySpan::Impact`]): the pulse, and a tail as long again showing the force settle to
/// its resting level or reach zero.
pub const IMPACT_HISTORY_SPAN: f64 = 2.0;

/// The impact at the start of a contact: from touch until the pulse is over, at separation (a
/// rebound) or at the first turn of the overlap from unloading back to loading after the peak
/// (the body no longer rebounds: its force is back to the quasi-static support). What an
/// instrumented sphere records of one impact.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ImpactPulse {
    /// End of the pulse (s).
    pub t_end_s: f64,
    /// Duration of the pulse (s).
    pub duration_s: f64,
    /// Largest normal force of the pulse (N).
    pub peak_force_n: f64,
    /// Time of the peak (s).
    pub t_peak_s: f64,
    /// Normal impulse of the pulse, sum of P dt (N s).
    pub impulse_n_s: f64,
    /// Work absorbed by the normal force over the pulse (J).
    pub absorbed_energy_j: f64,
    /// Apple `a`'s part of `absorbed_energy_j` (J) ([`crate::contact::share`]).
    pub a_absorbed_energy_j: f64,
    /// Largest mean contact pressure of the pulse (Pa).
    pub max_pressure_pa: f64,
    /// Largest overlap of the pulse (m).
    pub max_overlap_m: f64,
    /// Largest contact radius of the pulse (m; the radius of the circle of the true area).
    pub max_contact_radius_m: f64,
    /// Apple `a`'s own deformation at the peak force (m): its share of the overlap (the other
    /// body's is the overlap at the peak less this).
    pub a_indentation_m: f64,
    /// Overlap at the peak force (m).
    pub overlap_at_peak_m: f64,
    /// Where each body was hit, in its own frame: the unit vector from the centre of apple `a`
    /// (first) and of the other body, if an apple (second), towards the contact point at the
    /// peak force, turned back by the body's orientation then. The site of a bruise on the
    /// fruit ([`crate::analysis::damage`]); the second is meaningless for a surface.
    #[serde(skip)]
    pub sites: [[f64; 3]; 2],
    /// Contact normal at the peak, towards the apple.
    pub normal: [f64; 3],
    /// Change of each body's velocity along the contact normal over the pulse (m/s): apple `a`
    /// along the normal (towards it), the other body against it. Measured from the bodies'
    /// velocities at the touch and after the pulse's last force kick, so that it is the change
    /// of speed the body went through: an apple hit while another apple lands on it is not
    /// credited with the other's push (the contact's impulse over the mass would be). A rebound
    /// at v0 with restitution e gives (1 + e) v0.
    pub velocity_change_m_s: [f64; 2],
}

/// The load a contact carries at rest (after its impact, or all along for a contact that starts
/// at rest): the static loads storage bruising depends on.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RestingLoad {
    /// Time spent resting (s).
    pub duration_s: f64,
    /// Time-averaged normal force (N).
    pub mean_force_n: f64,
    /// Largest normal force while resting (N).
    pub max_force_n: f64,
    /// Time-averaged mean contact pressure (Pa).
    pub mean_pressure_pa: f64,
    /// Largest mean contact pressure while resting (Pa).
    pub max_pressure_pa: f64,
}

/// Below this approach speed (m/s) a contact counts as starting at rest: no restitution.
pub const RESTING_APPROACH_SPEED_M_S: f64 = 1e-3;

/// An evenly decimated (time, force) history with a bounded number of samples.
#[derive(Debug, Clone, Default)]
struct History {
    samples: Vec<(f64, f64)>,
    stride: u64,
    seen: u64,
    cap: usize,
}

impl History {
    fn new(cap: usize) -> Self {
        Self {
            samples: Vec::new(),
            stride: 1,
            seen: 0,
            cap: cap.max(2),
        }
    }

    fn push(&mut self, t: f64, p: f64) {
        if self.seen % self.stride == 0 {
            if self.samples.len() >= self.cap {
                // Keep every other sample and double the stride: still evenly spaced.
                let kept: Vec<_> = self.samples.iter().copied().step_by(2).collect();
                self.samples = kept;
                self.stride *= 2;
            }
            if self.seen % self.stride == 0 {
                self.samples.push((t, p));
            }
        }
        self.seen += 1;
    }
}

/// A contact in progress.
#[derive(Debug, Clone)]
pub struct OpenContact {
    t_start: f64,
    approach: f64,
    peak: f64,
    t_peak: f64,
    impulse: f64,
    max_u: f64,
    max_a: f64,
    max_p: f64,
    absorbed: f64,
    /// Apple `a`'s part of `absorbed`.
    absorbed_a: f64,
    prev_u: f64,
    last_u: f64,
    last_p: f64,
    /// Mean contact pressure at the last pose (Pa; a rider's frozen contact holds it).
    last_pressure: f64,
    /// Apple `a`'s share of the loss at the last pose.
    last_share: f64,
    /// Apple `a`'s share of the overlap and of the loss ([`crate::contact::share`]): set by the
    /// layer once for a contact whose shares do not change, pose by pose for a pad's.
    shares: (f64, f64),
    /// The kick weights of the last pose: (h_back + h_next) / 4 / h_next and / h_back.
    last_w: (f64, f64),
    rate: f64,
    steps: u64,
    point_at_peak: Vec3,
    /// Boxed: most runs record no histories, and the record is touched every step.
    history: Option<Box<History>>,
    /// Samples after this time are not kept ([`HistorySpan::Impact`], once the pulse is over).
    history_until: f64,
    /// A sample after `history_until` was seen (and dropped).
    history_cut: bool,
    /// Which part of the contact the history covers.
    history_span: HistorySpan,
    /// Elastic contact time and maximum overlap of the impact at the approach speed, once known.
    impact_scale: Option<(f64, f64)>,
    /// The impact pulse while it lasts (`None` once over, or for a contact starting at rest).
    /// Boxed, as the impact below: most contacts of a pile rest, and the slab of contacts is
    /// walked every step (docs/performance.md).
    pulse: Option<Box<Pulse>>,
    /// The impact once over.
    impact: Option<Box<ImpactPulse>>,
    /// Resting sums: time, force x time, pressure x time, largest force and pressure.
    rest: (f64, f64, f64, f64, f64),
    /// The pose of `last_u` belonged to the impact (its absorbed work is the impact's).
    last_in_pulse: bool,
    /// Time of the last pose (s).
    last_t: f64,
    /// Contact normal at the peak of the pulse.
    normal_at_peak: Vec3,
    /// The time by which the impact is over whatever the overlap does (s; see
    /// [`Self::set_impact_deadline`]).
    impact_deadline: f64,
}

/// The sums of an impact in progress.
#[derive(Debug, Clone, Copy, Default)]
struct Pulse {
    peak: f64,
    t_peak: f64,
    impulse: f64,
    absorbed: f64,
    /// Apple `a`'s part of `absorbed`.
    absorbed_a: f64,
    max_p: f64,
    max_u: f64,
    max_a: f64,
    /// Overlap and apple `a`'s indentation at the peak.
    u_at_peak: f64,
    indentation_at_peak: f64,
    sites: [[f64; 3]; 2],
    /// The last pose raised the peak: the layer places the hit on the bodies
    /// ([`OpenContact::place_peak`]).
    new_peak: bool,
    /// The bodies' normal velocities at the touch (m/s; see [`ContactSample::normal_velocities`]).
    v_touch: [f64; 2],
    /// The bodies' normal velocities at the last pose (m/s).
    v_last: [f64; 2],
    /// The overlap has started to fall after the peak.
    unloading: bool,
    /// The fastest the overlap has fallen so far (m/s).
    fastest_unloading: f64,
}

/// The impact pulse of a contact that neither parts nor reloads is over once its overlap falls
/// at less than this share of the fastest it fell: the apple has come to rest on its support
/// (an overdamped landing, e.g. on a belt, approaches its resting overlap without overshoot).
/// The velocity change left uncounted is at most this share of the apple's fastest rebound.
pub const PULSE_SETTLED_SHARE: f64 = 0.01;

/// One step's observation of an overlapping contact.
#[derive(Debug, Clone, Copy)]
pub struct ContactSample {
    /// Time of the pose (s).
    pub time_s: f64,
    /// Step length that follows (s).
    pub dt_s: f64,
    /// Step length that led to this pose (s); equal to `dt_s` with a fixed step.
    pub dt_back_s: f64,
    /// How far back this pose's force kick reaches (s): `dt_back_s`, or with adaptive steps the
    /// contact's age if shorter (a contact pushes only since its touch; see `layer::StepControl`).
    pub kick_back_s: f64,
    /// Overlap (m).
    pub overlap_m: f64,
    /// Normal force (N).
    pub force_n: f64,
    /// Contact radius (m): the radius of the circle of the true contact area, sqrt(a b) on an
    /// elliptical contact (a roller's side).
    pub contact_radius_m: f64,
    /// Mean pressure P / (true contact area) (Pa).
    pub pressure_pa: f64,
    /// Contact point (m).
    pub point: Vec3,
    /// Contact normal, towards the apple.
    pub normal: Vec3,
    /// Velocities along `normal` of apple `a` and of the other body at this pose, before this
    /// pose's force kick (m/s): what the impact's velocity change is measured from.
    pub normal_velocities: [f64; 2],
}

/// A body's orientation (rapier's, glam `DQuat`).
pub type Rotation = rapier3d_f64::math::Rotation;

impl OpenContact {
    /// Opens a contact first seen overlapping at `time_s` with overlap `u` and overlap rate
    /// `du_dt` (> 0 approaching). The touch instant is interpolated within the last step. Its
    /// force history keeps at most `history_cap` samples (0: none) over `span`.
    pub fn begin(
        time_s: f64,
        dt_s: f64,
        u: f64,
        du_dt: f64,
        history_cap: usize,
        span: HistorySpan,
    ) -> Self {
        let impact = du_dt > RESTING_APPROACH_SPEED_M_S;
        let keep = history_cap > 0 && (span == HistorySpan::Whole || impact);
        let back = if du_dt > 0.0 {
            (u / du_dt).min(dt_s)
        } else {
            0.0
        };
        Self {
            t_start: (time_s - back).max(0.0),
            approach: du_dt.max(0.0),
            peak: 0.0,
            t_peak: time_s,
            impulse: 0.0,
            max_u: 0.0,
            max_a: 0.0,
            max_p: 0.0,
            absorbed: 0.0,
            absorbed_a: 0.0,
            prev_u: f64::NAN,
            last_u: 0.0,
            last_p: 0.0,
            last_pressure: 0.0,
            last_share: 1.0,
            shares: (1.0, 1.0),
            last_w: (0.5, 0.5),
            rate: du_dt,
            steps: 0,
            point_at_peak: Vec3::ZERO,
            history: keep.then(|| Box::new(History::new(history_cap))),
            history_until: f64::INFINITY,
            history_cut: false,
            history_span: span,
            impact_scale: None,
            pulse: impact.then(Box::default),
            impact: None,
            rest: (0.0, 0.0, 0.0, 0.0, 0.0),
            last_in_pulse: false,
            last_t: time_s,
            normal_at_peak: Vec3::Z,
            impact_deadline: f64::INFINITY,
        }
    }

    /// Work absorbed by the force of the last observed pose, given the next overlap.
    ///
    /// With the leapfrog kick the stepping applies (see `layer::StepControl`: the impulse of pose
    /// k is F_k (h_k-1 + h_k) / 2) the kinetic energy changes over pose k by exactly
    /// F_k (h_k-1 + h_k) / 4 ((x_k+1 - x_k) / h_k + (x_k - x_k-1) / h_k-1); with a fixed step that
    /// is F_k (x_k+1 - x_k-1) / 2. The energy the contact absorbs is the sum of these terms: zero to
    /// round-off for an elastic impact, the hysteresis loss otherwise.
    fn absorb(&mut self, next_u: f64) {
        if self.steps > 0 {
            let (w_next, w_back) = self.last_w;
            let w = self.last_p
                * (w_next * (next_u - self.last_u) + w_back * (self.last_u - self.prev_u));
            let wa = w * self.last_share;
            self.absorbed += w;
            self.absorbed_a += wa;
            if self.last_in_pulse {
                if let Some(p) = &mut self.pulse {
                    p.absorbed += w;
                    p.absorbed_a += wa;
                } else if let Some(i) = &mut self.impact {
                    // The pose that ended the pulse: its work belongs to it.
                    i.absorbed_energy_j += w;
                    i.a_absorbed_energy_j += wa;
                }
            }
        }
    }

    /// Ends the impact pulse at the last pose (the overlap turned back to loading after the
    /// peak) or at `t_end` (separation).
    fn end_pulse(&mut self, t_end: f64) {
        if let Some(p) = self.pulse.take() {
            if self.history_span == HistorySpan::Impact {
                self.history_until = self.t_start + IMPACT_HISTORY_SPAN * (t_end - self.t_start);
            }
            let [va, vb] = p.v_last;
            let [va0, vb0] = p.v_touch;
            self.impact = Some(Box::new(ImpactPulse {
                t_end_s: t_end,
                duration_s: t_end - self.t_start,
                peak_force_n: p.peak,
                t_peak_s: p.t_peak,
                impulse_n_s: p.impulse,
                absorbed_energy_j: p.absorbed,
                a_absorbed_energy_j: p.absorbed_a,
                max_pressure_pa: p.max_p,
                max_overlap_m: p.max_u,
                max_contact_radius_m: p.max_a,
                a_indentation_m: p.indentation_at_peak,
                overlap_at_peak_m: p.u_at_peak,
                sites: p.sites,
                normal: arr3(self.normal_at_peak),
                velocity_change_m_s: [va - va0, vb0 - vb],
            }));
        }
    }

    /// Records one step with overlap.
    #[inline]
    pub fn observe(&mut self, s: &ContactSample) {
        if self.steps == 0 {
            // The pose before first touch, on the straight line the step followed.
            self.prev_u = s.overlap_m - self.rate * s.dt_back_s;
        } else {
            self.absorb(s.overlap_m);
            self.prev_u = self.last_u;
        }
        // The pulse is over when the overlap, falling after the peak, turns back to growing (the
        // body no longer rebounds, its force is back to the quasi-static support) or all but
        // stops falling (an overdamped landing settling onto its support), and at the latest
        // when the layer counts the contact as resting (an apple hit and then held, its overlap
        // still growing under the apples that land on it).
        if let Some(p) = &mut self.pulse {
            // This pose's velocities hold the last pose's kick: the pulse's velocity change
            // runs to here if it ends now (at the last pose). At parting, the last pose's kick
            // (of a force near zero) is not seen.
            if self.steps == 0 {
                p.v_touch = s.normal_velocities;
            }
            p.v_last = s.normal_velocities;
        }
        if self.pulse.is_some() && self.steps > 0 && s.time_s > self.impact_deadline {
            let t = self.last_t;
            self.end_pulse(t);
        }
        if let Some(p) = &mut self.pulse {
            if self.steps > 0 {
                let falling = (self.last_u - s.overlap_m) / s.dt_back_s;
                if falling > 0.0 {
                    p.unloading = true;
                    p.fastest_unloading = p.fastest_unloading.max(falling);
                }
                if p.unloading
                    && (falling <= 0.0 || falling < PULSE_SETTLED_SHARE * p.fastest_unloading)
                {
                    let t = self.last_t;
                    self.end_pulse(t);
                }
            }
        }
        let span = 0.5 * (s.kick_back_s + s.dt_s);
        self.last_w = if s.kick_back_s == s.dt_s && s.dt_back_s == s.dt_s {
            // A fixed step: the same numbers without two divisions per contact and step.
            (0.5, 0.5)
        } else {
            (0.5 * span / s.dt_s, 0.5 * span / s.dt_back_s)
        };
        self.last_u = s.overlap_m;
        self.last_p = s.force_n;
        self.last_pressure = s.pressure_pa;
        self.last_share = self.shares.1;
        self.impulse += s.force_n * span;
        self.steps += 1;
        if s.force_n > self.peak {
            self.peak = s.force_n;
            self.t_peak = s.time_s;
            self.point_at_peak = s.point;
        }
        self.max_u = self.max_u.max(s.overlap_m);
        self.max_a = self.max_a.max(s.contact_radius_m);
        self.max_p = self.max_p.max(s.pressure_pa);
        self.last_t = s.time_s;
        match &mut self.pulse {
            Some(p) => {
                self.last_in_pulse = true;
                p.impulse += s.force_n * span;
                p.max_p = p.max_p.max(s.pressure_pa);
                p.max_u = p.max_u.max(s.overlap_m);
                p.max_a = p.max_a.max(s.contact_radius_m);
                if s.force_n > p.peak {
                    p.peak = s.force_n;
                    p.t_peak = s.time_s;
                    p.u_at_peak = s.overlap_m;
                    p.indentation_at_peak = self.shares.0 * s.overlap_m;
                    p.new_peak = true;
                    self.normal_at_peak = s.normal;
                }
            }
            None => {
                self.last_in_pulse = false;
                let r = &mut self.rest;
                r.0 += span;
                r.1 += s.force_n * span;
                r.2 += s.pressure_pa * span;
                r.3 = r.3.max(s.force_n);
                r.4 = r.4.max(s.pressure_pa);
            }
        }
        if let Some(h) = &mut self.history {
            if s.time_s <= self.history_until {
                h.push(s.time_s, s.force_n);
            } else {
                self.history_cut = true;
            }
        }
    }

    /// A frozen contact (an apple riding a belt, `layer::sleep`) held its last pose for `dt_s`
    /// more, to `time_s`: its impulse, steps and resting sums go on as if it had been evaluated
    /// (the same force and pressure), so that the contact's record is the same as without riding.
    /// Once per step: a step whose detection is redone (an apple woke in its first pass) carries
    /// its riders again at the same time, and that second carry adds nothing.
    pub fn carry(&mut self, dt_s: f64, time_s: f64) {
        if time_s <= self.last_t {
            return;
        }
        if self.pulse.is_some() {
            let t = self.last_t;
            self.end_pulse(t);
        }
        self.impulse += self.last_p * dt_s;
        self.steps += 1;
        self.last_t = time_s;
        let r = &mut self.rest;
        r.0 += dt_s;
        r.1 += self.last_p * dt_s;
        r.2 += self.last_pressure * dt_s;
    }

    /// Sets apple `a`'s share of the overlap and of the loss from now on
    /// ([`crate::contact::share`]).
    #[inline]
    pub fn set_shares(&mut self, indentation: f64, energy: f64) {
        self.shares = (indentation, energy);
    }

    /// Whether the last pose raised the impact's peak force: then the layer places the hit on
    /// the bodies' own surfaces with [`Self::place_peak`] (only while an impact loads, so the
    /// bodies' orientations are read then and not at every pose).
    #[inline]
    pub fn peak_raised(&self) -> bool {
        self.pulse.as_ref().is_some_and(|p| p.new_peak)
    }

    /// Places the impact's peak on the bodies: `rotations` are the orientations of apple `a` and
    /// of the other body (identity for a surface) at the last pose; the normal points towards
    /// apple `a`, which is hit at -n, the other body at +n.
    pub fn place_peak(&mut self, rotations: [Rotation; 2]) {
        let n = self.normal_at_peak;
        if let Some(p) = &mut self.pulse {
            let [ra, rb] = rotations;
            p.sites = [arr3(ra.inverse() * -n), arr3(rb.inverse() * n)];
            p.new_peak = false;
        }
    }

    /// Whether the contact's impact is over: its [`ImpactPulse`] is then final (a
    /// [`Self::snapshot`] reports one still in progress as far as it went).
    pub fn impact_over(&self) -> bool {
        self.pulse.is_none() && self.impact.is_some()
    }

    /// Largest overlap so far (m).
    pub fn max_overlap_m(&self) -> f64 {
        self.max_u
    }

    /// Work done on the contact by its normal force so far (J): the absorbed sum through the
    /// previous pose plus P_k (u_k - u_k-1) / 2, which together with the kinetic energy at the
    /// pose's time (v + a h_k-1 / 2) is conserved by the stepping to second order, for fixed and
    /// changing steps alike.
    pub fn work_so_far_j(&self) -> f64 {
        if self.steps == 0 {
            0.0
        } else {
            // The half of pose k's term that the velocity at the pose's time (v + a h_k-1 / 2)
            // already holds: F (x_k - x_k-1) / 2, whatever the next step.
            self.absorbed + 0.5 * self.last_p * (self.last_u - self.prev_u)
        }
    }

    /// The elastic contact time and maximum overlap of this contact's impact (at its approach
    /// speed), computed once by `f` and kept (they need powers; the layer asks every step).
    pub fn impact_scale(&mut self, f: impl FnOnce(f64) -> (f64, f64)) -> (f64, f64) {
        let v = self.approach;
        *self.impact_scale.get_or_insert_with(|| f(v))
    }

    /// The time from which the layer counts the contact as resting (1.2 times eq. 12's contact
    /// time at the approach speed after the touch, `layer::kernel`): its impact pulse, if still
    /// open then, ends there, so that the impact's impulse and velocity change cover the impact
    /// and not the loads the contact carries later.
    pub fn set_impact_deadline(&mut self, time_s: f64) {
        self.impact_deadline = time_s;
    }

    /// Time of first touch (s).
    pub fn start_time_s(&self) -> f64 {
        self.t_start
    }

    /// Replaces the approach speed taken from the first pose's overlap rate by a better estimate
    /// of the speed at the touch instant (the layer knows the free acceleration; m/s).
    pub fn set_approach_speed(&mut self, v: f64) {
        self.approach = v;
    }

    /// Normal approach speed at first touch (m/s).
    pub fn approach_speed_m_s(&self) -> f64 {
        self.approach
    }

    /// Normal force at the last observed pose (N; 0 before the first).
    pub fn last_force_n(&self) -> f64 {
        self.last_p
    }

    /// Closes the contact seen apart at `time_s` with overlap `u` <= 0 and separation rate
    /// `sep` = -du/dt > 0; the parting instant is interpolated within the last step.
    pub fn finish(
        mut self,
        time_s: f64,
        dt_s: f64,
        u: f64,
        sep: f64,
        names: Names,
    ) -> ContactEvent {
        self.absorb(u);
        let back = if sep > 0.0 { (-u / sep).min(dt_s) } else { 0.0 };
        let t_end = (time_s - back).max(self.t_start);
        self.end_pulse(t_end);
        self.into_event(Some((t_end, sep.max(0.0))), names)
    }

    /// The event of a contact still open at the end of a run.
    pub fn snapshot(&self, names: Names) -> ContactEvent {
        self.clone().into_snapshot(names)
    }

    /// [`Self::snapshot`] of a record the caller no longer needs (not copied again).
    pub fn into_snapshot(mut self, names: Names) -> ContactEvent {
        // An impact still in progress when the run ends: reported as far as it went.
        let t = self.last_t;
        self.end_pulse(t);
        self.into_event(None, names)
    }

    fn into_event(self, end: Option<(f64, f64)>, names: Names) -> ContactEvent {
        let restitution = match end {
            Some((_, sep)) if self.approach > RESTING_APPROACH_SPEED_M_S => {
                Some(sep / self.approach)
            }
            _ => None,
        };
        ContactEvent {
            a: names.a,
            b: names.b,
            a_index: names.a_index,
            b_party: names.b_party,
            t_start_s: self.t_start,
            t_end_s: end.map(|e| e.0),
            duration_s: end.map(|e| e.0 - self.t_start),
            peak_force_n: self.peak,
            t_peak_s: self.t_peak,
            impulse_n_s: self.impulse,
            max_overlap_m: self.max_u,
            max_contact_radius_m: self.max_a,
            max_pressure_pa: self.max_p,
            approach_speed_m_s: self.approach,
            separation_speed_m_s: end.map(|e| e.1),
            restitution,
            absorbed_energy_j: self.absorbed,
            a_absorbed_energy_j: self.absorbed_a,
            steps: self.steps,
            contact_point_m: arr3(self.point_at_peak),
            impact: self.impact.map(|i| *i),
            resting: resting_load(self.rest),
            history_cut_s: self.history_cut.then_some(self.history_until),
            history: self.history.map(|h| h.samples),
        }
    }
}

/// The resting load of the sums (time, force x time, pressure x time, largest force, largest
/// pressure), if the contact rested at all.
fn resting_load(r: (f64, f64, f64, f64, f64)) -> Option<RestingLoad> {
    (r.0 > 0.0).then(|| RestingLoad {
        duration_s: r.0,
        mean_force_n: r.1 / r.0,
        max_force_n: r.3,
        mean_pressure_pa: r.2 / r.0,
        max_pressure_pa: r.4,
    })
}

/// A finished contact as a run keeps it until its end: the fields of its [`ContactEvent`] without
/// the names (the indices name the parties), without the options a finished contact always fills
/// and without what follows from the other fields (duration, restitution). A 5 s run of the 8036-apple reference pile finishes about 58 000 contacts.
#[derive(Debug, Clone)]
pub struct FinishedContact {
    a_index: u32,
    b_party: Party,
    steps: u64,
    t_start_s: f64,
    /// NaN for a contact without an end (kept only if a caller stores one).
    t_end_s: f64,
    peak_force_n: f64,
    t_peak_s: f64,
    impulse_n_s: f64,
    max_overlap_m: f64,
    max_contact_radius_m: f64,
    max_pressure_pa: f64,
    approach_speed_m_s: f64,
    /// NaN without an end.
    separation_speed_m_s: f64,
    absorbed_energy_j: f64,
    a_absorbed_energy_j: f64,
    contact_point_m: [f64; 3],
    impact: Option<ImpactPulse>,
    resting: Option<RestingLoad>,
    history: Option<Box<[(f64, f64)]>>,
    /// NaN when the history holds the whole contact.
    history_cut_s: f64,
}

impl From<ContactEvent> for FinishedContact {
    fn from(e: ContactEvent) -> Self {
        Self {
            a_index: e.a_index,
            b_party: e.b_party,
            steps: e.steps,
            t_start_s: e.t_start_s,
            t_end_s: e.t_end_s.unwrap_or(f64::NAN),
            peak_force_n: e.peak_force_n,
            t_peak_s: e.t_peak_s,
            impulse_n_s: e.impulse_n_s,
            max_overlap_m: e.max_overlap_m,
            max_contact_radius_m: e.max_contact_radius_m,
            max_pressure_pa: e.max_pressure_pa,
            approach_speed_m_s: e.approach_speed_m_s,
            separation_speed_m_s: e.separation_speed_m_s.unwrap_or(f64::NAN),
            absorbed_energy_j: e.absorbed_energy_j,
            a_absorbed_energy_j: e.a_absorbed_energy_j,
            contact_point_m: e.contact_point_m,
            impact: e.impact,
            resting: e.resting,
            history: e.history.map(Vec::into_boxed_slice),
            history_cut_s: e.history_cut_s.unwrap_or(f64::NAN),
        }
    }
}

impl FinishedContact {
    /// The apple's index.
    pub fn a_index(&self) -> u32 {
        self.a_index
    }

    /// The other party.
    pub fn b_party(&self) -> Party {
        self.b_party
    }

    /// The event again, with the parties' names: every field as [`OpenContact::finish`] gave it
    /// (duration and restitution are recomputed by the same operations).
    pub fn into_event(self, names: Names) -> ContactEvent {
        let end = (!self.t_end_s.is_nan()).then_some((self.t_end_s, self.separation_speed_m_s));
        let restitution = match end {
            Some((_, sep)) if self.approach_speed_m_s > RESTING_APPROACH_SPEED_M_S => {
                Some(sep / self.approach_speed_m_s)
            }
            _ => None,
        };
        ContactEvent {
            a: names.a,
            b: names.b,
            a_index: self.a_index,
            b_party: self.b_party,
            t_start_s: self.t_start_s,
            t_end_s: end.map(|e| e.0),
            duration_s: end.map(|e| e.0 - self.t_start_s),
            peak_force_n: self.peak_force_n,
            t_peak_s: self.t_peak_s,
            impulse_n_s: self.impulse_n_s,
            max_overlap_m: self.max_overlap_m,
            max_contact_radius_m: self.max_contact_radius_m,
            max_pressure_pa: self.max_pressure_pa,
            approach_speed_m_s: self.approach_speed_m_s,
            separation_speed_m_s: end.map(|e| e.1),
            restitution,
            absorbed_energy_j: self.absorbed_energy_j,
            a_absorbed_energy_j: self.a_absorbed_energy_j,
            steps: self.steps,
            contact_point_m: self.contact_point_m,
            impact: self.impact,
            resting: self.resting,
            history: self.history.map(Vec::from),
            history_cut_s: (!self.history_cut_s.is_nan()).then_some(self.history_cut_s),
        }
    }
}

/// Who an event is about.
#[derive(Debug, Clone)]
pub struct Names {
    /// Apple name.
    pub a: Arc<str>,
    /// Other body's name.
    pub b: Arc<str>,
    /// Apple index.
    pub a_index: u32,
    /// Other party.
    pub b_party: Party,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names() -> Names {
        Names {
            a: "a".into(),
            b: "b".into(),
            a_index: 0,
            b_party: Party::Surface(0),
        }
    }

    #[test]
    fn interpolates_touch_and_parting() {
        // u grows at 1 m/s: first seen at t = 1.0 with u = 0.25 mm, dt = 1 ms -> touch at 0.99975.
        let mut c = OpenContact::begin(1.0, 1e-3, 0.25e-3, 1.0, 0, HistorySpan::Whole);
        c.observe(&ContactSample {
            time_s: 1.0,
            dt_s: 1e-3,
            dt_back_s: 1e-3,
            kick_back_s: 1e-3,
            overlap_m: 0.25e-3,
            force_n: 2.0,
            contact_radius_m: 1e-3,
            pressure_pa: 5.0,
            point: Vec3::ZERO,
            normal: Vec3::Z,
            normal_velocities: [0.0, 0.0],
        });
        let e = c.finish(1.002, 1e-3, -0.5e-3, 1.0, names());
        assert!((e.t_start_s - 0.99975).abs() < 1e-12);
        assert!((e.t_end_s.unwrap() - 1.0015).abs() < 1e-12);
        assert!((e.impulse_n_s - 2e-3).abs() < 1e-15);
        assert_eq!(e.restitution, Some(1.0));
    }

    #[test]
    fn finished_contact_gives_the_event_back() {
        let mut c = OpenContact::begin(1.0, 1e-3, 0.25e-3, 1.0, 8, HistorySpan::Whole);
        for k in 0..3 {
            c.observe(&ContactSample {
                time_s: 1.0 + k as f64 * 1e-3,
                dt_s: 1e-3,
                dt_back_s: 1e-3,
                kick_back_s: 1e-3,
                overlap_m: 0.25e-3 * (k + 1) as f64,
                force_n: 2.0 + k as f64,
                contact_radius_m: 1e-3,
                pressure_pa: 5.0,
                point: Vec3::new(0.1, 0.2, 0.3),
                normal: Vec3::Z,
                normal_velocities: [0.0, 0.0],
            });
        }
        let e = c.finish(1.004, 1e-3, -0.5e-3, 0.7, names());
        let back = FinishedContact::from(e.clone()).into_event(names());
        assert_eq!(format!("{back:?}"), format!("{e:?}"));
        assert!(std::mem::size_of::<FinishedContact>() < std::mem::size_of::<ContactEvent>());
    }

    #[test]
    fn history_decimates_evenly() {
        let mut h = History::new(8);
        for i in 0..100 {
            h.push(i as f64, 0.0);
        }
        assert!(h.samples.len() <= 8);
        let dts: Vec<f64> = h.samples.windows(2).map(|w| w[1].0 - w[0].0).collect();
        assert!(dts.iter().all(|&d| d == dts[0]), "{dts:?}");
    }
}
