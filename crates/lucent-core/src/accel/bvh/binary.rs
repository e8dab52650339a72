//! First stage of the BVH build: a binary tree by the binned surface area heuristic
//! (Wald 2007), later collapsed into the wide tree ([`super::wide`]).
//!
//! At each node the primitive centroids are sorted into 32 bins (16 in nodes of at most
//! 64 primitives) along all three axes at once, the candidate planes per axis are priced
//! with
//! `C_trav + (A_l·P(N_l) + A_r·P(N_r)) / A`, where `P(n) = ⌈n/4⌉` counts the four-wide
//! packets a leaf of `n` primitives needs, and the node becomes a leaf when that is no
//! cheaper than its own packets. (Only the planes between occupied bins are priced, and a
//! node of one packet is a leaf without binning: the same choices, for less.) Near the
//! root, a node of one packet is split too when `(A_l + A_r) / A < 1` (see
//! [`SMALL_SPLIT_DEPTH`]): the walls of a room. Below
//! depth 48 (only pathological inputs get there), and when no plane separates the
//! centroids, nodes are split at the object median so the depth stays bounded. The build
//! works on a flat array of 32-byte references ([`super::build_ref`]) that it partitions
//! in place: no allocation per node and no indirection. Binning and pricing planes are
//! [`super::sah_bins`].
//!
//! With more than one thread, subtrees of more than [`PARALLEL_REFS`] references (and
//! more than an eighth of one thread's share of the whole) are built on two threads at
//! once (`rayon::join`): each side into its own lists of nodes, put together at the end as
//! parent, left subtree, right subtree — the very order the one-thread recursion writes
//! — so the tree is the same, node for node, for any number of threads. One thread
//! writes every node in place.

use super::build_ref::BuildRef;
use super::sah_bins::{area, bin_node, cheapest_plane, packets, side_bounds, Bins, PARALLEL_BINNING};
use super::sah_bins::{FEW_BINS, FEW_BINS_UP_TO, MANY_BINS};
use crate::aabb::Aabb;
use crate::math::Vec3A;

/// Leaves hold at most this many primitives (one packet; the collapse may merge two).
pub const MAX_LEAF: usize = 4;
/// Cost of one traversal step relative to one packet test (measured on the benchmark
/// dragons: 2 beats 0.5 and 1, and gives smaller trees; 3 and 4 are no better).
const TRAVERSAL_COST: f32 = 2.0;
const MEDIAN_SPLIT_DEPTH: usize = 48;
/// Nodes of one packet shallower than this are split when their two sides' boxes are
/// smaller than theirs (`A_l + A_r < A`), with no traversal cost: the collapse puts the
/// two sides in free slots of the wide node above, or merges them back into one leaf
/// when it has none ([`super::wide`]). That separates the big flat pieces of a small
/// scene: the Cornell box's walls, packed four triangles to a leaf, made leaf boxes as
/// large as the room, which every ray inside it entered. Split, the kernel runs 34 % and
/// 39 % fewer instructions on the box's diffuse and shadow rays, and the path-traced box
/// 15 % fewer in all (the same answers).
/// Each split adds at most one packet, and a binary tree has fewer than 2¹⁰ nodes above
/// depth 10, so this adds at most 160 KB to any scene; a big mesh's nodes of one packet
/// lie deeper (the dragons' trees are unchanged), and the showcase's spheres and floor
/// run 5 % fewer instructions than with depth 6.
const SMALL_SPLIT_DEPTH: usize = 10;
/// Subtrees larger than this may be built with their two halves in parallel; smaller
/// ones are not worth a task.
const PARALLEL_REFS: usize = 4096;

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
        nodes: crate::huge_pages::vec_with_capacity(refs.len() + 1),
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
            // Each part moves into place once, its child indices rebased, on the pool's
            // threads.
            let mut bases = Vec::with_capacity(parts.len());
            let mut total = 0;
            for part in &parts {
                bases.push(total);
                total += part.len();
            }
            use rayon::prelude::*;
            tree.nodes.par_extend((0..total).into_par_iter().map(|i| {
                // The last part that begins at or before node i.
                let k = bases.partition_point(|&b| b <= i) - 1;
                let mut n = parts[k][i - bases[k]];
                if let Kind::Interior { left, right } = &mut n.kind {
                    *left += bases[k] as u32;
                    *right += bases[k] as u32;
                }
                n
            }));
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
    match sah_split(refs, bounds, cb, depth) {
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

/// Partitions at the best SAH plane, or returns `None` when a leaf is cheaper (or no
/// plane separates the centroids).
fn sah_split(refs: &mut [BuildRef], bounds: &Aabb, cb: &Aabb, depth: usize) -> Option<Split> {
    let count = refs.len();
    // A split costs at least the traversal step, no less than one packet: a node that
    // fits in one packet is a leaf, whatever its planes would cost (most nodes are
    // these, so they are not binned for nothing) -- except near the root, where the
    // step is free (see SMALL_SPLIT_DEPTH).
    let small = count <= MAX_LEAF;
    let free_step = small && depth < SMALL_SPLIT_DEPTH;
    if small && !free_step && TRAVERSAL_COST >= packets(count) {
        return None;
    }
    if count <= FEW_BINS_UP_TO {
        binned_split::<FEW_BINS>(refs, bounds, cb, small, free_step)
    } else {
        binned_split::<MANY_BINS>(refs, bounds, cb, small, free_step)
    }
}

/// [`sah_split`] with `N` bins.
fn binned_split<const N: usize>(
    refs: &mut [BuildRef],
    bounds: &Aabb,
    cb: &Aabb,
    small: bool,
    free_step: bool,
) -> Option<Split> {
    let count = refs.len();
    let (bins, scale): (Bins<N>, Vec3A) = bin_node(refs, cb);
    let (cost, axis, split_bin) = cheapest_plane(&bins, scale)?;
    let a = area(bounds.min, bounds.max);
    let step = if free_step { 0.0 } else { TRAVERSAL_COST };
    let split_cost = step + if a > 0.0 { cost / a } else { packets(count) };
    if small && split_cost >= packets(count) {
        return None;
    }
    let (mid, centroids) = partition_with_centroids(refs, |r| r.bin(axis) < split_bin);
    if mid == 0 || mid == count {
        return None;
    }
    // The children's boxes come from the bins, their centroid bounds from the partition.
    let (left, right) = side_bounds(&bins, axis, split_bin);
    Some(Split {
        mid,
        left: (left, centroids[0]),
        right: (right, centroids[1]),
    })
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
    use super::super::sah_bins::tests::boxes;
    use super::*;

    /// Nodes and leaf order as plain values, to compare trees.
    fn shape(t: &BinaryTree) -> (Vec<String>, Vec<u32>) {
        (
            t.nodes.iter().map(|n| format!("{n:?}")).collect(),
            t.refs.iter().map(|r| r.prim).collect(),
        )
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

    #[test]
    fn a_rooms_walls_get_binary_leaves_of_their_own() {
        // Five walls of the 2 × 2 × 2 room (no front), two triangles each: each
        // triangle's box is its wall's. Four triangles fit one packet, but a leaf of two
        // walls has the room's box, which every ray inside the room enters.
        let v = |x: f32, y: f32, z: f32| Vec3A::new(x, y, z);
        let walls = [
            (v(-1.0, 0.0, -1.0), v(1.0, 0.0, 1.0)),
            (v(-1.0, 2.0, -1.0), v(1.0, 2.0, 1.0)),
            (v(-1.0, 0.0, -1.0), v(1.0, 2.0, -1.0)),
            (v(-1.0, 0.0, -1.0), v(-1.0, 2.0, 1.0)),
            (v(1.0, 0.0, -1.0), v(1.0, 2.0, 1.0)),
        ];
        // Two boxes per wall, the same: both triangles of a wall's quad span it.
        let items: Vec<(u32, Aabb)> = (0..10u32)
            .map(|i| {
                let (lo, hi) = walls[i as usize / 2];
                (i, Aabb::new(lo, hi))
            })
            .collect();
        let tree = build(items.iter().copied());
        for n in &tree.nodes {
            if let Kind::Leaf { start, count } = n.kind {
                let prims = &tree.refs[start as usize..(start + count) as usize];
                let wall = prims[0].prim / 2;
                assert!(
                    prims.iter().all(|r| r.prim / 2 == wall),
                    "a leaf holds two walls: {n:?}"
                );
            }
        }
        // Deeper down, one packet stays one leaf: the same boxes far from the root
        // (below a 2¹²-way split of many copies) are not split.
        let rooms = 1u32 << 12;
        let many: Vec<(u32, Aabb)> = (0..10 * rooms)
            .map(|i| {
                let (lo, hi) = walls[(i % 10) as usize / 2];
                let shift = v((i / 10) as f32 * 10.0, 0.0, 0.0);
                (i, Aabb::new(lo + shift, hi + shift))
            })
            .collect();
        let tree = build(many.iter().copied());
        let leaves = tree
            .nodes
            .iter()
            .filter(|n| matches!(n.kind, Kind::Leaf { .. }))
            .count();
        assert!(leaves < rooms as usize * 5, "{leaves} leaves");
    }
}
