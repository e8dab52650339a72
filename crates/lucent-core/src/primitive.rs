//! The primitives a scene holds: what the acceleration structures bound and intersect,
//! and what turns a hit into a surface point for shading.

use std::sync::Arc;

use crate::aabb::Aabb;
use crate::hit::{Hit, SurfacePoint};
use crate::instance::Instance;
use crate::math::{Affine3A, Mat3A, Vec3A};
use crate::mesh::MeshShape;
use crate::ray::PreparedRay;
use crate::shape::{cone, cuboid, cylinder, disk, plane, quadric, sphere, texcoord, triangle};
use glam::Vec2;

/// A sphere or ellipsoid: the unit sphere mapped by an affine object-to-world transform.
#[derive(Clone, Copy, Debug)]
pub struct Sphere {
    pub world_to_object: Affine3A,
    /// Inverse transpose of the object-to-world linear part: carries normals to world.
    pub normal_to_world: Mat3A,
    pub bounds: Aabb,
}

impl Sphere {
    /// `object_to_world` maps the unit sphere at the origin onto the sphere.
    pub fn new(object_to_world: Affine3A) -> Sphere {
        let world_to_object = object_to_world.inverse();
        // Exact bounds of an affinely mapped unit sphere: along world axis i the half
        // extent is the length of row i of the linear part.
        let m = object_to_world.matrix3;
        let rows = m.transpose();
        let half = Vec3A::new(rows.x_axis.length(), rows.y_axis.length(), rows.z_axis.length());
        let c = object_to_world.translation;
        Sphere {
            world_to_object,
            normal_to_world: world_to_object.matrix3.transpose(),
            bounds: Aabb::new(c - half, c + half),
        }
    }
}

/// A shape of the geometry extensions in its object space (see `crate::shape`).
#[derive(Clone, Copy, Debug)]
pub enum AnalyticKind {
    /// The plane through `point` with normal `normal`: unbounded, so it is kept out of
    /// the acceleration structures and tested on its own.
    Plane {
        point: Vec3A,
        normal: Vec3A,
    },
    Cuboid(Aabb),
    Cylinder {
        radius: f32,
        zmin: f32,
        zmax: f32,
    },
    Disk {
        radius: f32,
    },
    Cone {
        radius: f32,
        height: f32,
    },
    Quadric {
        coefficients: quadric::Coefficients,
        clip: Aabb,
    },
}

impl AnalyticKind {
    /// Bounds in object space; `None` for the unbounded plane.
    fn object_bounds(&self) -> Option<Aabb> {
        let z = |lo: f32, hi: f32, r: f32| Aabb::new(Vec3A::new(-r, -r, lo), Vec3A::new(r, r, hi));
        match *self {
            AnalyticKind::Plane { .. } => None,
            AnalyticKind::Cuboid(b) => Some(b),
            AnalyticKind::Cylinder { radius, zmin, zmax } => Some(z(zmin, zmax, radius)),
            AnalyticKind::Disk { radius } => Some(z(0.0, 0.0, radius)),
            AnalyticKind::Cone { radius, height } => Some(z(0.0, height, radius)),
            AnalyticKind::Quadric { clip, .. } => Some(clip),
        }
    }

    fn intersect(&self, o: Vec3A, d: Vec3A, t_min: f32, t_max: f32) -> Option<f32> {
        match self {
            AnalyticKind::Plane { point, normal } => plane::intersect_plane(o, d, *point, *normal, t_min, t_max),
            AnalyticKind::Cuboid(b) => cuboid::intersect(b, o, d, t_min, t_max),
            AnalyticKind::Cylinder { radius, zmin, zmax } => {
                cylinder::intersect(*radius, *zmin, *zmax, o, d, t_min, t_max)
            }
            AnalyticKind::Disk { radius } => disk::intersect(*radius, o, d, t_min, t_max),
            AnalyticKind::Cone { radius, height } => cone::intersect(*radius, *height, o, d, t_min, t_max),
            AnalyticKind::Quadric { coefficients, clip } => quadric::intersect(coefficients, clip, o, d, t_min, t_max),
        }
    }

    /// Texture coordinates at an object-space surface point with object normal `n`.
    fn uv(&self, p: Vec3A, n: Vec3A) -> Vec2 {
        match self {
            AnalyticKind::Plane { point, normal } => texcoord::plane(*point, *normal, p),
            AnalyticKind::Cuboid(b) => texcoord::cuboid(b, n, p),
            AnalyticKind::Cylinder { zmin, zmax, .. } => texcoord::cylinder(p, *zmin, *zmax),
            AnalyticKind::Disk { radius } => texcoord::disk(p, *radius),
            AnalyticKind::Cone { height, .. } => texcoord::cone(p, *height),
            AnalyticKind::Quadric { clip, .. } => texcoord::quadric(clip, p),
        }
    }

    /// Object-space normal (not normalised) at a surface point.
    fn normal(&self, p: Vec3A) -> Vec3A {
        match self {
            AnalyticKind::Plane { normal, .. } => *normal,
            AnalyticKind::Cuboid(b) => cuboid::normal(b, p),
            AnalyticKind::Cylinder { .. } => cylinder::normal(p),
            AnalyticKind::Disk { .. } => Vec3A::Z,
            AnalyticKind::Cone { radius, height } => cone::normal(*radius, *height, p),
            AnalyticKind::Quadric { coefficients, .. } => quadric::normal(coefficients, p),
        }
    }
}

/// An analytic shape placed by an affine object-to-world transform. Rays go into object
/// space unnormalised, so `t` is the same in both spaces; normals come back by the
/// inverse transpose.
#[derive(Clone, Copy, Debug)]
pub struct Analytic {
    pub world_to_object: Affine3A,
    pub normal_to_world: Mat3A,
    /// World bounds; infinite for the plane.
    pub bounds: Aabb,
    pub kind: AnalyticKind,
}

impl Analytic {
    pub fn new(object_to_world: Affine3A, kind: AnalyticKind) -> Analytic {
        let world_to_object = object_to_world.inverse();
        let bounds = match kind.object_bounds() {
            Some(b) => b.transformed(&object_to_world),
            None => Aabb {
                min: Vec3A::NEG_INFINITY,
                max: Vec3A::INFINITY,
            },
        };
        Analytic {
            world_to_object,
            normal_to_world: world_to_object.matrix3.transpose(),
            bounds,
            kind,
        }
    }
}

#[derive(Clone, Debug)]
pub enum Shape {
    /// World-space vertices; `normals` indexes the scene's per-vertex normals
    /// (`trinormal`), `None` for the flat geometric normal (`tri`).
    Triangle {
        p: [Vec3A; 3],
        normals: Option<u32>,
    },
    Sphere(Sphere),
    /// Boxed: it is much larger than a triangle, and triangles should not pay for it.
    Analytic(Box<Analytic>),
    /// A whole triangle mesh (with its own structure), possibly shared.
    Mesh(Arc<MeshShape>),
    /// An object placed by `instance`.
    Instance(Box<Instance>),
}

#[derive(Clone, Debug)]
pub struct Primitive {
    pub shape: Shape,
    pub material: u32,
}

impl Primitive {
    pub fn bounds(&self) -> Aabb {
        match &self.shape {
            Shape::Triangle { p, .. } => Aabb::from_points(p),
            Shape::Sphere(s) => s.bounds,
            Shape::Analytic(a) => a.bounds,
            Shape::Mesh(m) => m.bounds(),
            Shape::Instance(i) => i.bounds,
        }
    }

    /// How many simple primitives this one stands for (see
    /// [`crate::geometry::Geometry::shown_primitive_count`]).
    pub fn shown_count(&self) -> u64 {
        match &self.shape {
            Shape::Mesh(m) => m.mesh.indices.len() as u64,
            Shape::Instance(i) => i.object.shown_primitive_count(),
            _ => 1,
        }
    }

    /// The corners, if this is a plain triangle.
    #[inline]
    pub fn triangle(&self) -> Option<[Vec3A; 3]> {
        match &self.shape {
            Shape::Triangle { p, .. } => Some(*p),
            _ => None,
        }
    }

    /// Whether anything of this primitive lies in `(ray.t_min, t_max]` (shadow rays:
    /// any hit will do, which is cheaper than the closest for meshes and instances).
    #[inline(always)]
    pub fn occludes(&self, ray: &PreparedRay, t_max: f32) -> bool {
        match &self.shape {
            Shape::Mesh(m) => m.occludes(ray, t_max),
            Shape::Instance(i) => i.occludes(ray, t_max),
            _ => self.intersect(0, ray, t_max).is_some(),
        }
    }

    /// The hit of `ray` with this primitive in `(t_min, t_max]`, reported as primitive
    /// `index` (barycentrics are 0 for shapes other than triangles).
    #[inline(always)]
    pub fn intersect(&self, index: u32, ray: &PreparedRay, t_max: f32) -> Option<Hit> {
        match &self.shape {
            Shape::Triangle { p, .. } => {
                triangle::intersect(ray, p[0], p[1], p[2], t_max).map(|h| Hit::new(h.t, index, h.b1, h.b2))
            }
            Shape::Sphere(s) => {
                let o = s.world_to_object.transform_point3a(ray.ray.origin);
                let d = s.world_to_object.transform_vector3a(ray.ray.dir);
                sphere::intersect_unit_geometric(o, d, ray.ray.t_min, t_max).map(|t| Hit::new(t, index, 0.0, 0.0))
            }
            Shape::Analytic(a) => {
                let o = a.world_to_object.transform_point3a(ray.ray.origin);
                let d = a.world_to_object.transform_vector3a(ray.ray.dir);
                a.kind
                    .intersect(o, d, ray.ray.t_min, t_max)
                    .map(|t| Hit::new(t, index, 0.0, 0.0))
            }
            Shape::Mesh(m) => m.intersect(ray, t_max).map(|h| h.within(index)),
            Shape::Instance(i) => i.intersect(ray, t_max).map(|h| h.within(index)),
        }
    }

    /// World-space `∂p/∂u` and `∂p/∂v` at a hit of `origin + t·dir` (for bump mapping):
    /// exact for triangles, by differences of the texture-coordinate formulas for the
    /// other shapes.
    pub fn tangents(&self, hit: &Hit, origin: Vec3A, dir: Vec3A) -> (Vec3A, Vec3A) {
        use crate::shape::parametric::uv_tangents;
        let object_point = |w2o: &Affine3A| w2o.transform_point3a(origin) + w2o.transform_vector3a(dir) * hit.t;
        match &self.shape {
            Shape::Triangle { p, .. } => (p[1] - p[0], p[2] - p[0]),
            Shape::Sphere(s) => {
                let p = object_point(&s.world_to_object).normalize();
                let (du, dv) = uv_tangents(p, p, |q| texcoord::sphere(q.normalize()));
                let m = s.world_to_object.matrix3.inverse();
                (m * du, m * dv)
            }
            Shape::Analytic(a) => {
                let p = object_point(&a.world_to_object);
                let n = a.kind.normal(p).normalize();
                let (du, dv) = uv_tangents(p, n, |q| a.kind.uv(q, n));
                let m = a.world_to_object.matrix3.inverse();
                (m * du, m * dv)
            }
            Shape::Mesh(m) => m.mesh.tangents(&hit.inside()),
            Shape::Instance(i) => i.tangents(&hit.inside(), origin, dir),
        }
    }

    /// Shading data at a hit of `origin + t·dir` on this primitive.
    pub fn surface_point(&self, hit: &Hit, origin: Vec3A, dir: Vec3A, vertex_normals: &[[Vec3A; 3]]) -> SurfacePoint {
        match &self.shape {
            Shape::Mesh(m) => return m.mesh.surface_point(&hit.inside(), origin, dir),
            Shape::Instance(i) => return i.surface_point(&hit.inside(), origin, dir),
            _ => {}
        }
        let point = origin + dir * hit.t;
        let barycentric = Vec2::new(hit.b1, hit.b2);
        let (normal, uv) = match &self.shape {
            Shape::Triangle { p, normals: None } => (triangle::geometric_normal(p[0], p[1], p[2]), barycentric),
            Shape::Triangle { normals: Some(i), .. } => {
                let n = &vertex_normals[*i as usize];
                let b0 = 1.0 - hit.b1 - hit.b2;
                ((n[0] * b0 + n[1] * hit.b1 + n[2] * hit.b2).normalize(), barycentric)
            }
            Shape::Sphere(s) => {
                // The object-space hit point is the object-space normal of the unit sphere.
                let o = s.world_to_object.transform_point3a(origin);
                let d = s.world_to_object.transform_vector3a(dir);
                let p = o + d * hit.t;
                ((s.normal_to_world * p).normalize(), texcoord::sphere(p.normalize()))
            }
            Shape::Analytic(a) => {
                let o = a.world_to_object.transform_point3a(origin);
                let d = a.world_to_object.transform_vector3a(dir);
                let p = o + d * hit.t;
                let n = a.kind.normal(p);
                ((a.normal_to_world * n).normalize(), a.kind.uv(p, n))
            }
            Shape::Mesh(_) | Shape::Instance(_) => unreachable!("handled above"),
        };
        SurfacePoint {
            point,
            normal,
            uv,
            material: self.material,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ray::Ray;

    #[test]
    fn ellipsoid_bounds_are_exact_and_normals_use_the_inverse_transpose() {
        // Unit sphere scaled by (2, 1, 1) then rotated 90° about z: extends ±1 in x, ±2 in y.
        let m = Affine3A::from_rotation_z(std::f32::consts::FRAC_PI_2)
            * Affine3A::from_scale(glam::Vec3::new(2.0, 1.0, 1.0));
        let s = Sphere::new(m);
        assert!((s.bounds.max - Vec3A::new(1.0, 2.0, 1.0)).abs().max_element() < 1e-5);
        let prim = Primitive {
            shape: Shape::Sphere(s),
            material: 0,
        };
        // A ray down the z axis at (x=0.5, y=0) hits the ellipsoid x² + (y/2)² + z² = 1 at z = sqrt(0.75).
        let ray = Ray::segment(Vec3A::new(0.5, 0.0, 5.0), -Vec3A::Z, 1e-4, f32::INFINITY);
        let t = prim.intersect(0, &PreparedRay::new(ray), f32::INFINITY).unwrap().t;
        assert!((t - (5.0 - 0.75f32.sqrt())).abs() < 1e-5);
        let hit = Hit::new(t, 0, 0.0, 0.0);
        let sp = prim.surface_point(&hit, ray.origin, ray.dir, &[]);
        // Gradient of x² + y²/4 + z² is (2x, y/2, 2z) ∝ (x, y/4, z).
        let expect = Vec3A::new(0.5, 0.0, 0.75f32.sqrt()).normalize();
        assert!((sp.normal - expect).length() < 1e-5, "{}", sp.normal);
    }

    #[test]
    fn analytic_shapes_shade_in_object_space() {
        // A cylinder of radius 1, z in [0, 2], turned by R_x(−90°) (object z → world +y,
        // object y → world −z) and moved to x = 5. A ray along −z at (5, 1.5, 10) meets it
        // at world (5, 1.5, 1) = object (0, −1, 1.5): longitude 3/4, v = 1.5 / 2, and the
        // object normal (0, −1, 0) comes back as world +z.
        let m = Affine3A::from_translation(glam::Vec3::new(5.0, 0.0, 0.0))
            * Affine3A::from_rotation_x(-std::f32::consts::FRAC_PI_2);
        let prim = Primitive {
            shape: Shape::Analytic(Box::new(Analytic::new(
                m,
                AnalyticKind::Cylinder {
                    radius: 1.0,
                    zmin: 0.0,
                    zmax: 2.0,
                },
            ))),
            material: 0,
        };
        // World bounds: x 4..6, y 0..2, z −1..1, widened by a few units in the last place.
        let b = prim.bounds();
        let (lo, hi) = (Vec3A::new(4.0, 0.0, -1.0), Vec3A::new(6.0, 2.0, 1.0));
        assert!(b.min.cmple(lo).all() && b.max.cmpge(hi).all());
        assert!((b.min - lo).length() < 1e-4 && (b.max - hi).length() < 1e-4);
        let ray = Ray::segment(Vec3A::new(5.0, 1.5, 10.0), -Vec3A::Z, 1e-4, f32::INFINITY);
        let t = prim.intersect(0, &PreparedRay::new(ray), f32::INFINITY).unwrap().t;
        assert!((t - 9.0).abs() < 1e-5, "{t}");
        let hit = Hit::new(t, 0, 0.0, 0.0);
        let sp = prim.surface_point(&hit, ray.origin, ray.dir, &[]);
        assert!((sp.normal - Vec3A::Z).length() < 1e-5, "{}", sp.normal);
        assert!((sp.uv - glam::Vec2::new(0.75, 0.75)).length() < 1e-5, "{}", sp.uv);
    }
}
