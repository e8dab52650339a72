//! What the grid, the octree and the kd-tree share. Each visits its cells (leaves) in
//! order along the ray, every cell holding a list of primitives that may also appear in
//! other cells; the closest-hit and any-hit queries on top of such a walk are the same
//! for all three: test each primitive once per ray ([`Mailbox`]), keep the closest hit
//! with the scene-order tie rule, and stop once it lies before the next cell.

use super::mailbox::Mailbox;
use super::{search_limit, Accelerator, PrimitiveSet};
use crate::hit::Hit;
use crate::ray::PreparedRay;

pub trait CellWalk {
    /// Visits the cells `ray` crosses, nearest first. `cell` gets a cell's primitives and
    /// returns the distance beyond which nothing more can be found; `None` stops the walk.
    fn walk(&self, r: &PreparedRay, cell: impl FnMut(&[u32]) -> Option<f32>);
    /// One more than the largest primitive index the cells hold (the mailbox's size).
    fn prim_count(&self) -> usize;
    /// Bytes of the cells and their primitive lists.
    fn memory_bytes(&self) -> usize;
}

/// Every cell walk is a structure: the queries are the same for all of them.
impl<W: CellWalk + Send + Sync, P: PrimitiveSet + ?Sized> Accelerator<P> for W {
    fn closest_hit(&self, prims: &P, r: &PreparedRay) -> Option<Hit> {
        closest_hit(self, prims, r)
    }

    fn occluded(&self, prims: &P, r: &PreparedRay) -> bool {
        occluded(self, prims, r)
    }

    fn memory_bytes(&self) -> usize {
        CellWalk::memory_bytes(self)
    }
}

pub fn closest_hit<P: PrimitiveSet + ?Sized>(w: &impl CellWalk, prims: &P, r: &PreparedRay) -> Option<Hit> {
    let mut best: Option<Hit> = None;
    if !r.ray.is_line() {
        return best;
    }
    let mut t_max = r.ray.t_max;
    Mailbox::with(w.prim_count(), |mailbox| {
        w.walk(r, |ids| {
            for &pi in ids {
                if !mailbox.first_visit(pi) {
                    continue;
                }
                if let Some(hit) = prims.intersect(pi, r, t_max) {
                    if Hit::is_closer_than(hit.t, pi, &best) {
                        best = Some(hit);
                        t_max = hit.t;
                    }
                }
            }
            Some(best.map_or(f32::INFINITY, |h| search_limit(h.t)))
        })
    });
    best
}

pub fn occluded<P: PrimitiveSet + ?Sized>(w: &impl CellWalk, prims: &P, r: &PreparedRay) -> bool {
    let mut hit = false;
    if !r.ray.is_line() {
        return hit;
    }
    Mailbox::with(w.prim_count(), |mailbox| {
        w.walk(r, |ids| {
            hit = ids
                .iter()
                .any(|&pi| mailbox.first_visit(pi) && prims.occludes(pi, r, r.ray.t_max));
            (!hit).then_some(f32::INFINITY)
        })
    });
    hit
}
