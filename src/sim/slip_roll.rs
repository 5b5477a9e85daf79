//! The slip/roll detector (issue 8): where and when each apple stops sliding and starts rolling,
//! and whether it slips again at a transfer (docs/transitions.md); the records it writes are in
//! [`crate::record::transitions`]. It reads the layer after every force pass, beside the driver
//! that calls it.
//!
//! Every step the layer reports the slip of each contact it evaluated
//! ([`crate::layer::SlipSample`]: the tangential speed of the apple's surface point over the
//! other surface, belt velocity included, physics.md section 5). The detector turns that into
//! one state per apple:
//!
//! - **airborne**: no contact;
//! - **sliding**: at least one contact slides; the apple slides *on* the sliding contact that
//!   carries the largest normal force;
//! - **rolling**: in contact and no contact slides (rolling without slip, or resting, or carried
//!   by a belt); the apple rolls on the contact with the largest normal force.
//!
//! A rolling apple starts sliding when a contact's slip exceeds `hysteresis` x the threshold
//! `max(slip_speed_m_s, relative_tolerance |v|)` (|v| the apple's centre speed); a sliding one
//! stops when every slip is below the threshold: between the two it keeps its state (hysteresis). A new
//! apple state, or a new surface under it, counts only once it has lasted `min_dwell_s`: slips,
//! bounces and rolls shorter than that are not transitions (no chatter). A transition that counts is
//! dated back to where it began: where the slip reached zero, extrapolated linearly from the last
//! two steps (the slip of a sliding sphere changes linearly in time, physics.md section 6), or the
//! step of touch or lift-off. The apple's position, speed and spin are interpolated to that instant.
//!
//! The distance slid is the path of the contact point over the surface, the integral of the slip
//! speed (trapezoids between steps, plus the extrapolated ends): s0 t_roll / 2 on a flat plate.

use crate::layer::{AppleId, ContactLayer, SlipSample, SurfaceId};
use crate::math::{arr3, Vec3};
use crate::record::events::Party;
use crate::record::transitions::{
    histogram, AppleSlipSummary, Motion, SurfaceRollSummary, Transition, TransitionSummary,
};
use crate::scenario::TransitionSpec;
use rapier3d_f64::math::Pose;
use std::sync::Arc;

/// The state of an apple at one step.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Snap {
    t: f64,
    pos: Vec3,
    vel: Vec3,
    angvel: Vec3,
    slip: f64,
    point: Vec3,
}

impl Snap {
    /// Linear interpolation to time `t` (clamped to the two snaps).
    fn lerp(&self, b: &Snap, t: f64) -> Snap {
        let span = b.t - self.t;
        let f = if span > 0.0 {
            ((t - self.t) / span).clamp(0.0, 1.0)
        } else {
            1.0
        };
        Snap {
            t,
            pos: self.pos.lerp(b.pos, f),
            vel: self.vel.lerp(b.vel, f),
            angvel: self.angvel.lerp(b.angvel, f),
            slip: self.slip + (b.slip - self.slip) * f,
            point: self.point.lerp(b.point, f),
        }
    }
}

type Key = (Motion, Option<Party>);

#[derive(Debug, Clone)]
struct Pending {
    key: Key,
    t_start: f64,
    /// Slide distance and time accumulated up to `t_start`.
    acc: (f64, f64),
    before: Snap,
    after: Option<Snap>,
}

/// Per-apple detector state.
#[derive(Debug, Clone)]
struct Track {
    seen: bool,
    committed: Key,
    since: f64,
    /// Slide distance and time since the last committed transition.
    acc: (f64, f64),
    /// Previous step: instant state, slip of its contact, snapshot.
    prev_state: Motion,
    prev_slip: f64,
    prev: Option<Snap>,
    pending: Option<Pending>,
    /// Summary figures.
    first_seen_s: f64,
    first_rolling_s: Option<f64>,
    episodes: u32,
    slid_total: f64,
    surfaces: Vec<Party>,
    current_slip: f64,
}

impl Default for Track {
    fn default() -> Self {
        Self {
            seen: false,
            committed: (Motion::Airborne, None),
            since: 0.0,
            acc: (0.0, 0.0),
            prev_state: Motion::Airborne,
            prev_slip: 0.0,
            prev: None,
            pending: None,
            first_seen_s: 0.0,
            first_rolling_s: None,
            episodes: 0,
            slid_total: 0.0,
            surfaces: Vec::new(),
            current_slip: 0.0,
        }
    }
}

/// The slip/roll detector: fed every step by the driver.
#[derive(Debug, Clone)]
pub struct Detector {
    spec: TransitionSpec,
    tracks: Vec<Track>,
    frames: Vec<Option<Pose>>,
    apple_names: Vec<Arc<str>>,
    surface_names: Vec<Arc<str>>,
    events: Vec<Transition>,
    order: Vec<u32>,
    start: Vec<u32>,
    fill: Vec<u32>,
    contacts: Vec<SlipSample>,
}

impl Detector {
    /// A detector with the given settings; `frames` are the surfaces' along-frames in layer order
    /// (`None` for surfaces without a running direction).
    pub fn new(spec: TransitionSpec, frames: Vec<Option<Pose>>) -> Self {
        Self {
            spec,
            tracks: Vec::new(),
            frames,
            apple_names: Vec::new(),
            surface_names: Vec::new(),
            events: Vec::new(),
            order: Vec::new(),
            start: Vec::new(),
            fill: Vec::new(),
            contacts: Vec::new(),
        }
    }

    /// Slip speed of the contact apple `k` is on at the last step (0 when airborne or unknown).
    pub fn current_slip(&self, k: usize) -> f64 {
        self.tracks.get(k).map_or(0.0, |t| t.current_slip)
    }

    /// Current (committed) state of apple `k`.
    pub fn state(&self, k: usize) -> Motion {
        self.tracks
            .get(k)
            .map_or(Motion::Airborne, |t| t.committed.0)
    }

    /// Transitions so far, in the order they were confirmed.
    pub fn transitions(&self) -> &[Transition] {
        &self.events
    }

    /// Looks at the contacts of the last force pass of `layer` (time `t`).
    pub fn observe(&mut self, t: f64, layer: &ContactLayer) {
        let n = layer.apple_count();
        while self.apple_names.len() < n {
            let k = self.apple_names.len();
            self.apple_names
                .push(layer.apple_name(AppleId(k as u32)).into());
        }
        while self.surface_names.len() < layer.surface_count() {
            let s = self.surface_names.len();
            self.surface_names
                .push(layer.surface_name(SurfaceId(s as u32)).into());
        }
        self.tracks.resize_with(n, Track::default);
        // The samples grouped by apple (a counting sort: the layer's order within each apple).
        let slips = layer.slips();
        self.start.clear();
        self.start.resize(n + 1, 0);
        for s in slips {
            self.start[s.apple as usize + 1] += 1;
        }
        for k in 0..n {
            self.start[k + 1] += self.start[k];
        }
        self.order.clear();
        self.order.resize(slips.len(), 0);
        let mut fill = std::mem::take(&mut self.fill);
        fill.clear();
        fill.extend_from_slice(&self.start[..n]);
        for (i, s) in slips.iter().enumerate() {
            let k = s.apple as usize;
            self.order[fill[k] as usize] = i as u32;
            fill[k] += 1;
        }
        self.fill = fill;
        for k in 0..n {
            self.contacts.clear();
            let (lo, hi) = (self.start[k] as usize, self.start[k + 1] as usize);
            for &i in &self.order[lo..hi] {
                self.contacts.push(slips[i as usize]);
            }
            if layer.is_asleep(AppleId(k as u32)) || layer.is_riding(AppleId(k as u32)) {
                // Asleep, or riding a belt (rolling with it, no slip): nothing evaluated; the
                // state stands.
                let tr = &mut self.tracks[k];
                tr.prev = None;
                tr.current_slip = 0.0;
                continue;
            }
            let (pos, vel, angvel) = layer.apple_motion(AppleId(k as u32));
            self.observe_apple(k, t, pos, vel, angvel);
        }
    }

    fn observe_apple(&mut self, k: usize, t: f64, pos: Vec3, vel: Vec3, angvel: Vec3) {
        let spec = self.spec;
        let th = spec
            .slip_speed_m_s
            .max(spec.relative_tolerance * vel.length());
        let th_hi = spec.hysteresis * th;
        let tr = &mut self.tracks[k];
        // Contact states with hysteresis: after a rolling step a contact must exceed the upper
        // threshold to slide; after a sliding step (or a landing) the threshold itself.
        let limit = if tr.prev_state == Motion::Rolling {
            th_hi
        } else {
            th
        };
        let mut best: Option<(bool, f64, usize)> = None;
        for (c_idx, c) in self.contacts.iter().enumerate() {
            let sliding = c.slip_m_s > limit;
            // The contact the apple is on: sliding ones first, then the largest normal force.
            let cand = (sliding, c.normal_force_n, c_idx);
            best = match best {
                Some(b) if (b.0, b.1) >= (cand.0, cand.1) => Some(b),
                _ => Some(cand),
            };
        }
        let (state, support, slip, point) = match best {
            None => (Motion::Airborne, None, 0.0, pos),
            Some((sliding, _, c_idx)) => {
                let c = &self.contacts[c_idx];
                (
                    if sliding {
                        Motion::Sliding
                    } else {
                        Motion::Rolling
                    },
                    Some(c.other),
                    c.slip_m_s,
                    c.point,
                )
            }
        };
        tr.current_slip = slip;
        let snap = Snap {
            t,
            pos,
            vel,
            angvel,
            slip,
            point,
        };
        let key = (state, support);
        if !tr.seen {
            tr.seen = true;
            tr.committed = key;
            tr.since = t;
            tr.first_seen_s = t;
            if state == Motion::Rolling {
                tr.first_rolling_s = Some(t);
            }
            if state == Motion::Sliding {
                tr.episodes += 1;
            }
            if let Some(p) = support {
                tr.surfaces.push(p);
            }
            tr.prev_state = state;
            tr.prev_slip = slip;
            tr.prev = Some(snap);
            return;
        }
        let dt = tr.prev.map_or(0.0, |p| t - p.t);
        // The distance slid, and where a change of sliding began.
        let was = tr.prev_state == Motion::Sliding;
        let is = state == Motion::Sliding;
        let mut edge: Option<(f64, (f64, f64))> = None;
        if dt > 0.0 {
            if is && was {
                tr.acc.0 += 0.5 * (tr.prev_slip + slip) * dt;
                tr.acc.1 += dt;
            } else if is {
                // Onset: back to where the slip left zero (from rolling), else this step.
                let t0 = if tr.prev_state == Motion::Rolling && slip > tr.prev_slip {
                    (t - slip * dt / (slip - tr.prev_slip)).clamp(t - spec.min_dwell_s.max(dt), t)
                } else {
                    t
                };
                let before = tr.acc;
                tr.acc.0 += 0.5 * slip * (t - t0);
                tr.acc.1 += t - t0;
                edge = Some((t0, before));
            } else if was {
                tr.acc.0 += 0.5 * (tr.prev_slip + slip) * dt;
                tr.acc.1 += dt;
                // Stop: on to where the slip reaches zero (to rolling), else this step.
                let t0 = if state == Motion::Rolling && tr.prev_slip > slip {
                    (t + slip * dt / (tr.prev_slip - slip)).clamp(t, t + spec.min_dwell_s)
                } else {
                    t
                };
                tr.acc.0 += 0.5 * slip * (t0 - t);
                tr.acc.1 += t0 - t;
                edge = Some((t0, tr.acc));
            }
        }
        // Candidates, dwell, confirmation.
        if key == tr.committed {
            tr.pending = None;
        } else if tr.pending.as_ref().is_none_or(|p| p.key != key) {
            let (t_start, acc) = edge.unwrap_or((t, tr.acc));
            let prev = tr.prev.unwrap_or(snap);
            let (before, after) = if t_start < t {
                (prev.lerp(&snap, t_start), None)
            } else {
                (snap, None)
            };
            tr.pending = Some(Pending {
                key,
                t_start,
                acc,
                before,
                after,
            });
        } else if let Some(p) = tr.pending.as_mut() {
            if p.after.is_none() {
                if t <= p.t_start {
                    p.before = snap;
                } else {
                    p.after = Some(snap);
                }
            }
        }
        tr.prev_state = state;
        tr.prev_slip = slip;
        tr.prev = Some(snap);
        let confirm = tr
            .pending
            .as_ref()
            .is_some_and(|p| t - p.t_start >= spec.min_dwell_s && t > p.t_start);
        if confirm {
            let p = tr.pending.take().expect("pending");
            let at = match &p.after {
                Some(a) => p.before.lerp(a, p.t_start),
                None => Snap {
                    t: p.t_start,
                    ..p.before
                },
            };
            let (from, from_surface) = tr.committed;
            let (to, surface) = p.key;
            let along = match surface {
                Some(Party::Surface(s)) => self
                    .frames
                    .get(s as usize)
                    .copied()
                    .flatten()
                    .map(|f| f.inverse_transform_point(at.point).x),
                _ => None,
            };
            let ev = Transition {
                apple: self.apple_names[k].clone(),
                apple_index: k as u32,
                from,
                to,
                from_surface: from_surface
                    .map(|q| party_name(&self.apple_names, &self.surface_names, q)),
                surface: surface.map(|q| party_name(&self.apple_names, &self.surface_names, q)),
                time_s: p.t_start,
                position_m: arr3(at.pos),
                along_m: along,
                speed_m_s: at.vel.length(),
                spin_rad_s: at.angvel.length(),
                slip_m_s: if to == Motion::Airborne { 0.0 } else { at.slip },
                slid_m: p.acc.0,
                sliding_time_s: p.acc.1,
                since_previous_s: p.t_start - tr.since,
            };
            if to == Motion::Rolling && tr.first_rolling_s.is_none() {
                tr.first_rolling_s = Some(p.t_start);
            }
            if to == Motion::Sliding && from != Motion::Sliding {
                tr.episodes += 1;
            }
            if let Some(q) = surface {
                if !tr.surfaces.contains(&q) {
                    tr.surfaces.push(q);
                }
            }
            tr.slid_total += p.acc.0;
            tr.acc = (tr.acc.0 - p.acc.0, tr.acc.1 - p.acc.1);
            tr.committed = p.key;
            tr.since = p.t_start;
            self.events.push(ev);
        }
    }

    /// The transitions in order of time (then apple), and the summary section.
    pub fn finish(self) -> (Vec<Transition>, TransitionSummary) {
        let mut events = self.events;
        events.sort_by(|a, b| {
            a.time_s
                .total_cmp(&b.time_s)
                .then(a.apple_index.cmp(&b.apple_index))
        });
        let apples: Vec<AppleSlipSummary> = self
            .tracks
            .iter()
            .enumerate()
            .filter(|(_, t)| t.seen)
            .map(|(k, t)| AppleSlipSummary {
                apple: self.apple_names[k].clone(),
                first_rolling_s: t.first_rolling_s,
                slide_distance_m: t.slid_total + t.acc.0,
                slip_episodes: t.episodes,
                final_state: t.committed.0,
                surfaces: t
                    .surfaces
                    .iter()
                    .map(|&p| party_name(&self.apple_names, &self.surface_names, p))
                    .collect(),
            })
            .collect();
        let bin = self.spec.histogram_bin_m;
        let mut surfaces = Vec::new();
        for name in &self.surface_names {
            let on = |m: Motion| {
                events
                    .iter()
                    .filter(move |e| e.to == m && e.surface.as_deref() == Some(&**name))
            };
            let rolling: Vec<f64> = on(Motion::Rolling).filter_map(|e| e.along_m).collect();
            let rolling_starts = on(Motion::Rolling).count();
            let sliding_starts = on(Motion::Sliding).count();
            if rolling_starts == 0 && sliding_starts == 0 {
                continue;
            }
            let (edges, counts) = histogram(&rolling, bin);
            surfaces.push(SurfaceRollSummary {
                surface: name.clone(),
                rolling_starts,
                sliding_starts,
                rolling_start_along_m: (!rolling.is_empty()).then(|| {
                    [
                        rolling.iter().copied().fold(f64::INFINITY, f64::min),
                        rolling.iter().sum::<f64>() / rolling.len() as f64,
                        rolling.iter().copied().fold(f64::NEG_INFINITY, f64::max),
                    ]
                }),
                histogram_edges_m: edges,
                histogram_counts: counts,
            });
        }
        let summary = TransitionSummary {
            settings: self.spec,
            transitions: events.len(),
            apples,
            surfaces,
        };
        (events, summary)
    }
}

/// The name of a party.
fn party_name(apples: &[Arc<str>], surfaces: &[Arc<str>], p: Party) -> Arc<str> {
    match p {
        Party::Apple(j) => apples[j as usize].clone(),
        Party::Surface(s) => surfaces[s as usize].clone(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn snaps_interpolate_linearly() {
        let a = Snap {
            t: 1.0,
            pos: Vec3::ZERO,
            vel: Vec3::new(1.0, 0.0, 0.0),
            angvel: Vec3::ZERO,
            slip: 0.4,
            point: Vec3::ZERO,
        };
        let b = Snap {
            t: 2.0,
            pos: Vec3::new(2.0, 0.0, 0.0),
            vel: Vec3::new(3.0, 0.0, 0.0),
            slip: 0.0,
            ..a
        };
        let m = a.lerp(&b, 1.25);
        assert!((m.pos.x - 0.5).abs() < 1e-12);
        assert!((m.vel.x - 1.5).abs() < 1e-12);
        assert!((m.slip - 0.3).abs() < 1e-12);
    }
}
