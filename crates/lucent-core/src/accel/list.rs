//! The brute-force list: every ray tests every primitive. The reference that every
//! other structure is checked against (`--accel list`).

use super::Accelerator;
use crate::hit::Hit;
use crate::primitive::Primitive;
use crate::ray::{PreparedRay, Ray};

pub struct PrimitiveList {
    /// The bounded primitives, in scene order.
    indices: Vec<u32>,
}

impl PrimitiveList {
    pub fn new(prims: &[Primitive]) -> PrimitiveList {
        PrimitiveList {
            indices: super::bounded(prims).map(|(i, _)| i).collect(),
        }
    }
}

impl Accelerator for PrimitiveList {
    fn closest_hit(&self, prims: &[Primitive], ray: &Ray) -> Option<Hit> {
        let r = PreparedRay::new(*ray);
        let mut best: Option<Hit> = None;
        for &i in &self.indices {
            let t_max = best.map_or(ray.t_max, |b| b.t);
            if let Some((t, b1, b2)) = prims[i as usize].intersect(&r, t_max) {
                if Hit::is_closer_than(t, i, &best) {
                    best = Some(Hit { t, prim: i, b1, b2 });
                }
            }
        }
        best
    }

    fn occluded(&self, prims: &[Primitive], ray: &Ray) -> bool {
        let r = PreparedRay::new(*ray);
        self.indices
            .iter()
            .any(|&i| prims[i as usize].intersect(&r, ray.t_max).is_some())
    }

    fn memory_bytes(&self) -> usize {
        self.indices.len() * 4
    }
}
