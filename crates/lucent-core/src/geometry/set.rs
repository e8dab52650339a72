//! A set of primitives with its acceleration structure: the whole scene, or one object
//! that `instance` places many times ([`super::instance`]).

use super::primitive::{Primitive, Shape};
use crate::accel::{AccelKind, Accelerator};
use crate::hit::{Hit, SurfacePoint};
use crate::math::Vec3A;
use crate::ray::{PreparedRay, Ray};

pub struct Geometry {
    pub primitives: Vec<Primitive>,
    /// Per-vertex normals of `trinormal` triangles, indexed by `Shape::Triangle::normals`.
    pub vertex_normals: Vec<[Vec3A; 3]>,
    accel: Box<dyn Accelerator<[Primitive]>>,
    /// Primitives without finite bounds (planes), tested by every ray outside `accel`.
    unbounded: Vec<u32>,
}

impl Geometry {
    pub fn new(primitives: Vec<Primitive>, vertex_normals: Vec<[Vec3A; 3]>, accel: AccelKind) -> Geometry {
        let unbounded = (0..primitives.len() as u32)
            .filter(|&i| !crate::accel::is_bounded(&primitives[i as usize].bounds()))
            .collect();
        Geometry {
            accel: accel.build(primitives.as_slice()),
            unbounded,
            primitives,
            vertex_normals,
        }
    }

    #[inline]
    pub fn closest_hit(&self, ray: &Ray) -> Option<Hit> {
        self.closest_hit_prepared(&PreparedRay::new(*ray))
    }

    /// [`Geometry::closest_hit`] of a ray prepared already.
    #[inline]
    pub fn closest_hit_prepared(&self, r: &PreparedRay) -> Option<Hit> {
        let mut best = None;
        self.closest_hit_into(r, &mut best);
        best
    }

    /// [`Geometry::closest_hit_prepared`] into `best`, where the caller keeps it (see
    /// [`crate::accel::Accelerator::closest_hit_into`]).
    #[inline]
    pub fn closest_hit_into(&self, r: &PreparedRay, best: &mut Option<Hit>) {
        self.accel.closest_hit_into(&self.primitives, r, best);
        // (The emptiness test here: the search is not inlined, and most scenes have no
        // planes.)
        if !self.unbounded.is_empty() {
            self.nearer_unbounded(r, best);
        }
    }

    /// [`Geometry::closest_hit`] of each of `rays` (`out[i]` for `rays[i]`), coherent
    /// rays together (see [`Accelerator::closest_hits`]).
    pub fn closest_hits(&self, rays: &[Ray], out: &mut [Option<Hit>]) {
        self.accel.closest_hits(&self.primitives, rays, out);
        if !self.unbounded.is_empty() {
            for (best, ray) in out.iter_mut().zip(rays) {
                self.nearer_unbounded(&PreparedRay::new(*ray), best);
            }
        }
    }

    /// Replaces `best` (the structure's answer for `r`) by a nearer hit on a primitive
    /// outside the structure (planes), with the structures' tie rule: scene order.
    #[inline]
    fn nearer_unbounded(&self, r: &PreparedRay, best: &mut Option<Hit>) {
        for &i in &self.unbounded {
            let t_max = best.map_or(r.ray.t_max, |b| b.t);
            if let Some(hit) = self.primitives[i as usize].intersect(i, r, t_max) {
                if Hit::is_closer_than(hit.t, i, best) {
                    *best = Some(hit);
                }
            }
        }
    }

    /// Whether a primitive outside the structure (a plane) blocks `r`.
    #[inline]
    fn unbounded_occludes(&self, r: &PreparedRay) -> bool {
        // (The emptiness test first: the search was not inlined, and most scenes have no
        // planes.)
        !self.unbounded.is_empty()
            && self
                .unbounded
                .iter()
                .any(|&i| self.primitives[i as usize].occludes(r, r.ray.t_max))
    }

    /// [`Geometry::occluded`] of each of `rays` (`out[i]` for `rays[i]`), coherent rays
    /// together (see [`Accelerator::occluded_rays`]).
    pub fn occluded_rays(&self, rays: &[Ray], out: &mut [bool]) {
        self.accel.occluded_rays(&self.primitives, rays, out);
        if !self.unbounded.is_empty() {
            for (blocked, ray) in out.iter_mut().zip(rays) {
                *blocked = *blocked || self.unbounded_occludes(&PreparedRay::new(*ray));
            }
        }
    }

    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.occluded_prepared(&PreparedRay::new(*ray))
    }

    /// [`Geometry::occluded`] of a ray prepared already.
    #[inline]
    pub fn occluded_prepared(&self, r: &PreparedRay) -> bool {
        self.unbounded_occludes(r) || self.accel.occluded(&self.primitives, r)
    }

    /// World-space `∂p/∂u`, `∂p/∂v` at `hit` (see [`Primitive::tangents`]).
    pub fn tangents(&self, hit: &Hit, origin: Vec3A, dir: Vec3A) -> (Vec3A, Vec3A) {
        self.primitives[hit.prim as usize].tangents(hit, origin, dir)
    }

    /// Shading data at `hit` on the ray `origin + t·dir`.
    pub fn surface_point(&self, hit: &Hit, origin: Vec3A, dir: Vec3A) -> SurfacePoint {
        self.primitives[hit.prim as usize].surface_point(hit, origin, dir, &self.vertex_normals)
    }

    /// How many simple primitives the scene shows: every triangle of every mesh, and
    /// every primitive of an object once per instance.
    pub fn shown_primitive_count(&self) -> u64 {
        self.primitives.iter().map(|p| p.shown_count()).sum()
    }

    /// Bytes of every acceleration structure: this one, and those of the meshes and
    /// objects it holds, each shared one counted once.
    pub fn accel_memory_bytes(&self) -> usize {
        let mut seen = std::collections::HashSet::new();
        self.accel_bytes_unique(&mut seen)
    }

    fn accel_bytes_unique(&self, seen: &mut std::collections::HashSet<usize>) -> usize {
        let mut total = self.accel.memory_bytes();
        for p in &self.primitives {
            match &p.shape {
                Shape::Mesh(m) if seen.insert(std::sync::Arc::as_ptr(m) as usize) => total += m.accel_memory_bytes(),
                Shape::Instance(i) if seen.insert(std::sync::Arc::as_ptr(&i.object) as usize) => {
                    total += i.object.accel_bytes_unique(seen)
                }
                _ => {}
            }
        }
        total
    }
}
