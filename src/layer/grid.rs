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
//!
//! Most rebuilds of a line are set off by a few fast apples while the others moved little: the
//! pairs then come from a wider outer list kept up by listing again only the apples that moved
//! far (`NeighborList::list_pairs`), the same pairs in the same order as a build from the grid.

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
    /// The outer list (see `NeighborList::list_pairs`): each apple's anchor, its position when its
    /// outer pairs were last listed.
    anchor: Vec<Vec3>,
    /// Per apple, the apples whose anchors are closer than R_i + R_j + the outer skin (each pair
    /// in both lists, in no order).
    outer: Vec<Vec<u32>>,
    /// Whether `anchor` and `outer` hold the outer list.
    outer_valid: bool,
    movers: Vec<u32>,
    is_mover: Vec<bool>,
    /// Builds by kind: the pairs listed from the grid directly, the outer list listed again in
    /// full, the outer list kept (its movers listed again).
    builds: [u64; 3],
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

    /// Rebuilds by how their pairs were listed: from the grid directly, from the outer list
    /// listed again in full, from the outer list kept (see `NeighborList::list_pairs`).
    pub fn builds(&self) -> [u64; 3] {
        self.builds
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
        self.list_pairs(pos, radius);
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
    ///
    /// Most rebuilds are set off by a few fast apples (one falling into a bin) while most of
    /// the others moved little since the last (apples riding a belt). The pairs then come from
    /// an outer list, of the pairs closer than R_i + R_j + [`OUTER_SKIN`] skins at their
    /// anchors, kept by listing again only the apples that moved more than half the difference of
    /// the skins from their anchors: any two apples have then moved less than that difference
    /// together, so each pair within reach now is in the outer list, and the pairs are the same,
    /// in the same order, as from the grid. When many apples moved (a falling pile) the pairs
    /// come from the grid directly, as the outer list would have to be built again each time.
    fn list_pairs(&mut self, pos: &[Vec3], radius: &[f64]) {
        let n = pos.len();
        let skin = self.skin_m;
        let outer_skin = OUTER_SKIN * skin;
        // A thousandth of the margin kept back for rounding.
        let lim = 0.5 * (outer_skin - skin) * (1.0 - 1e-3);
        let lim2 = lim * lim;
        let usable = n >= 2 && skin > 0.0;
        if usable && self.outer_valid && self.anchor.len() <= n {
            self.movers.clear();
            let anchor = &self.anchor;
            self.movers.extend((0..n as u32).filter(|&k| {
                let k = k as usize;
                k >= anchor.len() || (pos[k] - anchor[k]).length_squared() > lim2
            }));
            if self.movers.len() <= n / MAX_MOVER_SHARE {
                self.keep_outer(pos, radius, outer_skin);
                self.filter_outer(pos, radius);
                self.builds[2] += 1;
                return;
            }
        }
        // The outer list is listed in full (about a third more pairs than the list) only at a
        // calm rebuild, when few apples moved since the last one.
        let calm = usable
            && self.reference.len() == n
            && (0..n)
                .filter(|&k| (pos[k] - self.reference[k]).length_squared() > lim2)
                .count()
                <= n / MAX_MOVER_SHARE;
        if calm {
            self.build(pos, radius, outer_skin);
            self.anchor.clear();
            self.anchor.extend_from_slice(pos);
            self.outer.resize_with(n, Vec::new);
            self.outer.iter_mut().for_each(Vec::clear);
            for &(i, j) in &self.fresh {
                self.outer[i as usize].push(j);
                self.outer[j as usize].push(i);
            }
            self.outer_valid = true;
            self.filter_outer(pos, radius);
            self.builds[1] += 1;
        } else {
            self.outer_valid = false;
            self.build(pos, radius, skin);
            self.builds[0] += 1;
        }
    }

    /// Lists the movers' outer pairs again from their new anchors (their positions now).
    fn keep_outer(&mut self, pos: &[Vec3], radius: &[f64], outer_skin: f64) {
        let n = pos.len();
        let movers = std::mem::take(&mut self.movers);
        self.is_mover.clear();
        self.is_mover.resize(n, false);
        for &k in &movers {
            self.is_mover[k as usize] = true;
        }
        self.outer.resize_with(n, Vec::new);
        // The movers' old pairs leave their partners' lists.
        for &k in &movers {
            let mut list = std::mem::take(&mut self.outer[k as usize]);
            for &j in &list {
                if !self.is_mover[j as usize] {
                    let partner = &mut self.outer[j as usize];
                    if let Some(at) = partner.iter().position(|&m| m == k) {
                        partner.swap_remove(at);
                    }
                }
            }
            list.clear();
            self.outer[k as usize] = list;
        }
        self.anchor.resize(n, Vec3::ZERO);
        for &k in &movers {
            self.anchor[k as usize] = pos[k as usize];
        }
        let anchor = std::mem::take(&mut self.anchor);
        let mut outer = std::mem::take(&mut self.outer);
        if let Some(cells) = self.bin(&anchor, radius, outer_skin) {
            for &k in &movers {
                let k = k as usize;
                let (ak, rk) = (anchor[k], radius[k]);
                let (outer, is_mover) = (&mut outer, &self.is_mover);
                let mut found = |m: usize| {
                    let reach = rk + radius[m] + outer_skin;
                    if m != k && (anchor[m] - ak).length_squared() < reach * reach {
                        outer[k].push(m as u32);
                        if !is_mover[m] {
                            outer[m].push(k as u32);
                        }
                    }
                };
                self.around(&cells, k, &mut found);
            }
        }
        self.outer = outer;
        self.anchor = anchor;
        self.movers = movers;
    }

    /// The list's pairs, those of the outer list within R_i + R_j + skin now, sorted by (i, j),
    /// into `fresh` (the grid's test, to the bit).
    fn filter_outer(&mut self, pos: &[Vec3], radius: &[f64]) {
        self.fresh.clear();
        let skin = self.skin_m;
        for (i, partners) in self.outer.iter().enumerate().take(pos.len()) {
            let from = self.fresh.len();
            for &j in partners {
                let b = j as usize;
                let reach = radius[i] + radius[b] + skin;
                if b > i && (pos[b] - pos[i]).length_squared() < reach * reach {
                    self.fresh.push((i as u32, j));
                }
            }
            self.fresh[from..].sort_unstable();
        }
    }

    /// Lists every pair closer than R_i + R_j + `skin` into `fresh`, sorted by (i, j).
    fn build(&mut self, pos: &[Vec3], radius: &[f64], skin: f64) {
        self.fresh.clear();
        match self.bin(pos, radius, skin) {
            Some(Cells::Dense(dims)) => self.build_dense(pos, radius, skin, dims),
            Some(Cells::Sparse) => self.build_sparse(pos, radius, skin),
            None => {}
        }
    }

    /// Bins the apples into cells of edge 2 R_max + skin: a dense grid (`start`, `sorted`) by a
    /// counting sort, or a sparse one (`keyed`) when a dense one would be mostly empty. None
    /// for fewer than two apples.
    fn bin(&mut self, pos: &[Vec3], radius: &[f64], skin: f64) -> Option<Cells> {
        let n = pos.len();
        if n < 2 {
            return None;
        }
        let r_max = radius.iter().cloned().fold(0.0, f64::max);
        let cell = (2.0 * r_max + skin).max(1e-9);
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
            let cells = cells as usize;
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
            self.sorted.resize(n, 0);
            let mut fill: Vec<u32> = self.start[..cells].to_vec();
            for (m, &k) in self.cell_of.iter().enumerate() {
                self.sorted[fill[k] as usize] = m as u32;
                fill[k] += 1;
            }
            Some(Cells::Dense(dims))
        } else {
            self.keyed.clear();
            for (m, c) in self.coords.iter().enumerate() {
                self.keyed.push((*c, m as u32));
            }
            self.keyed.sort_unstable();
            Some(Cells::Sparse)
        }
    }

    /// Calls `f` with every apple binned in the 27 cells around apple `k`'s (itself included).
    fn around(&self, cells: &Cells, k: usize, f: &mut impl FnMut(usize)) {
        let c = self.coords[k];
        match *cells {
            Cells::Dense(dims) => {
                let id = |c: [i64; 3]| ((c[0] * dims[1] + c[1]) * dims[2] + c[2]) as usize;
                for x in (c[0] - 1).max(0)..=(c[0] + 1).min(dims[0] - 1) {
                    for y in (c[1] - 1).max(0)..=(c[1] + 1).min(dims[1] - 1) {
                        let (z0, z1) = ((c[2] - 1).max(0), (c[2] + 1).min(dims[2] - 1));
                        let run = self.start[id([x, y, z0])]..self.start[id([x, y, z1]) + 1];
                        for &m in &self.sorted[run.start as usize..run.end as usize] {
                            f(m as usize);
                        }
                    }
                }
            }
            Cells::Sparse => {
                for dx in -1..=1 {
                    for dy in -1..=1 {
                        for dz in -1..=1 {
                            let key = [c[0] + dx, c[1] + dy, c[2] + dz];
                            let s = self.keyed.partition_point(|e| e.0 < key);
                            for &(kk, m) in &self.keyed[s..] {
                                if kk != key {
                                    break;
                                }
                                f(m as usize);
                            }
                        }
                    }
                }
            }
        }
    }

    fn build_dense(&mut self, pos: &[Vec3], radius: &[f64], skin: f64, dims: [i64; 3]) {
        let id = |c: [i64; 3]| ((c[0] * dims[1] + c[1]) * dims[2] + c[2]) as usize;
        let (start, sorted) = (&self.start, &self.sorted);
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
    fn build_sparse(&mut self, pos: &[Vec3], radius: &[f64], skin: f64) {
        let mut fresh = std::mem::take(&mut self.fresh);
        let this = &*self;
        let scan = |i: usize, out: &mut Vec<(u32, u32)>| {
            let first = out.len();
            let mut near = NearPairs::default();
            this.around(&Cells::Sparse, i, &mut |m| {
                if m > i {
                    near.offer(out, pos, radius, skin, i, m);
                }
            });
            near.flush(out);
            out[first..].sort_unstable();
        };
        scan_apples(pos.len(), &mut fresh, scan);
        self.fresh = fresh;
    }
}

/// The outer list's skin, in list skins (see [`NeighborList::list_pairs`]): the wider, the
/// fewer apples to list again at a rebuild, and the more pairs to filter.
const OUTER_SKIN: f64 = 2.0;

/// The outer list is kept while at most one apple in this many moved past its anchor's limit
/// (else the pairs come from the grid).
const MAX_MOVER_SHARE: usize = 4;

/// How [`NeighborList::bin`] binned the apples.
enum Cells {
    /// A dense grid of these dimensions.
    Dense([i64; 3]),
    /// Cells sorted by key.
    Sparse,
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

    /// The outer list gives, at every rebuild, the pairs and order the grid gives (and brute
    /// force): 600 apples in a box, a third riding along x at 0.6 mm a step, five falling at 3
    /// mm a step, every 40th step all of them shaken by 4 mm, every 50th step ten more apples;
    /// and, in a second run, the same with a far cluster (the sparse grid). Every kind of build
    /// occurs.
    #[test]
    fn an_outer_list_kept_lists_the_pairs_of_the_grid() {
        for far in [false, true] {
            let (mut pos, mut r) = random_cloud(600, 1.2);
            if far {
                for p in pos.iter_mut().skip(500) {
                    *p += Vec3::new(1000.0, 0.0, 0.0);
                }
            }
            let skin = 0.01;
            let mut list = NeighborList::new(skin);
            let mut seed = 99u64;
            let mut rnd = || {
                seed = seed
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
            };
            let mut rebuilt = 0;
            for step in 0..400 {
                for (k, p) in pos.iter_mut().enumerate() {
                    if k % 3 == 0 {
                        *p += Vec3::new(6e-4, 0.0, 0.0);
                    }
                    if k % 120 == 7 {
                        *p += Vec3::new(0.0, 0.0, -3e-3);
                    }
                    if step % 40 == 39 {
                        *p += Vec3::new(rnd(), rnd(), rnd()).normalize() * 4e-3;
                    }
                }
                if step % 50 == 49 {
                    for k in 0..10 {
                        pos.push(Vec3::new(0.1 * k as f64 - 0.5, 0.3, 0.2 + 0.01 * rnd()));
                        r.push(0.04);
                    }
                }
                let all: Vec<u32> = (0..pos.len() as u32).collect();
                if list.update(&pos, &r, &all, false, |_| {}) {
                    rebuilt += 1;
                    let direct = listed_all(&pos, &r, skin);
                    assert_eq!(direct.builds(), [1, 0, 0]);
                    assert_eq!(listed(&list), listed(&direct), "far {far}, step {step}");
                    assert_eq!(
                        listed(&list),
                        brute(&pos, &r, skin),
                        "far {far}, step {step}"
                    );
                }
            }
            let builds = list.builds();
            assert_eq!(builds.iter().sum::<u64>(), rebuilt);
            assert!(builds.iter().all(|&b| b > 0), "far {far}: {builds:?}");
            assert!(builds[2] > builds[0] + builds[1], "far {far}: {builds:?}");
        }
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
