//! Random and degenerate primitive soups shared by the tests of the structures and the
//! scene.

use super::analytic::Sphere;
use super::primitive::{Primitive, Shape};
use crate::math::{Affine3A, Vec3, Vec3A};
pub use crate::test_rng::Rng;

pub fn soup(seed: u64, n: usize) -> Vec<Primitive> {
    let mut rng = Rng(seed);
    (0..n)
        .map(|i| {
            let c = rng.vec(10.0);
            let shape = if i % 5 == 0 {
                let m = Affine3A::from_translation(c.into())
                    * Affine3A::from_scale(Vec3::new(rng.range(0.1, 1.0), rng.range(0.1, 1.0), rng.range(0.1, 1.0)));
                Shape::Sphere(Box::new(Sphere::new(m)))
            } else {
                Shape::Triangle {
                    p: [c + rng.vec(1.5), c + rng.vec(1.5), c + rng.vec(1.5)],
                    normals: None,
                }
            };
            Primitive::new(shape, 0)
        })
        .collect()
}

/// Spheres and ellipsoids alone (rotated, scaled, overlapping), so that the BVH's leaves
/// hold several and the packets' sphere-against-all-rays test runs on most of the rays.
pub fn sphere_soup(seed: u64, n: usize) -> Vec<Primitive> {
    let mut rng = Rng(seed);
    (0..n)
        .map(|_| {
            let m = Affine3A::from_translation(rng.vec(10.0).into())
                * Affine3A::from_axis_angle(rng.vec(1.0).normalize_or(Vec3A::X).into(), rng.range(0.0, 6.3))
                * Affine3A::from_scale(Vec3::new(rng.range(0.1, 1.5), rng.range(0.1, 1.5), rng.range(0.1, 1.5)));
            Primitive::new(Shape::Sphere(Box::new(Sphere::new(m))), 0)
        })
        .collect()
}

/// Boxes, cylinders, disks, cones and quadrics under random affine transforms, and a
/// few unbounded planes (which every structure leaves to the scene).
pub fn analytic_soup(seed: u64, n: usize) -> Vec<Primitive> {
    use super::analytic::{Analytic, AnalyticKind};
    use crate::aabb::Aabb;
    let mut rng = Rng(seed);
    (0..n)
        .map(|i| {
            let kind = match i % 6 {
                0 => AnalyticKind::Cuboid(Aabb::new(rng.vec(1.0), rng.vec(1.0))),
                1 => AnalyticKind::Cylinder {
                    radius: rng.range(0.2, 1.0),
                    zmin: rng.range(-1.0, 0.0),
                    zmax: rng.range(0.1, 1.0),
                },
                2 => AnalyticKind::Disk {
                    radius: rng.range(0.2, 1.0),
                },
                3 => AnalyticKind::Cone {
                    radius: rng.range(0.2, 1.0),
                    height: rng.range(-1.5, 1.5),
                },
                4 => AnalyticKind::Quadric {
                    // x² + y² − z² − r² (a hyperboloid) clipped to a box.
                    coefficients: [1.0, 1.0, -1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -rng.range(0.1, 0.5)],
                    clip: Aabb::new(Vec3A::splat(-1.0), Vec3A::splat(1.0)),
                },
                _ if i % 60 == 5 => AnalyticKind::Plane {
                    point: rng.vec(10.0),
                    normal: rng.vec(1.0),
                },
                _ => AnalyticKind::Disk { radius: 0.5 },
            };
            let m = Affine3A::from_translation(rng.vec(10.0).into())
                * Affine3A::from_axis_angle(rng.vec(1.0).normalize().into(), rng.range(0.0, 6.0))
                * Affine3A::from_scale(Vec3::new(rng.range(0.3, 2.0), rng.range(0.3, 2.0), rng.range(0.3, 2.0)));
            Primitive::new(Shape::Analytic(Box::new(Analytic::new(m, kind))), 0)
        })
        .collect()
}

/// A regular grid of coplanar quads (two triangles each) in z = 0: every shared
/// edge is an opportunity for ties and leaks.
pub fn coplanar_grid(n: usize) -> Vec<Primitive> {
    let mut prims = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let p = |a: usize, b: usize| Vec3A::new(a as f32, b as f32, 0.0);
            prims.push(Primitive::new(
                Shape::Triangle {
                    p: [p(i, j), p(i + 1, j), p(i + 1, j + 1)],
                    normals: None,
                },
                0,
            ));
            prims.push(Primitive::new(
                Shape::Triangle {
                    p: [p(i, j), p(i + 1, j + 1), p(i, j + 1)],
                    normals: None,
                },
                0,
            ));
        }
    }
    prims
}
