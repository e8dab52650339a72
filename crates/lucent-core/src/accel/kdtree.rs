//! kd-tree (`--accel kdtree`): an axis-aligned BSP tree with SAH split planes.
//!
//! Build (after Wald & Havran 2006, binned): a node's primitives are described by their
//! bounds *clipped to the node* ([`overlap::clipped_bounds`]), so a long triangle that
//! reaches into a node only with its tip counts only with its tip. Candidate planes are
//! the 31 inner boundaries of 32 bins along each axis, priced with
//! `C_trav + C_isect·(1 − bonus)·(P_below·N_below + P_above·N_above)` (a bonus for cutting
//! off empty space); a node becomes a leaf when no plane is cheaper than testing all its
//! primitives, or at depth `8 + 1.3·log₂ N`. Primitives that only touch a node are not
//! priced, and a node is not peeled when that separates little (one side keeping every
//! priced item while the other holds at least half): see [`best_plane`]. A primitive that straddles the plane goes to each side it
//! really overlaps (the exact triangle–box test), on boxes padded by their own
//! [`overlap::cell_padding`].
//!
//! Traversal (Havran's recursive ray traversal, iterative): the ray's `[t_min, t_max]`
//! interval is cut at each split plane; the near child is visited first and the far one
//! is pushed with its part of the interval; as soon as the closest hit lies before the
//! entry of the next node to visit, the search stops.

use super::cell_walk::CellWalk;
use super::overlap::{cell_padding, clipped_bounds, overlaps, padded};
use super::{search_limit, PrimitiveSet};
use crate::aabb::Aabb;
use crate::ray::PreparedRay;

const BINS: usize = 32;
const TRAVERSAL_COST: f32 = 1.0;
const INTERSECTION_COST: f32 = 1.5;
const EMPTY_BONUS: f32 = 0.2;
const LEAF: u32 = 3;
/// Deeper than any tree the depth limit allows (it is at most 8 + 1.3·32).
const STACK_SIZE: usize = 64;

/// 8 bytes. Interior: `a` = split position (f32 bits), `b` = above child << 2 | axis (the
/// below child follows the node). Leaf: `a` = primitive count, `b` = first << 2 | 3.
#[derive(Clone, Copy, Debug)]
struct KdNode {
    a: u32,
    b: u32,
}

pub struct KdTree {
    nodes: Vec<KdNode>,
    prim_ids: Vec<u32>,
    bounds: Aabb,
    /// The scene's primitive count (the mailbox's size).
    prim_count: usize,
}

struct Item {
    prim: u32,
    /// The primitive's bounds clipped to the current node.
    b: Aabb,
    /// Whether its part in the node has area: see [`best_plane`] for what the others,
    /// which only touch the node, are left out of.
    priced: bool,
}

struct Builder<'a, P: ?Sized> {
    prims: &'a P,
    max_depth: usize,
    nodes: Vec<KdNode>,
    prim_ids: Vec<u32>,
}

impl KdTree {
    pub fn build<P: PrimitiveSet + ?Sized>(prims: &P) -> KdTree {
        let items: Vec<Item> = super::bounded(prims)
            .map(|(prim, b)| Item { prim, b, priced: true })
            .collect();
        let bounds = items.iter().fold(Aabb::EMPTY, |acc, it| acc.union(&it.b));
        let count = items.len();
        let mut builder = Builder {
            prims,
            max_depth: (8.0 + 1.3 * (count.max(1) as f32).log2()).round() as usize,
            nodes: Vec::new(),
            prim_ids: Vec::new(),
        };
        if count > 0 {
            builder.build_node(bounds, items, 0);
        }
        KdTree {
            nodes: builder.nodes,
            prim_ids: builder.prim_ids,
            bounds,
            prim_count: prims.count(),
        }
    }
}

impl<P: PrimitiveSet + ?Sized> Builder<'_, P> {
    fn leaf(&mut self, items: &[Item]) {
        self.nodes.push(KdNode {
            a: items.len() as u32,
            b: (self.prim_ids.len() as u32) << 2 | LEAF,
        });
        self.prim_ids.extend(items.iter().map(|it| it.prim));
    }

    fn build_node(&mut self, node_box: Aabb, items: Vec<Item>, depth: usize) {
        let n = items.len();
        if n <= 1 || depth >= self.max_depth {
            return self.leaf(&items);
        }
        let Some((axis, pos)) = best_plane(&node_box, &items) else {
            return self.leaf(&items);
        };
        let mut below_box = node_box;
        below_box.max[axis] = pos;
        let mut above_box = node_box;
        above_box.min[axis] = pos;
        let (below, above) = self.distribute(items, axis, pos, &below_box, &above_box);
        if below.len() == n && above.len() == n {
            // The plane separates nothing (every primitive spans it): stop here.
            let mut all = below;
            all.sort_by_key(|it| it.prim);
            return self.leaf(&all);
        }
        let me = self.nodes.len();
        self.nodes.push(KdNode {
            a: pos.to_bits(),
            b: axis as u32,
        });
        self.build_node(below_box, below, depth + 1);
        let above_index = self.nodes.len() as u32;
        self.nodes[me].b = above_index << 2 | axis as u32;
        self.build_node(above_box, above, depth + 1);
    }

    /// Sends each primitive to the side(s) of the plane it overlaps.
    fn distribute(
        &self,
        items: Vec<Item>,
        axis: usize,
        pos: f32,
        below: &Aabb,
        above: &Aabb,
    ) -> (Vec<Item>, Vec<Item>) {
        let pad = cell_padding(&below.union(above));
        let (pb, pa) = (padded(below, pad), padded(above, pad));
        let (mut lo, mut hi) = (Vec::new(), Vec::new());
        for it in items {
            if it.b.max[axis] < pos - pad {
                lo.push(it);
            } else if it.b.min[axis] > pos + pad {
                hi.push(it);
            } else {
                for (side, padded_side, out) in [(below, &pb, &mut lo), (above, &pa, &mut hi)] {
                    if overlaps(self.prims, it.prim, padded_side) {
                        // Bounds for pricing planes further down; a sliver lost to clipping
                        // rounding keeps the plane position as a degenerate box.
                        let (b, priced) = match clipped_bounds(self.prims, it.prim, side) {
                            Some(part) => (part.bounds, !part.touches_only),
                            None => {
                                let mut flat = it.b;
                                flat.min[axis] = pos;
                                flat.max[axis] = pos;
                                (flat, false)
                            }
                        };
                        out.push(Item {
                            prim: it.prim,
                            b,
                            priced,
                        });
                    }
                }
            }
        }
        (lo, hi)
    }
}

/// The cheapest binned SAH plane, if it is cheaper than a leaf.
///
/// Only items whose part in the node has area are priced: those that merely touch it
/// (a mesh's neighbours across the plane that made the node, along an edge or at a
/// corner; or within the padding) follow the side they touch, but the node is not split
/// for them. Priced, they made flat nodes (a tessellated floor or wall, where the two
/// children's areas add up to the parent's) peel off slice after slice to the depth
/// limit: a slice holding one triangle and the neighbour touching its face was split
/// again because its wider part then held one item instead of two. A flat mesh of
/// 80,000 triangles took 3.7 s and 18 MB to build.
///
/// Nor is a node peeled when that separates little: split where one side keeps every
/// priced item and the other at least half of them. The side that keeps them all is the
/// same problem in a smaller box, and in flat nodes it was peeled again and again, each
/// time a little cheaper by the SAH. A peel that leaves few items on the other side
/// stays (a small object cut out of a large floor's two triangles: refusing every peel
/// made such a render 150 times slower), and so does a cut that leaves the other side
/// empty (it cuts off empty space).
fn best_plane(node_box: &Aabb, items: &[Item]) -> Option<(usize, f32)> {
    let priced = || items.iter().filter(|it| it.priced);
    let n = priced().count();
    if n == 0 {
        return None;
    }
    let extent = node_box.extent();
    let total_area = node_box.surface_area();
    if !(total_area > 0.0) {
        return None;
    }
    let mut best: Option<(f32, usize, f32)> = None;
    for axis in 0..3 {
        let (lo, w) = (node_box.min[axis], extent[axis]);
        if !(w > 0.0) {
            continue;
        }
        let scale = BINS as f32 / w;
        let bin = |x: f32| (((x - lo) * scale) as isize).clamp(0, BINS as isize - 1) as usize;
        let mut starts = [0u32; BINS];
        let mut ends = [0u32; BINS];
        for it in priced() {
            starts[bin(it.b.min[axis])] += 1;
            ends[bin(it.b.max[axis])] += 1;
        }
        let (o1, o2) = ((axis + 1) % 3, (axis + 2) % 3);
        let cap = extent[o1] * extent[o2];
        let ring = extent[o1] + extent[o2];
        let (mut below, mut above) = (0u32, n as u32);
        for k in 1..BINS {
            below += starts[k - 1];
            above -= ends[k - 1];
            let pos = lo + k as f32 * w / BINS as f32;
            let (wb, wa) = (pos - lo, node_box.max[axis] - pos);
            let area_below = 2.0 * (cap + wb * ring);
            let area_above = 2.0 * (cap + wa * ring);
            let peel = (below == n as u32 && above > 0) || (above == n as u32 && below > 0);
            if peel && 2 * below.min(above) >= n as u32 {
                // A peel that separates little (see above).
                continue;
            }
            let bonus = if below == 0 || above == 0 { EMPTY_BONUS } else { 0.0 };
            let cost = TRAVERSAL_COST
                + INTERSECTION_COST * (1.0 - bonus) * (area_below * below as f32 + area_above * above as f32)
                    / total_area;
            if best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, axis, pos));
            }
        }
    }
    let (cost, axis, pos) = best?;
    (cost < INTERSECTION_COST * n as f32).then_some((axis, pos))
}

impl CellWalk for KdTree {
    #[inline(always)]
    fn walk(&self, r: &PreparedRay, mut leaf: impl FnMut(&[u32]) -> Option<f32>) {
        if self.nodes.is_empty() {
            return;
        }
        let ray = &r.ray;
        let Some((t0, t1)) = self.bounds.intersect(r, search_limit(ray.t_max)) else {
            return;
        };
        let mut stack = [(0u32, 0.0f32, 0.0f32); STACK_SIZE];
        let mut sp = 0;
        let (mut node, mut t_min, mut t_max) = (0usize, t0, t1);
        loop {
            let n = self.nodes[node];
            if n.b & 3 == LEAF {
                let first = (n.b >> 2) as usize;
                let Some(limit) = leaf(&self.prim_ids[first..first + n.a as usize]) else {
                    return;
                };
                // Next node in ray order, unless the closest hit lies before it.
                if sp == 0 {
                    return;
                }
                sp -= 1;
                let (next, a, b) = stack[sp];
                if limit < a {
                    return;
                }
                (node, t_min, t_max) = (next as usize, a, b);
            } else {
                let axis = (n.b & 3) as usize;
                let split = f32::from_bits(n.a);
                let (o, inv) = (ray.origin[axis], r.inv_dir[axis]);
                let t_plane = (split - o) * inv;
                let below_first = o < split || (o == split && ray.dir[axis] <= 0.0);
                let (first, second) = if below_first {
                    (node + 1, (n.b >> 2) as usize)
                } else {
                    ((n.b >> 2) as usize, node + 1)
                };
                // With a margin on both sides: near the plane, both children are visited.
                if t_plane > search_limit(t_max) || t_plane <= 0.0 {
                    node = first;
                } else if search_limit(t_plane) < t_min {
                    node = second;
                } else {
                    stack[sp] = (second as u32, t_plane, t_max);
                    sp += 1;
                    node = first;
                    t_max = t_plane;
                }
            }
        }
    }

    fn prim_count(&self) -> usize {
        self.prim_count
    }

    fn memory_bytes(&self) -> usize {
        self.nodes.len() * std::mem::size_of::<KdNode>() + self.prim_ids.len() * 4
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::test_sets::Triangles;
    use crate::math::Vec3A;

    /// A tessellated floor: `n` × `n` unit squares of two triangles each, at z = 0.
    fn floor(n: usize) -> Triangles {
        let p = |i: usize, j: usize| Vec3A::new(i as f32, j as f32, 0.0);
        Triangles(
            (0..n * n)
                .flat_map(|k| {
                    let (i, j) = (k % n, k / n);
                    [
                        [p(i, j), p(i + 1, j), p(i + 1, j + 1)],
                        [p(i, j), p(i + 1, j + 1), p(i, j + 1)],
                    ]
                })
                .collect(),
        )
    }

    #[test]
    fn a_small_detail_in_a_large_scene_is_padded_by_its_own_size() {
        // 5,000 triangles 0.01 wide and one 10⁴ away: padded by the scene's size (0.12),
        // every triangle fell into the cells on both sides of each plane near it (117.9
        // entries a triangle; now 1.1).
        let prims = Triangles::detail_in_a_stadium(7, 5_000);
        let tree = KdTree::build(&prims);
        let entries = tree.prim_ids.len() as f64 / prims.0.len() as f64;
        assert!(entries < 4.0, "{entries:.2} entries a triangle");
    }

    #[test]
    fn a_flat_mesh_is_not_cut_into_slivers() {
        // Before its items that only touch a node went unpriced and peels that separate
        // little were refused, the kd-tree held about 17 entries a triangle of these
        // floors (18.3, 17.4 and 17.0) in 18 nodes a triangle; now 6.0–6.6 in 3.6. (The coplanar-grid property
        // test in `geometry::structure_tests` checks such a tree's answers.)
        for n in [20, 40, 60] {
            let prims = floor(n);
            let tree = KdTree::build(&prims);
            let entries = tree.prim_ids.len() as f64 / prims.0.len() as f64;
            assert!(entries < 8.0, "{n} × {n}: {entries:.2} entries a triangle");
            assert!(
                tree.nodes.len() < 5 * prims.0.len(),
                "{n} × {n}: {} nodes",
                tree.nodes.len()
            );
        }
    }
}
