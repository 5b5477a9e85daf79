//! Where the apples' rigid bodies live: rapier's own body set (the one passed to the layer's
//! step as `bodies`, with the surfaces' bodies and any body of the user's), or further worlds
//! that hold nothing but collider-less apples, stepped by the driver concurrently with rapier's
//! own (issue 30 item 2).
//!
//! Why: rapier's step is serial, and on an impact phase it is a third of the time. The apples
//! touch nothing in rapier (the layer computes every force; a collider-less body has no contact
//! and no joint), so each apple is integrated on its own: the same bits in whichever set it is,
//! beside whichever other bodies (`benches/rapier_floor.rs` checks every pose and velocity
//! against one set, and `tests/determinism.rs` the outputs). Splitting the apples over sets
//! therefore changes no result, and the sets can be stepped on different threads. rapier still
//! integrates every body.

use rapier3d_f64::dynamics::{IslandManager, RigidBody, RigidBodyHandle, RigidBodySet};
use rapier3d_f64::pipeline::PhysicsWorld;

/// An apple's rigid body: the set it is in and its handle there. Set 0 is the `bodies` passed to
/// the layer's step; set `s >= 1` is `BodySets::apple_sets[s - 1]`. A bare handle is in set 0.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct BodyRef {
    /// 0: rapier's own set; `s >= 1`: the apple set `s - 1`.
    pub set: u32,
    /// The body's handle in its set.
    pub handle: RigidBodyHandle,
}

impl From<RigidBodyHandle> for BodyRef {
    fn from(handle: RigidBodyHandle) -> Self {
        Self { set: 0, handle }
    }
}

/// The rigid-body sets of one step: rapier's own, with its island manager, and the apple sets
/// (worlds of collider-less apples only; empty for a layer attached to one plain rapier world).
pub struct BodySets<'a> {
    /// rapier's own set: the surfaces' bodies, the user's, and the apples of set 0.
    pub main: &'a mut RigidBodySet,
    /// The island manager of `main` (rapier's wake-ups of apples show up in its active set).
    pub islands: &'a IslandManager,
    /// Worlds holding only collider-less apples (their own sets, islands and pipelines).
    pub apple_sets: &'a mut [PhysicsWorld],
}

impl<'a> BodySets<'a> {
    /// One plain rapier world: every apple in `bodies`.
    pub fn one(bodies: &'a mut RigidBodySet, islands: &'a IslandManager) -> Self {
        Self {
            main: bodies,
            islands,
            apple_sets: &mut [],
        }
    }

    /// The body of `r`, if its set and handle exist.
    #[inline]
    pub fn get(&self, r: BodyRef) -> Option<&RigidBody> {
        match r.set {
            0 => self.main.get(r.handle),
            s => self.apple_sets.get(s as usize - 1)?.bodies.get(r.handle),
        }
    }

    /// The body of `r`, mutably (rapier marks it modified).
    #[inline]
    pub fn get_mut(&mut self, r: BodyRef) -> Option<&mut RigidBody> {
        match r.set {
            0 => self.main.get_mut(r.handle),
            s => self
                .apple_sets
                .get_mut(s as usize - 1)?
                .bodies
                .get_mut(r.handle),
        }
    }

    /// Calls `f(set, bodies)` for every set, rapier's own and the apple sets: concurrently on
    /// rayon's pool when `parallel` (each set is written by one task only), else in set order
    /// (a region costs its threads' wake-up, more than a few loads are worth).
    pub fn for_each_set(&mut self, parallel: bool, f: impl Fn(u32, &mut RigidBodySet) + Sync) {
        if parallel && !self.apple_sets.is_empty() {
            use rayon::prelude::*;
            let (main, sets) = (&mut *self.main, &mut *self.apple_sets);
            rayon::join(
                || f(0, main),
                || {
                    sets.par_iter_mut()
                        .enumerate()
                        .for_each(|(s, w)| f(s as u32 + 1, &mut w.bodies))
                },
            );
        } else {
            f(0, self.main);
            for (s, w) in self.apple_sets.iter_mut().enumerate() {
                f(s as u32 + 1, &mut w.bodies);
            }
        }
    }

    /// Every body rapier holds active, set by set (set 0 first).
    pub fn active(&self) -> impl Iterator<Item = BodyRef> + '_ {
        let main = self.islands.active_bodies().map(BodyRef::from);
        let rest = self.apple_sets.iter().enumerate().flat_map(|(s, w)| {
            w.islands.active_bodies().map(move |handle| BodyRef {
                set: s as u32 + 1,
                handle,
            })
        });
        main.chain(rest)
    }
}
