//! A scene ready to render: primitives with their acceleration structure, materials,
//! lights, the camera and the global settings.

use crate::accel::{AccelKind, Accelerator};
use crate::camera::Camera;
use crate::hit::{Hit, SurfacePoint};
use crate::light::Light;
use crate::material::Material;
use crate::math::Vec3A;
use crate::primitive::Primitive;
use crate::ray::{PreparedRay, Ray};

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
    /// Primitives without finite bounds (planes), tested by every ray outside `accel`.
    unbounded: Vec<u32>,
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
        let unbounded = (0..primitives.len() as u32)
            .filter(|&i| !crate::accel::is_bounded(&primitives[i as usize].bounds()))
            .collect();
        Scene {
            width,
            height,
            camera,
            unbounded,
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
        let mut best = self.accel.closest_hit(&self.primitives, ray);
        if !self.unbounded.is_empty() {
            let r = PreparedRay::new(*ray);
            for &i in &self.unbounded {
                let t_max = best.map_or(ray.t_max, |b| b.t);
                if let Some((t, b1, b2)) = self.primitives[i as usize].intersect(&r, t_max) {
                    // The same tie rule as inside the structures: scene order.
                    if Hit::is_closer_than(t, i, &best) {
                        best = Some(Hit { t, prim: i, b1, b2 });
                    }
                }
            }
        }
        best
    }

    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        if !self.unbounded.is_empty() {
            let r = PreparedRay::new(*ray);
            if self
                .unbounded
                .iter()
                .any(|&i| self.primitives[i as usize].intersect(&r, ray.t_max).is_some())
            {
                return true;
            }
        }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::test_scenes::{analytic_soup, Rng};
    use crate::math::DVec3;

    fn scene_of(primitives: Vec<Primitive>, accel: AccelKind) -> Scene {
        let camera = Camera::look_at(DVec3::Z, DVec3::ZERO, DVec3::Y, 45.0, 4, 4).unwrap();
        let parts = SceneParts {
            width: 4,
            height: 4,
            camera,
            primitives,
            materials: vec![Material::default()],
            lights: Vec::new(),
            vertex_normals: Vec::new(),
        };
        Scene::new(parts, accel)
    }

    #[test]
    fn unbounded_planes_are_found_beside_every_structure() {
        let prims = analytic_soup(5, 360); // six planes among them
        let planes = prims.iter().filter(|p| !p.bounds().min.is_finite()).count();
        assert!(planes >= 5, "{planes}");
        let mut rng = Rng(11);
        let rays: Vec<Ray> = (0..2000)
            .map(|_| {
                let o = rng.vec(15.0);
                Ray::new(o, (rng.vec(8.0) - o).normalize())
            })
            .collect();
        // Brute force over every primitive, planes included, with the scene-order tie rule.
        let expected: Vec<Option<Hit>> = rays
            .iter()
            .map(|ray| {
                let r = PreparedRay::new(*ray);
                let mut best: Option<Hit> = None;
                for (i, p) in prims.iter().enumerate() {
                    if let Some((t, b1, b2)) = p.intersect(&r, best.map_or(ray.t_max, |b| b.t)) {
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
            })
            .collect();
        let plane_hits = expected
            .iter()
            .filter(|h| h.is_some_and(|h| !prims[h.prim as usize].bounds().min.is_finite()))
            .count();
        assert!(plane_hits > 100, "{plane_hits}");
        for kind in AccelKind::ALL {
            let scene = scene_of(prims.clone(), kind);
            for (ray, want) in rays.iter().zip(&expected) {
                assert_eq!(scene.closest_hit(ray), *want, "{kind:?}");
                assert_eq!(scene.occluded(ray), want.is_some(), "{kind:?}");
            }
        }
    }
}
