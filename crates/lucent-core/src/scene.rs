//! A scene ready to render: primitives with their acceleration structure, materials,
//! lights, the camera and the global settings.

use crate::accel::{AccelKind, Accelerator};
use crate::camera::Camera;
use crate::hit::{Hit, SurfacePoint};
use crate::light::Light;
use crate::material::Material;
use crate::math::Vec3A;
use crate::primitive::Primitive;
use crate::ray::Ray;

pub struct Scene {
    pub width: u32,
    pub height: u32,
    pub camera: Camera,
    pub primitives: Vec<Primitive>,
    pub materials: Vec<Material>,
    pub lights: Vec<Light>,
    /// Per-vertex normals of `trinormal` triangles, indexed by `Shape::Triangle::normals`.
    pub vertex_normals: Vec<[Vec3A; 3]>,
    accel: Box<dyn Accelerator>,
    accel_kind: AccelKind,
}

/// Everything a [`Scene`] is made of, before its acceleration structure is built.
pub struct SceneParts {
    pub width: u32,
    pub height: u32,
    pub camera: Camera,
    pub primitives: Vec<Primitive>,
    pub materials: Vec<Material>,
    pub lights: Vec<Light>,
    pub vertex_normals: Vec<[Vec3A; 3]>,
}

impl Scene {
    pub fn new(parts: SceneParts, accel: AccelKind) -> Scene {
        let SceneParts {
            width,
            height,
            camera,
            primitives,
            materials,
            lights,
            vertex_normals,
        } = parts;
        Scene {
            width,
            height,
            camera,
            accel: accel.build(&primitives),
            accel_kind: accel,
            primitives,
            materials,
            lights,
            vertex_normals,
        }
    }

    #[inline]
    pub fn closest_hit(&self, ray: &Ray) -> Option<Hit> {
        self.accel.closest_hit(&self.primitives, ray)
    }

    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.accel.occluded(&self.primitives, ray)
    }

    pub fn surface_point(&self, hit: &Hit, ray: &Ray) -> SurfacePoint {
        self.primitives[hit.prim as usize].surface_point(hit, ray.origin, ray.dir, &self.vertex_normals)
    }

    pub fn accel_kind(&self) -> AccelKind {
        self.accel_kind
    }

    pub fn accel_memory_bytes(&self) -> usize {
        self.accel.memory_bytes()
    }
}
