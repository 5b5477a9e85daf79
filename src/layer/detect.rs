//! Contact detection at the current poses: which contacts exist now, which ended, which sleepers
//! must wake, and (with step control) how long the coming step may be.
//!
//! Apple-apple candidates come from the Verlet list ([`super::grid`]); apple-surface candidates
//! from a list of the surfaces within the skin of each apple, rebuilt together with it (or when a
//! surface moved by more than half the skin). Between rebuilds a step costs one distance test
//! per candidate; only overlapping candidates touch the contact store.

use super::adaptive::{limit_in_contact, time_to_touch};
use super::contacts::Contact;
use super::grid::{Pair, NONE};
use super::{lookahead, surface, ContactLayer, StepLimit, SurfaceCandidate};
use crate::contact::{self, theory};
use crate::math::Vec3;
use crate::record::events::Party;
use rapier3d_f64::dynamics::RigidBodySet;
use rapier3d_f64::geometry::ColliderSet;
use rapier3d_f64::math::Pose;
use rapier3d_f64::parry::bounding_volume::{Aabb, BoundingVolume};

impl ContactLayer {
    /// Reads each surface's pose and motion once per step, notes which moved or vanished, and
    /// lists the sleepers near those for waking (their support may have gone).
    pub(super) fn observe_surfaces(&mut self, bodies: &RigidBodySet, colliders: &ColliderSet) {
        let half_skin = 0.5 * self.grid.skin_m();
        let mut any_changed = false;
        for (surf, now) in self.surfaces.iter().zip(self.surf_now.iter_mut()) {
            now.changed = false;
            let Some(co) = colliders.get(surf.collider) else {
                if now.exists {
                    now.exists = false;
                    now.changed = true;
                    any_changed = true;
                    self.rebuild_candidates = true;
                }
                continue;
            };
            let pose = *co.position();
            if !now.exists {
                now.exists = true;
                now.pose = pose;
                now.pose_at_build = pose;
                let bs = co.shape().compute_local_bounding_sphere();
                let extent = bs.center.length() + bs.radius;
                now.extent_m = if extent.is_finite() && extent < 1e12 {
                    extent
                } else {
                    f64::INFINITY
                };
                self.rebuild_candidates = true;
            } else if pose != now.pose {
                now.pose = pose;
                now.changed = true;
                any_changed = true;
                if moved_by(&now.pose_at_build, &pose, now.extent_m) > half_skin {
                    self.rebuild_candidates = true;
                }
            }
            let parent = co.parent().and_then(|p| bodies.get(p).map(|rb| (p, rb)));
            match parent {
                Some((p, rb)) if !rb.is_fixed() => {
                    now.moving = true;
                    now.lin = rb.linvel();
                    now.ang = rb.angvel();
                    now.com = rb.center_of_mass();
                    now.inv_mass = if rb.is_dynamic() && rb.mass() > 0.0 {
                        1.0 / rb.mass()
                    } else {
                        0.0
                    };
                    now.dynamic_body = rb.is_dynamic().then_some(p);
                }
                _ => {
                    now.moving = false;
                    now.lin = Vec3::ZERO;
                    now.ang = Vec3::ZERO;
                    now.com = Vec3::ZERO;
                    now.inv_mass = 0.0;
                    now.dynamic_body = None;
                }
            }
            now.belt = pose.rotation * surf.belt_local;
            now.plane = match (&surf.shape, co.shape().as_halfspace()) {
                (surface::SurfaceShape::FromCollider, Some(hs)) => {
                    let n = pose.rotation * hs.normal;
                    Some((n, n.dot(pose.translation)))
                }
                _ => None,
            };
            if surf.belt_local != Vec3::ZERO {
                now.moving = true;
            }
        }
        if any_changed {
            for c in &self.candidates {
                let a = c.apple as usize;
                if self.asleep[a] && self.surf_now[c.surface as usize].changed {
                    self.to_wake.push(c.apple);
                }
            }
        }
    }

    /// Finds every contact at the current poses, closes contacts that parted, and lists
    /// sleepers that must wake (into `to_wake`).
    pub(super) fn detect(&mut self, colliders: &ColliderSet, time_s: f64, dt_s: f64) {
        self.stats = super::StepStats {
            dt_limit_s: f64::INFINITY,
            ..super::StepStats::default()
        };
        self.epoch += 1;
        self.count.iter_mut().for_each(|c| *c = 0);
        let mut dropped: Vec<Pair> = Vec::new();
        let rebuilt = self
            .grid
            .update(&self.pos, &self.radius, &self.awake, false, |p| {
                dropped.push(p)
            });
        if rebuilt {
            self.pair_scan = None;
        }
        // Contacts dropped by a rebuild are farther apart than the skin: they ended.
        for p in dropped {
            self.close_apple_pair(p, time_s);
        }
        if rebuilt || self.rebuild_candidates {
            self.rebuild_surface_candidates(colliders, time_s);
        }
        if rebuilt {
            self.reorder_contacts();
        }
        self.stats.apple_candidates = self.grid.pairs().len();
        self.detect_apple_pairs(time_s);
        self.detect_surface_contacts(colliders, time_s, dt_s);
    }

    /// Closes the contact of an apple pair that parted (or left the list).
    fn close_apple_pair(&mut self, p: Pair, time_s: f64) {
        let (i, j) = (p.i as usize, p.j as usize);
        let d = self.pos[i] - self.pos[j];
        let dist = d.length();
        let u = self.radius[i] + self.radius[j] - dist;
        let n = if dist > 0.0 { d / dist } else { Vec3::Z };
        let sep = (self.vel[i] - self.vel[j]).dot(n);
        if let Some(open) = self.contacts.remove(p.contact) {
            let names = self.names(p.i, Party::Apple(p.j));
            self.finished
                .push(open.finish(time_s, self.dt_back, u, sep, names));
        }
    }

    /// Closes a surface contact. `geometry` is the overlap and separation speed where the
    /// surface was seen; `None` when the apple left the surface's neighbourhood (overlap 0,
    /// separating at the apple's speed).
    fn close_surface_contact(&mut self, k: u32, geometry: Option<(f64, f64)>, time_s: f64) {
        let c = self.contacts.get(k);
        let (a, other) = (c.i, c.other);
        let (u, sep) = geometry.unwrap_or((0.0, self.vel[a as usize].length()));
        if let Some(open) = self.contacts.remove(k) {
            let names = self.names(a, other);
            self.finished
                .push(open.finish(time_s, self.dt_back, u, sep, names));
        }
    }

    fn detect_apple_pairs(&mut self, time_s: f64) {
        let wake_ratio = self.config.sleep.wake_overlap_ratio;
        let control = self.config.step_control;
        let horizon = control.map_or(0.0, |c| lookahead(self.last_dt, &c));
        let energy_loss = self.config.parts.energy_loss;
        let n_mat = self.materials.len();
        let epoch = self.epoch;
        let mut touching = 0;
        let mut parted: Vec<Pair> = Vec::new();
        // With sleepers, only the pairs with an awake apple (listed when the awake set or the
        // pairs change); a settled pile has none.
        let all = self.awake.len() == self.apples.len();
        if !all && self.pair_scan.is_none() {
            let active = &self.active;
            self.pair_scan = Some(
                (0..self.grid.pairs().len() as u32)
                    .filter(|&k| {
                        let p = self.grid.pairs()[k as usize];
                        active[p.i as usize] || active[p.j as usize]
                    })
                    .collect(),
            );
        }
        let scan = if all { None } else { self.pair_scan.take() };
        let count = scan.as_ref().map_or(self.grid.pairs().len(), |s| s.len());
        for q in 0..count {
            let k = scan.as_ref().map_or(q, |s| s[q] as usize);
            let p = self.grid.pairs()[k];
            let (i, j) = (p.i as usize, p.j as usize);
            let (ai, aj) = (self.active[i], self.active[j]);
            if !ai && !aj {
                continue;
            }
            let d = self.pos[i] - self.pos[j];
            let r2 = d.length_squared();
            let rs = self.radius[i] + self.radius[j];
            if r2 >= rs * rs && p.contact == NONE && control.is_none() && ai == aj {
                // The common case: apart, nothing open, nothing to plan.
                continue;
            }
            let dist = r2.sqrt();
            let u = rs - dist;
            let n = if dist > 0.0 {
                d * (1.0 / dist)
            } else {
                Vec3::Z
            };
            if ai != aj {
                // One sleeper: wake it if this contact starts, ends, or its overlap drifts.
                let sleeper = if ai { j } else { i };
                let drifts = p.contact != NONE && u > 0.0 && {
                    let c = self.contacts.get_mut(p.contact);
                    if c.ref_u.is_nan() {
                        c.ref_u = c.last_u;
                    }
                    (u - c.ref_u).abs() > wake_ratio * c.ref_u.max(0.0) + 1e-9
                };
                let starts = u > 0.0 && p.contact == NONE;
                let ends = u <= 0.0 && p.contact != NONE;
                if starts || ends || drifts {
                    self.to_wake.push(sleeper as u32);
                }
            } else if p.contact != NONE {
                self.contacts.get_mut(p.contact).ref_u = f64::NAN;
            }
            if let Some(c) = control {
                let law = self.laws[self.apples[i].material.0 as usize * n_mat
                    + self.apples[j].material.0 as usize];
                let (ri, rj) = (self.radius[i], self.radius[j]);
                let r_star = ri * rj / (ri + rj);
                let k_n = contact::normal::stiffness(law.e_star_pa, r_star);
                let m_n = theory::reduced_mass(self.apples[i].mass, self.apples[j].mass);
                if u <= 0.0 {
                    let closing = (self.vel[j] - self.vel[i]).dot(n);
                    // Relative acceleration of two apples: bounded by g (one supported, one
                    // falling); contact forces are not known yet at this point.
                    let accel = c.gravity.length();
                    if let Some(t_touch) = time_to_touch(-u, closing, accel, horizon) {
                        // About to touch: resolve the impact (see `StepControl`).
                        let closing = closing + accel * t_touch;
                        let t_h = theory::elastic_impact(m_n, closing, k_n, r_star).contact_time_s;
                        self.stats
                            .limit(t_touch + t_h / c.steps_per_contact, StepLimit::Approaching);
                    }
                } else {
                    let rate = (self.vel[j] - self.vel[i]).dot(n);
                    let record = match p.contact {
                        NONE => None,
                        slot => self.contacts.get_mut(slot).record.as_mut(),
                    };
                    let ke = if energy_loss { law.ke } else { 1.0 };
                    let lim = limit_in_contact(&c, record, m_n, k_n, u, rate, ke, time_s);
                    self.stats.limit(lim.0, lim.1);
                }
            }
            if u > 0.0 {
                let slot = match p.contact {
                    NONE => {
                        let s = self.contacts.insert(Contact::new(p.i, Party::Apple(p.j)));
                        self.grid.pairs_mut()[k].contact = s;
                        s
                    }
                    s => s,
                };
                self.contacts.see(slot, epoch);
                let c = self.contacts.get_mut(slot);
                c.normal = n;
                c.overlap_m = u;
                c.curvature2 = 1.0 / self.radius[j];
                c.last_u = u;
                self.count[i] += 1;
                self.count[j] += 1;
                touching += 1;
            } else if p.contact != NONE {
                parted.push(p);
                self.grid.pairs_mut()[k].contact = NONE;
            }
        }
        if scan.is_some() {
            self.pair_scan = scan;
        }
        for p in parted {
            self.close_apple_pair(p, time_s);
        }
        self.stats.apple_apple_contacts = touching;
    }

    fn detect_surface_contacts(&mut self, colliders: &ColliderSet, time_s: f64, dt_s: f64) {
        let control = self.config.step_control;
        let horizon = control.map_or(0.0, |c| lookahead(self.last_dt, &c));
        let ahead = control.map_or(dt_s, |_| horizon.max(dt_s));
        let energy_loss = self.config.parts.energy_loss;
        let n_mat = self.materials.len();
        let epoch = self.epoch;
        let mut touching = 0;
        let mut chain = std::mem::take(&mut self.chain);
        let mut hits = std::mem::take(&mut self.scratch);
        // A sleeper's surface contacts are frozen: only the awake apples' candidates.
        for w in 0..self.awake.len() {
            let k = self.awake[w] as usize;
            for ci in self.cand_start[k] as usize..self.cand_start[k + 1] as usize {
                let cand = self.candidates[ci];
                let a = cand.apple as usize;
                let s = cand.surface as usize;
                chain.clear();
                let mut k = cand.first;
                while k != NONE {
                    chain.push(k);
                    k = self.contacts.get(k).next;
                }
                hits.clear();
                let surf = &self.surfaces[s];
                let now = &self.surf_now[s];
                if now.exists {
                    if let Some(co) = colliders.get(surf.collider) {
                        let margin = 2.0 * self.vel[a].length() * ahead + 1e-9;
                        surface::surface_hits(
                            &surf.shape,
                            co,
                            self.pos[a],
                            self.radius[a],
                            margin,
                            &mut hits,
                        );
                    }
                }
                if hits.is_empty() && chain.is_empty() {
                    continue;
                }
                let law = self.laws
                    [self.apples[a].material.0 as usize * n_mat + surf.material.0 as usize];
                for hit in &hits {
                    // Match the hit to the open contact with the closest normal (one per smooth
                    // region), among those not matched yet.
                    let mut best: Option<(u32, f64)> = None;
                    for &k in &chain {
                        if !self.contacts.is_live(k) || self.contacts.stamp(k) == epoch {
                            continue;
                        }
                        let c = self.contacts.get(k);
                        let cos = c.normal.dot(hit.normal);
                        if cos > surface::MESH_MERGE_COS && best.is_none_or(|b| cos > b.1) {
                            best = Some((k, cos));
                        }
                    }
                    let r_star =
                        contact::normal::effective_radius(1.0 / self.radius[a], hit.curvature_1_m);
                    let v_s = self.surf_now[s].velocity_at(self.pos[a]);
                    if let (Some(c), Some(r_star)) = (control, r_star) {
                        let k_n = contact::normal::stiffness(law.e_star_pa, r_star);
                        let m_n = self.apples[a].mass;
                        if hit.overlap_m <= 0.0 {
                            // About to touch: resolve the impact (see `StepControl`).
                            let closing = (v_s - self.vel[a]).dot(hit.normal);
                            // Gravity towards the surface closes the gap within the step too.
                            let accel = (-c.gravity.dot(hit.normal)).max(0.0);
                            if let Some(t_touch) =
                                time_to_touch(-hit.overlap_m, closing, accel, horizon)
                            {
                                let closing = closing + accel * t_touch;
                                let t_h = theory::elastic_impact(m_n, closing, k_n, r_star)
                                    .contact_time_s;
                                self.stats.limit(
                                    t_touch + t_h / c.steps_per_contact,
                                    StepLimit::Approaching,
                                );
                            }
                        } else {
                            let rate = (v_s - self.vel[a]).dot(hit.normal);
                            let record =
                                best.and_then(|(k, _)| self.contacts.get_mut(k).record.as_mut());
                            let ke = if energy_loss { law.ke } else { 1.0 };
                            let lim = limit_in_contact(
                                &c,
                                record,
                                m_n,
                                k_n,
                                hit.overlap_m,
                                rate,
                                ke,
                                time_s,
                            );
                            self.stats.limit(lim.0, lim.1);
                        }
                    }
                    let slot = match best {
                        Some((k, _)) => k,
                        None => {
                            if hit.overlap_m <= 0.0 {
                                continue;
                            }
                            let k = self
                                .contacts
                                .insert(Contact::new(cand.apple, Party::Surface(cand.surface)));
                            chain.push(k);
                            k
                        }
                    };
                    if hit.overlap_m > 0.0 {
                        self.contacts.see(slot, epoch);
                        let c = self.contacts.get_mut(slot);
                        c.normal = hit.normal;
                        c.overlap_m = hit.overlap_m;
                        c.curvature2 = hit.curvature_1_m;
                        self.count[a] += 1;
                        touching += 1;
                    } else {
                        // Seen apart: it ended within the last step.
                        let sep = (self.vel[a] - v_s).dot(hit.normal);
                        self.close_surface_contact(slot, Some((hit.overlap_m, sep)), time_s);
                    }
                }
                // Contacts not seen this step: the apple left the surface's neighbourhood.
                let mut first = NONE;
                let mut last = NONE;
                for &k in &chain {
                    if !self.contacts.is_live(k) {
                        continue;
                    }
                    if self.contacts.stamp(k) != epoch {
                        self.close_surface_contact(k, None, time_s);
                        continue;
                    }
                    if last == NONE {
                        first = k;
                    } else {
                        self.contacts.get_mut(last).next = k;
                    }
                    last = k;
                }
                if last != NONE {
                    self.contacts.get_mut(last).next = NONE;
                }
                self.candidates[ci].first = first;
            }
        }
        self.chain = chain;
        self.scratch = hits;
        self.stats.contacts = self.stats.apple_apple_contacts + touching;
    }

    /// Lists, for every apple, the Hertz surfaces closer than the skin (their AABB first, then
    /// the exact geometry), keeping the open contacts of candidates that stay; contacts of
    /// candidates that leave the list are closed.
    fn rebuild_surface_candidates(&mut self, colliders: &ColliderSet, time_s: f64) {
        self.rebuild_candidates = false;
        let skin = self.grid.skin_m();
        let mut boxes: Vec<(u32, Aabb)> = Vec::new();
        for (s, (surf, now)) in self
            .surfaces
            .iter()
            .zip(self.surf_now.iter_mut())
            .enumerate()
        {
            now.pose_at_build = now.pose;
            if surf.rigid || !now.exists {
                continue;
            }
            if let Some(co) = colliders.get(surf.collider) {
                boxes.push((s as u32, co.compute_aabb().loosened(skin)));
            }
        }
        let mut fresh: Vec<SurfaceCandidate> = Vec::new();
        let mut hits = std::mem::take(&mut self.scratch);
        for (a, &p) in self.pos.iter().enumerate() {
            let r = self.radius[a];
            let ball = Aabb::new(p - Vec3::splat(r), p + Vec3::splat(r));
            for &(s, ref bx) in &boxes {
                if !bx.intersects(&ball) {
                    continue;
                }
                hits.clear();
                self.surf_now[s as usize].hits(
                    &self.surfaces[s as usize],
                    colliders,
                    p,
                    r,
                    skin,
                    &mut hits,
                );
                if !hits.is_empty() {
                    fresh.push(SurfaceCandidate {
                        apple: a as u32,
                        surface: s,
                        first: NONE,
                    });
                }
            }
        }
        self.scratch = hits;
        // Merge: both lists are sorted by (apple, surface).
        let old = std::mem::take(&mut self.candidates);
        let mut o = 0;
        let mut gone: Vec<u32> = Vec::new();
        let key = |c: &SurfaceCandidate| (c.apple, c.surface);
        for f in fresh.iter_mut() {
            while o < old.len() && key(&old[o]) < key(f) {
                gone.push(old[o].first);
                o += 1;
            }
            if o < old.len() && key(&old[o]) == key(f) {
                f.first = old[o].first;
                o += 1;
            }
        }
        gone.extend(old[o..].iter().map(|c| c.first));
        self.candidates = fresh;
        self.cand_start.clear();
        self.cand_start.resize(self.pos.len() + 1, 0);
        for c in &self.candidates {
            self.cand_start[c.apple as usize + 1] += 1;
        }
        for k in 0..self.pos.len() {
            self.cand_start[k + 1] += self.cand_start[k];
        }
        for mut k in gone {
            while k != NONE {
                let next = self.contacts.get(k).next;
                self.close_surface_contact(k, None, time_s);
                k = next;
            }
        }
    }
}

impl ContactLayer {
    /// Puts the contacts in the order detection visits them (the pairs, then the surface
    /// candidates), so that detection and the force pass walk the slab forwards: measured on the
    /// 8036-apple pile, where the slab (8.8 MB) outgrows the caches, pair detection took 14 % of
    /// a step with contacts in the order they happened to start, against 8 % on 1000 apples.
    fn reorder_contacts(&mut self) {
        let mut order = Vec::with_capacity(self.contacts.live_count());
        order.extend(
            self.grid
                .pairs()
                .iter()
                .filter(|p| p.contact != NONE)
                .map(|p| p.contact),
        );
        for c in &self.candidates {
            let mut k = c.first;
            while k != NONE {
                order.push(k);
                k = self.contacts.get(k).next;
            }
        }
        if order.len() != self.contacts.live_count() {
            // Every live contact belongs to a pair or a chain; if not, leave the slab as it is.
            debug_assert!(false, "contacts outside the lists");
            return;
        }
        let new_of = self.contacts.reorder(&order);
        for p in self.grid.pairs_mut() {
            if p.contact != NONE {
                p.contact = new_of[p.contact as usize];
            }
        }
        for c in &mut self.candidates {
            if c.first != NONE {
                c.first = new_of[c.first as usize];
            }
        }
    }
}

/// Largest displacement of a point of a shape within `extent` of its origin when its pose goes
/// from `a` to `b` (m).
fn moved_by(a: &Pose, b: &Pose, extent: f64) -> f64 {
    let shift = (b.translation - a.translation).length();
    let angle = a.rotation.angle_between(b.rotation);
    if angle == 0.0 {
        shift
    } else {
        shift + angle * extent
    }
}
