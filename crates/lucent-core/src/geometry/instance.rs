//! An object placed in the scene by `instance`: shared geometry (never copied) seen
//! through a transform. This is the second level of a two-level structure: the scene's
//! structure finds the instance by its world bounds, the ray goes into the object's
//! space, and the object's own structure finds the primitive.

use std::sync::Arc;

use super::Geometry;
use crate::aabb::Aabb;
use crate::hit::{Hit, SurfacePoint};
use crate::math::{Affine3A, Mat3A, Vec3A};
use crate::ray::{PreparedRay, Ray};
use crate::spawn;

#[derive(Clone)]
pub struct Instance {
    pub object: Arc<Geometry>,
    pub world_to_object: Affine3A,
    pub object_to_world: Affine3A,
    /// Inverse transpose of the object-to-world linear part: carries normals to world.
    pub normal_to_world: Mat3A,
    pub bounds: Aabb,
}

impl std::fmt::Debug for Instance {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Instance({} primitives)", self.object.primitives.len())
    }
}

impl Instance {
    /// `object_bounds` are the bounds of the object's bounded primitives.
    pub fn new(object: Arc<Geometry>, object_bounds: Aabb, object_to_world: Affine3A) -> Instance {
        let world_to_object = object_to_world.inverse();
        Instance {
            object,
            world_to_object,
            object_to_world,
            normal_to_world: world_to_object.matrix3.transpose(),
            bounds: object_bounds.transformed(&object_to_world),
        }
    }

    /// The ray in object space. The direction is not renormalised, so `t` means the same
    /// point in both spaces.
    #[inline(always)]
    fn to_object(&self, ray: &Ray, t_max: f32) -> Ray {
        Ray {
            origin: self.world_to_object.transform_point3a(ray.origin),
            dir: self.world_to_object.transform_vector3a(ray.dir),
            t_min: ray.t_min,
            t_max,
        }
    }

    /// The closest hit: `prim` is the object's primitive, `inner[0]` the triangle if
    /// that is a mesh.
    #[inline]
    pub fn intersect(&self, ray: &PreparedRay, t_max: f32) -> Option<Hit> {
        self.object.closest_hit(&self.to_object(&ray.ray, t_max))
    }

    #[inline]
    pub fn occludes(&self, ray: &PreparedRay, t_max: f32) -> bool {
        self.object.occluded(&self.to_object(&ray.ray, t_max))
    }

    /// World-space `∂p/∂u`, `∂p/∂v` at `hit`.
    pub fn tangents(&self, hit: &Hit, origin: Vec3A, dir: Vec3A) -> (Vec3A, Vec3A) {
        let o = self.world_to_object.transform_point3a(origin);
        let d = self.world_to_object.transform_vector3a(dir);
        let (du, dv) = self.object.tangents(hit, o, d);
        let m = self.object_to_world.matrix3;
        (m * du, m * dv)
    }

    /// Shading data in world space at `hit` (as [`Instance::intersect`] gave it).
    pub fn surface_point(&self, hit: &Hit, origin: Vec3A, dir: Vec3A) -> SurfacePoint {
        let o = self.world_to_object.transform_point3a(origin);
        let d = self.world_to_object.transform_vector3a(dir);
        let sp = self.object.surface_point(hit, o, d);
        let (point, error) = spawn::transform_point(&self.object_to_world, sp.point, sp.error);
        let normal = (self.normal_to_world * sp.normal).normalize();
        let ng = (self.normal_to_world * sp.geometric_normal).normalize();
        SurfacePoint {
            point,
            error,
            // The inverse transpose need not keep the two normals' dot product positive.
            geometric_normal: if ng.dot(normal) < 0.0 { -ng } else { ng },
            normal,
            ..sp
        }
    }
}
