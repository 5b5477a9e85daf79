//! Apple-apple pair finding with our own cell grid and a Verlet list.
//!
//! rapier-notes.md measured that rapier's narrow phase costs 8-32x more per apple-step than a
//! plain cell grid for apple piles (73 candidates per apple instead of 9, and cache misses in
//! `process_pair`), so apple-apple pairs never reach rapier and are found here.
//!
//! The list holds every pair closer than R_i + R_j + skin; it is rebuilt only when some apple has
//! moved more than skin / 2 since the last build (or the caller forces it), so no contact can be
//! missed in between. A build bins the apples into a dense grid of cells of edge 2 R_max + skin by
//! a counting sort (O(n); a sparse, sorted grid when the apples are spread so thinly that a dense
//! one would be mostly empty) and tests each pair of apples in neighbouring cells once (the dense
//! grid: an apple's own cell and the 13 cells ahead of it; the sparse one: the 27 cells around
//! each apple). Pairs are sorted by (i, j): the order of force accumulation is fixed, and results
//! are bit-identical whatever the history of rebuilds or the scan. Each pair carries the index of
//! its open contact (or [`NONE`]) across rebuilds.

use crate::math::Vec3;

/// No index: a pair without an open contact.
pub const NONE: u32 = u32::MAX;

/// A candidate pair of apples, closer than R_i + R_j + skin at the last build.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pair {
    /// First apple (i < j).
    pub i: u32,
    /// Second apple.
    pub j: u32,
    /// The pair's open contact in the layer's contact store, or [`NONE`].
    pub contact: u32,
    /// A lower bound of the gap between the two apples when they are apart (m), kept by
    /// detection for pairs with a spheroid, whose exact test is a search: while the motion since
    /// it was measured cannot have closed it, the pair is not tested (0: test it).
    pub gap_bound_m: f32,
}

/// Verlet list over a uniform cell grid.
#[derive(Debug, Clone, Default)]
pub struct NeighborList {
    skin_m: f64,
    pairs: Vec<Pair>,
    reference: Vec<Vec3>,
    rebuilds: u64,
    // Build scratch, kept to avoid allocating at every build.
    coords: Vec<[i64; 3]>,
    cell_of: Vec<usize>,
    start: Vec<u32>,
    sorted: Vec<u32>,
    keyed: Vec<([i64; 3], u32)>,
    fresh: Vec<(u32, u32)>,
    unsorted: Vec<(u32, u32)>,
    by_first: Vec<u32>,
}

impl NeighborList {
    /// An empty list with the given skin (m).
    pub fn new(skin_m: f64) -> Self {
        Self {
            skin_m,
            ..Self::default()
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
    pub fn pairs(&self) -> &[Pair] {
        &self.pairs
    }

    /// Mutable access to the pairs (their contact indices).
    pub fn pairs_mut(&mut self) -> &mut [Pair] {
        &mut self.pairs
    }

    /// Whether some awake apple moved more than skin / 2 since the last build (or the number of
    /// apples changed). `awake` lists the apples that can have moved.
    pub fn needs_rebuild(&self, pos: &[Vec3], awake: &[u32]) -> bool {
        if self.reference.len() != pos.len() {
            return true;
        }
        let lim = 0.25 * self.skin_m * self.skin_m;
        awake.iter().any(|&k| {
            let k = k as usize;
            (pos[k] - self.reference[k]).length_squared() > lim
        })
    }

    /// Rebuilds if needed (or if `force`); returns whether it did. Sleeping apples are still
    /// listed, so their pairs keep their contacts; the caller skips pairs of two sleepers. Pairs
    /// dropped by a rebuild that hold an open contact are handed to `dropped` (they are farther
    /// apart than the skin: the contact has ended).
    pub fn update(
        &mut self,
        pos: &[Vec3],
        radius: &[f64],
        awake: &[u32],
        force: bool,
        mut dropped: impl FnMut(Pair),
    ) -> bool {
        if !force && !self.needs_rebuild(pos, awake) {
            return false;
        }
        self.build(pos, radius);
        // Merge: carry the contacts of pairs present in both lists (both sorted by (i, j)).
        let old = std::mem::take(&mut self.pairs);
        let mut merged = Vec::with_capacity(self.fresh.len());
        let mut o = 0;
        for &(i, j) in &self.fresh {
            while o < old.len() && (old[o].i, old[o].j) < (i, j) {
                if old[o].contact != NONE {
                    dropped(old[o]);
                }
                o += 1;
            }
            let contact = if o < old.len() && (old[o].i, old[o].j) == (i, j) {
                o += 1;
                old[o - 1].contact
            } else {
                NONE
            };
            merged.push(Pair {
                i,
                j,
                contact,
                gap_bound_m: 0.0,
            });
        }
        for p in &old[o..] {
            if p.contact != NONE {
                dropped(*p);
            }
        }
        self.pairs = merged;
        self.reference.clear();
        self.reference.extend_from_slice(pos);
        self.rebuilds += 1;
        true
    }

    /// Lists every pair closer than R_i + R_j + skin into `fresh`, sorted by (i, j).
    fn build(&mut self, pos: &[Vec3], radius: &[f64]) {
        self.fresh.clear();
        let n = pos.len();
        if n < 2 {
            return;
        }
        let r_max = radius.iter().cloned().fold(0.0, f64::max);
        let cell = (2.0 * r_max + self.skin_m).max(1e-9);
        let inv = 1.0 / cell;
        let mut lo = Vec3::splat(f64::INFINITY);
        for p in pos {
            lo = lo.min(*p);
        }
        self.coords.clear();
        let mut hi = [0i64; 3];
        for p in pos {
            let q = (*p - lo) * inv;
            let c = [q.x as i64, q.y as i64, q.z as i64];
            for d in 0..3 {
                hi[d] = hi[d].max(c[d]);
            }
            self.coords.push(c);
        }
        let dims = [hi[0] + 1, hi[1] + 1, hi[2] + 1];
        let cells = dims[0].saturating_mul(dims[1]).saturating_mul(dims[2]);
        if cells <= (8 * n as i64).max(1 << 16) {
            self.build_dense(pos, radius, dims, cells as usize);
        } else {
            self.build_sparse(pos, radius);
        }
    }

    fn build_dense(&mut self, pos: &[Vec3], radius: &[f64], dims: [i64; 3], cells: usize) {
        let id = |c: [i64; 3]| ((c[0] * dims[1] + c[1]) * dims[2] + c[2]) as usize;
        // Counting sort of the apples by cell: cell c holds sorted[start[c]..start[c + 1]],
        // in increasing apple index.
        self.start.clear();
        self.start.resize(cells + 1, 0);
        self.cell_of.clear();
        for c in &self.coords {
            let k = id(*c);
            self.cell_of.push(k);
            self.start[k + 1] += 1;
        }
        for k in 0..cells {
            self.start[k + 1] += self.start[k];
        }
        self.sorted.clear();
        self.sorted.resize(pos.len(), 0);
        let mut fill: Vec<u32> = self.start[..cells].to_vec();
        for (m, &k) in self.cell_of.iter().enumerate() {
            self.sorted[fill[k] as usize] = m as u32;
            fill[k] += 1;
        }
        let (start, sorted, skin) = (&self.start, &self.sorted, self.skin_m);
        // Each pair of apples in neighbouring cells is tested once: from the lower index within
        // a cell, and from the cell behind it across cells (the 13 cells ahead of a cell in
        // (x, y, z) order, read as 5 runs of cells consecutive in z). Half the tests of a scan of
        // all 27 cells, and none of the branches on the index order.
        let range = |x: i64, y: i64, z0: i64, z1: i64| {
            let (z0, z1) = (z0.max(0), z1.min(dims[2] - 1));
            start[id([x, y, z0])] as usize..start[id([x, y, z1]) + 1] as usize
        };
        let scan = |i: usize, out: &mut Vec<(u32, u32)>| {
            let c = self.coords[i];
            let own = &sorted[start[id(c)] as usize..start[id(c) + 1] as usize];
            let after = own.partition_point(|&m| (m as usize) <= i);
            let mut near = NearPairs::default();
            for &m in &own[after..] {
                near.offer(out, pos, radius, skin, i, m as usize);
            }
            let mut ahead = |r: std::ops::Range<usize>| {
                for &m in &sorted[r] {
                    let m = m as usize;
                    near.offer(out, pos, radius, skin, i.min(m), i.max(m));
                }
            };
            if c[2] + 1 < dims[2] {
                ahead(range(c[0], c[1], c[2] + 1, c[2] + 1));
            }
            if c[1] + 1 < dims[1] {
                ahead(range(c[0], c[1] + 1, c[2] - 1, c[2] + 1));
            }
            if c[0] + 1 < dims[0] {
                for y in (c[1] - 1).max(0)..=(c[1] + 1).min(dims[1] - 1) {
                    ahead(range(c[0] + 1, y, c[2] - 1, c[2] + 1));
                }
            }
            near.flush(out);
        };
        scan_apples(pos.len(), &mut self.fresh, scan);
        sort_pairs(
            &mut self.fresh,
            &mut self.by_first,
            &mut self.unsorted,
            pos.len(),
        );
    }

    /// For apples spread over a region whose dense grid would be mostly empty: cells sorted by
    /// their key (exactly, never a hash: colliding hashes interleave cells), found by binary search.
    fn build_sparse(&mut self, pos: &[Vec3], radius: &[f64]) {
        self.keyed.clear();
        for (m, c) in self.coords.iter().enumerate() {
            self.keyed.push((*c, m as u32));
        }
        self.keyed.sort_unstable();
        let (keyed, skin) = (&self.keyed, self.skin_m);
        let scan = |i: usize, out: &mut Vec<(u32, u32)>| {
            let c = self.coords[i];
            let first = out.len();
            let mut near = NearPairs::default();
            for dx in -1..=1 {
                for dy in -1..=1 {
                    for dz in -1..=1 {
                        let key = [c[0] + dx, c[1] + dy, c[2] + dz];
                        let s = keyed.partition_point(|e| e.0 < key);
                        for &(k, m) in &keyed[s..] {
                            if k != key {
                                break;
                            }
                            let m = m as usize;
                            if m > i {
                                near.offer(out, pos, radius, skin, i, m);
                            }
                        }
                    }
                }
            }
            near.flush(out);
            out[first..].sort_unstable();
        };
        scan_apples(pos.len(), &mut self.fresh, scan);
    }
}

/// Apples from which a build scans its cells in parallel, on rayon's current pool, when it has
/// more than one thread (below that, the pool's overhead outweighs a scan of ~1 us per apple).
const PARALLEL_MIN_APPLES: usize = 256;

/// Apples per parallel chunk of a scan.
const SCAN_CHUNK: usize = 128;

/// Appends the pairs of apples `0..n` to `out` in apple order: `scan(i, out)` appends apple i's
/// pairs (sorted). In parallel, chunks of apples fill their own lists, appended in chunk order:
/// the list is the same, bit for bit, whatever the number of threads (so is every result that
/// follows its order, the force sums included).
fn scan_apples(
    n: usize,
    out: &mut Vec<(u32, u32)>,
    scan: impl Fn(usize, &mut Vec<(u32, u32)>) + Sync,
) {
    if n >= PARALLEL_MIN_APPLES && rayon::current_num_threads() > 1 {
        use rayon::prelude::*;
        let chunks: Vec<Vec<(u32, u32)>> = (0..n.div_ceil(SCAN_CHUNK))
            .into_par_iter()
            .map(|c| {
                let mut v = Vec::with_capacity(8 * SCAN_CHUNK);
                for i in c * SCAN_CHUNK..((c + 1) * SCAN_CHUNK).min(n) {
                    scan(i, &mut v);
                }
                v
            })
            .collect();
        out.reserve(chunks.iter().map(Vec::len).sum());
        for v in chunks {
            out.extend_from_slice(&v);
        }
    } else {
        for i in 0..n {
            scan(i, out);
        }
    }
}

/// The pairs of one apple's scan, kept without a branch on the distance test: each candidate is
/// written and kept by advancing the count when near (whether a neighbour is within reach is what
/// a branch predictor cannot learn: half the candidates of a pile are not).
#[derive(Default)]
struct NearPairs {
    buf: [(u32, u32); 32],
    len: usize,
}

impl NearPairs {
    /// Offers the pair (a, b), a < b: kept if the apples are closer than R_a + R_b + skin (the
    /// one distance test of both grids' scans).
    #[inline(always)]
    fn offer(
        &mut self,
        out: &mut Vec<(u32, u32)>,
        pos: &[Vec3],
        radius: &[f64],
        skin: f64,
        a: usize,
        b: usize,
    ) {
        if self.len == self.buf.len() {
            out.extend_from_slice(&self.buf);
            self.len = 0;
        }
        let reach = radius[a] + radius[b] + skin;
        let near = (pos[b] - pos[a]).length_squared() < reach * reach;
        self.buf[self.len] = (a as u32, b as u32);
        self.len += usize::from(near);
    }

    /// Appends the kept pairs to `out`.
    fn flush(&mut self, out: &mut Vec<(u32, u32)>) {
        out.extend_from_slice(&self.buf[..self.len]);
        self.len = 0;
    }
}

/// Sorts pairs (i, j), each listed once with i < j, by (i, j): a counting sort by i, then each
/// apple's few pairs by j (`counts` and `scratch` are scratch).
fn sort_pairs(
    pairs: &mut Vec<(u32, u32)>,
    counts: &mut Vec<u32>,
    scratch: &mut Vec<(u32, u32)>,
    n: usize,
) {
    counts.clear();
    counts.resize(n + 1, 0);
    for &(i, _) in pairs.iter() {
        counts[i as usize + 1] += 1;
    }
    for k in 0..n {
        counts[k + 1] += counts[k];
    }
    std::mem::swap(pairs, scratch);
    pairs.clear();
    pairs.resize(scratch.len(), (0, 0));
    let sorted = pairs;
    for &(i, j) in scratch.iter() {
        let at = &mut counts[i as usize];
        sorted[*at as usize] = (i, j);
        *at += 1;
    }
    // counts[i] now ends apple i's run; the run starts where apple i - 1's ends.
    let mut from = 0;
    for &end in &counts[..n] {
        sorted[from..end as usize].sort_unstable();
        from = end as usize;
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

    /// Builds a list with every apple awake.
    fn listed_all(pos: &[Vec3], r: &[f64], skin: f64) -> NeighborList {
        let mut list = NeighborList::new(skin);
        let all: Vec<u32> = (0..pos.len() as u32).collect();
        list.update(pos, r, &all, false, |_| {});
        list
    }

    fn listed(list: &NeighborList) -> Vec<(u32, u32)> {
        list.pairs().iter().map(|p| (p.i, p.j)).collect()
    }

    fn random_cloud(n: usize, spread: f64) -> (Vec<Vec3>, Vec<f64>) {
        let mut pos = Vec::new();
        let mut r = Vec::new();
        let mut seed = 12345u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..n {
            pos.push(Vec3::new(
                spread * (rnd() - 0.5),
                spread * (rnd() - 0.5),
                spread * 0.6 * rnd(),
            ));
            r.push(0.036 + 0.008 * rnd());
        }
        (pos, r)
    }

    #[test]
    fn finds_the_same_pairs_as_brute_force() {
        let (pos, r) = random_cloud(400, 1.0);
        let active: Vec<u32> = (0..pos.len() as u32).collect();
        let mut list = NeighborList::new(0.01);
        assert!(list.update(&pos, &r, &active, false, |_| {}));
        assert_eq!(listed(&list), brute(&pos, &r, 0.01));
        assert!(
            !list.update(&pos, &r, &active, false, |_| {}),
            "no motion, no rebuild"
        );
        assert!(list.update(&pos, &r, &active, true, |_| {}), "forced");
    }

    #[test]
    fn parallel_scans_list_the_same_pairs_in_the_same_order() {
        // Dense (one cloud) and sparse (two clouds 1 km apart), above the parallel threshold:
        // one thread and two give the brute-force list, in the same order.
        let (mut pos, mut r) = random_cloud(1500, 1.5);
        let dense = brute(&pos, &r, 0.01);
        let (far, rf) = random_cloud(700, 1.0);
        let (mut pos2, mut r2) = (pos.clone(), r.clone());
        pos2.extend(far.iter().map(|p| *p + Vec3::new(1000.0, 1000.0, 0.0)));
        r2.extend(rf);
        let sparse = brute(&pos2, &r2, 0.01);
        assert!(pos.len() >= PARALLEL_MIN_APPLES && dense.len() > 1000);
        for threads in [1, 2] {
            super::super::on_pool(threads, || {
                assert_eq!(
                    listed(&listed_all(&pos, &r, 0.01)),
                    dense,
                    "dense, {threads}"
                );
                assert_eq!(
                    listed(&listed_all(&pos2, &r2, 0.01)),
                    sparse,
                    "sparse, {threads}"
                );
            });
        }
        pos.truncate(10);
        r.truncate(10);
        assert_eq!(listed(&listed_all(&pos, &r, 0.01)), brute(&pos, &r, 0.01));
    }

    #[test]
    fn sparse_grid_finds_the_same_pairs() {
        // Two clusters 1 km apart: a dense grid would have 1e10 cells, the sparse one is used.
        let (mut pos, mut r) = random_cloud(200, 0.6);
        let (far, rf) = random_cloud(200, 0.6);
        pos.extend(far.iter().map(|p| *p + Vec3::new(1000.0, 1000.0, 0.0)));
        r.extend(rf);
        let list = listed_all(&pos, &r, 0.01);
        assert_eq!(listed(&list), brute(&pos, &r, 0.01));
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
        let mut list = NeighborList::new(0.011);
        list.update(&pos, &r, &[0, 1], false, |_| {});
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
        let list = listed_all(&pos, &r, 0.01);
        assert_eq!(listed(&list), brute(&pos, &r, 0.01));
    }

    #[test]
    fn carries_contacts_over_rebuilds() {
        let pos = vec![
            Vec3::ZERO,
            Vec3::new(0.08, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
        ];
        let r = vec![0.04; 3];
        let active: Vec<u32> = vec![0, 1, 2];
        let mut list = NeighborList::new(0.01);
        list.update(&pos, &r, &active, false, |_| {});
        list.pairs_mut()[0].contact = 7;
        let mut moved = pos.clone();
        moved[2] = Vec3::new(0.16, 0.0, 0.0);
        let mut dropped = Vec::new();
        list.update(&moved, &r, &active, false, |p| dropped.push(p));
        assert!(dropped.is_empty());
        assert_eq!(listed(&list), vec![(0, 1), (1, 2)]);
        assert_eq!(list.pairs()[0].contact, 7);
        assert_eq!(list.pairs()[1].contact, NONE);
        // Apple 1 leaves: its pair with 0 (holding contact 7) is handed back.
        let mut gone = moved.clone();
        gone[1] = Vec3::new(0.0, 5.0, 0.0);
        list.update(&gone, &r, &active, false, |p| dropped.push(p));
        assert_eq!(dropped.len(), 1);
        assert_eq!((dropped[0].i, dropped[0].j, dropped[0].contact), (0, 1, 7));
    }
}
