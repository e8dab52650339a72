//! First stage of the BVH build: a binary tree by the binned surface area heuristic
//! (Wald 2007), later collapsed into the wide tree ([`super::wide`]).
//!
//! At each node the primitive centroids are sorted into 16 bins along all three axes at
//! once, the 15 candidate planes per axis are priced with
//! `C_trav + (A_l·P(N_l) + A_r·P(N_r)) / A`, where `P(n) = ⌈n/4⌉` counts the four-wide
//! packets a leaf of `n` primitives needs, and the node becomes a leaf when that is no
//! cheaper than its own packets. (Only the planes between occupied bins are priced, and a
//! node of one packet is a leaf without binning: the same choices, for less.) Below
//! depth 48 (only pathological inputs get there), and when no plane separates the
//! centroids, nodes are split at the object median so the depth stays bounded. The build
//! works on a flat array of 32-byte references that it partitions in place: no
//! allocation per node and no indirection.
//!
//! With more than one thread, subtrees of more than [`PARALLEL_REFS`] references (and
//! more than an eighth of one thread's share of the whole) are built on two threads at once
//! (`rayon::join`): each side into its own lists of nodes, put together at the end as
//! parent, left subtree, right subtree — the very order the one-thread recursion writes
//! — so the tree is the same, node for node, for any number of threads. One thread
//! writes every node in place.

use crate::aabb::Aabb;
use crate::math::Vec3A;

use super::packet::LANES;

const BINS: usize = 16;
const _: () = assert!(BINS.is_power_of_two(), "bin indices are masked with BINS - 1");
/// Leaves hold at most this many primitives (one packet; the collapse may merge two).
pub const MAX_LEAF: usize = 4;
/// Cost of one traversal step relative to one packet test (measured on the benchmark
/// dragons: 2 beats 0.5 and 1, and gives smaller trees; 3 and 4 are no better).
const TRAVERSAL_COST: f32 = 2.0;
const MEDIAN_SPLIT_DEPTH: usize = 48;
/// Subtrees larger than this may be built with their two halves in parallel; smaller
/// ones are not worth a task.
const PARALLEL_REFS: usize = 4096;
/// Nodes over more references than this bin them on the pool's threads, in chunks whose
/// bins are then merged (exactly: minima, maxima and counts).
const PARALLEL_BINNING: usize = 1 << 16;

/// A primitive's box and index, as the builder moves them around.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
pub struct BuildRef {
    pub lo: [f32; 3],
    pub prim: u32,
    pub hi: [f32; 3],
    /// The reference's bin along x, y and z at the last binning (4 bits each), so that
    /// the partition reads its side instead of computing it again.
    bins: u32,
}

impl BuildRef {
    pub fn new(b: &Aabb, prim: u32) -> BuildRef {
        BuildRef {
            lo: b.min.into(),
            prim,
            hi: b.max.into(),
            bins: 0,
        }
    }
    #[inline(always)]
    fn lo(&self) -> Vec3A {
        load_xyz::<0>(self)
    }
    #[inline(always)]
    fn hi(&self) -> Vec3A {
        load_xyz::<1>(self)
    }
    pub fn bounds(&self) -> Aabb {
        Aabb {
            min: self.lo(),
            max: self.hi(),
        }
    }
    /// Twice the centroid (the factor ½ cancels in every use).
    #[inline(always)]
    fn centroid2(&self) -> Vec3A {
        self.lo() + self.hi()
    }
}

/// Half `HALF` of a reference (0: `lo` and `prim`, 1: `hi` and `bins`) as a vector of
/// its three floats: one aligned load on x86-64, the fourth lane cleared (the builder
/// reads references some hundred million times; assembling three scalars costs more).
#[inline(always)]
fn load_xyz<const HALF: usize>(r: &BuildRef) -> Vec3A {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: a `BuildRef` is 32 bytes, 32-byte aligned, with `lo` at offset 0 and `hi`
    // at 16 (asserted below): both halves are aligned, readable 16-byte groups; the
    // fourth float of each (`prim` or `bins`) is masked off.
    unsafe {
        use std::arch::x86_64::*;
        let xyz = _mm_castsi128_ps(_mm_set_epi32(0, -1, -1, -1));
        let half = (r as *const BuildRef as *const f32).add(4 * HALF);
        Vec3A::from(_mm_and_ps(_mm_load_ps(half), xyz))
    }
    #[cfg(not(target_arch = "x86_64"))]
    Vec3A::from_array(if HALF == 0 { r.lo } else { r.hi })
}

const _: () = assert!(
    std::mem::offset_of!(BuildRef, lo) == 0
        && std::mem::offset_of!(BuildRef, hi) == 16
        && std::mem::size_of::<BuildRef>() == 32
);

#[derive(Clone, Copy, Debug)]
pub enum Kind {
    Interior {
        left: u32,
        right: u32,
    },
    /// `refs[start..start + count]`.
    Leaf {
        start: u32,
        count: u32,
    },
}

#[derive(Clone, Copy, Debug)]
pub struct BinaryNode {
    pub bounds: Aabb,
    pub kind: Kind,
}

/// The binary tree; `refs` is in leaf order. Node 0 is the root (absent when empty).
pub struct BinaryTree {
    pub nodes: Vec<BinaryNode>,
    pub refs: Vec<BuildRef>,
}

/// Truncates three non-negative bin coordinates at once (one SIMD conversion on x86-64).
#[inline(always)]
fn bin_indices(v: Vec3A) -> [u32; 4] {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: SSE2 is part of x86-64; the values are in [0, BINS) or NaN (→ 0x80000000,
    // masked to a valid bin by the caller).
    unsafe {
        use std::arch::x86_64::*;
        let i = _mm_cvttps_epi32(v.into());
        std::mem::transmute::<__m128i, [u32; 4]>(i)
    }
    #[cfg(not(target_arch = "x86_64"))]
    [v.x as u32, v.y as u32, v.z as u32, 0]
}

#[inline(always)]
fn packets(n: usize) -> f32 {
    n.div_ceil(LANES) as f32
}

/// Builds over `(primitive index, bounds)` pairs.
#[cfg(test)]
pub fn build(items: impl Iterator<Item = (u32, Aabb)>) -> BinaryTree {
    build_refs(items.map(|(i, b)| BuildRef::new(&b, i)).collect())
}

/// Builds over the references `refs` (in this order: the tree depends on it).
pub fn build_refs(refs: Vec<BuildRef>) -> BinaryTree {
    let mut tree = BinaryTree {
        // About two nodes for every three references (leaves hold three on average);
        // pages never written are never touched.
        nodes: crate::accel::huge_pages::vec_with_capacity(refs.len() + 1),
        refs,
    };
    if !tree.refs.is_empty() {
        let (b, c) = parallel_bounds(&tree.refs);
        let threads = rayon::current_num_threads();
        if threads == 1 {
            let n = tree.refs.len();
            let mut refs = std::mem::take(&mut tree.refs);
            build_node(&mut tree, &mut refs, 0, 0, n, b, c, 0);
            tree.refs = refs;
        } else {
            // Enough tasks to keep every thread busy, few enough that the joins do not
            // copy the nodes over and over.
            let parallel = PARALLEL_REFS.max(tree.refs.len() / (8 * threads));
            let parts = build_subtree(&mut tree.refs, 0, b, c, 0, parallel);
            // Each part moves into place once, its child indices rebased.
            for part in parts {
                let base = tree.nodes.len() as u32;
                tree.nodes.extend(part.into_iter().map(|mut n| {
                    if let Kind::Interior { left, right } = &mut n.kind {
                        *left += base;
                        *right += base;
                    }
                    n
                }));
            }
        }
    }
    tree
}

/// [`range_bounds`] over chunks on the pool's threads when there are many references
/// (minima and maxima are exact: the same bits in any grouping).
fn parallel_bounds(refs: &[BuildRef]) -> (Aabb, Aabb) {
    use rayon::prelude::*;
    if refs.len() <= PARALLEL_BINNING {
        return range_bounds(refs);
    }
    refs.par_chunks(PARALLEL_BINNING / 4).map(range_bounds).reduce(
        || {
            let e = Aabb {
                min: Vec3A::INFINITY,
                max: Vec3A::NEG_INFINITY,
            };
            (e, e)
        },
        |(a, ac), (b, bc)| (a.union(&b), ac.union(&bc)),
    )
}

/// The nodes of the subtree over `refs` (which start at index `offset` of the whole
/// array) in the one-thread order, its root first, as consecutive parts: each part's
/// child indices count from the part's first node. (The parts are only put together
/// at the end, so that no node is copied more than once.)
fn build_subtree(
    refs: &mut [BuildRef],
    offset: usize,
    bounds: Aabb,
    cb: Aabb,
    depth: usize,
    parallel: usize,
) -> Vec<Vec<BinaryNode>> {
    if refs.len() <= parallel {
        let mut tree = BinaryTree {
            nodes: Vec::with_capacity(refs.len() + 1),
            refs: Vec::new(),
        };
        build_node(&mut tree, refs, offset, 0, refs.len(), bounds, cb, depth);
        return vec![tree.nodes];
    }
    let count = refs.len();
    let leaf = BinaryNode {
        bounds,
        kind: Kind::Leaf {
            start: offset as u32,
            count: count as u32,
        },
    };
    let Some(split) = choose_split(refs, &bounds, &cb, depth) else {
        return vec![vec![leaf]];
    };
    let (l, r) = refs.split_at_mut(split.mid);
    let (left, right) = rayon::join(
        || build_subtree(l, offset, split.left.0, split.left.1, depth + 1, parallel),
        || build_subtree(r, offset + split.mid, split.right.0, split.right.1, depth + 1, parallel),
    );
    // Parent, left subtree, right subtree: the order of the one-thread recursion. The
    // parent is a part of its own, its children counted from it.
    let left_len: usize = left.iter().map(Vec::len).sum();
    let mut parts = Vec::with_capacity(1 + left.len() + right.len());
    parts.push(vec![BinaryNode {
        bounds,
        kind: Kind::Interior {
            left: 1,
            right: 1 + left_len as u32,
        },
    }]);
    parts.extend(left);
    parts.extend(right);
    parts
}

/// Where to split `refs` (partitioning them), or `None` for a leaf.
fn choose_split(refs: &mut [BuildRef], bounds: &Aabb, cb: &Aabb, depth: usize) -> Option<Split> {
    let count = refs.len();
    if count <= 1 {
        return None;
    }
    if depth >= MEDIAN_SPLIT_DEPTH {
        return Some(median_split(refs, cb));
    }
    match sah_split(refs, bounds, cb) {
        Some(s) => Some(s),
        None if count > MAX_LEAF => Some(median_split(refs, cb)),
        None => None,
    }
}

/// Bounds of the boxes and of the doubled centroids of `refs`.
fn range_bounds(refs: &[BuildRef]) -> (Aabb, Aabb) {
    let (mut lo, mut hi) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
    let (mut clo, mut chi) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
    for r in refs {
        lo = lo.min(r.lo());
        hi = hi.max(r.hi());
        let c = r.centroid2();
        clo = clo.min(c);
        chi = chi.max(c);
    }
    (Aabb { min: lo, max: hi }, Aabb { min: clo, max: chi })
}

/// The one-thread recursion over `refs[start..end]` (`refs` starts at index `offset` of
/// the whole array): pushes the node, then its left and right subtrees; returns its index.
#[allow(clippy::too_many_arguments)]
fn build_node(
    tree: &mut BinaryTree,
    refs: &mut [BuildRef],
    offset: usize,
    start: usize,
    end: usize,
    bounds: Aabb,
    cb: Aabb,
    depth: usize,
) -> u32 {
    let me = tree.nodes.len();
    tree.nodes.push(BinaryNode {
        bounds,
        kind: Kind::Leaf {
            start: (offset + start) as u32,
            count: (end - start) as u32,
        },
    });
    let Some(split) = choose_split(&mut refs[start..end], &bounds, &cb, depth) else {
        return me as u32;
    };
    let mid = start + split.mid;
    let left = build_node(tree, refs, offset, start, mid, split.left.0, split.left.1, depth + 1);
    let right = build_node(tree, refs, offset, mid, end, split.right.0, split.right.1, depth + 1);
    tree.nodes[me].kind = Kind::Interior { left, right };
    me as u32
}

struct Split {
    mid: usize,
    /// Box and centroid bounds of each side (so children need not scan again).
    left: (Aabb, Aabb),
    right: (Aabb, Aabb),
}

#[derive(Clone, Copy)]
struct Bin {
    lo: Vec3A,
    hi: Vec3A,
    count: u32,
}

const EMPTY_BIN: Bin = Bin {
    lo: Vec3A::INFINITY,
    hi: Vec3A::NEG_INFINITY,
    count: 0,
};

fn area(lo: Vec3A, hi: Vec3A) -> f32 {
    let e = (hi - lo).max(Vec3A::ZERO);
    e.x * e.y + e.y * e.z + e.z * e.x
}

type Bins = [[Bin; BINS]; 3];

/// Sorts the references' centroids into bins along the three axes (and notes each
/// one's bins in it).
fn bin_refs(refs: &mut [BuildRef], lo: Vec3A, scale: Vec3A) -> Bins {
    if refs.len() < TWO_BIN_SETS {
        let mut bins = [[EMPTY_BIN; BINS]; 3];
        for r in refs.iter_mut() {
            bin_ref(&mut bins, r, lo, scale);
        }
        return bins;
    }
    // Neighbouring references mostly fall into the same bins, and each bin update waits
    // for the one before it (load, min, store): alternating between two sets of bins
    // halves that chain. Merging them is exact (minima, maxima, counts).
    let (mut even, mut odd) = ([[EMPTY_BIN; BINS]; 3], [[EMPTY_BIN; BINS]; 3]);
    let mut pairs = refs.chunks_exact_mut(2);
    for pair in &mut pairs {
        let [a, b] = pair else { unreachable!("pairs") };
        bin_ref(&mut even, a, lo, scale);
        bin_ref(&mut odd, b, lo, scale);
    }
    for r in pairs.into_remainder() {
        bin_ref(&mut even, r, lo, scale);
    }
    merge_bins(even, odd)
}

/// Nodes over at least this many references bin them into two sets of bins.
const TWO_BIN_SETS: usize = 64;

/// Adds one reference to `bins` and notes its bins in it.
#[inline(always)]
fn bin_ref(bins: &mut Bins, r: &mut BuildRef, lo: Vec3A, scale: Vec3A) {
    let max_bin = Vec3A::splat((BINS - 1) as f32);
    // Both halves are read once, before `bins` is written (a 16-byte load of the half
    // that holds a 4-byte store still in flight waits for it).
    let (rlo, rhi) = (r.lo(), r.hi());
    let b = bin_indices(((rlo + rhi - lo) * scale).min(max_bin)).map(|i| i as usize & (BINS - 1));
    for (axis, bin_axis) in bins.iter_mut().enumerate() {
        let bin = &mut bin_axis[b[axis]];
        bin.lo = bin.lo.min(rlo);
        bin.hi = bin.hi.max(rhi);
        bin.count += 1;
    }
    r.bins = (b[0] | b[1] << 4 | b[2] << 8) as u32;
}

/// The bins of two groups of references together.
fn merge_bins(mut a: Bins, b: Bins) -> Bins {
    for (axis_a, axis_b) in a.iter_mut().zip(&b) {
        for (x, y) in axis_a.iter_mut().zip(axis_b) {
            x.lo = x.lo.min(y.lo);
            x.hi = x.hi.max(y.hi);
            x.count += y.count;
        }
    }
    a
}

/// Partitions at the best SAH plane, or returns `None` when a leaf is cheaper (or no
/// plane separates the centroids).
fn sah_split(refs: &mut [BuildRef], bounds: &Aabb, cb: &Aabb) -> Option<Split> {
    let count = refs.len();
    // A split costs at least the traversal step, no less than one packet: a node that
    // fits in one packet is a leaf, whatever its planes would cost (most nodes are
    // these, so they are not binned for nothing).
    if count <= MAX_LEAF && TRAVERSAL_COST >= packets(count) {
        return None;
    }
    let extent = cb.max - cb.min;
    let lo = cb.min;
    // Axes with no extent get scale 0: everything lands in bin 0 and no plane is priced.
    let scale = Vec3A::select(
        extent.cmpgt(Vec3A::ZERO),
        Vec3A::splat(BINS as f32 * (1.0 - 1e-6)) / extent,
        Vec3A::ZERO,
    );
    let bins = if count > PARALLEL_BINNING {
        use rayon::prelude::*;
        refs.par_chunks_mut(PARALLEL_BINNING / 4)
            .map(|chunk| bin_refs(chunk, lo, scale))
            .reduce(|| [[EMPTY_BIN; BINS]; 3], merge_bins)
    } else {
        bin_refs(refs, lo, scale)
    };
    let (cost, axis, split_bin) = cheapest_plane(&bins, scale)?;
    let a = area(bounds.min, bounds.max);
    let split_cost = TRAVERSAL_COST + if a > 0.0 { cost / a } else { packets(count) };
    if count <= MAX_LEAF && split_cost >= packets(count) {
        return None;
    }
    let shift = 4 * axis as u32;
    let goes_left = |r: &BuildRef| ((r.bins >> shift) as usize & (BINS - 1)) < split_bin;
    let (mid, centroids) = partition_with_centroids(refs, goes_left);
    if mid == 0 || mid == count {
        return None;
    }
    // The children's boxes are the unions of their bins' boxes (min and max are exact:
    // the same bits as scanning the references again); their centroid bounds came from
    // the partition.
    let union = |bins: &[Bin]| {
        bins.iter().fold(
            Aabb {
                min: Vec3A::INFINITY,
                max: Vec3A::NEG_INFINITY,
            },
            |b, bin| Aabb {
                min: b.min.min(bin.lo),
                max: b.max.max(bin.hi),
            },
        )
    };
    let bins = &bins[axis];
    Some(Split {
        mid,
        left: (union(&bins[..split_bin]), centroids[0]),
        right: (union(&bins[split_bin..]), centroids[1]),
    })
}

/// No plane chosen (see [`cheapest_plane`]).
const NO_PLANE: u32 = u32::MAX;

/// The cheapest plane of `bins` by the SAH, as (cost, axis, first bin on the right);
/// `None` when no plane has references on both sides. Axes of `scale` 0 are not split.
fn cheapest_plane(bins: &Bins, scale: Vec3A) -> Option<(f32, usize, usize)> {
    // The cheapest plane so far, as its cost and `axis << 8 | first bin on the right`
    // (none yet: cost ∞), chosen without branches: which candidate wins is data, and a
    // mispredicted branch per win cost more than the pricing.
    let (mut best_cost, mut best_plane) = (f32::INFINITY, NO_PLANE);
    for axis in 0..3 {
        if scale[axis] == 0.0 {
            continue;
        }
        let bins = &bins[axis];
        // Only planes between two occupied bins can split, and all planes in one gap
        // between them make the same two sides at the same cost: pricing the lowest plane
        // of each gap, in order, finds the split that pricing every plane finds (its
        // folds skip only empty bins, which change no bit), at the cost of the occupied
        // bins alone — few in the many small nodes near the leaves.
        let mut occupied = [0u8; BINS];
        let mut m = 0;
        for (k, bin) in bins.iter().enumerate() {
            occupied[m] = k as u8;
            m += (bin.count > 0) as usize;
        }
        let occupied = &occupied[..m];
        // right_cost[t]: the bins occupied[t..] on the right.
        let mut right_cost = [0.0f32; BINS];
        let (mut rlo, mut rhi, mut n) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY, 0usize);
        for t in (1..m).rev() {
            let bin = &bins[occupied[t] as usize];
            rlo = rlo.min(bin.lo);
            rhi = rhi.max(bin.hi);
            n += bin.count as usize;
            right_cost[t] = area(rlo, rhi) * packets(n);
        }
        let (mut llo, mut lhi, mut n) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY, 0usize);
        for t in 1..m {
            let bin = &bins[occupied[t - 1] as usize];
            llo = llo.min(bin.lo);
            lhi = lhi.max(bin.hi);
            n += bin.count as usize;
            let cost = area(llo, lhi) * packets(n) + right_cost[t];
            // (A NaN or infinite cost, from areas past f32's range, never wins.)
            let better = cost < best_cost;
            best_cost = if better { cost } else { best_cost };
            let plane = (axis as u32) << 8 | (occupied[t - 1] as u32 + 1);
            best_plane = if better { plane } else { best_plane };
        }
    }
    (best_plane != NO_PLANE).then_some((best_cost, (best_plane >> 8) as usize, (best_plane & 0xff) as usize))
}

/// In-place partition (Hoare style): how many elements satisfy `pred` (they come first),
/// and the bounds of the doubled centroids of each side.
fn partition_with_centroids(v: &mut [BuildRef], pred: impl Fn(&BuildRef) -> bool) -> (usize, [Aabb; 2]) {
    let empty = Aabb {
        min: Vec3A::INFINITY,
        max: Vec3A::NEG_INFINITY,
    };
    let mut sides = [empty, empty];
    let mut add = |side: usize, r: &BuildRef| {
        let c = r.centroid2();
        sides[side].min = sides[side].min.min(c);
        sides[side].max = sides[side].max.max(c);
    };
    let (mut i, mut j) = (0, v.len());
    loop {
        while i < j && pred(&v[i]) {
            add(0, &v[i]);
            i += 1;
        }
        while i < j && !pred(&v[j - 1]) {
            add(1, &v[j - 1]);
            j -= 1;
        }
        if i >= j {
            return (i, sides);
        }
        // v[i] belongs right and v[j - 1] left: swapped, each is counted once.
        add(1, &v[i]);
        add(0, &v[j - 1]);
        v.swap(i, j - 1);
        i += 1;
        j -= 1;
    }
}

/// Splits in the middle by centroid along the widest axis (ties by index).
fn median_split(refs: &mut [BuildRef], cb: &Aabb) -> Split {
    let axis = cb.largest_axis();
    let mid = refs.len() / 2;
    refs.select_nth_unstable_by(mid, |a, b| {
        (a.lo[axis] + a.hi[axis])
            .total_cmp(&(b.lo[axis] + b.hi[axis]))
            .then(a.prim.cmp(&b.prim))
    });
    Split {
        mid,
        left: range_bounds(&refs[..mid]),
        right: range_bounds(&refs[mid..]),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn boxes(n: u32) -> Vec<(u32, Aabb)> {
        let mut x = 0x9e37_79b9u32;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            x as f32 / u32::MAX as f32
        };
        (0..n)
            .map(|i| {
                let c = Vec3A::new(next(), next(), next()) * 100.0;
                let e = Vec3A::new(next(), next(), next());
                (i, Aabb { min: c - e, max: c + e })
            })
            .collect()
    }

    /// Nodes and leaf order as plain values, to compare trees.
    fn shape(t: &BinaryTree) -> (Vec<String>, Vec<u32>) {
        (
            t.nodes.iter().map(|n| format!("{n:?}")).collect(),
            t.refs.iter().map(|r| r.prim).collect(),
        )
    }

    /// Every one of the 15 planes per axis priced, empty bins folded in (the plain
    /// binned SAH), the first cheapest one kept.
    fn cheapest_of_every_plane(bins: &Bins, scale: Vec3A) -> Option<(f32, usize, usize)> {
        let mut best: Option<(f32, usize, usize)> = None;
        for axis in (0..3).filter(|&a| scale[a] != 0.0) {
            let bins = &bins[axis];
            for k in 1..BINS {
                let side = |range: &[Bin]| {
                    range
                        .iter()
                        .fold((Vec3A::INFINITY, Vec3A::NEG_INFINITY, 0usize), |(lo, hi, n), b| {
                            (lo.min(b.lo), hi.max(b.hi), n + b.count as usize)
                        })
                };
                let (llo, lhi, nl) = side(&bins[..k]);
                let (rlo, rhi, nr) = side(&bins[k..]);
                let cost = area(llo, lhi) * packets(nl) + area(rlo, rhi) * packets(nr);
                if nl > 0 && nr > 0 && best.is_none_or(|(c, _, _)| cost < c) {
                    best = Some((cost, axis, k));
                }
            }
        }
        best
    }

    #[test]
    fn pricing_only_occupied_gaps_finds_the_plane_every_plane_finds() {
        for n in [2, 3, 5, 8, 13, 17, 40, 100, 300] {
            for seed in 0..20 {
                // Boxes clustered on a few spots, so many bins stay empty and many
                // planes tie.
                let mut refs: Vec<BuildRef> = boxes(n + seed * 7)
                    .into_iter()
                    .skip(seed as usize * 7)
                    .map(|(i, b)| {
                        let snapped = Aabb {
                            min: (b.min / 25.0).round() * 25.0,
                            max: (b.min / 25.0).round() * 25.0 + (b.max - b.min),
                        };
                        BuildRef::new(if seed % 2 == 0 { &snapped } else { &b }, i)
                    })
                    .collect();
                let (_, cb) = range_bounds(&refs);
                let extent = cb.max - cb.min;
                let scale = Vec3A::select(
                    extent.cmpgt(Vec3A::ZERO),
                    Vec3A::splat(BINS as f32 * (1.0 - 1e-6)) / extent,
                    Vec3A::ZERO,
                );
                let bins = bin_refs(&mut refs, cb.min, scale);
                let fast = cheapest_plane(&bins, scale).map(|(c, a, k)| (c.to_bits(), a, k));
                let every = cheapest_of_every_plane(&bins, scale).map(|(c, a, k)| (c.to_bits(), a, k));
                assert_eq!(fast, every, "{n} boxes, seed {seed}");
            }
        }
    }

    #[test]
    fn two_sets_of_bins_bin_as_one() {
        let mut refs: Vec<BuildRef> = boxes(1000).iter().map(|(i, b)| BuildRef::new(b, *i)).collect();
        let (_, cb) = range_bounds(&refs);
        let scale = Vec3A::splat(BINS as f32 * (1.0 - 1e-6)) / (cb.max - cb.min);
        let mut one = [[EMPTY_BIN; BINS]; 3];
        for r in refs.iter_mut() {
            bin_ref(&mut one, r, cb.min, scale);
        }
        let two = bin_refs(&mut refs, cb.min, scale);
        assert!(refs.len() >= TWO_BIN_SETS);
        for (a, b) in one.iter().flatten().zip(two.iter().flatten()) {
            assert_eq!(
                (a.lo.to_array(), a.hi.to_array(), a.count),
                (b.lo.to_array(), b.hi.to_array(), b.count)
            );
        }
    }

    #[test]
    fn the_parallel_build_makes_the_one_thread_tree_for_any_thread_count() {
        let items = boxes(40_000);
        // The plain recursion, with no parallel split at all.
        let mut refs: Vec<BuildRef> = items.iter().map(|(i, b)| BuildRef::new(b, *i)).collect();
        let (b, c) = range_bounds(&refs);
        let mut plain = BinaryTree {
            nodes: Vec::new(),
            refs: Vec::new(),
        };
        let n = refs.len();
        build_node(&mut plain, &mut refs, 0, 0, n, b, c, 0);
        plain.refs = refs;
        let expected = shape(&plain);
        for threads in [1, 2, 3, 8] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let tree = pool.install(|| build(items.iter().copied()));
            assert!(shape(&tree) == expected, "{threads} threads");
        }
    }
}
