//! The brute-force list: every ray tests every primitive. The reference that every
//! other structure is checked against (`--accel list`).

use super::Accelerator;
use crate::hit::Hit;
use crate::primitive::Primitive;
use crate::ray::{PreparedRay, Ray};

pub struct PrimitiveList {
    len: usize,
}

impl PrimitiveList {
    pub fn new(len: usize) -> PrimitiveList {
        PrimitiveList { len }
    }
}

impl Accelerator for PrimitiveList {
    fn closest_hit(&self, prims: &[Primitive], ray: &Ray) -> Option<Hit> {
        debug_assert_eq!(prims.len(), self.len);
        let r = PreparedRay::new(*ray);
        let mut best: Option<Hit> = None;
        for (i, p) in prims.iter().enumerate() {
            let t_max = best.map_or(ray.t_max, |b| b.t);
            if let Some((t, b1, b2)) = p.intersect(&r, t_max) {
                if Hit::is_closer_than(t, i as u32, &best) {
                    best = Some(Hit {
                        t,
                        prim: i as u32,
                        b1,
                        b2,
                    });
                }
            }
        }
        best
    }

    fn occluded(&self, prims: &[Primitive], ray: &Ray) -> bool {
        let r = PreparedRay::new(*ray);
        prims.iter().any(|p| p.intersect(&r, ray.t_max).is_some())
    }

    fn memory_bytes(&self) -> usize {
        0
    }
}
