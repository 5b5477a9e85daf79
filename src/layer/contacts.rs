//! The open contacts: a slab of contact states with a free list.
//!
//! A contact exists from the step its two bodies are first seen overlapping until they part. Its
//! slot never moves while it lives, so the pair lists point at it by index, the force pass runs
//! over the slab itself (in parallel, each contact writing only its own state and output slot)
//! and the forces are summed in slab order. Freed slots are reused last-freed-first: the order
//! depends only on the run's history, never on the thread count, which keeps runs bit-identical.
//!
//! Which contacts the current detection pass saw overlapping is kept beside the slab, one stamp
//! per slot: the force pass finds them without loading a whole contact per slot (a settled pile
//! has thousands of frozen contacts and nothing to evaluate).
//!
//! A rider's frozen belt contact is carried lazily ([`ContactStore::carry_later`]): the steps it
//! rode through are logged once, beside the slab, and replayed on its record when anything next
//! takes the contact (detection, its end, a query), the same operations in the same order as
//! carrying it at every step.

use super::grid::NONE;
use crate::contact::ContactConstants;
use crate::math::Vec3;
use crate::record::events::{OpenContact, Party};
use std::borrow::Cow;

/// One contact of an apple with another apple or with a surface.
#[derive(Debug, Clone)]
pub struct Contact {
    /// The apple (for an apple-apple contact, the one of lower index).
    pub i: u32,
    /// The other party.
    pub other: Party,
    /// Next contact of the same (apple, surface) candidate (a mesh can touch an apple at several
    /// places), or [`NONE`].
    pub next: u32,
    /// Unit normal from the other body towards apple `i`, at the current poses.
    pub normal: Vec3,
    /// The normal of the step before (a spheroid pair's search starts from the two normals'
    /// linear extrapolation; NaN before it has two).
    pub prev_normal: Vec3,
    /// Overlap at the current poses (m).
    pub overlap_m: f64,
    /// Curvature of the other body at the contact (1/m).
    pub curvature2: f64,
    /// Stored tangential displacement of the Mindlin stick spring (see `contact::friction`).
    pub xi: Vec3,
    /// Stored torque of the `epsd2` rolling spring on apple `i` (see `contact::rolling`).
    pub rolling: Vec3,
    /// Overlap at the last detection (for the wake rule of a sleeper's contacts).
    pub last_u: f64,
    /// Overlap when one of the two fell asleep (NaN while both are awake).
    pub ref_u: f64,
    /// The contact's record; `None` until its first evaluation.
    pub record: Option<OpenContact>,
    /// Constants of the law for this contact, valid for the curvature `consts_curvature` (NaN:
    /// not computed yet).
    pub consts: ContactConstants,
    /// See `consts`.
    pub consts_curvature: f64,
    /// When the contact's impact is over and it counts as resting (s; NaN: not known yet).
    pub resting_from_s: f64,
    /// Overlap rate du/dt at the last evaluation (m/s; NaN before the first): with the force of
    /// that step it gives the free relative acceleration the eq. 12 step mean needs.
    pub prev_rate: f64,
    /// Index of the pair's law in the layer's table (set with `consts`).
    pub law: u32,
    /// 1 / the smaller radius (set with `consts`), for the overlap guard.
    pub inv_r_min: f64,
    /// On a padded surface: the furthest limit of the pad law this contact has passed (each
    /// warned once).
    pub pad_limit: Option<crate::contact::padding::PadLimit>,
    /// The geometry of a contact with a spheroidal apple (`None`: two spheres, or a sphere and a
    /// surface, whose geometry follows from the radius and `curvature2`). Detection sets it
    /// with the normal, at every step: it turns with the apple.
    pub shaped: Option<Shaped>,
    /// A lower bound of its step limit once it rests, for detection to skip the exact one (see
    /// [`super::adaptive::RestingBound`]; spheres only).
    pub resting_bound: super::adaptive::RestingBound,
}

/// The geometry of a contact with a spheroidal apple at the current poses (see
/// [`crate::contact::spheroid`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Shaped {
    /// Apple `i`'s surface point deepest into the other body, from its centre (m, world).
    pub arm: Vec3,
    /// The other body's lever: its surface point's distance from its centre (m; an apple's).
    pub lever2_m: f64,
    /// The elliptic law's stiffness radius R_k (m); NaN when the contact conforms.
    pub r_star_m: f64,
    /// The elliptic law's area radius R_a (m).
    pub area_radius_m: f64,
    /// The smallest principal radius of curvature of the bodies at the contact (m): the overlap
    /// guard's radius.
    pub r_min_m: f64,
}

impl Contact {
    /// A contact first seen now.
    pub fn new(i: u32, other: Party) -> Self {
        Self {
            i,
            other,
            next: NONE,
            normal: Vec3::Z,
            prev_normal: Vec3::NAN,
            overlap_m: 0.0,
            curvature2: 0.0,
            xi: Vec3::ZERO,
            rolling: Vec3::ZERO,
            last_u: 0.0,
            ref_u: f64::NAN,
            record: None,
            consts: ContactConstants {
                r_star_m: 0.0,
                sqrt_r_star: 0.0,
                stiffness: 0.0,
                area_scale: 1.0,
                normal_mass_kg: 0.0,
                inv_normal_mass: 0.0,
                tangential_mass_kg: 0.0,
                rolling_inertia_kg_m2: 0.0,
                spin_inertia_kg_m2: 0.0,
                pad: None,
            },
            pad_limit: None,
            consts_curvature: f64::NAN,
            resting_from_s: f64::NAN,
            prev_rate: f64::NAN,
            law: 0,
            inv_r_min: 0.0,
            shaped: None,
            resting_bound: super::adaptive::RestingBound::NONE,
        }
    }
}

/// Stamp of a free slot (detection passes count from 1).
pub const FREE: u64 = 0;

/// Stamp of a live contact not seen by any detection pass yet.
const NEW: u64 = 1;

/// The slab of contacts.
#[derive(Debug, Clone, Default)]
pub struct ContactStore {
    slots: Vec<Contact>,
    /// Per slot: [`FREE`], or the detection pass that last saw the contact overlapping. The force
    /// pass evaluates the contacts seen by the current pass; a sleeper's frozen contacts keep an
    /// older stamp.
    stamps: Vec<u64>,
    free: Vec<u32>,
    pub(super) carries: Carries,
}

/// Rider carries not yet applied to their records ([`ContactStore::carry_later`]).
#[derive(Debug, Clone, Default)]
pub(super) struct Carries {
    /// One entry per step in which a contact was carried lazily, in step order: (step number,
    /// the step that led to the poses, their time), as [`OpenContact::carry`] takes them.
    log: Vec<(u64, f64, f64)>,
    /// Per slot: the first and the last step it owes its record ([`OPEN`]: every step logged
    /// from the first on, while it rides quietly), or [`NOT_OWED`].
    pending: Vec<(u64, u64)>,
    /// How many slots owe carries.
    count: usize,
    /// Tests: how often the log was full, and how often the slab was reordered while slots
    /// owed carries.
    #[cfg(test)]
    pub full: usize,
    #[cfg(test)]
    pub reordered_owing: usize,
}

/// A slot that owes no carry.
const NOT_OWED: (u64, u64) = (u64::MAX, u64::MAX);

/// The last step owed by a quiet rider's contact: every step logged ([`ContactStore::carry_quietly`]).
const OPEN: u64 = u64::MAX - 1;

/// Log entries from which every pending carry is applied and the log started again (riders
/// that ride on for many steps): at most 96 KiB of log. Tests fill it often.
#[cfg(not(test))]
const CARRY_LOG_MAX: usize = 4096;
#[cfg(test)]
const CARRY_LOG_MAX: usize = 64;

impl Carries {
    /// The log entries of steps `first..=last`.
    fn owed(&self, (first, last): (u64, u64)) -> &[(u64, f64, f64)] {
        let from = self.log.partition_point(|e| e.0 < first);
        let to = self.log.partition_point(|e| e.0 <= last);
        &self.log[from..to.max(from)]
    }

    /// Carries record `r` through the steps `owed`.
    fn replay(&self, owed: (u64, u64), r: &mut OpenContact) {
        for &(_, dt, t) in self.owed(owed) {
            r.carry(dt, t);
        }
    }

    /// Slot `k` owes nothing more (the log starts again once no slot owes).
    fn forget(&mut self, k: usize) {
        if self.pending[k] != NOT_OWED {
            self.pending[k] = NOT_OWED;
            self.count -= 1;
            if self.count == 0 {
                self.log.clear();
            }
        }
    }
}

impl ContactStore {
    /// Stores a new contact and returns its slot.
    pub fn insert(&mut self, c: Contact) -> u32 {
        match self.free.pop() {
            Some(k) => {
                self.slots[k as usize] = c;
                self.stamps[k as usize] = NEW;
                debug_assert_eq!(self.carries.pending[k as usize], NOT_OWED);
                k
            }
            None => {
                self.slots.push(c);
                self.stamps.push(NEW);
                self.carries.pending.push(NOT_OWED);
                (self.slots.len() - 1) as u32
            }
        }
    }

    /// Logs step `step` (the poses at `time_s`, reached by a step of `dt_back_s`) as one in
    /// which riders are carried lazily, once however many detection passes the step makes.
    #[inline]
    pub fn log_carry_step(&mut self, step: u64, dt_back_s: f64, time_s: f64) {
        if self.carries.log.last().is_some_and(|e| e.0 == step) {
            return;
        }
        if self.carries.log.len() >= CARRY_LOG_MAX {
            self.apply_all_carries(step);
        }
        self.carries.log.push((step, dt_back_s, time_s));
    }

    /// The rider's frozen contact in slot `k` rode through step `step` ([`Self::log_carry_step`]'s
    /// arguments): its record is carried ([`OpenContact::carry`]) when the contact is next
    /// taken (detection, its end, a query). The steps a slot owes follow one another; after a
    /// gap the earlier ones are applied first.
    pub fn carry_later(&mut self, k: u32, step: u64, dt_back_s: f64, time_s: f64) {
        self.owe(k, step, dt_back_s, time_s, step);
    }

    /// As [`Self::carry_later`], and the contact goes on owing every step logged from now on,
    /// its rider skipped by detection without a call per step, until [`Self::end_quiet`].
    pub fn carry_quietly(&mut self, k: u32, step: u64, dt_back_s: f64, time_s: f64) {
        self.owe(k, step, dt_back_s, time_s, OPEN);
    }

    fn owe(&mut self, k: u32, step: u64, dt_back_s: f64, time_s: f64, last: u64) {
        self.log_carry_step(step, dt_back_s, time_s);
        let (f, l) = self.carries.pending[k as usize];
        if (f, l) == NOT_OWED {
            self.carries.pending[k as usize] = (step, last);
            self.carries.count += 1;
        } else if l == OPEN || l == step || l + 1 == step {
            self.carries.pending[k as usize].1 = l.max(last);
        } else {
            self.apply_carries(k);
            self.carries.pending[k as usize] = (step, last);
            self.carries.count += 1;
        }
    }

    /// The quiet rider of slot `k` was last skipped in step `through`: it owes no step after
    /// that.
    pub fn end_quiet(&mut self, k: u32, through: u64) {
        let c = &mut self.carries;
        match c.pending.get(k as usize) {
            Some(&(first, OPEN)) if through < first => c.forget(k as usize),
            Some(&(_, OPEN)) => c.pending[k as usize].1 = through,
            _ => {}
        }
    }

    /// Applies the carries slot `k` owes to its record. A quiet rider's contact goes on owing
    /// the steps logged after these.
    #[inline]
    fn apply_carries(&mut self, k: u32) {
        let c = &mut self.carries;
        let owed = c.pending[k as usize];
        if owed == NOT_OWED {
            return;
        }
        if let Some(r) = self.slots[k as usize].record.as_mut() {
            c.replay(owed, r);
        }
        match (owed.1, c.log.last()) {
            (OPEN, Some(e)) => c.pending[k as usize].0 = owed.0.max(e.0 + 1),
            (OPEN, None) => {}
            _ => c.forget(k as usize),
        }
    }

    /// Applies every pending carry and starts the log again (when it is full, before step
    /// `next` is logged).
    fn apply_all_carries(&mut self, next: u64) {
        #[cfg(test)]
        {
            self.carries.full += 1;
        }
        if self.carries.count > 0 {
            for k in 0..self.slots.len() as u32 {
                self.apply_carries(k);
            }
        }
        self.carries.log.clear();
        for p in &mut self.carries.pending {
            if p.1 == OPEN {
                p.0 = next;
            }
        }
    }

    /// The live contacts, each with its record as it stands after the carries it owes (applied
    /// to a copy), for reading without taking the slab mutably.
    pub fn iter_records_now(
        &self,
    ) -> impl Iterator<Item = (&Contact, Option<Cow<'_, OpenContact>>)> {
        self.slots
            .iter()
            .zip(&self.stamps)
            .zip(&self.carries.pending)
            .filter(|((_, &s), _)| s != FREE)
            .map(|((c, _), &owed)| {
                let r = c.record.as_ref().map(|r| {
                    if owed == NOT_OWED {
                        Cow::Borrowed(r)
                    } else {
                        let mut r = r.clone();
                        self.carries.replay(owed, &mut r);
                        Cow::Owned(r)
                    }
                });
                (c, r)
            })
    }

    /// Removes the contact in slot `k` and returns its record.
    pub fn remove(&mut self, k: u32) -> Option<OpenContact> {
        debug_assert!(self.is_live(k));
        self.apply_carries(k);
        // A quiet rider's contact still owes the steps to come: it ended.
        self.carries.forget(k as usize);
        self.stamps[k as usize] = FREE;
        self.free.push(k);
        let c = &mut self.slots[k as usize];
        c.next = NONE;
        c.record.take()
    }

    /// Whether slot `k` holds a contact.
    pub fn is_live(&self, k: u32) -> bool {
        self.stamps[k as usize] != FREE
    }

    /// The detection pass that last saw the contact in slot `k` (see [`Self::stamps`]).
    pub fn stamp(&self, k: u32) -> u64 {
        self.stamps[k as usize]
    }

    /// Marks the contact in slot `k` as seen overlapping by detection pass `pass` (>= 2).
    pub fn see(&mut self, k: u32, pass: u64) {
        self.stamps[k as usize] = pass;
    }

    /// The stamps, one per slot.
    #[cfg(test)]
    pub fn stamps(&self) -> &[u64] {
        &self.stamps
    }

    /// The slots (free ones included) and their stamps, for the force pass (which evaluates only
    /// contacts seen by the current pass: none owes a carry, see [`Self::carry_later`]).
    pub fn slots_and_stamps(&mut self) -> (&mut [Contact], &[u64]) {
        (&mut self.slots, &self.stamps)
    }

    /// The slots (free ones included) and their stamps, both mutable, for detection's runs of
    /// pairs (see `detect::SlotsMut`).
    pub fn slots_and_stamps_mut(&mut self) -> (&mut [Contact], &mut [u64]) {
        (&mut self.slots, &mut self.stamps)
    }

    /// The contact in slot `k`.
    pub fn get(&self, k: u32) -> &Contact {
        &self.slots[k as usize]
    }

    /// The contact in slot `k`, mutable (its record carried as far as it rode).
    pub fn get_mut(&mut self, k: u32) -> &mut Contact {
        if self.carries.count > 0 {
            self.apply_carries(k);
        }
        &mut self.slots[k as usize]
    }

    /// Number of live contacts.
    pub fn live_count(&self) -> usize {
        self.slots.len() - self.free.len()
    }

    /// Puts the live contacts in the order `order` lists them (slots 0, 1, ...; the slab
    /// loses its free slots) and returns the new slot of each old one ([`NONE`] for free
    /// ones). `order` must list every live slot once. The pair lists and chains are the
    /// caller's to renumber.
    ///
    /// The permutation is applied in place, cycle by cycle: the slab is not copied into a new
    /// one (a fresh 9 MB slab at every rebuild of the 8036-apple pile grew the peak resident
    /// memory from 42 to 77 MiB through the allocator's reuse of freed blocks).
    pub fn reorder(&mut self, order: &[u32]) -> Vec<u32> {
        debug_assert_eq!(order.len(), self.live_count());
        #[cfg(test)]
        {
            self.carries.reordered_owing += usize::from(self.carries.count > 0);
        }
        let n = self.slots.len();
        let mut new_of = vec![NONE; n];
        for (new, &old) in order.iter().enumerate() {
            new_of[old as usize] = new as u32;
        }
        // Free slots go after the live ones, in any order (they are dropped).
        let mut source = order.to_vec();
        for (old, target) in new_of.iter().enumerate() {
            if *target == NONE {
                source.push(old as u32);
            }
        }
        // source[new] = old: slot `new` receives the contact of slot `old`.
        let mut done = vec![false; n];
        let slots = self.slots.as_mut_ptr();
        for start in 0..n {
            if done[start] || source[start] as usize == start {
                done[start] = true;
                continue;
            }
            // Follow the cycle: position j takes from source[j] until the cycle closes, the
            // first contact held aside meanwhile. Each contact is copied once (a swap copies two:
            // a contact started mid-list shifts every one after it, one long cycle).
            // SAFETY: every index is below n = slots.len(); the cycle visits each of its
            // positions once, so each is read once (from) and written once (j); nothing between
            // the read of `start` and the write back can panic, so no slot is dropped twice.
            unsafe {
                let held = std::ptr::read(slots.add(start));
                let held_stamp = self.stamps[start];
                let held_carries = self.carries.pending[start];
                let mut j = start;
                loop {
                    done[j] = true;
                    let from = source[j] as usize;
                    if from == start {
                        std::ptr::write(slots.add(j), held);
                        self.stamps[j] = held_stamp;
                        self.carries.pending[j] = held_carries;
                        break;
                    }
                    std::ptr::copy_nonoverlapping(slots.add(from), slots.add(j), 1);
                    self.stamps[j] = self.stamps[from];
                    self.carries.pending[j] = self.carries.pending[from];
                    j = from;
                }
            }
        }
        self.slots.truncate(order.len());
        self.stamps.truncate(order.len());
        self.carries.pending.truncate(order.len());
        for c in &mut self.slots {
            if c.next != NONE {
                c.next = new_of[c.next as usize];
            }
        }
        self.free.clear();
        new_of
    }

    /// Live contacts.
    pub fn iter(&self) -> impl Iterator<Item = &Contact> {
        self.slots
            .iter()
            .zip(&self.stamps)
            .filter(|(_, &s)| s != FREE)
            .map(|(c, _)| c)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slots_are_reused_last_freed_first() {
        let mut s = ContactStore::default();
        let a = s.insert(Contact::new(0, Party::Apple(1)));
        let b = s.insert(Contact::new(0, Party::Apple(2)));
        let c = s.insert(Contact::new(1, Party::Surface(0)));
        assert_eq!((a, b, c), (0, 1, 2));
        s.remove(a);
        s.remove(c);
        assert_eq!(s.iter().count(), 1);
        assert_eq!(s.insert(Contact::new(3, Party::Apple(4))), 2);
        assert_eq!(s.insert(Contact::new(3, Party::Apple(5))), 0);
        assert_eq!(s.get(0).other, Party::Apple(5));
    }

    #[test]
    fn reorder_keeps_contacts_and_chains() {
        let mut s = ContactStore::default();
        let a = s.insert(Contact::new(0, Party::Surface(0)));
        let b = s.insert(Contact::new(0, Party::Surface(0)));
        let c = s.insert(Contact::new(1, Party::Apple(2)));
        s.get_mut(a).next = b;
        s.remove(c);
        let d = s.insert(Contact::new(3, Party::Apple(4)));
        assert_eq!(d, c, "reused");
        let new_of = s.reorder(&[d, a, b]);
        assert_eq!(
            (new_of[d as usize], new_of[a as usize], new_of[b as usize]),
            (0, 1, 2)
        );
        assert_eq!(s.get(0).other, Party::Apple(4));
        assert_eq!(s.get(1).next, 2, "the chain follows its contacts");
        assert_eq!(s.live_count(), 3);
        assert_eq!(s.insert(Contact::new(5, Party::Apple(6))), 3);
    }

    #[test]
    fn reorder_in_place_matches_a_copy() {
        // 60 slots, every fifth freed, then a scrambled order of the live ones.
        let mut s = ContactStore::default();
        for k in 0..60 {
            s.insert(Contact::new(k, Party::Apple(k + 1)));
        }
        for k in (0..60).step_by(5) {
            s.remove(k);
        }
        let mut order: Vec<u32> = (0..60).filter(|k| k % 5 != 0).collect();
        let mut seed = 7u64;
        for i in (1..order.len()).rev() {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1);
            order.swap(i, (seed >> 33) as usize % (i + 1));
        }
        let want: Vec<u32> = order.iter().map(|&k| s.get(k).i).collect();
        s.reorder(&order);
        let got: Vec<u32> = (0..order.len() as u32).map(|k| s.get(k).i).collect();
        assert_eq!(got, want);
        assert_eq!(s.live_count(), 48);
        assert_eq!(s.stamps().len(), 48);
    }

    #[test]
    fn reorder_of_a_contact_started_mid_list_shifts_the_rest() {
        // The common order at a rebuild: a new contact (the last slot) belongs between the first
        // two, so every contact after it moves up one slot (one cycle through all of them).
        let mut s = ContactStore::default();
        for k in 0..40 {
            s.insert(Contact::new(k, Party::Apple(k + 1)));
        }
        let mut order: Vec<u32> = vec![0, 39];
        order.extend(1..39);
        let new_of = s.reorder(&order);
        let got: Vec<u32> = (0..40).map(|k| s.get(k).i).collect();
        assert_eq!(got, order);
        assert_eq!(new_of[39], 1);
        assert_eq!(new_of[38], 39);
    }
}
