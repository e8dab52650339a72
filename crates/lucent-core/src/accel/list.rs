//! The brute-force list: every ray tests every primitive. The reference that every
//! other structure is checked against (`--accel list`).

use super::{Accelerator, PrimitiveSet};
use crate::hit::Hit;
use crate::ray::PreparedRay;

pub struct PrimitiveList {
    /// The bounded primitives, in scene order.
    indices: Vec<u32>,
}

impl PrimitiveList {
    pub fn new<P: PrimitiveSet + ?Sized>(prims: &P) -> PrimitiveList {
        PrimitiveList {
            indices: super::bounded(prims).map(|(i, _)| i).collect(),
        }
    }
}

impl<P: PrimitiveSet + ?Sized> Accelerator<P> for PrimitiveList {
    fn closest_hit(&self, prims: &P, r: &PreparedRay) -> Option<Hit> {
        if !r.ray.is_line() {
            return None;
        }
        let mut best: Option<Hit> = None;
        for &i in &self.indices {
            let t_max = best.map_or(r.ray.t_max, |b| b.t);
            if let Some(hit) = prims.intersect(i, r, t_max) {
                if Hit::is_closer_than(hit.t, i, &best) {
                    best = Some(hit);
                }
            }
        }
        best
    }

    fn occluded(&self, prims: &P, r: &PreparedRay) -> bool {
        r.ray.is_line() && self.indices.iter().any(|&i| prims.occludes(i, r, r.ray.t_max))
    }

    fn memory_bytes(&self) -> usize {
        self.indices.len() * 4
    }
}
