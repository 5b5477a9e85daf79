//! Apple-apple pair finding with our own cell grid and a Verlet list.
//!
//! rapier-notes.md measured that rapier's narrow phase costs 8-32x more per apple-step than a
//! plain cell grid for apple piles (73 candidates per apple instead of 9, and cache misses in
//! `process_pair`), so apple-apple pairs are kept out of rapier (collision groups) and found here.
//!
//! The list holds every pair closer than R_i + R_j + skin; it is rebuilt only when some apple has
//! moved more than skin / 2 since the last build, so no contact can be missed in between. Pairs are
//! sorted by (i, j): the order of force accumulation is fixed, and results are bit-identical
//! whatever the history of rebuilds. Each pair carries its contact state, carried over rebuilds.

use crate::math::Vec3;
use rustc_hash::FxHashMap;

/// A candidate pair with the state the law needs across steps.
#[derive(Debug, Clone)]
pub struct NeighborPair<S> {
    /// First apple (i < j).
    pub i: u32,
    /// Second apple.
    pub j: u32,
    /// Per-pair state (tangential history, open contact record).
    pub state: S,
}

/// Verlet list over a uniform cell grid.
#[derive(Debug, Clone)]
pub struct NeighborList<S> {
    skin_m: f64,
    pairs: Vec<NeighborPair<S>>,
    reference: Vec<Vec3>,
    rebuilds: u64,
    cells: FxHashMap<(i64, i64, i64), (u32, u32)>,
    order: Vec<((i64, i64, i64), u32)>,
    keys: Vec<(i64, i64, i64)>,
}

impl<S: Default> NeighborList<S> {
    /// An empty list with the given skin (m).
    pub fn new(skin_m: f64) -> Self {
        Self {
            skin_m,
            pairs: Vec::new(),
            reference: Vec::new(),
            rebuilds: 0,
            cells: FxHashMap::default(),
            order: Vec::new(),
            keys: Vec::new(),
        }
    }

    /// The skin (m).
    pub fn skin_m(&self) -> f64 {
        self.skin_m
    }

    /// Number of rebuilds so far.
    pub fn rebuilds(&self) -> u64 {
        self.rebuilds
    }

    /// The candidate pairs, sorted by (i, j).
    pub fn pairs(&self) -> &[NeighborPair<S>] {
        &self.pairs
    }

    /// Mutable access to the pairs (states).
    pub fn pairs_mut(&mut self) -> &mut [NeighborPair<S>] {
        &mut self.pairs
    }

    /// Whether some apple moved more than skin / 2 since the last build (or the count changed).
    pub fn needs_rebuild(&self, pos: &[Vec3], active: &[bool]) -> bool {
        if self.reference.len() != pos.len() {
            return true;
        }
        let lim = 0.25 * self.skin_m * self.skin_m;
        pos.iter()
            .zip(&self.reference)
            .zip(active)
            .any(|((p, r), &a)| a && (*p - *r).length_squared() > lim)
    }

    /// Rebuilds if needed; returns whether it did. `active[i] == false` apples (asleep) are still
    /// listed, so their pairs keep their state; the caller skips pairs of two sleeping apples.
    /// Pairs dropped by a rebuild are handed to `dropped` (they may hold an open contact).
    pub fn update(
        &mut self,
        pos: &[Vec3],
        radius: &[f64],
        active: &[bool],
        mut dropped: impl FnMut(NeighborPair<S>),
    ) -> bool {
        if !self.needs_rebuild(pos, active) {
            return false;
        }
        let new_pairs = self.build(pos, radius);
        // Merge: carry states of pairs present in both lists (both sorted by (i, j)).
        let old = std::mem::take(&mut self.pairs);
        let mut merged = Vec::with_capacity(new_pairs.len());
        let mut old_iter = old.into_iter().peekable();
        for (i, j) in new_pairs {
            while let Some(o) = old_iter.peek() {
                if (o.i, o.j) < (i, j) {
                    dropped(old_iter.next().unwrap());
                } else {
                    break;
                }
            }
            let state = match old_iter.peek() {
                Some(o) if (o.i, o.j) == (i, j) => old_iter.next().unwrap().state,
                _ => S::default(),
            };
            merged.push(NeighborPair { i, j, state });
        }
        old_iter.for_each(&mut dropped);
        self.pairs = merged;
        self.reference.clear();
        self.reference.extend_from_slice(pos);
        self.rebuilds += 1;
        true
    }

    fn build(&mut self, pos: &[Vec3], radius: &[f64]) -> Vec<(u32, u32)> {
        let r_max = radius.iter().cloned().fold(0.0, f64::max);
        let cell = (2.0 * r_max + self.skin_m).max(1e-9);
        let inv = 1.0 / cell;
        self.keys.clear();
        self.keys.extend(pos.iter().map(|p| {
            (
                (p.x * inv).floor() as i64,
                (p.y * inv).floor() as i64,
                (p.z * inv).floor() as i64,
            )
        }));
        // Sort apples by cell key (exactly, never a hash: colliding hashes interleave cells) so
        // each cell is one contiguous run; ties by index keep it deterministic.
        self.order.clear();
        for (n, k) in self.keys.iter().enumerate() {
            self.order.push((*k, n as u32));
        }
        self.order.sort_unstable();
        self.cells.clear();
        let mut start = 0usize;
        while start < self.order.len() {
            let key = self.order[start].0;
            let mut end = start + 1;
            while end < self.order.len() && self.order[end].0 == key {
                end += 1;
            }
            self.cells.insert(key, (start as u32, end as u32));
            start = end;
        }
        let mut out = Vec::new();
        for (n, &(kx, ky, kz)) in self.keys.iter().enumerate() {
            let pi = pos[n];
            for dx in -1..=1 {
                for dy in -1..=1 {
                    for dz in -1..=1 {
                        let Some(&(s, e)) = self.cells.get(&(kx + dx, ky + dy, kz + dz)) else {
                            continue;
                        };
                        for &(_, m) in &self.order[s as usize..e as usize] {
                            if (m as usize) <= n {
                                continue;
                            }
                            let reach = radius[n] + radius[m as usize] + self.skin_m;
                            if (pos[m as usize] - pi).length_squared() < reach * reach {
                                out.push((n as u32, m));
                            }
                        }
                    }
                }
            }
        }
        out.sort_unstable();
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn brute(pos: &[Vec3], r: &[f64], skin: f64) -> Vec<(u32, u32)> {
        let mut v = Vec::new();
        for i in 0..pos.len() {
            for j in i + 1..pos.len() {
                if (pos[i] - pos[j]).length() < r[i] + r[j] + skin {
                    v.push((i as u32, j as u32));
                }
            }
        }
        v
    }

    #[test]
    fn finds_the_same_pairs_as_brute_force() {
        let mut pos = Vec::new();
        let mut r = Vec::new();
        let mut seed = 12345u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..400 {
            pos.push(Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() * 0.6));
            r.push(0.036 + 0.008 * rnd());
        }
        let active = vec![true; pos.len()];
        let mut list: NeighborList<()> = NeighborList::new(0.01);
        assert!(list.update(&pos, &r, &active, |_| {}));
        let got: Vec<_> = list.pairs().iter().map(|p| (p.i, p.j)).collect();
        assert_eq!(got, brute(&pos, &r, 0.01));
        assert!(
            !list.update(&pos, &r, &active, |_| {}),
            "no motion, no rebuild"
        );
    }

    #[test]
    fn regression_adjacent_cells_with_colliding_hashes() {
        // A hash of the cell key used as sort key interleaved cells whose hashes collided, and
        // pairs of adjacent cells were lost (an apple pile fell through itself).
        let pos = vec![
            Vec3::new(
                0.20463681687935084,
                -0.0958655273965989,
                0.03493802636169242,
            ),
            Vec3::new(
                0.20496990901464243,
                -0.10377874208606211,
                0.10983959130024909,
            ),
        ];
        let r = vec![0.0392, 0.0392];
        let mut list: NeighborList<()> = NeighborList::new(0.011);
        list.update(&pos, &r, &[true, true], |_| {});
        assert_eq!(list.pairs().len(), 1);
        // A full column of cells on both sides of zero.
        let mut pos = Vec::new();
        for x in -5..5 {
            for y in -5..5 {
                for z in 0..30 {
                    pos.push(Vec3::new(x as f64 * 0.07, y as f64 * 0.07, z as f64 * 0.07));
                }
            }
        }
        let r = vec![0.04; pos.len()];
        let mut list: NeighborList<()> = NeighborList::new(0.01);
        list.update(&pos, &r, &vec![true; pos.len()], |_| {});
        let got: Vec<_> = list.pairs().iter().map(|p| (p.i, p.j)).collect();
        assert_eq!(got, brute(&pos, &r, 0.01));
    }

    #[test]
    fn carries_state_over_rebuilds() {
        let pos = vec![
            Vec3::ZERO,
            Vec3::new(0.08, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
        ];
        let r = vec![0.04; 3];
        let active = vec![true; 3];
        let mut list: NeighborList<u32> = NeighborList::new(0.01);
        list.update(&pos, &r, &active, |_| {});
        list.pairs_mut()[0].state = 7;
        let mut moved = pos.clone();
        moved[2] = Vec3::new(0.16, 0.0, 0.0);
        let mut dropped = 0;
        list.update(&moved, &r, &active, |_| dropped += 1);
        assert_eq!(dropped, 0);
        assert_eq!(list.pairs().len(), 2);
        assert_eq!(
            (list.pairs()[0].i, list.pairs()[0].j, list.pairs()[0].state),
            (0, 1, 7)
        );
        assert_eq!(list.pairs()[1].state, 0);
    }
}
