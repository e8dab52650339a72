//! Octree (`--accel octree`).
//!
//! Build: adaptive subdivision of the scene box's cube ([`cube`]). A cell with more than `MAX_LEAF`
//! primitives is cut at its centre into eight octants, each primitive going to every
//! octant it overlaps (the exact triangle–box test, on padded boxes), until cells are
//! small enough, the depth limit is reached, a cut stops separating anything or
//! separates too little (its octants hold four times the cell's primitives), or the
//! tree holds [`MAX_ENTRIES_PER_PRIM`] entries a primitive.
//!
//! Traversal: front to back. Inside a cell the octants the ray may enter — by the
//! conservative slab test of each octant's box, the test the root's box passes — are
//! visited in the order of their entry distances (at most four along a line; more only
//! where rounding makes a crossing a near tie). The search skips every cell that lies
//! beyond the closest hit. (Octants chosen by the order of the mid-plane crossings, as
//! Revelles, Ureña & Lastra 2000 do, lost an octant near a corner when rounding put one
//! crossing on the wrong side of another; the cells' padding, a millionth of their own
//! coordinates, does not cover rounding that grows with the ray's distance.)

use super::cell_walk::CellWalk;
use super::overlap::{cell_padding, overlaps, padded};
use super::{search_limit, PrimitiveSet};
use crate::aabb::Aabb;
use crate::math::{gamma, Vec3A};
use crate::ray::PreparedRay;
use std::mem::MaybeUninit;

const MAX_LEAF: usize = 8;
/// Cells down to 2⁻³² of the root's side: a detail a millionth of the scene's size still
/// gets leaves of its own (at 16 levels, 50,000 triangles 0.01 wide beside one 10⁴ away
/// made leaves of hundreds). The entry budget bounds the tree, not the depth.
const MAX_DEPTH: usize = 32;
/// The most primitive entries the cells may hold, per primitive: a cut that would take
/// its cell's share past it makes a leaf instead. A primitive lies in every octant it
/// touches, and cells thinner than their padding (a flat scene's, or around primitives
/// that meet at a point) pass it to both halves, level after level: without a bound,
/// nine primitives meeting at a point made 4¹⁶ cells.
///
/// The bound is shared out: a cell's subtree may add entries in proportion to the
/// entries it holds. One bound for the whole tree was spent where cutting never
/// separates (around the vertices of a floor whose every triangle is stacked 50 times,
/// cut down to the depth limit) before the rest of the scene was built, which was left
/// in leaves of hundreds.
const MAX_ENTRIES_PER_PRIM: usize = 64;
/// Each level pops one cell and pushes at most eight octants.
const STACK_SIZE: usize = 7 * MAX_DEPTH + 8;
const INTERIOR: u32 = u32::MAX;

/// Interior: `first` = index of the first of eight consecutive children (octant `i` has
/// bit 0 set for the upper half in x, bit 1 in y, bit 2 in z), `count` = `INTERIOR`.
/// Leaf: `prim_ids[first..first + count]`.
#[derive(Clone, Copy, Debug)]
struct OctNode {
    first: u32,
    count: u32,
}

pub struct Octree {
    bounds: Aabb,
    nodes: Vec<OctNode>,
    prim_ids: Vec<u32>,
    prim_count: usize,
}

fn octant(b: &Aabb, i: usize) -> Aabb {
    let mid = b.centroid();
    let mut o = *b;
    for a in 0..3 {
        if i >> a & 1 == 1 {
            o.min[a] = mid[a];
        } else {
            o.max[a] = mid[a];
        }
    }
    o
}

/// The cube of `b`'s largest side from its lower corner (or `b` where that is beyond
/// `f32`). A flat scene's own box (a tessellated floor) is as thin as its padding: every
/// cut passed every primitive to both halves along the thin axis, and the tree spent its
/// entries on copies, then made the rest of the scene into leaves of tens of thousands
/// of primitives (a flat mesh of 500,000 triangles rendered at 0.001 Msamples/s). In the
/// cube, the floor lies in the lower cells along that axis, once.
fn cube(b: Aabb) -> Aabb {
    let side = b.extent().max_element();
    let max = b.min + Vec3A::splat(side);
    if max.is_finite() {
        Aabb { min: b.min, max }
    } else {
        b
    }
}

struct Builder<'a, P: ?Sized> {
    prims: &'a P,
    boxes: Vec<Aabb>,
    nodes: Vec<OctNode>,
    prim_ids: Vec<u32>,
}

impl<P: PrimitiveSet + ?Sized> Builder<'_, P> {
    /// Makes node `me` the tree over `items` in `cell`, which may add `budget` entries by
    /// cutting (see [`MAX_ENTRIES_PER_PRIM`]).
    fn build(&mut self, me: usize, cell: &Aabb, items: Vec<u32>, depth: usize, budget: usize) {
        let leaf = |b: &mut Self, items: &[u32]| {
            b.nodes[me] = OctNode {
                first: b.prim_ids.len() as u32,
                count: items.len() as u32,
            };
            b.prim_ids.extend_from_slice(items);
        };
        if items.len() <= MAX_LEAF || depth >= MAX_DEPTH {
            return leaf(self, &items);
        }
        let pad = cell_padding(cell);
        let children: Vec<Vec<u32>> = (0..8)
            .map(|i| {
                let o = padded(&octant(cell, i), pad);
                items
                    .iter()
                    .copied()
                    .filter(|&p| {
                        let b = &self.boxes[p as usize];
                        b.min.cmple(o.max).all() && o.min.cmple(b.max).all() && overlaps(self.prims, p, &o)
                    })
                    .collect()
            })
            .collect();
        let holding = children.iter().filter(|c| !c.is_empty()).count();
        if holding > 1 && children.iter().all(|c| c.len() == items.len() || c.is_empty()) {
            // Cutting separates nothing (every primitive spans the centre). (Everything
            // in one octant is cut on: the cut took empty space away. Taken for
            // "nothing", it left a mesh alone in a large cell one leaf of all its
            // triangles.)
            return leaf(self, &items);
        }
        // The children's entries replace this cell's. A cut that puts the cell's
        // primitives into four children each, on average, separates too little to pay.
        let entries = children.iter().map(Vec::len).sum::<usize>();
        let growth = entries.saturating_sub(items.len());
        if entries == 0 || entries > 4 * items.len() || growth > budget {
            return leaf(self, &items);
        }
        // What is left is shared out by the entries each child holds.
        let left = (budget - growth) as u128;
        let first = self.nodes.len();
        self.nodes[me] = OctNode {
            first: first as u32,
            count: INTERIOR,
        };
        self.nodes.extend([OctNode { first: 0, count: 0 }; 8]);
        for (i, c) in children.into_iter().enumerate() {
            let share = (left * c.len() as u128 / entries as u128) as usize;
            self.build(first + i, &octant(cell, i), c, depth + 1, share);
        }
    }
}

impl Octree {
    pub fn build<P: PrimitiveSet + ?Sized>(prims: &P) -> Octree {
        let boxes: Vec<Aabb> = (0..prims.count() as u32).map(|i| prims.bounds(i)).collect();
        let items: Vec<u32> = super::bounded(prims).map(|(i, _)| i).collect();
        let scene = items.iter().fold(Aabb::EMPTY, |b, &i| b.union(&boxes[i as usize]));
        if items.is_empty() {
            return Octree {
                bounds: Aabb::EMPTY,
                nodes: Vec::new(),
                prim_ids: Vec::new(),
                prim_count: 0,
            };
        }
        let pad = cell_padding(&scene);
        let bounds = cube(padded(&scene, pad));
        let mut b = Builder {
            prims,
            boxes,
            nodes: vec![OctNode { first: 0, count: 0 }],
            prim_ids: Vec::new(),
        };
        let budget = (MAX_ENTRIES_PER_PRIM - 1) * items.len();
        b.build(0, &bounds, items, 0, budget);
        Octree {
            bounds,
            nodes: b.nodes,
            prim_ids: b.prim_ids,
            prim_count: prims.count(),
        }
    }
}

/// Along each axis, the ray's interval in the lower and the upper half of `cell`: the
/// slab test of [`Aabb::intersect`] (its far distances widened by `1 + 2γ(3)`) for the
/// eight octants at once, from the nine plane distances they share. An axis the ray
/// does not move along (or so little that `1/d` overflows) admits the halves that hold
/// the origin, faces included.
fn half_intervals(cell: &Aabb, r: &PreparedRay) -> ([[f32; 2]; 3], [[f32; 2]; 3]) {
    const WIDEN: f32 = 1.0 + 2.0 * gamma(3);
    let (o, inv, mid) = (r.ray.origin, r.inv_dir, cell.centroid());
    let mut near = [[0.0f32; 2]; 3];
    let mut far = [[0.0f32; 2]; 3];
    for a in 0..3 {
        let planes = [cell.min[a], mid[a], cell.max[a]];
        if r.zero_axes.test(a) || !inv[a].is_finite() {
            for h in 0..2 {
                let inside = planes[h] <= o[a] && o[a] <= planes[h + 1];
                near[a][h] = if inside { f32::NEG_INFINITY } else { f32::INFINITY };
                far[a][h] = f32::INFINITY;
            }
        } else {
            let t = planes.map(|p| (p - o[a]) * inv[a]);
            for h in 0..2 {
                near[a][h] = t[h].min(t[h + 1]);
                far[a][h] = t[h].max(t[h + 1]) * WIDEN;
            }
        }
    }
    (near, far)
}

impl CellWalk for Octree {
    #[inline(always)]
    fn walk(&self, r: &PreparedRay, mut leaf: impl FnMut(&[u32]) -> Option<f32>) {
        if self.nodes.is_empty() {
            return;
        }
        let ray = &r.ray;
        let t_far = search_limit(ray.t_max);
        let Some((t0, _)) = self.bounds.intersect(r, t_far) else {
            return;
        };
        // (node, cell, entry), nearest on top. Uninitialised: a ray reaches a few dozen
        // of its entries, and filling them all would cost more than the walk.
        let mut stack = [const { MaybeUninit::<(u32, Aabb, f32)>::uninit() }; STACK_SIZE];
        stack[0].write((0, self.bounds, t0));
        let mut sp = 1;
        let mut limit = f32::INFINITY;
        while sp > 0 {
            sp -= 1;
            // SAFETY: the entries below `sp` were written (pushes write before they count).
            let (node, cell, t0) = unsafe { stack[sp].assume_init_read() };
            if limit < t0 {
                // This cell lies beyond the closest hit (those below it on the stack
                // nearly all do too, but rounding may order siblings' entries either way).
                continue;
            }
            let n = self.nodes[node as usize];
            if n.count != INTERIOR {
                let first = n.first as usize;
                match leaf(&self.prim_ids[first..first + n.count as usize]) {
                    Some(l) => limit = l,
                    None => return,
                }
                continue;
            }
            // Every octant the ray may enter, by the conservative slab test of its box (the
            // test the root passed): an octant chosen by the order of the mid-plane
            // crossings alone was dropped when rounding, which grows with the ray's
            // distance, put a crossing on the wrong side of another, near a corner.
            let (near, far) = half_intervals(&cell, r);
            let mut visits = [(0usize, 0.0f32); 8];
            let mut k = 0;
            for o in 0..8 {
                let child = self.nodes[n.first as usize + o];
                if child.count == 0 {
                    continue;
                }
                let h = [o & 1, o >> 1 & 1, o >> 2 & 1];
                let enter = near[0][h[0]].max(near[1][h[1]]).max(near[2][h[2]]).max(ray.t_min);
                let exit = far[0][h[0]].min(far[1][h[1]]).min(far[2][h[2]]).min(t_far);
                // (An octant beyond the closest hit found is not even pushed.)
                if enter <= exit && enter <= limit {
                    visits[k] = (o, enter);
                    k += 1;
                }
            }
            visits[..k].sort_unstable_by(|x, y| x.1.total_cmp(&y.1));
            // Farthest pushed first; at most eight a level, one of them popped next.
            for &(o, enter) in visits[..k].iter().rev() {
                stack[sp].write((n.first + o as u32, octant(&cell, o), enter));
                sp += 1;
            }
        }
    }

    fn prim_count(&self) -> usize {
        self.prim_count
    }

    fn memory_bytes(&self) -> usize {
        self.nodes.len() * std::mem::size_of::<OctNode>() + self.prim_ids.len() * 4
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::test_sets::Triangles;
    use crate::math::Vec3A;

    #[test]
    fn primitives_meeting_at_a_point_and_flat_scenes_make_bounded_trees() {
        // Nine triangles shrunk to one point and a sliver from it: every cut put them
        // into four octants at once (the cells grew thinner than their padding), and the
        // build made 4¹⁶ cells. (The flat grid made 174 entries a triangle.)
        let p = Vec3A::splat(2.0);
        let mut meet: Vec<[Vec3A; 3]> = (0..9).map(|_| [p; 3]).collect();
        meet.push([p, Vec3A::new(2.0, 18.0, 2.0), p]);
        // A flat grid of triangles: each cut through its plane passes every triangle to
        // both halves.
        let flat: Vec<[Vec3A; 3]> = (0..10_000)
            .map(|k| {
                let c = Vec3A::new((k % 100) as f32, (k / 100) as f32, 0.0);
                [c, c + Vec3A::X, c + Vec3A::Y]
            })
            .collect();
        for tris in [meet, flat] {
            let n = tris.len();
            let tree = Octree::build(&Triangles(tris));
            assert!(
                tree.prim_ids.len() <= MAX_ENTRIES_PER_PRIM * n,
                "{} entries",
                tree.prim_ids.len()
            );
            assert!(
                tree.nodes.len() <= 8 * tree.prim_ids.len() + 1,
                "{} nodes",
                tree.nodes.len()
            );
        }
    }

    /// The most primitives a leaf of `tree` holds.
    fn largest_leaf(tree: &Octree) -> Option<u32> {
        tree.nodes.iter().filter(|c| c.count != INTERIOR).map(|c| c.count).max()
    }

    #[test]
    fn a_flat_mesh_lies_in_one_layer_of_cells() {
        // A floor of 20,000 triangles at z = 0. In its own box (as thin as the padding)
        // every cut passed every triangle to both halves along z; the tree spent its 64
        // entries a triangle on copies and left leaves of thousands (64.0 entries, a leaf
        // of 5,202; now 4.1 and 8).
        let flat: Vec<[Vec3A; 3]> = (0..10_000)
            .flat_map(|k| {
                let c = Vec3A::new((k % 100) as f32, (k / 100) as f32, 0.0);
                [
                    [c, c + Vec3A::X, c + Vec3A::Y],
                    [c + Vec3A::X, c + Vec3A::ONE.with_z(0.0), c + Vec3A::Y],
                ]
            })
            .collect();
        let n = flat.len();
        let tree = Octree::build(&Triangles(flat));
        let largest_leaf = largest_leaf(&tree);
        let entries = tree.prim_ids.len() as f64 / n as f64;
        assert!(entries < 6.0, "{entries:.2} entries a triangle");
        assert!(largest_leaf <= Some(64), "a leaf of {largest_leaf:?}");
    }

    #[test]
    fn a_small_detail_in_a_large_scene_has_small_leaves() {
        // 5,000 triangles 0.01 wide and one 10⁴ away: padded by the scene's size (0.12),
        // and cut no deeper than cells of 10⁴ / 2¹⁶, the detail made leaves of up to 307
        // triangles (15.2 entries a triangle; now 8 and 1.4).
        let prims = Triangles::detail_in_a_stadium(7, 5_000);
        let tree = Octree::build(&prims);
        let largest_leaf = largest_leaf(&tree);
        assert!(largest_leaf <= Some(64), "a leaf of {largest_leaf:?}");
    }

    #[test]
    fn stacked_copies_do_not_spend_the_whole_trees_entries() {
        // A floor of 40 × 40 squares whose every triangle is there 20 times. Around its
        // vertices cutting never separates, and with one budget for the whole tree the
        // cells there took all of it down to the depth limit: the rest of the floor was
        // left in leaves of up to 17,640 (64.0 entries a triangle). Now the largest leaf
        // holds the copies of the six triangles that meet at a vertex (120; 36.6 entries).
        let mut tris = Vec::new();
        for k in 0..1600 {
            let c = Vec3A::new((k % 40) as f32, (k / 40) as f32, 0.0);
            for _ in 0..20 {
                tris.push([c, c + Vec3A::X, c + Vec3A::Y]);
                tris.push([c + Vec3A::X, c + Vec3A::ONE.with_z(0.0), c + Vec3A::Y]);
            }
        }
        let tree = Octree::build(&Triangles(tris));
        let largest_leaf = largest_leaf(&tree);
        assert!(largest_leaf <= Some(200), "a leaf of {largest_leaf:?}");
    }

    #[test]
    fn an_object_alone_in_a_large_cell_is_cut_on() {
        // Two small clusters of triangles far apart: each ends alone in one octant of
        // its cell, level after level, until the cells fit it.
        let mut tris = Vec::new();
        for centre in [Vec3A::ZERO, Vec3A::splat(20.0)] {
            tris.extend((0..2_000).map(|k| {
                let c = centre + Vec3A::new((k % 40) as f32, (k / 40) as f32, (k % 7) as f32) * 0.01;
                [c, c + Vec3A::X * 0.01, c + Vec3A::Y * 0.01]
            }));
        }
        let tree = Octree::build(&Triangles(tris));
        let largest_leaf = largest_leaf(&tree);
        assert!(largest_leaf <= Some(64), "a leaf of {largest_leaf:?}");
    }
}
