//! The primitives a scene holds: what the acceleration structures bound and intersect,
//! and what turns a hit into a surface point for shading. A slice of primitives is a
//! [`PrimitiveSet`] a structure can be built over.

use std::sync::Arc;

use super::analytic::{Analytic, Sphere};
use super::instance::Instance;
use super::mesh::MeshShape;
use crate::aabb::Aabb;
use crate::accel::PrimitiveSet;
use crate::hit::{Hit, SurfacePoint};
use crate::math::{gamma, Affine3A, Vec3A};
use crate::ray::PreparedRay;
use crate::shape::{sphere, texcoord, triangle};
use crate::spawn;
use glam::Vec2;

#[derive(Clone, Debug)]
pub enum Shape {
    /// World-space vertices; `normals` indexes the scene's per-vertex normals
    /// (`trinormal`), `None` for the flat geometric normal (`tri`).
    Triangle { p: [Vec3A; 3], normals: Option<u32> },
    /// Boxed like `Analytic`: three transforms and a box, four times the size of a
    /// triangle, which every primitive would otherwise carry (and bring into the cache).
    Sphere(Box<Sphere>),
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
    /// The light this primitive is the surface of (index into the scene's lights), if it
    /// emits: a surface point on it knows which light it is.
    pub light: Option<u32>,
}

// Every triangle of a scene is one of these, and shading each hit reads one: keep the
// large shapes boxed.
const _: () = assert!(std::mem::size_of::<Primitive>() <= 80);

impl Primitive {
    /// A primitive that does not emit light.
    pub fn new(shape: Shape, material: u32) -> Primitive {
        Primitive {
            shape,
            material,
            light: None,
        }
    }

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
        use crate::shape::tangents::uv_tangents;
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
            Shape::Mesh(m) => return m.mesh.surface_point(&hit.inside()),
            Shape::Instance(i) => return i.surface_point(&hit.inside(), origin, dir),
            _ => {}
        }
        let barycentric = Vec2::new(hit.b1, hit.b2);
        // (point, its error bound, geometric normal, shading normal, uv); the geometric
        // normal is turned to the shading normal's side (only interpolated normals can
        // differ from it: the other shapes give the same vector twice, and skip the test).
        let (point, error, ng, normal, uv) = match &self.shape {
            Shape::Triangle { p, normals } => {
                let (point, error) = spawn::barycentric_point(*p, hit.b1, hit.b2);
                let ng = triangle::geometric_normal(p[0], p[1], p[2]);
                let (ng, normal) = match normals {
                    None => (ng, ng),
                    Some(i) => {
                        let n = &vertex_normals[*i as usize];
                        let b0 = 1.0 - hit.b1 - hit.b2;
                        let normal = (n[0] * b0 + n[1] * hit.b1 + n[2] * hit.b2).normalize();
                        (if ng.dot(normal) < 0.0 { -ng } else { ng }, normal)
                    }
                };
                (point, error, ng, normal, barycentric)
            }
            Shape::Sphere(s) => {
                // The object-space hit point is the object-space normal of the unit
                // sphere. Projected back onto the sphere, its error no longer depends on
                // the error of t (PBR 4th ed. §6.8.5).
                let o = s.world_to_object.transform_point3a(origin);
                let d = s.world_to_object.transform_vector3a(dir);
                let p = (o + d * hit.t).normalize();
                let (point, error) = spawn::transform_point(&s.object_to_world, p, p.abs() * gamma(5));
                let n = (s.normal_to_world * p).normalize();
                (point, error, n, n, texcoord::sphere(p))
            }
            Shape::Analytic(a) => {
                let o = a.world_to_object.transform_point3a(origin);
                let d = a.world_to_object.transform_vector3a(dir);
                let p = o + d * hit.t;
                let n = a.kind.normal(p);
                let normal = (a.normal_to_world * n).normalize();
                // These shapes find t in f64 and round it once: the point is off by the
                // rounding of t and of the ray's trip through the transform, a few ulps
                // of the coordinates involved; 16 of them is a generous bound.
                let point = origin + dir * hit.t;
                let error = (origin.abs() + (dir * hit.t).abs()) * gamma(16);
                (point, error, normal, normal, a.kind.uv(p, n))
            }
            Shape::Mesh(_) | Shape::Instance(_) => unreachable!("handled above"),
        };
        SurfacePoint {
            point,
            error,
            geometric_normal: ng,
            normal,
            uv,
            material: self.material,
            light: self.light,
        }
    }
}

impl PrimitiveSet for [Primitive] {
    #[inline(always)]
    fn count(&self) -> usize {
        self.len()
    }

    fn bounds(&self, i: u32) -> Aabb {
        self[i as usize].bounds()
    }

    fn triangle(&self, i: u32) -> Option<[Vec3A; 3]> {
        self[i as usize].triangle()
    }

    #[inline(always)]
    fn sphere(&self, i: u32) -> Option<&Affine3A> {
        match &self[i as usize].shape {
            Shape::Sphere(s) => Some(&s.world_to_object),
            _ => None,
        }
    }

    #[inline(always)]
    fn intersect(&self, i: u32, ray: &PreparedRay, t_max: f32) -> Option<Hit> {
        self[i as usize].intersect(i, ray, t_max)
    }

    #[inline(always)]
    fn occludes(&self, i: u32, ray: &PreparedRay, t_max: f32) -> bool {
        self[i as usize].occludes(ray, t_max)
    }

    #[inline(always)]
    fn prefetch(&self, i: u32) {
        if let Some(p) = self.get(i as usize) {
            crate::accel::prefetch_value(p);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::analytic::AnalyticKind;
    use super::*;
    use crate::geometry::test_scenes::Rng;
    use crate::ray::Ray;

    #[test]
    fn ellipsoid_bounds_are_exact_and_normals_use_the_inverse_transpose() {
        // Unit sphere scaled by (2, 1, 1) then rotated 90° about z: extends ±1 in x, ±2 in y.
        let m = Affine3A::from_rotation_z(std::f32::consts::FRAC_PI_2)
            * Affine3A::from_scale(glam::Vec3::new(2.0, 1.0, 1.0));
        let s = Sphere::new(m);
        assert!((s.bounds.max - Vec3A::new(1.0, 2.0, 1.0)).abs().max_element() < 1e-5);
        let prim = Primitive::new(Shape::Sphere(Box::new(s)), 0);
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
        let prim = Primitive::new(
            Shape::Analytic(Box::new(Analytic::new(
                m,
                AnalyticKind::Cylinder {
                    radius: 1.0,
                    zmin: 0.0,
                    zmax: 2.0,
                },
            ))),
            0,
        );
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

    /// Aims 20,000 rays from `distance` away at points within `spread` of `centre`; from
    /// each hit, a ray leaves `lift` (a sine) off the tangent plane, outward or (with
    /// `both_sides`) either way. Returns (hits, rays from the bare hit point that find
    /// `prim` again, spawned rays that do), all with ε = 0.
    fn refound(
        prim: &Primitive,
        centre: Vec3A,
        distance: f32,
        spread: f32,
        lift: f32,
        both_sides: bool,
    ) -> (u32, u32, u32) {
        let mut rng = Rng(7);
        let mut next = || rng.range(-0.5, 0.5);
        let finds = |origin: Vec3A, dir: Vec3A| {
            let r = Ray::segment(origin, dir, 0.0, f32::INFINITY);
            prim.intersect(0, &PreparedRay::new(r), f32::INFINITY).is_some()
        };
        let (mut tried, mut bare, mut spawned) = (0, 0, 0);
        for _ in 0..20_000 {
            let origin = centre + Vec3A::new(next(), next(), next()).normalize() * distance;
            let dir = (centre + Vec3A::new(next(), next(), next()) * spread - origin).normalize();
            let ray = Ray::segment(origin, dir, 1e-4, f32::INFINITY);
            let Some(hit) = prim.intersect(0, &PreparedRay::new(ray), f32::INFINITY) else {
                continue;
            };
            let sp = prim.surface_point(&hit, origin, dir, &[]);
            let ng = sp.geometric_normal;
            let side = if both_sides && next() < 0.0 { -ng } else { ng };
            let tangent = ng.cross(Vec3A::new(next(), next(), next())).normalize();
            let out = (tangent + side * lift).normalize();
            tried += 1;
            bare += finds(sp.point, out) as u32;
            spawned += finds(sp.spawn(out).origin, out) as u32;
        }
        (tried, bare, spawned)
    }

    /// A small ellipsoid far from the origin, hit from all sides; rays leave almost along
    /// the tangent plane, outward. Spawned as `SurfacePoint::spawn` does it, none finds
    /// the ellipsoid again even with no ε at all; started at the bare hit point, many do
    /// (so the test can fail).
    #[test]
    fn rays_leaving_a_sphere_do_not_find_it_again() {
        let m = Affine3A::from_translation(glam::Vec3::new(1000.0, -700.0, 300.0))
            * Affine3A::from_rotation_y(0.3)
            * Affine3A::from_scale(glam::Vec3::new(3.0, 1.5, 2.0));
        let prim = Primitive::new(Shape::Sphere(Box::new(Sphere::new(m))), 0);
        let (tried, bare, spawned) = refound(&prim, Vec3A::new(1000.0, -700.0, 300.0), 40.0, 5.0, 1e-3, false);
        assert!(tried > 5_000, "{tried}");
        assert_eq!(spawned, 0, "of {tried}");
        assert!(bare > 50, "the test must be able to fail: {bare} of {tried}");
    }

    /// The same for a triangle far from the origin, left at grazing angles on both sides.
    #[test]
    fn rays_leaving_a_triangle_do_not_find_it_again() {
        let p = [
            Vec3A::new(-2000.0, 500.0, 1000.0),
            Vec3A::new(-1990.0, 503.0, 1001.0),
            Vec3A::new(-1996.0, 509.0, 995.0),
        ];
        let prim = Primitive::new(Shape::Triangle { p, normals: None }, 0);
        let (tried, bare, spawned) = refound(&prim, (p[0] + p[1] + p[2]) / 3.0, 30.0, 4.0, 1e-4, true);
        assert!(tried > 5_000, "{tried}");
        assert_eq!(spawned, 0, "of {tried}");
        assert!(bare > 50, "the test must be able to fail: {bare} of {tried}");
    }

    #[test]
    fn barycentric_points_lie_on_the_plane_within_their_bound() {
        let p = [
            Vec3A::new(1e3, 2e3, -5e2),
            Vec3A::new(1e3 + 1.0, 2e3 + 0.3, -5e2 + 0.1),
            Vec3A::new(1e3 - 0.2, 2e3 + 0.9, -5e2 + 0.7),
        ];
        let n = (p[1] - p[0]).cross(p[2] - p[0]).normalize();
        let mut rng = Rng(3);
        let mut next = || rng.next();
        for _ in 0..10_000 {
            let (b1, b2) = (next() * 0.5, next() * 0.5);
            let (q, e) = spawn::barycentric_point(p, b1, b2);
            // Distance from the plane, in f64 from the exact vertices.
            let dq = q.as_dvec3() - p[0].as_dvec3();
            let dn = n.as_dvec3();
            let along = dq.dot(dn).abs();
            assert!(
                along <= n.abs().dot(e) as f64 * 1.01 + 1e-9,
                "{along} > {}",
                n.abs().dot(e)
            );
        }
    }
}
