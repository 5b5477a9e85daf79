//! Contact detection at the current poses: which contacts exist now, which ended, which sleepers
//! must wake, and (with step control) how long the coming step may be.
//!
//! Apple-apple candidates come from the Verlet list ([`super::grid`]); apple-surface candidates
//! from a list of the surfaces within the skin of each apple, rebuilt together with it (or when a
//! surface moved by more than half the skin). Between rebuilds a step costs one distance test
//! per candidate; only overlapping candidates touch the contact store.
//!
//! [`Detection`] owns the pair finding state (the grid, the surface candidates, the surfaces as
//! seen this step); what it finds goes into the contact slab, the frame's contact counts, the
//! finished events and the step statistics, which it borrows for the pass ([`Parts`]).

use super::adaptive::{limit_in_contact, stick_half_period, time_to_touch, RestingBound};
use super::clock::{StepClock, StepLimit};
use super::config::{LayerConfig, StepControl};
use super::contacts::{Contact, ContactStore, Shaped};
use super::frame::Frame;
use super::grid::{NeighborList, Pair, NONE};
use super::outputs::{Outputs, StepStats};
use super::registry::Registry;
use super::scene::{Seen, SurfaceNow};
use super::sleep::Sleep;
use super::stage_clock::{Clock, Stage};
use super::surface::{self, SurfaceHit};
use crate::contact::{self, geometry, theory};
use crate::math::Vec3;
use crate::record::events::Party;
use rapier3d_f64::dynamics::RigidBodySet;
use rapier3d_f64::geometry::ColliderSet;
use rapier3d_f64::parry::bounding_volume::{Aabb, BoundingVolume};

/// A surface near an apple: listed at the last rebuild (closer than the skin), with the chain of
/// its open contacts (see [`Contact::next`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct SurfaceCandidate {
    apple: u32,
    surface: u32,
    first: u32,
}

/// The rest of the layer, as one detection pass uses it.
pub(super) struct Parts<'a> {
    pub registry: &'a Registry,
    pub config: &'a LayerConfig,
    pub clock: &'a StepClock,
    pub frame: &'a mut Frame,
    pub sleep: &'a mut Sleep,
    pub contacts: &'a mut ContactStore,
    pub out: &'a mut Outputs,
}

/// Pair finding state.
#[derive(Debug)]
pub(super) struct Detection {
    grid: NeighborList,
    /// Surfaces near each apple, sorted by (apple, surface).
    candidates: Vec<SurfaceCandidate>,
    /// `candidates[cand_start[k]..cand_start[k + 1]]` are apple k's surface candidates.
    cand_start: Vec<u32>,
    /// With the pairs examined in several runs: the slot at which each run's open contacts
    /// begin in the slab ([`NONE`] for a run without one; 0 for the first), then the end of the
    /// apple pairs' contacts; empty with one run. The force pass splits the slab by it
    /// ([`super::kernel::share_ranges`]).
    pub slab_shares: Vec<u32>,
    rebuild_candidates: bool,
    /// Each surface as seen this step.
    pub surf_now: Vec<SurfaceNow>,
    /// The detection pass counter (see [`ContactStore::stamp`]); passes count from 2.
    pub epoch: u64,
    /// Indices of the pairs with an awake apple, when some apples sleep (`None`: all pairs, or
    /// not listed yet).
    pair_scan: Option<Vec<u32>>,
    scratch: Vec<SurfaceHit>,
    shaped_scratch: Vec<surface::ShapedHit>,
    spheroid_scratch: surface::SpheroidScratch,
    chain: Vec<u32>,
    /// Apples taken out of the run ([`Detection::retire`]): they touch nothing any more.
    retired: Vec<bool>,
    /// Per apple: a quiet rider, whose one candidate is its belt and took the riders' fast path
    /// at its last look. Until its ride over the belt's face ends (or the belt changes, or
    /// another candidate comes near) nothing of it can change: it is skipped, its record carried
    /// lazily ([`ContactStore::carry_quietly`]). On the 1000-apple line's late steps this is
    /// most of 950 riders among about 1 540 awake apples (docs/performance.md, "Twelfth
    /// session"). Its belt contact's slot, or [`NONE`].
    quiet: Vec<u32>,
    /// Per apple: the last step in which it was skipped as a quiet rider.
    skipped_through: Vec<u64>,
    /// The fastest moving surface this step (m/s; see [`SurfaceNow::shape_speed_m_s`]).
    pub surface_speed_m_s: f64,
    /// Contact counts per apple of the pair runs after the first (see `detect_apple_pairs`).
    run_counts: Vec<Vec<u16>>,
    /// Tests: this many runs of pairs, whatever the pool (on a pool of one thread, in turn).
    #[cfg(test)]
    force_runs: Option<usize>,
    /// Tests: how many contacts started, ended, woke a sleeper and limited the step, over the
    /// pair passes.
    #[cfg(test)]
    found_kinds: [usize; 4],
    /// Tests: whether resting contacts' lower bounds may skip their exact limits (see
    /// [`RestingBound`]), how many they skipped, and how many of those were surface contacts'.
    #[cfg(test)]
    bound_skip: bool,
    #[cfg(test)]
    bound_skips: usize,
    #[cfg(test)]
    surface_bound_skips: usize,
    /// Tests: whether a rider over its belt's face is listed as its belt's candidate without a
    /// query, and how many were.
    #[cfg(test)]
    face_skip: bool,
    #[cfg(test)]
    face_skips: usize,
    /// Tests: whether riders are carried lazily and quiet ones skipped, and how many were.
    #[cfg(test)]
    lazy_carry: bool,
    #[cfg(test)]
    quiet_skips: usize,
}

/// The relative drift of a rider's belt contact overlap that wakes it (see
/// `detect_surface_contacts`).
const RIDE_DRIFT: f64 = 1e-6;

/// How far inside a box belt's face edges a riding sphere is not queried again (m): nearer the
/// edges the full query decides whether it still holds.
const RIDE_FACE_INSET_M: f64 = 1e-3;

/// Listed pairs from which detection examines them on rayon's pool (below that, a task costs more
/// than it saves). Measured on the 1000-apple line's late steps (about 1 400 listed pairs, the
/// pool's threads polling): the pair stage 38-40 us a step on one run, 21-23 us on two.
const PARALLEL_MIN_PAIRS: usize = 512;

/// Apples from which the surface candidates are listed on rayon's pool, in runs of consecutive
/// apples (the 1000-apple line's 1 560 apples: 13 us a step of its rebuild on one thread).
pub const PARALLEL_MIN_CANDIDATE_APPLES: usize = 512;

/// The contact slots, written by several runs of pairs at once: each pair reaches only its own
/// contact's slot (a slot is opened for one pair, named by it alone, and opened or freed only in
/// the serial part of the pass), so no two runs touch the same slot.
struct SlotsMut {
    slots: *mut Contact,
    stamps: *mut u64,
    len: usize,
}

// SAFETY: see the type's doc; the store outlives the pass that holds this.
unsafe impl Sync for SlotsMut {}

impl SlotsMut {
    fn new(store: &mut ContactStore) -> Self {
        let (slots, stamps) = store.slots_and_stamps_mut();
        Self {
            slots: slots.as_mut_ptr(),
            stamps: stamps.as_mut_ptr(),
            len: slots.len(),
        }
    }

    /// The open contact in slot `k`, seen by this pass.
    ///
    /// # Safety
    /// Only the pair whose contact `k` is may call this, and only while it is examined.
    #[allow(clippy::mut_from_ref)]
    unsafe fn see(&self, k: u32, epoch: u64) -> &mut Contact {
        let k = k as usize;
        assert!(k < self.len, "a pair's contact slot is in the store");
        // SAFETY: in bounds (above); exclusive by the caller's contract.
        unsafe {
            *self.stamps.add(k) = epoch;
            &mut *self.slots.add(k)
        }
    }

    /// The open contact in slot `k`, as [`Self::see`] without seeing it.
    ///
    /// # Safety
    /// As [`Self::see`].
    #[allow(clippy::mut_from_ref)]
    unsafe fn get(&self, k: u32) -> &mut Contact {
        let k = k as usize;
        assert!(k < self.len, "a pair's contact slot is in the store");
        // SAFETY: as in `see`.
        unsafe { &mut *self.slots.add(k) }
    }
}

/// What one examination of the listed pairs reads: the poses, the sleepers, the settings; and
/// the slots of the contacts it updates.
struct PairView<'a> {
    registry: &'a Registry,
    frame: &'a Frame,
    asleep: &'a [bool],
    sleep: &'a Sleep,
    retired: &'a [bool],
    control: Option<StepControl>,
    gravity: Vec3,
    horizon: f64,
    dt_back: f64,
    energy_loss: bool,
    friction: bool,
    wake_ratio: f64,
    time_s: f64,
    epoch: u64,
    slots: SlotsMut,
    #[cfg(test)]
    bound_skip: bool,
}

/// A run of listed pairs: `pairs` from list index `first_k`, the scan's part naming them (`None`:
/// every pair), its contact counts per apple and what it found.
struct PairRun<'a> {
    pairs: &'a mut [Pair],
    first_k: usize,
    scan: Option<&'a [u32]>,
    len: usize,
    count: &'a mut [u16],
    found: &'a mut Found,
}

/// A contact that starts this pass: opened in pair order once every run is examined.
struct Start {
    k: u32,
    n: Vec3,
    u: f64,
    geo: Option<Shaped>,
}

/// What a run of pairs leaves for the serial part of the pass, in pair order.
#[derive(Default)]
struct Found {
    starts: Vec<Start>,
    parted: Vec<Pair>,
    to_wake: Vec<u32>,
    /// The run's shortest step limit, the first of equals (as `StepStats::limit` keeps it).
    limit: Option<(f64, StepLimit)>,
    touching: usize,
    /// The slots of the first and the last open contact the run examined, in pair order
    /// ([`NONE`] and 0 when none): where its contacts lie in the slab after a reorder.
    slots: (u32, u32),
    /// Tests: exact limits skipped by a resting contact's bound.
    #[cfg(test)]
    bound_skips: usize,
}

impl Found {
    fn limit(&mut self, dt: f64, why: StepLimit) {
        if self.limit.is_none_or(|(best, _)| dt < best) && dt < f64::INFINITY {
            self.limit = Some((dt, why));
        }
    }
}

/// Writes an apple pair's geometry at the current poses into its contact (`new`: opened now).
fn fill_pair_contact(
    c: &mut Contact,
    n: Vec3,
    u: f64,
    geo: Option<Shaped>,
    radius_j: f64,
    new: bool,
) {
    let old_normal = if new { Vec3::NAN } else { c.normal };
    c.normal = n;
    c.overlap_m = u;
    match geo {
        Some(sh) => {
            // The key of the law's constants: they follow R_k as the apples turn.
            c.curvature2 = 1.0 / sh.r_star_m;
            c.shaped = Some(sh);
            c.prev_normal = old_normal;
        }
        None => c.curvature2 = 1.0 / radius_j,
    }
    c.last_u = u;
}

impl Detection {
    pub fn new() -> Self {
        Self {
            grid: NeighborList::new(0.0),
            candidates: Vec::new(),
            cand_start: Vec::new(),
            slab_shares: Vec::new(),
            rebuild_candidates: true,
            surf_now: Vec::new(),
            epoch: 1,
            pair_scan: None,
            scratch: Vec::new(),
            shaped_scratch: Vec::new(),
            spheroid_scratch: surface::SpheroidScratch::default(),
            chain: Vec::new(),
            retired: Vec::new(),
            quiet: Vec::new(),
            skipped_through: Vec::new(),
            surface_speed_m_s: 0.0,
            run_counts: Vec::new(),
            #[cfg(test)]
            force_runs: None,
            #[cfg(test)]
            found_kinds: [0; 4],
            #[cfg(test)]
            bound_skip: true,
            #[cfg(test)]
            bound_skips: 0,
            #[cfg(test)]
            surface_bound_skips: 0,
            #[cfg(test)]
            face_skip: true,
            #[cfg(test)]
            face_skips: 0,
            #[cfg(test)]
            lazy_carry: true,
            #[cfg(test)]
            quiet_skips: 0,
        }
    }

    /// Takes apple `k` out of the run: from the next pass on it has no surface candidate and no
    /// apple contact (those open close then), wherever its body is. An apple that left the scene
    /// is parked far away, and a far place may still lie inside a surface (below an upward plane:
    /// a half-space reaches down without end).
    pub fn retire(&mut self, k: usize) {
        if self.retired.len() <= k {
            self.retired.resize(k + 1, false);
        }
        self.retired[k] = true;
        self.rebuild_candidates = true;
    }

    /// A new apple: the first one sets the grid's skin (its cells follow the largest radius).
    pub fn apple_added(&mut self, count: usize, radius: f64, skin_ratio: f64) {
        if count == 1 {
            self.grid = NeighborList::new(skin_ratio * radius);
        }
    }

    /// A new surface: the candidate lists must include it.
    pub fn surface_added(&mut self) {
        self.surf_now.push(SurfaceNow::new());
        self.rebuild_candidates = true;
    }

    /// The awake set changed: the list of pairs to scan must be made again.
    pub fn awake_changed(&mut self) {
        self.pair_scan = None;
    }

    /// The Verlet skin of the pair lists (m).
    pub fn skin_m(&self) -> f64 {
        self.grid.skin_m()
    }

    /// Reads each surface's pose and motion once per step, notes which moved or vanished, and
    /// asks to wake the sleepers near those (their support may have gone).
    pub fn observe_surfaces(
        &mut self,
        bodies: &RigidBodySet,
        colliders: &ColliderSet,
        registry: &Registry,
        sleep: &mut Sleep,
    ) {
        let half_skin = 0.5 * self.grid.skin_m();
        let mut any_changed = false;
        self.surface_speed_m_s = 0.0;
        for (surf, now) in registry.surfaces.iter().zip(self.surf_now.iter_mut()) {
            let (seen, rebuild) = now.observe(surf, bodies, colliders, half_skin);
            any_changed |= seen == Seen::Changed;
            self.rebuild_candidates |= rebuild;
            if !surf.rigid {
                self.surface_speed_m_s = self.surface_speed_m_s.max(now.shape_speed_m_s());
            }
        }
        if any_changed {
            for c in &self.candidates {
                if sleep.is_asleep(c.apple as usize) && self.surf_now[c.surface as usize].changed {
                    sleep.request_wake(c.apple);
                }
            }
        }
    }

    /// Finds every contact at the current poses, closes contacts that parted, and asks to wake
    /// the sleepers whose contacts start, end or drift.
    pub fn detect(&mut self, cx: &mut Parts, colliders: &ColliderSet, dt_s: f64) {
        let time_s = cx.clock.time_s;
        cx.out.stats = StepStats::fresh();
        self.epoch += 1;
        cx.frame.count.iter_mut().for_each(|c| *c = 0);
        let mut dropped: Vec<Pair> = Vec::new();
        let timer = Clock::start();
        let rebuilt = self.grid.update(
            &cx.frame.pos,
            &cx.frame.radius,
            cx.sleep.awake(),
            false,
            |p| dropped.push(p),
        );
        if rebuilt {
            self.pair_scan = None;
        }
        // Contacts dropped by a rebuild are farther apart than the skin: they ended.
        for p in dropped {
            close_apple_pair(cx, p, time_s);
        }
        let candidates = rebuilt || self.rebuild_candidates;
        if candidates {
            self.rebuild_surface_candidates(cx, colliders, time_s);
        }
        if rebuilt {
            self.reorder_contacts(cx.contacts);
        }
        if candidates {
            // A quiet rider stays quiet while its belt is still its one candidate (a candidate
            // that stays keeps its contacts, renumbered with the slab).
            for k in 0..self.quiet.len() {
                let slot = self.quiet[k];
                if slot != NONE {
                    let (c0, c1) = (self.cand_start[k] as usize, self.cand_start[k + 1] as usize);
                    let stays = c1 == c0 + 1
                        && self.candidates[c0].first == slot
                        && cx
                            .sleep
                            .ride_ref(k)
                            .is_some_and(|r| r.surface == self.candidates[c0].surface);
                    if !stays {
                        cx.contacts.end_quiet(slot, self.skipped_through[k]);
                        self.quiet[k] = NONE;
                    }
                }
            }
        }
        if candidates {
            timer.stop(Stage::Rebuild);
        }
        cx.out.stats.apple_candidates = self.grid.pairs().len();
        let timer = Clock::start();
        self.detect_apple_pairs(cx, time_s);
        timer.stop(Stage::Pairs);
        let timer = Clock::start();
        self.detect_surface_contacts(cx, colliders, time_s, dt_s);
        timer.stop(Stage::Surfaces);
    }

    fn detect_apple_pairs(&mut self, cx: &mut Parts, time_s: f64) {
        // With sleepers, only the pairs with an awake apple (listed when the awake set or the
        // pairs change); a settled pile has none.
        let all = cx.sleep.awake().len() == cx.registry.apples.len();
        if !all && self.pair_scan.is_none() {
            let asleep = cx.sleep.asleep();
            let pairs = self.grid.pairs();
            self.pair_scan = Some(
                (0..pairs.len() as u32)
                    .filter(|&k| {
                        let p = pairs[k as usize];
                        !asleep[p.i as usize] || !asleep[p.j as usize]
                    })
                    .collect(),
            );
        }
        let scan = if all { None } else { self.pair_scan.take() };
        let count = scan.as_ref().map_or(self.grid.pairs().len(), |s| s.len());
        // Runs of listed pairs, each examined on its own (on rayon's pool from
        // `PARALLEL_MIN_PAIRS` pairs) and applied in pair order: the same contacts, slots and
        // step limit for any number of runs.
        let threads = rayon::current_num_threads();
        let runs = if threads > 1 && count >= PARALLEL_MIN_PAIRS {
            threads
        } else {
            1
        };
        #[cfg(test)]
        let runs = self.force_runs.unwrap_or(runs).clamp(1, count.max(1));
        let mut counts = std::mem::take(&mut cx.frame.count);
        let n = counts.len();
        self.run_counts.resize_with(runs - 1, Vec::new);
        for c in &mut self.run_counts {
            c.clear();
            c.resize(n, 0);
        }
        let view = PairView {
            registry: cx.registry,
            frame: cx.frame,
            asleep: cx.sleep.asleep(),
            sleep: cx.sleep,
            retired: &self.retired,
            control: cx.config.step_control,
            gravity: cx.config.gravity,
            horizon: cx.clock.horizon_s,
            dt_back: cx.clock.dt_back,
            energy_loss: cx.config.parts.energy_loss,
            friction: cx.config.parts.friction,
            wake_ratio: cx.config.sleep.wake_overlap_ratio,
            time_s,
            epoch: self.epoch,
            slots: SlotsMut::new(cx.contacts),
            #[cfg(test)]
            bound_skip: self.bound_skip,
        };
        // Each run takes a range of the scan and the pairs it names (the scan is increasing, so
        // the runs' pairs are disjoint ranges of the list).
        let scan_ref = scan.as_deref();
        let bound = |r: usize| -> (usize, usize) {
            let q = r * count / runs;
            let k = match scan_ref {
                // The first run starts at the list's start (its slice does).
                _ if r == 0 => 0,
                Some(s) if q < count => s[q] as usize,
                Some(_) => self.grid.pairs().len(),
                None => q,
            };
            (q, k)
        };
        let bounds: Vec<(usize, usize)> = (0..=runs).map(bound).collect();
        let mut found: Vec<Found> = (0..runs)
            .map(|_| Found {
                slots: (NONE, 0),
                ..Found::default()
            })
            .collect();
        {
            let mut rest = self.grid.pairs_mut();
            let mut run_counts = self.run_counts.iter_mut();
            let mut jobs = Vec::with_capacity(runs);
            let mut first_counts = Some(&mut counts[..]);
            for (r, f) in found.iter_mut().enumerate() {
                let (q0, k0) = bounds[r];
                let (q1, k1) = bounds[r + 1];
                let (mine, tail) = std::mem::take(&mut rest).split_at_mut(k1 - k0);
                rest = tail;
                let count_r = match first_counts.take() {
                    Some(c) => c,
                    None => &mut run_counts.next().expect("one per extra run")[..],
                };
                jobs.push(PairRun {
                    pairs: mine,
                    first_k: k0,
                    scan: scan_ref.map(|s| &s[q0..q1]),
                    len: q1 - q0,
                    count: count_r,
                    found: f,
                });
            }
            if runs == 1 {
                jobs.iter_mut().for_each(|run| view.examine(run));
            } else {
                use rayon::prelude::*;
                jobs.par_iter_mut().for_each(|run| view.examine(run));
            }
        }
        for extra in &self.run_counts {
            for (c, e) in counts.iter_mut().zip(extra) {
                *c += e;
            }
        }
        cx.frame.count = counts;
        if scan.is_some() {
            self.pair_scan = scan;
        }
        // In pair order: the contacts that start (their slots), the step limit, the wakes and
        // the contacts that end.
        let mut touching = 0;
        for f in &found {
            #[cfg(test)]
            {
                let k = &mut self.found_kinds;
                k[0] += f.starts.len();
                k[1] += f.parted.len();
                k[2] += f.to_wake.len();
                k[3] += usize::from(f.limit.is_some());
                self.bound_skips += f.bound_skips;
            }
            touching += f.touching;
            for s in &f.starts {
                let p = self.grid.pairs()[s.k as usize];
                let slot = cx.contacts.insert(Contact::new(p.i, Party::Apple(p.j)));
                self.grid.pairs_mut()[s.k as usize].contact = slot;
                cx.contacts.see(slot, self.epoch);
                let radius_j = cx.frame.radius[p.j as usize];
                fill_pair_contact(cx.contacts.get_mut(slot), s.n, s.u, s.geo, radius_j, true);
                cx.frame.count[p.i as usize] += 1;
                cx.frame.count[p.j as usize] += 1;
            }
            if let Some((dt, why)) = f.limit {
                cx.out.stats.limit(dt, why);
            }
        }
        for f in &found {
            for &k in &f.to_wake {
                cx.sleep.request_wake(k);
            }
        }
        for f in &found {
            for &p in &f.parted {
                close_apple_pair(cx, p, time_s);
            }
        }
        cx.out.stats.apple_apple_contacts = touching;
        // Where each run's contacts begin in the slab (the slab is in pair order after a
        // reorder, the surfaces' contacts after the pairs'), for the force pass to evaluate each
        // contact on the thread that just examined it.
        self.slab_shares.clear();
        if runs > 1 {
            self.slab_shares.extend(found.iter().map(|f| f.slots.0));
            self.slab_shares[0] = 0;
            let end = found
                .iter()
                .rev()
                .find(|f| f.slots.0 != NONE)
                .map_or(0, |f| f.slots.1 + 1);
            self.slab_shares.push(end);
        }
    }

    fn detect_surface_contacts(
        &mut self,
        cx: &mut Parts,
        colliders: &ColliderSet,
        time_s: f64,
        dt_s: f64,
    ) {
        let control = cx.config.step_control;
        let gravity = cx.config.gravity;
        let horizon = cx.clock.horizon_s;
        let ahead = control.map_or(dt_s, |_| horizon.max(dt_s));
        let energy_loss = cx.config.parts.energy_loss;
        let friction = cx.config.parts.friction;
        let registry = cx.registry;
        let epoch = self.epoch;
        let mut touching = 0;
        let mut chain = std::mem::take(&mut self.chain);
        let mut hits = std::mem::take(&mut self.scratch);
        let mut shaped_hits = std::mem::take(&mut self.shaped_scratch);
        self.quiet.resize(cx.frame.pos.len(), NONE);
        self.skipped_through.resize(cx.frame.pos.len(), 0);
        let (step, dt_back) = (cx.clock.steps, cx.clock.dt_back);
        #[cfg(test)]
        let lazy = self.lazy_carry;
        #[cfg(not(test))]
        let lazy = true;
        // A sleeper's surface contacts are frozen: only the awake apples' candidates.
        for w in 0..cx.sleep.awake().len() {
            let k = cx.sleep.awake()[w] as usize;
            if self.quiet[k] != NONE {
                // What the fast path below tested of the candidate and its one contact cannot
                // change while the apple is skipped: only its ride, its belt and the time.
                match cx.sleep.ride_ref(k) {
                    Some(ride)
                        if time_s <= ride.face_until_s
                            && self.surf_now[ride.surface as usize].carries(ride.velocity) =>
                    {
                        cx.contacts.log_carry_step(step, dt_back, time_s);
                        self.skipped_through[k] = step;
                        #[cfg(test)]
                        {
                            self.quiet_skips += 1;
                        }
                        continue;
                    }
                    _ => {
                        cx.contacts
                            .end_quiet(self.quiet[k], self.skipped_through[k]);
                        self.quiet[k] = NONE;
                    }
                }
            }
            let one_candidate = self.cand_start[k + 1] == self.cand_start[k] + 1;
            for ci in self.cand_start[k] as usize..self.cand_start[k + 1] as usize {
                let cand = self.candidates[ci];
                let a = cand.apple as usize;
                let s = cand.surface as usize;
                chain.clear();
                let mut k = cand.first;
                while k != NONE {
                    chain.push(k);
                    k = cx.contacts.get(k).next;
                }
                hits.clear();
                shaped_hits.clear();
                let surf = &registry.surfaces[s];
                let now = &self.surf_now[s];
                let shape = registry.apples[a].shape;
                if let Some(ride) = cx.sleep.ride(a) {
                    // A sphere riding over its belt's face, well inside its edges, keeps its one
                    // hit at the same overlap (the check below would hold): not queried.
                    if shape.is_none()
                        && s as u32 == ride.surface
                        && chain.len() == 1
                        && cx.contacts.is_live(chain[0])
                        && !cx.contacts.get(chain[0]).ref_u.is_nan()
                        && now.carries(ride.velocity)
                        && time_s <= {
                            if ride.face_until_s.is_nan() {
                                // First look: until when it rides well inside the face.
                                let left = colliders.get(surf.collider).and_then(|co| {
                                    surface::time_over_a_box_face(
                                        &surf.shape,
                                        co,
                                        cx.frame.pos[a],
                                        ride.velocity,
                                        RIDE_FACE_INSET_M,
                                    )
                                });
                                let until = left.map_or(f64::NEG_INFINITY, |t| time_s + t);
                                cx.sleep.set_face_until(a, until);
                                until
                            } else {
                                ride.face_until_s
                            }
                        }
                    {
                        if lazy && one_candidate {
                            cx.contacts.carry_quietly(chain[0], step, dt_back, time_s);
                            self.quiet[a] = chain[0];
                            self.skipped_through[a] = step;
                        } else if lazy {
                            cx.contacts.carry_later(chain[0], step, dt_back, time_s);
                        } else if let Some(r) = cx.contacts.get_mut(chain[0]).record.as_mut() {
                            r.carry(dt_back, time_s);
                        }
                        continue;
                    }
                }
                if now.exists {
                    if let Some(co) = colliders.get(surf.collider) {
                        let margin = 2.0 * cx.frame.vel[a].length() * ahead + 1e-9;
                        match &shape {
                            Some(sph) => surface::spheroid_hits(
                                &surf.shape,
                                co,
                                cx.frame.pos[a],
                                &cx.frame.rot[a],
                                sph,
                                margin,
                                &mut hits,
                                &mut shaped_hits,
                                &mut self.spheroid_scratch,
                            ),
                            None => surface::surface_hits(
                                &surf.shape,
                                co,
                                cx.frame.pos[a],
                                cx.frame.radius[a],
                                margin,
                                &mut hits,
                            ),
                        }
                    }
                }
                if hits.is_empty() && chain.is_empty() {
                    continue;
                }
                if let Some(ride) = cx.sleep.ride(a) {
                    // A rider's frozen contact holds while its belt runs on unchanged under it,
                    // with one region of it at the same overlap, and nothing else is within the
                    // search margin: it is left unseen (not evaluated, not closed). Else it
                    // wakes, and this detection is redone with it awake.
                    let holds = if s as u32 == ride.surface {
                        self.surf_now[s].carries(ride.velocity)
                            && hits.len() == 1
                            && chain.len() == 1
                            && cx.contacts.is_live(chain[0])
                            && {
                                let (u, n) = (hits[0].overlap_m, hits[0].normal);
                                let c = cx.contacts.get_mut(chain[0]);
                                if c.ref_u.is_nan() {
                                    c.ref_u = c.overlap_m;
                                }
                                // On a belt's flat face a carried apple's overlap stays the
                                // same to the bit: any drift is the face's end (or a curve),
                                // where an awake apple begins to tip, so the rider wakes there
                                // (a 1e-6 drift: 4 um past a box's edge for an 80 mm apple).
                                u > 0.0
                                    && c.normal.dot(n) > surface::MESH_MERGE_COS
                                    && (u - c.ref_u).abs() <= RIDE_DRIFT * c.ref_u
                            }
                    } else {
                        hits.is_empty()
                    };
                    if holds {
                        // Its record goes on as if evaluated (impulse, resting time, steps).
                        if let Some(r) = cx.contacts.get_mut(chain[0]).record.as_mut() {
                            r.carry(cx.clock.dt_back, time_s);
                        }
                        continue;
                    }
                    cx.sleep.request_wake(a as u32);
                }
                let law = &registry.laws()
                    [registry.law_index(registry.apples[a].material, surf.material)];
                for (h, hit) in hits.iter().enumerate() {
                    let extra = shaped_hits.get(h).copied();
                    // Match the hit to the open contact with the closest normal (one per smooth
                    // region), among those not matched yet.
                    let mut best: Option<(u32, f64)> = None;
                    for &k in &chain {
                        if !cx.contacts.is_live(k) || cx.contacts.stamp(k) == epoch {
                            continue;
                        }
                        let c = cx.contacts.get(k);
                        let cos = c.normal.dot(hit.normal);
                        if cos > surface::MESH_MERGE_COS && best.is_none_or(|b| cos > b.1) {
                            best = Some((k, cos));
                        }
                    }
                    let (r_star, arm) = match extra {
                        Some(e) => (Some(e.r_star_m).filter(|r| r.is_finite()), e.arm),
                        None => (
                            contact::normal::effective_radius(
                                1.0 / cx.frame.radius[a],
                                hit.curvature_1_m,
                            ),
                            -hit.normal * cx.frame.radius[a],
                        ),
                    };
                    // The surface's material point under the apple (a turning roller's or a
                    // swinging part's velocity differs from the one at the apple's centre).
                    let under = match extra {
                        Some(_) => cx.frame.pos[a] + arm + hit.normal * hit.overlap_m,
                        // A sphere's, as always written (the same bits).
                        None => cx.frame.pos[a] - hit.normal * (cx.frame.radius[a] - hit.overlap_m),
                    };
                    let v_s = self.surf_now[s].velocity_at(under);
                    // A sphere resting on a surface that does not turn under it, whose limit's
                    // lower bound exceeds the shortest limit offered before it in this pass: it
                    // cannot set the step (see `RestingBound`), as for two apples. The bound
                    // holds for the curvature it was made at (kept with the contact's, reset
                    // when that changes).
                    let bounded = control.is_some()
                        && hit.overlap_m > 0.0
                        && shape.is_none()
                        && surf.turned_by_contacts.is_none()
                        && best.is_some_and(|(k, _)| {
                            let c = cx.contacts.get(k);
                            c.curvature2.to_bits() == hit.curvature_1_m.to_bits()
                                && c.resting_bound.skips(
                                    cx.out.stats.dt_limit_s,
                                    hit.overlap_m,
                                    (v_s - cx.frame.vel[a]).dot(hit.normal),
                                )
                        });
                    #[cfg(test)]
                    let bounded = bounded && self.bound_skip;
                    #[cfg(test)]
                    {
                        self.bound_skips += usize::from(bounded);
                        self.surface_bound_skips += usize::from(bounded);
                    }
                    if let (Some(c), Some(r_star), false) = (control, r_star, bounded) {
                        let k_n = contact::normal::stiffness(law.e_star_pa, r_star);
                        let m_n = registry.apples[a].mass;
                        if hit.overlap_m <= 0.0 {
                            // About to touch: resolve the impact (see `StepControl`). A
                            // spheroid's turn moves its support point towards the surface too:
                            // its nearest point's velocity (a sphere's turn does not).
                            let v_a = match &shape {
                                Some(_) => cx.frame.vel[a] + cx.frame.angvel[a].cross(arm),
                                None => cx.frame.vel[a],
                            };
                            let closing = (v_s - v_a).dot(hit.normal);
                            // Gravity towards the surface closes the gap within the step too.
                            let accel = (-gravity.dot(hit.normal)).max(0.0);
                            if let Some(t_touch) =
                                time_to_touch(-hit.overlap_m, closing, accel, horizon)
                            {
                                let closing = closing + accel * t_touch;
                                // A spheroid may turn its stiffest point to the surface before
                                // it lands: plan with its largest radius of curvature.
                                let (k_n, r_star) = match &shape {
                                    Some(sph) => {
                                        let k2 = if hit.curvature_1_m.is_finite() {
                                            hit.curvature_1_m
                                        } else {
                                            0.0
                                        };
                                        match contact::normal::effective_radius(
                                            1.0 / sph.stiffest_radius(),
                                            k2,
                                        ) {
                                            Some(r) if r > r_star => {
                                                (contact::normal::stiffness(law.e_star_pa, r), r)
                                            }
                                            _ => (k_n, r_star),
                                        }
                                    }
                                    None => (k_n, r_star),
                                };
                                let t_h = theory::elastic_impact(m_n, closing, k_n, r_star)
                                    .contact_time_s;
                                cx.out.stats.limit(
                                    t_touch + t_h / c.steps_per_contact,
                                    StepLimit::Approaching,
                                );
                            }
                        } else {
                            // A spheroid: its contact point's velocity (the law's rate).
                            let v_a = match &shape {
                                Some(_) => cx.frame.vel[a] + cx.frame.angvel[a].cross(arm),
                                None => cx.frame.vel[a],
                            };
                            let rate = (v_s - v_a).dot(hit.normal);
                            let record =
                                best.and_then(|(k, _)| cx.contacts.get_mut(k).record.as_mut());
                            let ke = if energy_loss { law.ke } else { 1.0 };
                            let turned = surf.turned_by_contacts;
                            // The stick spring's half period at overlap u: asked for once the
                            // contact rests, or on a free roller.
                            let tangential_at = |u: f64| {
                                if friction && law.friction > 0.0 {
                                    // A free-turning roller's surface point moves with the slip
                                    // too (its R^2 / I), as in the kernel's tangential mass.
                                    let m_t = 1.0
                                        / (registry.apples[a].inv_tangential_mass
                                            + turned.unwrap_or(0.0));
                                    stick_half_period(law.g_star_pa, r_star, u, m_t)
                                } else {
                                    f64::INFINITY
                                }
                            };
                            let tangential = || tangential_at(hit.overlap_m);
                            // A free roller needs them at every step (below): once.
                            let on_roller = turned.map(|_| tangential());
                            let lim = limit_in_contact(
                                &c,
                                record,
                                m_n,
                                k_n,
                                hit.overlap_m,
                                rate,
                                ke,
                                time_s,
                                || on_roller.unwrap_or_else(tangential),
                            );
                            cx.out.stats.limit(lim.0, lim.1);
                            if let (StepLimit::Resting, None, None, Some((k, _))) =
                                (lim.1, &shape, turned, best)
                            {
                                cx.contacts.get_mut(k).resting_bound.refresh(
                                    &c,
                                    m_n,
                                    k_n,
                                    hit.overlap_m,
                                    rate,
                                    tangential_at,
                                );
                            }
                            if let Some(t_stick) = on_roller {
                                // A light free roller's spin rings on the stick spring faster
                                // than the impact: four steps per half period at all times
                                // (k_t h^2 / m_t = 0.62, stable; docs/physics.md 12.5).
                                cx.out.stats.limit(0.25 * t_stick, lim.1);
                            }
                        }
                    }
                    let slot = match best {
                        Some((k, _)) => k,
                        None => {
                            if hit.overlap_m <= 0.0 {
                                continue;
                            }
                            let k = cx
                                .contacts
                                .insert(Contact::new(cand.apple, Party::Surface(cand.surface)));
                            chain.push(k);
                            k
                        }
                    };
                    if hit.overlap_m > 0.0 {
                        cx.contacts.see(slot, epoch);
                        if let (Some(v), None) =
                            (self.surf_now[s].running_belt(), surf.turned_by_contacts)
                        {
                            // Its material moves at one velocity everywhere, for ever: an apple
                            // may ride it.
                            cx.frame.carrier[a] = Some((s as u32, v));
                        }
                        let c = cx.contacts.get_mut(slot);
                        c.ref_u = f64::NAN;
                        c.normal = hit.normal;
                        c.overlap_m = hit.overlap_m;
                        match (extra, &shape) {
                            (Some(e), Some(sph)) => {
                                c.curvature2 = 1.0 / e.r_star_m;
                                c.shaped = Some(Shaped {
                                    arm: e.arm,
                                    lever2_m: f64::NAN,
                                    r_star_m: e.r_star_m,
                                    area_radius_m: e.area_radius_m,
                                    r_min_m: sph.a.min(sph.c),
                                });
                            }
                            _ => {
                                // A resting bound holds for one curvature (see above).
                                if c.curvature2.to_bits() != hit.curvature_1_m.to_bits() {
                                    c.resting_bound = RestingBound::NONE;
                                }
                                c.curvature2 = hit.curvature_1_m;
                            }
                        }
                        cx.frame.count[a] += 1;
                        touching += 1;
                    } else {
                        // Seen apart: it ended within the last step.
                        let sep = (cx.frame.vel[a] - v_s).dot(hit.normal);
                        close_surface_contact(cx, slot, Some((hit.overlap_m, sep)), time_s);
                    }
                }
                // Contacts not seen this step: the apple left the surface's neighbourhood.
                let mut first = NONE;
                let mut last = NONE;
                for &k in &chain {
                    if !cx.contacts.is_live(k) {
                        continue;
                    }
                    if cx.contacts.stamp(k) != epoch {
                        close_surface_contact(cx, k, None, time_s);
                        continue;
                    }
                    if last == NONE {
                        first = k;
                    } else {
                        cx.contacts.get_mut(last).next = k;
                    }
                    last = k;
                }
                if last != NONE {
                    cx.contacts.get_mut(last).next = NONE;
                }
                self.candidates[ci].first = first;
            }
        }
        self.chain = chain;
        self.scratch = hits;
        self.shaped_scratch = shaped_hits;
        cx.out.stats.contacts = cx.out.stats.apple_apple_contacts + touching;
    }

    /// Lists, for every apple, the Hertz surfaces closer than the skin (their AABB first, then
    /// the exact geometry), keeping the open contacts of candidates that stay; contacts of
    /// candidates that leave the list are closed.
    fn rebuild_surface_candidates(&mut self, cx: &mut Parts, colliders: &ColliderSet, time_s: f64) {
        self.rebuild_candidates = false;
        let skin = self.grid.skin_m();
        let registry = cx.registry;
        let mut boxes: Vec<(u32, Aabb)> = Vec::new();
        for (s, (surf, now)) in registry
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
                boxes.push((s as u32, surface_box(co).loosened(skin)));
            }
        }
        // The boxes in groups of consecutive surfaces, each with the box around its members: an
        // apple far from a group (a line's rollers, its bin's walls) skips it with one test.
        // Only the number of box tests changes: each apple still meets its surfaces in order.
        let groups: Vec<(Aabb, std::ops::Range<usize>)> = (0..boxes.len())
            .step_by(BOX_GROUP)
            .map(|g| {
                let members = g..(g + BOX_GROUP).min(boxes.len());
                let hull = boxes[members.clone()]
                    .iter()
                    .fold(boxes[g].1, |h, (_, b)| h.merged(b));
                (hull, members)
            })
            .collect();
        // Each apple's candidates alone, in apple order: on rayon's pool in runs of consecutive
        // apples from `PARALLEL_MIN_CANDIDATE_APPLES` apples, the runs' lists joined in order
        // (the same list for any number of threads).
        let (surf_now, retired) = (&self.surf_now, &self.retired);
        let (pos, radius) = (&cx.frame.pos, &cx.frame.radius);
        let sleep = &*cx.sleep;
        #[cfg(test)]
        let face_skip = self.face_skip;
        #[cfg(not(test))]
        let face_skip = true;
        #[cfg(test)]
        let face_skips = std::sync::atomic::AtomicUsize::new(0);
        let scan = |apples: std::ops::Range<usize>,
                    hits: &mut Vec<SurfaceHit>,
                    fresh: &mut Vec<SurfaceCandidate>| {
            for a in apples {
                if is_retired(retired, a) {
                    continue;
                }
                let (p, r) = (pos[a], radius[a]);
                let ball = Aabb::new(p - Vec3::splat(r), p + Vec3::splat(r));
                let near = groups
                    .iter()
                    .filter(|(hull, _)| hull.intersects(&ball))
                    .flat_map(|(_, members)| &boxes[members.clone()]);
                let ride = sleep.ride(a).filter(|_| face_skip);
                for &(s, ref bx) in near {
                    if !bx.intersects(&ball) {
                        continue;
                    }
                    // A sphere riding over its belt's face, well inside its edges, keeps its one
                    // hit at the same overlap (as the step's detection finds, without a query):
                    // a candidate, not queried.
                    let on_face = ride.is_some_and(|ride| {
                        s == ride.surface
                            && time_s <= ride.face_until_s
                            && registry.apples[a].shape.is_none()
                            && surf_now[s as usize].carries(ride.velocity)
                    });
                    if on_face {
                        #[cfg(test)]
                        face_skips.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                    } else {
                        hits.clear();
                        surf_now[s as usize].hits(
                            &registry.surfaces[s as usize],
                            colliders,
                            p,
                            r,
                            skin,
                            hits,
                        );
                        if hits.is_empty() {
                            continue;
                        }
                    }
                    fresh.push(SurfaceCandidate {
                        apple: a as u32,
                        surface: s,
                        first: NONE,
                    });
                }
            }
        };
        let n_apples = pos.len();
        let threads = rayon::current_num_threads();
        let mut fresh: Vec<SurfaceCandidate> = Vec::new();
        if threads > 1 && n_apples >= PARALLEL_MIN_CANDIDATE_APPLES {
            use rayon::prelude::*;
            let per = n_apples.div_ceil(threads);
            let lists: Vec<Vec<SurfaceCandidate>> = (0..threads)
                .into_par_iter()
                .map(|t| {
                    let (mut hits, mut list) = (Vec::new(), Vec::new());
                    scan(t * per..((t + 1) * per).min(n_apples), &mut hits, &mut list);
                    list
                })
                .collect();
            fresh.reserve(lists.iter().map(Vec::len).sum());
            lists.into_iter().for_each(|l| fresh.extend(l));
        } else {
            let mut hits = std::mem::take(&mut self.scratch);
            scan(0..n_apples, &mut hits, &mut fresh);
            self.scratch = hits;
        }
        #[cfg(test)]
        {
            self.face_skips += face_skips.into_inner();
        }
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
        let n = cx.frame.pos.len();
        self.cand_start.clear();
        self.cand_start.resize(n + 1, 0);
        for c in &self.candidates {
            self.cand_start[c.apple as usize + 1] += 1;
        }
        for k in 0..n {
            self.cand_start[k + 1] += self.cand_start[k];
        }
        for mut k in gone {
            while k != NONE {
                let next = cx.contacts.get(k).next;
                close_surface_contact(cx, k, None, time_s);
                k = next;
            }
        }
    }

    /// Puts the contacts in the order detection visits them (the pairs, then the surface
    /// candidates), so that detection and the force pass walk the slab forwards: measured on the
    /// 8036-apple pile, where the slab (8.8 MB) outgrows the caches, pair detection took 14 % of
    /// a step with contacts in the order they happened to start, against 8 % on 1000 apples.
    fn reorder_contacts(&mut self, contacts: &mut ContactStore) {
        let mut order = Vec::with_capacity(contacts.live_count());
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
                k = contacts.get(k).next;
            }
        }
        if order.len() != contacts.live_count() {
            // Every live contact belongs to a pair or a chain; if not, leave the slab as it is.
            debug_assert!(false, "contacts outside the lists");
            return;
        }
        let new_of = contacts.reorder(&order);
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
        for q in &mut self.quiet {
            if *q != NONE {
                *q = new_of[*q as usize];
            }
        }
    }
}

impl PairView<'_> {
    /// Examines a run of listed pairs at the current poses: updates the open contacts that go
    /// on, the pairs' gap bounds and the run's contact counts; lists what starts, ends and wakes,
    /// and the shortest step limit, for the serial part of the pass.
    fn examine(&self, run: &mut PairRun) {
        let (registry, frame, asleep) = (self.registry, self.frame, self.asleep);
        let apples = &registry.apples;
        let (control, gravity, horizon, dt_back) =
            (self.control, self.gravity, self.horizon, self.dt_back);
        let (energy_loss, friction, wake_ratio) =
            (self.energy_loss, self.friction, self.wake_ratio);
        let (time_s, epoch) = (self.time_s, self.epoch);
        let retired = |k: usize| is_retired(self.retired, k);
        for q in 0..run.len {
            let k = run.scan.map_or(run.first_k + q, |s| s[q] as usize);
            let pk = k - run.first_k;
            let p = run.pairs[pk];
            let (i, j) = (p.i as usize, p.j as usize);
            let (ai, aj) = (!asleep[i], !asleep[j]);
            if !ai && !aj {
                continue;
            }
            if retired(i) || retired(j) {
                // Taken out of the run: its contact (if any) ends here.
                if p.contact != NONE {
                    run.found.parted.push(p);
                    run.pairs[pk].contact = NONE;
                }
                continue;
            }
            let d = frame.pos[i] - frame.pos[j];
            let r2 = d.length_squared();
            let rs = frame.radius[i] + frame.radius[j];
            if r2 >= rs * rs && p.contact == NONE && control.is_none() && ai == aj {
                // The common case: apart, nothing open, nothing to plan.
                continue;
            }
            let spheroid = apples[i].shape.is_some() || apples[j].shape.is_some();
            if spheroid && p.contact == NONE && p.gap_bound_m > 0.0 {
                // Apart when last tested: the gap closes at most by the relative motion of
                // the last step (symplectic Euler moved the poses by the velocities now held),
                // the turns swinging the surfaces by up to |w| R.
                let reach = ((frame.vel[i] - frame.vel[j]).length()
                    + frame.angvel[i].length() * frame.radius[i]
                    + frame.angvel[j].length() * frame.radius[j])
                    * dt_back;
                let gap = f64::from(p.gap_bound_m) - reach;
                // With step control, a pair that may touch within the horizon must be planned.
                let ahead = match control {
                    None => 0.0,
                    Some(_) => {
                        let speed = (frame.vel[i] - frame.vel[j]).length()
                            + frame.angvel[i].length() * frame.radius[i]
                            + frame.angvel[j].length() * frame.radius[j];
                        (speed + gravity.length() * horizon) * horizon
                    }
                };
                if gap > ahead {
                    run.pairs[pk].gap_bound_m = gap as f32;
                    continue;
                }
            }
            // A spheroid in the pair: the common normal, from the open contact's normal (the
            // last step's) or the line of centres.
            let shaped = if spheroid {
                let n0 = match p.contact {
                    // Coincident centres (only a broken scene): +z, as for spheres.
                    NONE if r2 > 0.0 => d / r2.sqrt(),
                    NONE => Vec3::Z,
                    slot => {
                        // The last normal, moved on as it moved in the last step (the apples
                        // turn smoothly: one Newton step less when they roll).
                        // SAFETY: the pair's own contact.
                        let c = unsafe { self.slots.get(slot) };
                        let ahead = c.normal * 2.0 - c.prev_normal;
                        if ahead.is_finite() && ahead.length_squared() > 0.25 {
                            ahead.normalize()
                        } else {
                            c.normal
                        }
                    }
                };
                Some(shaped_pair(registry, frame, i, j, n0))
            } else {
                None
            };
            let (n, u) = match &shaped {
                Some((g, _)) => (g.normal, g.overlap_m),
                None => geometry::sphere_sphere(d, r2, rs),
            };
            if u > 0.0 {
                // A rider touches nothing but its belt: a contact starting wakes it.
                for k in [i, j] {
                    if self.sleep.ride(k).is_some() {
                        run.found.to_wake.push(k as u32);
                    }
                }
            }
            // Made when needed (planning, or a contact).
            let mut contact_geo: Option<Shaped> = None;
            if ai != aj {
                // One sleeper: wake it if this contact starts, ends, or its overlap drifts.
                let sleeper = if ai { j } else { i };
                let drifts = p.contact != NONE && u > 0.0 && {
                    // SAFETY: the pair's own contact.
                    let c = unsafe { self.slots.get(p.contact) };
                    if c.ref_u.is_nan() {
                        c.ref_u = c.last_u;
                    }
                    (u - c.ref_u).abs() > wake_ratio * c.ref_u.max(0.0) + 1e-9
                };
                let starts = u > 0.0 && p.contact == NONE;
                let ends = u <= 0.0 && p.contact != NONE;
                if starts || ends || drifts {
                    run.found.to_wake.push(sleeper as u32);
                }
            } else if p.contact != NONE {
                // SAFETY: the pair's own contact.
                unsafe { self.slots.get(p.contact) }.ref_u = f64::NAN;
            }
            // Two spheres apart that cannot touch within the horizon: nothing to plan, and the
            // law's constants below are not needed (the same test as the planning's, first).
            let far = control.is_some()
                && shaped.is_none()
                && u <= 0.0
                && time_to_touch(
                    -u,
                    (frame.vel[j] - frame.vel[i]).dot(n),
                    gravity.length(),
                    horizon,
                )
                .is_none();
            // Two spheres resting in contact whose limit's lower bound exceeds the shortest
            // limit offered before them in this run: they cannot set the step (see
            // `RestingBound`), and nothing else below needs the law's constants.
            let bounded = control.is_some()
                && u > 0.0
                && shaped.is_none()
                && p.contact != NONE
                && run.found.limit.is_some_and(|(best, _)| {
                    // SAFETY: the pair's own contact.
                    let bound = &unsafe { self.slots.get(p.contact) }.resting_bound;
                    bound.skips(best, u, (frame.vel[j] - frame.vel[i]).dot(n))
                });
            #[cfg(test)]
            let bounded = bounded && self.bound_skip;
            #[cfg(test)]
            {
                run.found.bound_skips += usize::from(bounded);
            }
            if let Some(c) = control.filter(|_| !far && !bounded) {
                let law =
                    &registry.laws()[registry.law_index(apples[i].material, apples[j].material)];
                let (ri, rj) = (frame.radius[i], frame.radius[j]);
                if let (Some((g, r_min)), None) = (&shaped, &contact_geo) {
                    contact_geo = Some(shaped_contact(g, *r_min));
                }
                let r_star = match &contact_geo {
                    Some(sh) if sh.r_star_m.is_finite() => sh.r_star_m,
                    _ => ri * rj / (ri + rj),
                };
                let k_n = contact::normal::stiffness(law.e_star_pa, r_star);
                let m_n = theory::reduced_mass(apples[i].mass, apples[j].mass);
                if u <= 0.0 {
                    // Spheroids: the velocities of the nearest points (their turns move them).
                    let closing = match &shaped {
                        Some((g, _)) => ((frame.vel[j] + frame.angvel[j].cross(g.arm2))
                            - (frame.vel[i] + frame.angvel[i].cross(g.arm1)))
                        .dot(n),
                        None => (frame.vel[j] - frame.vel[i]).dot(n),
                    };
                    // Relative acceleration of two apples: bounded by g (one supported, one
                    // falling); contact forces are not known yet at this point.
                    let accel = gravity.length();
                    if let Some(t_touch) = time_to_touch(-u, closing, accel, horizon) {
                        // About to touch: resolve the impact (see `StepControl`).
                        let closing = closing + accel * t_touch;
                        // Spheroids may turn their stiffest points together before they meet:
                        // plan with their largest radii of curvature.
                        let (k_n, r_star) = match &shaped {
                            Some(_) => {
                                let stiff = |k: usize| {
                                    apples[k]
                                        .shape
                                        .map_or(frame.radius[k], |sh| sh.stiffest_radius())
                                };
                                let r = 1.0 / (1.0 / stiff(i) + 1.0 / stiff(j));
                                if r > r_star {
                                    (contact::normal::stiffness(law.e_star_pa, r), r)
                                } else {
                                    (k_n, r_star)
                                }
                            }
                            None => (k_n, r_star),
                        };
                        let t_h = theory::elastic_impact(m_n, closing, k_n, r_star).contact_time_s;
                        run.found
                            .limit(t_touch + t_h / c.steps_per_contact, StepLimit::Approaching);
                    }
                } else {
                    // Spheroids: the contact points' velocities, as the law's overlap rate.
                    let rate = match &shaped {
                        Some((g, _)) => ((frame.vel[j] + frame.angvel[j].cross(g.arm2))
                            - (frame.vel[i] + frame.angvel[i].cross(g.arm1)))
                        .dot(n),
                        None => (frame.vel[j] - frame.vel[i]).dot(n),
                    };
                    let record = match p.contact {
                        NONE => None,
                        // SAFETY: the pair's own contact.
                        slot => unsafe { self.slots.get(slot) }.record.as_mut(),
                    };
                    let ke = if energy_loss { law.ke } else { 1.0 };
                    // The stick spring's half period at overlap u: asked for only once the
                    // contact rests.
                    let tangential = |u: f64| {
                        if friction && law.friction > 0.0 {
                            let m_t = 1.0
                                / (apples[i].inv_tangential_mass + apples[j].inv_tangential_mass);
                            stick_half_period(law.g_star_pa, r_star, u, m_t)
                        } else {
                            f64::INFINITY
                        }
                    };
                    let lim = limit_in_contact(&c, record, m_n, k_n, u, rate, ke, time_s, || {
                        tangential(u)
                    });
                    run.found.limit(lim.0, lim.1);
                    if lim.1 == StepLimit::Resting && shaped.is_none() && p.contact != NONE {
                        // SAFETY: the pair's own contact.
                        unsafe { self.slots.get(p.contact) }
                            .resting_bound
                            .refresh(&c, m_n, k_n, u, rate, tangential);
                    }
                }
            }
            if spheroid {
                // Rounded down to f32 and shrunk: a lower bound.
                run.pairs[pk].gap_bound_m = if u < 0.0 {
                    (-u * (1.0 - 1e-6)) as f32
                } else {
                    0.0
                };
            }
            if u > 0.0 {
                let geo = match (&shaped, contact_geo) {
                    (Some((g, r_min)), None) => Some(shaped_contact(g, *r_min)),
                    (_, geo) => geo,
                };
                if p.contact == NONE {
                    // Opened in pair order after the runs (its slot).
                    run.found.starts.push(Start {
                        k: k as u32,
                        n,
                        u,
                        geo,
                    });
                } else {
                    // SAFETY: the pair's own contact.
                    let c = unsafe { self.slots.see(p.contact, epoch) };
                    fill_pair_contact(c, n, u, geo, frame.radius[j], false);
                    let seen = &mut run.found.slots;
                    if seen.0 == NONE {
                        seen.0 = p.contact;
                    }
                    seen.1 = p.contact;
                    run.count[i] += 1;
                    run.count[j] += 1;
                }
                run.found.touching += 1;
            } else if p.contact != NONE {
                run.found.parted.push(p);
                run.pairs[pk].contact = NONE;
            }
        }
    }
}

/// Surfaces per group of the candidates' box test ([`Detection::rebuild_surface_candidates`]):
/// measured on the 1000-apple line (40 surfaces, 35 of them its singulator's rollers), where
/// each of 1 760 apples tested every surface's box at every rebuild.
const BOX_GROUP: usize = 8;

/// A box around a surface's collider. A cylinder's (a roller's) in closed form: parry finds it
/// from six support points (measured: 2 % of the 1000-apple line's late steps); the box only
/// culls the candidates' exact test, so it need only enclose the shape.
fn surface_box(co: &rapier3d_f64::geometry::Collider) -> Aabb {
    match co.shape().as_cylinder() {
        Some(cy) => {
            let pose = co.position();
            // The axis (local y) in the world; the disc's extent along world axis i is
            // r sqrt(1 - a_i^2).
            let a = pose.rotation * Vec3::Y;
            let half = Vec3::new(
                cy.half_height * a.x.abs() + cy.radius * (1.0 - a.x * a.x).max(0.0).sqrt(),
                cy.half_height * a.y.abs() + cy.radius * (1.0 - a.y * a.y).max(0.0).sqrt(),
                cy.half_height * a.z.abs() + cy.radius * (1.0 - a.z * a.z).max(0.0).sqrt(),
            );
            // Rounding: a hair wider, never narrower.
            let half = half * (1.0 + 1e-12) + Vec3::splat(1e-12);
            Aabb::new(pose.translation - half, pose.translation + half)
        }
        None => match co.shape().as_halfspace() {
            // A floor (a catch floor under a line): parry's box is the whole space, so every
            // apple would be queried against it at every rebuild; with an axis for its normal,
            // the solid side is bounded along that axis.
            Some(hs) => {
                let pose = co.position();
                let n = pose.rotation * hs.normal;
                let t = pose.translation;
                let inf = f64::INFINITY;
                let (mut lo, mut hi) = (Vec3::splat(-inf), Vec3::splat(inf));
                let axes = [n.x, n.y, n.z];
                if axes.iter().filter(|c| **c == 0.0).count() == 2 {
                    // Solid where (x - t).n <= 0: below t along +axis, above it along -axis.
                    for (k, c) in axes.iter().enumerate() {
                        if *c > 0.0 {
                            hi[k] = t[k];
                        } else if *c < 0.0 {
                            lo[k] = t[k];
                        }
                    }
                }
                Aabb::new(lo, hi)
            }
            None => co.compute_aabb(),
        },
    }
}

/// Whether apple `k` was taken out of the run (see [`Detection::retire`]).
fn is_retired(retired: &[bool], k: usize) -> bool {
    retired.get(k).copied().unwrap_or(false)
}

/// Closes the contact of an apple pair that parted (or left the list).
fn close_apple_pair(cx: &mut Parts, p: Pair, time_s: f64) {
    let (i, j) = (p.i as usize, p.j as usize);
    let f = &cx.frame;
    let d = f.pos[i] - f.pos[j];
    let dist = d.length();
    let (n, u) = if cx.registry.apples[i].shape.is_some() || cx.registry.apples[j].shape.is_some() {
        let n0 = cx.contacts.get(p.contact).normal;
        let (g, _) = shaped_pair(cx.registry, f, i, j, n0);
        (g.normal, g.overlap_m)
    } else {
        (
            if dist > 0.0 { d / dist } else { Vec3::Z },
            f.radius[i] + f.radius[j] - dist,
        )
    };
    let sep = (f.vel[i] - f.vel[j]).dot(n);
    if let Some(open) = cx.contacts.remove(p.contact) {
        let names = cx.registry.names(p.i, Party::Apple(p.j));
        cx.out
            .finished
            .push(open.finish(time_s, cx.clock.dt_back, u, sep, names));
    }
}

/// Closes a surface contact. `geometry` is the overlap and separation speed where the surface
/// was seen; `None` when the apple left the surface's neighbourhood (overlap 0, separating at the
/// apple's speed).
fn close_surface_contact(cx: &mut Parts, k: u32, geometry: Option<(f64, f64)>, time_s: f64) {
    let c = cx.contacts.get(k);
    let (a, other) = (c.i, c.other);
    let (u, sep) = geometry.unwrap_or((0.0, cx.frame.vel[a as usize].length()));
    if let Some(open) = cx.contacts.remove(k) {
        let names = cx.registry.names(a, other);
        cx.out
            .finished
            .push(open.finish(time_s, cx.clock.dt_back, u, sep, names));
    }
}

/// The geometry of apples `i` and `j` when one of them is a spheroid (a sphere is the spheroid
/// a = c of its radius), from the starting normal `n0` (from j to i), and the smallest of their
/// radii a, c (the overlap guard's).
fn shaped_pair(
    registry: &Registry,
    frame: &Frame,
    i: usize,
    j: usize,
    n0: Vec3,
) -> (contact::spheroid::PairGeometry, f64) {
    use contact::spheroid::{self, Spheroid};
    let shape = |k: usize| {
        registry.apples[k]
            .shape
            .unwrap_or(Spheroid::new(frame.radius[k], frame.radius[k]))
    };
    let (si, sj) = (shape(i), shape(j));
    let g = spheroid::pair(
        frame.pos[i],
        &frame.rot[i],
        &si,
        frame.pos[j],
        &frame.rot[j],
        &sj,
        n0,
    );
    (g, si.a.min(si.c).min(sj.a.min(sj.c)))
}

/// The law's geometry of a spheroid pair (made only for the pairs that touch or are planned:
/// the elliptic radii take a logarithm and a table look-up).
fn shaped_contact(g: &contact::spheroid::PairGeometry, r_min_m: f64) -> Shaped {
    let (r_star_m, area_radius_m) =
        contact::spheroid::hertz_radii(&g.curvature).unwrap_or((f64::NAN, f64::NAN));
    Shaped {
        arm: g.arm1,
        lever2_m: g.arm2.length(),
        r_star_m,
        area_radius_m,
        r_min_m,
    }
}

#[cfg(test)]
mod tests {
    use super::super::{AppleId, ContactLayer, StepRequest};
    use super::*;
    use crate::contact::spheroid::Spheroid;
    use crate::contact::Material;
    use rapier3d_f64::dynamics::{IslandManager, RigidBodyBuilder};
    use rapier3d_f64::parry::mass_properties::MassProperties;

    /// The closed-form boxes of the candidates' cull hold their shapes: a roller's (cylinder)
    /// box contains parry's at any pose and is no wider than its disc and length allow; a floor's
    /// (half-space) box is bounded only on its solid side, and only when its normal is an axis.
    #[test]
    fn surface_boxes_enclose_their_shapes() {
        use rapier3d_f64::geometry::ColliderBuilder;
        use rapier3d_f64::math::{Pose, Rotation};
        let mut seed = 7u64;
        for _ in 0..200 {
            let axis = Vec3::new(rnd(&mut seed), rnd(&mut seed), rnd(&mut seed));
            let angle = 3.0 * rnd(&mut seed);
            let rot = if axis.length() > 1e-3 {
                Rotation::from_axis_angle(axis.normalize(), angle)
            } else {
                Rotation::IDENTITY
            };
            let at = Vec3::new(rnd(&mut seed), rnd(&mut seed), rnd(&mut seed)) * 5.0;
            let (half, r) = (0.45 + 0.4 * rnd(&mut seed), 0.03 + 0.02 * rnd(&mut seed));
            let co = ColliderBuilder::cylinder(half, r)
                .position(Pose::from_parts(at, rot))
                .build();
            let (ours, parry) = (surface_box(&co), co.compute_aabb());
            for k in 0..3 {
                assert!(ours.mins[k] <= parry.mins[k] && ours.maxs[k] >= parry.maxs[k]);
                // parry's support-point box is exact for a cylinder: ours is the same to rounding.
                assert!((ours.mins[k] - parry.mins[k]).abs() < 1e-9);
                assert!((ours.maxs[k] - parry.maxs[k]).abs() < 1e-9);
            }
        }
        // A roller along y, as the line's: its box is its length along y and its disc in x, z.
        let co = ColliderBuilder::cylinder(0.45, 0.03)
            .position(Pose::from_parts(
                Vec3::new(9.0, 0.0, 0.8),
                Rotation::IDENTITY,
            ))
            .build();
        let b = surface_box(&co);
        assert!((b.maxs - Vec3::new(9.03, 0.45, 0.83)).abs().max_element() < 1e-9);
        assert!((b.mins - Vec3::new(8.97, -0.45, 0.77)).abs().max_element() < 1e-9);
        // A floor with normal +z at z = -0.5: solid below, bounded above only.
        let floor = ColliderBuilder::new(rapier3d_f64::geometry::SharedShape::halfspace(Vec3::Z))
            .position(Pose::from_translation(Vec3::new(1.0, 2.0, -0.5)))
            .build();
        let b = surface_box(&floor);
        assert_eq!(b.maxs.z, -0.5);
        assert!(b.mins.z == f64::NEG_INFINITY && b.maxs.x == f64::INFINITY);
        assert!(b.mins.x == f64::NEG_INFINITY && b.maxs.y == f64::INFINITY);
        // A ceiling (normal -z) is bounded below; a tilted plane not at all.
        let ceiling =
            ColliderBuilder::new(rapier3d_f64::geometry::SharedShape::halfspace(-Vec3::Z))
                .position(Pose::from_translation(Vec3::new(0.0, 0.0, 2.0)))
                .build();
        let b = surface_box(&ceiling);
        assert!(b.mins.z == 2.0 && b.maxs.z == f64::INFINITY);
        let tilted = ColliderBuilder::new(rapier3d_f64::geometry::SharedShape::halfspace(
            Vec3::new(0.0, 0.6, 0.8),
        ))
        .build();
        let b = surface_box(&tilted);
        assert!(b.mins.max_element() == f64::NEG_INFINITY && b.maxs.min_element() == f64::INFINITY);
    }

    /// The next number of a fixed pseudo-random sequence, in [-1, 1).
    fn rnd(seed: &mut u64) -> f64 {
        *seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (*seed >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }

    /// Five steps of the layer (with step control) on 1000 apples in a jittered lattice, every
    /// fourth a spheroid, moved about between the steps (rapier does not step them); from the
    /// second step on every seventh apple and the first 20 sleep and apple 3 is out of the run;
    /// the pairs examined in `runs` runs on a pool of `threads`. Returns, per step, what the
    /// pass left (the pairs, the contact slab, the step's figures, the contacts that ended, the
    /// sleepers, the contact counts), and how many contacts started, ended, woke a sleeper and
    /// limited the step.
    fn steps_on(threads: usize, runs: usize) -> (Vec<String>, [usize; 4]) {
        super::super::on_pool(threads, || {
            let mut bodies = RigidBodySet::new();
            let colliders = ColliderSet::new();
            let islands = IslandManager::new();
            let mut layer = ContactLayer::new(LayerConfig {
                step_control: Some(StepControl {
                    steps_per_contact: 20.0,
                    max_displacement_m: 0.01,
                }),
                ..LayerConfig::default()
            });
            layer.detection.force_runs = Some(runs);
            let fruit = layer.add_material(
                "apple",
                Material::from_shear(1.1e6, 0.18, Some(800.0)).unwrap(),
            );
            layer.set_default_coefficients(0.5, 0.09, 1000.0);
            let mut seed = 7;
            let mut handles = Vec::new();
            for k in 0..1000 {
                let cell = Vec3::new((k % 10) as f64, (k / 10 % 10) as f64, (k / 100) as f64);
                let mut jitter = || Vec3::new(rnd(&mut seed), rnd(&mut seed), rnd(&mut seed));
                let pos = cell * 0.078 + jitter() * 0.004;
                let vel = jitter() * 0.5;
                let r = 0.04 + 0.003 * rnd(&mut seed);
                let m = 800.0 * 4.0 / 3.0 * std::f64::consts::PI * r * r * r;
                let body = bodies.insert(
                    RigidBodyBuilder::dynamic()
                        .translation(pos)
                        .linvel(vel)
                        .additional_mass_properties(MassProperties::new(
                            Vec3::ZERO,
                            m,
                            Vec3::splat(0.4 * m * r * r),
                        )),
                );
                let name = format!("a{k}");
                if k % 4 == 0 {
                    let shape = Spheroid::new(r, 0.85 * r);
                    layer.add_spheroid_body(&bodies, body, shape, fruit, &name)
                } else {
                    layer.add_apple_body(&bodies, body, r, fruit, &name)
                }
                .unwrap();
                handles.push(body);
            }
            let mut log = Vec::new();
            let (mut t, mut last) = (0.0, None);
            for step in 0..5 {
                if step == 1 {
                    // The first 20 too: the list's first pairs are asleep (not scanned).
                    for k in (0..1000).filter(|k| k % 7 == 0 || *k < 20) {
                        layer.sleep.put_to_sleep(k);
                    }
                    layer.take_out_apple(AppleId(3));
                }
                if step > 0 {
                    for (k, &h) in handles.iter().enumerate() {
                        let shift = Vec3::new(rnd(&mut seed), rnd(&mut seed), rnd(&mut seed));
                        if !layer.sleep.is_asleep(k) {
                            let b = &mut bodies[h];
                            let pos = b.translation() + shift * 0.002;
                            b.set_translation(pos, false);
                        }
                    }
                }
                let request = StepRequest::adaptive(t, 5e-3, last, 5e-3, 0.0);
                let dt = layer
                    .step(&mut bodies, &colliders, &islands, &request)
                    .unwrap();
                (t, last) = (t + dt, Some(dt));
                log.push(format!("{:?}", layer.detection.grid.pairs()));
                log.push(format!("{:?}", layer.contacts));
                log.push(format!("{:?}", layer.out.stats));
                log.push(format!("{:?}", layer.out.finished));
                log.push(format!("{:?}", layer.sleep.asleep()));
                log.push(format!("{:?}", layer.frame.count));
            }
            (log, layer.detection.found_kinds)
        })
    }

    /// The resting contacts' lower bounds skip only exact step limits that cannot set the step
    /// ([`RestingBound`]): 60 apples poured into a small bin at `preview` take the same steps
    /// and end at the same poses, bit for bit, with the skip and without it, and the skip did
    /// skip (most resting limits, once the heap rests).
    #[test]
    fn resting_bounds_leave_every_step_bit_for_bit() {
        let json = r#"{
            "duration_s": 2.0, "time_step_s": "adaptive", "accuracy": "preview",
            "gravity_m_s2": [0, 0, -9.81],
            "output": {"sample_interval_s": 0.5, "force_history": false},
            "materials": {"apple": {"preset": "apple-paper"}, "plastic": {"preset": "plastic-paper"}},
            "contact": {"friction": 0.5, "ke": 0.09, "lambda_s_m": 1000},
            "sources": [{"name": "pour", "material": "apple",
                "diameter_m": {"mean_m": 0.075, "spread_m": 0.005},
                "position_m": [0, 0, 0.3], "jitter_m": 0.05, "velocity_m_s": [0, 0, -0.5],
                "rate_per_s": 60, "count": 60, "seed": 3}],
            "surfaces": [{"name": "bin", "type": "bin", "material": "plastic",
                "inner_size_m": [0.4, 0.4, 0.4], "position_m": [0, 0, 0]}]
        }"#;
        let skipping = run_scene(json, |d| d.bound_skip = true);
        let all = run_scene(json, |d| d.bound_skip = false);
        assert_eq!(all.bound_skips, 0);
        let skipped = skipping.bound_skips;
        let steps = skipping.steps.len();
        assert!(skipped > steps, "{skipped} skips in {steps} steps");
        // The bin's floor and walls under the heap skip theirs too.
        let on_bin = skipping.surface_bound_skips;
        assert!(on_bin > steps, "{on_bin} surface skips in {steps} steps");
        assert!(skipping.steps == all.steps, "the step times differ");
        assert!(skipping.poses == all.poses, "the poses differ");
        assert!(skipping.events == all.events, "the contact events differ");
    }

    /// The same for surface contacts on curved surfaces (a bound holds for the curvature it was
    /// made at): apples resting on four turning rollers while eight more are fed onto them (their
    /// landings set short steps, under which the resting contacts skip their exact limits), some
    /// carried off onto a plate: the same steps, poses and contact events, bit for bit, with the
    /// skip and without it. (Checked when written: most of the surface skips were on the rollers.)
    #[test]
    fn resting_bounds_on_rollers_leave_every_step_bit_for_bit() {
        let roller = |x: f64| {
            format!(
                r#"{{"name": "roller-{x}", "type": "roller", "material": "steel", "radius_m": 0.03,
                "length_m": 0.4, "position_m": [{x}, 0, 0.1], "axis": [0, 1, 0],
                "angular_velocity_rad_s": -6}}"#
            )
        };
        let rollers: Vec<String> = [0.0, 0.08, 0.16, 0.24].iter().map(|&x| roller(x)).collect();
        let json = format!(
            r#"{{
            "duration_s": 1.5, "time_step_s": "adaptive", "accuracy": "preview",
            "gravity_m_s2": [0, 0, -9.81],
            "output": {{"sample_interval_s": 0.5, "force_history": false}},
            "materials": {{"apple": {{"preset": "apple-paper"}},
                "steel": {{"youngs_modulus_pa": 2.0e11, "poisson_ratio": 0.3}}}},
            "contact": {{"friction": 0.5, "ke": 0.09, "lambda_s_m": 1000}},
            "apples": [
                {{"name": "a1", "material": "apple", "diameter_m": 0.085, "position_m": [0.04, 0, 0.2]}},
                {{"name": "a2", "material": "apple", "diameter_m": 0.075, "position_m": [0.12, 0.1, 0.2]}},
                {{"name": "a3", "material": "apple", "diameter_m": 0.065, "position_m": [0.2, -0.1, 0.2]}},
                {{"name": "a4", "material": "apple", "diameter_m": 0.07, "position_m": [0.12, -0.1, 0.3]}}],
            "sources": [{{"name": "feed", "material": "apple",
                "diameter_m": {{"mean_m": 0.07, "spread_m": 0.005}}, "position_m": [0.12, 0, 0.35],
                "jitter_m": 0.05, "velocity_m_s": [0, 0, -0.5], "rate_per_s": 8, "count": 8,
                "seed": 5}}],
            "surfaces": [{rollers}, {{"name": "plate", "type": "plane", "material": "steel",
                "point_m": [0, 0, 0], "normal": [0, 0, 1]}}]
        }}"#,
            rollers = rollers.join(", ")
        );
        let skipping = run_scene(&json, |d| d.bound_skip = true);
        let all = run_scene(&json, |d| d.bound_skip = false);
        assert_eq!(all.bound_skips, 0);
        let (on_surfaces, steps) = (skipping.surface_bound_skips, skipping.steps.len());
        assert!(
            on_surfaces > steps,
            "{on_surfaces} surface skips in {steps} steps"
        );
        assert!(skipping.steps == all.steps, "the step times differ");
        assert!(skipping.poses == all.poses, "the poses differ");
        assert!(skipping.events == all.events, "the contact events differ");
    }

    /// A rider over its belt's face is listed as its belt's candidate without a query: eight
    /// apples fed onto a running belt ride it for 3 s with the same steps and poses, bit for bit,
    /// as when every candidate is queried, and the rebuilds did list riders so.
    #[test]
    fn riders_listed_without_a_query_move_the_same_bits() {
        let json = fed_belt(3.0, "", "");
        let skipping = run_scene(&json, |d| d.face_skip = true);
        let all = run_scene(&json, |d| d.face_skip = false);
        assert_eq!(all.face_skips, 0);
        // All eight ride; 929 riders were listed without a query when this was written.
        assert_eq!(skipping.riding, 8);
        let skipped = skipping.face_skips;
        assert!(skipped > 929 / 2, "{skipped} riders listed without a query");
        assert!(skipping.steps == all.steps, "the step times differ");
        assert!(skipping.poses == all.poses, "the poses differ");
    }

    /// Riders carried lazily, the quiet ones skipped: apples fed onto a running belt ride it,
    /// one of them is woken by an apple thrown onto it (its step's detection redone while the
    /// others ride on) and all leave the belt's end. The steps, the poses, the open contacts'
    /// records read during the run and every contact event at its end are the same, bit for
    /// bit, as with each rider carried at every step.
    #[test]
    fn riders_carried_lazily_move_and_record_the_same_bits() {
        let json = fed_belt(
            5.0,
            r#"{"name": "thrown", "material": "apple", "diameter_m": 0.08,
                "position_m": [-1.4, 0.0, 0.3], "velocity_m_s": [0.4, 0, 4.74]}"#,
            r#", {"name": "floor", "type": "plane", "material": "steel",
                "point_m": [0, 0, -0.3], "normal": [0, 0, 1]}"#,
        );
        let lazy = run_scene(&json, |d| d.lazy_carry = true);
        let eager = run_scene(&json, |d| d.lazy_carry = false);
        assert_eq!(eager.quiet_skips, 0);
        let skipped = lazy.quiet_skips;
        println!(
            "{skipped} quiet riders skipped; {} riding at most; carry log full {} times, slab reordered {} times owing carries",
            lazy.riding, lazy.carry_log_full, lazy.reordered_owing
        );
        assert!(lazy.carry_log_full > 0 && lazy.reordered_owing > 0);
        assert!(lazy.riding >= 6, "{} ride", lazy.riding);
        assert!(skipped > 1000, "{skipped} skipped");
        assert!(lazy.steps == eager.steps, "the step times differ");
        assert!(lazy.poses == eager.poses, "the poses differ");
        assert_eq!(lazy.open.len(), eager.open.len());
        for (k, (a, b)) in lazy.open.iter().zip(&eager.open).enumerate() {
            assert!(a == b, "open contacts differ at look {k}:\n{a}\n{b}");
        }
        assert!(lazy.events == eager.events, "the contact events differ");
        // The thrown apple landed on the first apple fed, riding since about 0.4 s, at 1 s.
        assert!(lazy.events.contains(r#"a: "thrown", b: "feed-1""#));
    }

    /// Eight apples (75 +- 5 mm) fed at 4 a second onto a 3 m rubber belt running at 0.4 m/s,
    /// for `duration_s`, with the listed `apples` (JSON objects) and `more_surfaces` (a comma
    /// and JSON objects) besides; steel is defined for them.
    fn fed_belt(duration_s: f64, apples: &str, more_surfaces: &str) -> String {
        format!(
            r#"{{
            "duration_s": {duration_s}, "time_step_s": "adaptive",
            "gravity_m_s2": [0, 0, -9.81],
            "output": {{"sample_interval_s": 0.5, "force_history": false}},
            "materials": {{"apple": {{"preset": "apple-paper"}},
                "rubber": {{"youngs_modulus_pa": 5e6, "poisson_ratio": 0.45}},
                "steel": {{"youngs_modulus_pa": 2e11, "poisson_ratio": 0.3}}}},
            "contact": {{"friction": 0.5, "ke": 0.09, "lambda_s_m": 1000}},
            "apples": [{apples}],
            "sources": [{{"name": "feed", "material": "apple",
                "diameter_m": {{"mean_m": 0.075, "spread_m": 0.005}},
                "position_m": [-1.4, 0, 0.0601], "jitter_m": 0.0, "velocity_m_s": [0.4, 0, 0],
                "rate_per_s": 4, "count": 8, "seed": 5}}],
            "surfaces": [{{"name": "belt", "type": "conveyor", "material": "rubber",
                "size_m": [3.0, 0.5, 0.04], "position_m": [0, 0, 0], "belt_velocity_m_s": 0.4}}
                {more_surfaces}]
        }}"#
        )
    }

    /// What [`run_scene`] leaves: every step's end time and the final centres, as bits, the
    /// most apples riding at once, and the detection's test counters.
    struct SceneRun {
        steps: Vec<u64>,
        poses: Vec<[u64; 3]>,
        riding: usize,
        /// The detection's test counters: riders listed without a query, quiet riders skipped,
        /// resting limits skipped.
        face_skips: usize,
        quiet_skips: usize,
        bound_skips: usize,
        surface_bound_skips: usize,
        /// The slab's counters: carry log full, reordered while slots owed carries.
        carry_log_full: usize,
        reordered_owing: usize,
        /// The open contacts' events every 50th step (`Debug`, which prints every number's
        /// shortest exact form), and every contact's event at the end.
        open: Vec<String>,
        events: String,
    }

    /// Runs the scenario `json` to its end, after `set` (a test switch) on its detection.
    fn run_scene(json: &str, set: fn(&mut Detection)) -> SceneRun {
        let sc = crate::scenario::from_json(json, "scene.json").unwrap();
        let mut sim = crate::sim::Simulation::new(&sc, std::path::Path::new(".")).unwrap();
        set(&mut sim.world_mut().layer.detection);
        let (mut steps, mut riding, mut open) = (Vec::new(), 0, Vec::new());
        while !sim.done() {
            sim.step(&mut crate::record::series::NoSamples).unwrap();
            steps.push(sim.time_s().to_bits());
            riding = riding.max(sim.world().layer.sleep.riding_count());
            if steps.len() % 50 == 0 {
                open.push(format!("{:?}", sim.world().layer.open_events()));
            }
        }
        let layer = &mut sim.world_mut().layer;
        let poses = layer
            .frame
            .pos
            .iter()
            .map(|p| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()])
            .collect();
        let (carry_log_full, reordered_owing) = (
            layer.contacts.carries.full,
            layer.contacts.carries.reordered_owing,
        );
        let d = &layer.detection;
        let (face_skips, quiet_skips, bound_skips) = (d.face_skips, d.quiet_skips, d.bound_skips);
        let surface_bound_skips = d.surface_bound_skips;
        let done = sim
            .run(&mut crate::record::series::NoSamples, &mut |_| {})
            .unwrap();
        SceneRun {
            steps,
            poses,
            riding,
            face_skips,
            quiet_skips,
            bound_skips,
            surface_bound_skips,
            carry_log_full,
            reordered_owing,
            open,
            events: format!("{:?}", done.events),
        }
    }

    /// The pairs examined in several runs (on one thread in turn, or on two at once) leave the
    /// same pairs, contacts, step figures, ended contacts, sleepers and counts as one run.
    #[test]
    fn runs_of_pairs_find_and_apply_the_same_as_one() {
        let (one, kinds) = steps_on(1, 1);
        // Every kind of finding occurs: contacts start, end, wake sleepers and limit steps.
        assert!(kinds.iter().all(|&k| k > 0), "{kinds:?}");
        for (threads, runs) in [(1, 3), (2, 2), (2, 5)] {
            let (other, _) = steps_on(threads, runs);
            assert_eq!(one.len(), other.len());
            for (k, (a, b)) in one.iter().zip(&other).enumerate() {
                assert!(
                    a == b,
                    "{runs} runs on {threads} threads: item {k} of the log differs"
                );
            }
        }
    }
}
