//! Scene commands: `tri i j k` and `trinormal i j k` — triangles from the vertex piles.
//!
//! The renderer uses the watertight test of Woop, Benthin & Wald (2013): the ray is
//! sheared onto the +z axis, the triangle is projected, and the three edge functions
//! `U, V, W` (2-D Cramer determinants) are the unnormalised barycentric coordinates.
//! Edges count as inside (`U, V, W ≥ 0` or all `≤ 0`), and because each edge function is
//! computed the same way for both triangles that share the edge, a ray can never slip
//! between them. `intersect_cramer` is the textbook form (Cramer's rule on the 3 × 3
//! system `o + t d = p0 + b1 (p1 − p0) + b2 (p2 − p0)`, i.e. Möller–Trumbore); it is kept
//! as an independent reference that the tests compare the watertight test against.

use crate::math::Vec3A;
use crate::ray::PreparedRay;

/// A hit on a triangle: ray parameter and the barycentric weights of `p1` and `p2`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleHit {
    pub t: f32,
    pub b1: f32,
    pub b2: f32,
}

/// Watertight ray–triangle test. Both sides of the triangle are hit. `t` must lie in
/// `(t_min, t_max]`.
#[inline(always)]
pub fn intersect(r: &PreparedRay, p0: Vec3A, p1: Vec3A, p2: Vec3A, t_max: f32) -> Option<TriangleHit> {
    let o = r.ray.origin;
    let a = p0 - o;
    let b = p1 - o;
    let c = p2 - o;
    let (kx, ky, kz) = (r.kx, r.ky, r.kz);
    let ax = a[kx] - r.sx * a[kz];
    let ay = a[ky] - r.sy * a[kz];
    let bx = b[kx] - r.sx * b[kz];
    let by = b[ky] - r.sy * b[kz];
    let cx = c[kx] - r.sx * c[kz];
    let cy = c[ky] - r.sy * c[kz];
    let mut u = cx * by - cy * bx;
    let mut v = ax * cy - ay * cx;
    let mut w = bx * ay - by * ax;
    // On an edge the f32 products can round to exactly zero with the wrong sign
    // information; redo those in f64 (the paper's fallback).
    if u == 0.0 || v == 0.0 || w == 0.0 {
        u = (cx as f64 * by as f64 - cy as f64 * bx as f64) as f32;
        v = (ax as f64 * cy as f64 - ay as f64 * cx as f64) as f32;
        w = (bx as f64 * ay as f64 - by as f64 * ax as f64) as f32;
    }
    if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
        return None;
    }
    let det = u + v + w;
    if det == 0.0 {
        return None;
    }
    let az = r.sz * a[kz];
    let bz = r.sz * b[kz];
    let cz = r.sz * c[kz];
    let t_scaled = u * az + v * bz + w * cz;
    let inv_det = 1.0 / det;
    let t = t_scaled * inv_det;
    if !(t > r.ray.t_min && t <= t_max) {
        return None;
    }
    Some(TriangleHit {
        t,
        b1: v * inv_det,
        b2: w * inv_det,
    })
}

/// The textbook test: Cramer's rule on `[-d, e1, e2] (t, b1, b2)ᵀ = o − p0`
/// (Möller & Trumbore 1997). Edges inclusive. Not watertight; used as a reference.
pub fn intersect_cramer(
    o: Vec3A,
    d: Vec3A,
    p0: Vec3A,
    p1: Vec3A,
    p2: Vec3A,
    t_min: f32,
    t_max: f32,
) -> Option<TriangleHit> {
    let e1 = p1 - p0;
    let e2 = p2 - p0;
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det == 0.0 {
        return None;
    }
    let inv = 1.0 / det;
    let s = o - p0;
    let b1 = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&b1) {
        return None;
    }
    let q = s.cross(e1);
    let b2 = d.dot(q) * inv;
    if b2 < 0.0 || b1 + b2 > 1.0 {
        return None;
    }
    let t = e2.dot(q) * inv;
    (t > t_min && t <= t_max).then_some(TriangleHit { t, b1, b2 })
}

/// Unit geometric normal from the winding: `normalize((p1 − p0) × (p2 − p0))`.
pub fn geometric_normal(p0: Vec3A, p1: Vec3A, p2: Vec3A) -> Vec3A {
    (p1 - p0).cross(p2 - p0).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ray::Ray;

    fn hit(o: Vec3A, d: Vec3A, p: [Vec3A; 3]) -> Option<TriangleHit> {
        let r = PreparedRay::new(Ray::segment(o, d, 1e-4, f32::INFINITY));
        intersect(&r, p[0], p[1], p[2], f32::INFINITY)
    }

    const TRI: [Vec3A; 3] = [
        Vec3A::new(0.0, 0.0, 0.0),
        Vec3A::new(1.0, 0.0, 0.0),
        Vec3A::new(0.0, 1.0, 0.0),
    ];

    #[test]
    fn barycentric_coordinates_of_an_interior_point() {
        let h = hit(Vec3A::new(0.25, 0.5, 2.0), -Vec3A::Z, TRI).unwrap();
        assert!((h.t - 2.0).abs() < 1e-6);
        assert!((h.b1 - 0.25).abs() < 1e-6 && (h.b2 - 0.5).abs() < 1e-6);
        let c = intersect_cramer(
            Vec3A::new(0.25, 0.5, 2.0),
            -Vec3A::Z,
            TRI[0],
            TRI[1],
            TRI[2],
            1e-4,
            f32::INFINITY,
        )
        .unwrap();
        assert!((c.t - h.t).abs() < 1e-6 && (c.b1 - h.b1).abs() < 1e-6 && (c.b2 - h.b2).abs() < 1e-6);
    }

    #[test]
    fn edges_and_vertices_are_inside() {
        for p in [
            Vec3A::new(0.5, 0.0, 1.0),
            Vec3A::new(0.0, 0.5, 1.0),
            Vec3A::new(0.5, 0.5, 1.0),
            Vec3A::new(0.0, 0.0, 1.0),
            Vec3A::new(1.0, 0.0, 1.0),
        ] {
            assert!(hit(p, -Vec3A::Z, TRI).is_some(), "{p}");
            assert!(
                intersect_cramer(p, -Vec3A::Z, TRI[0], TRI[1], TRI[2], 1e-4, f32::INFINITY).is_some(),
                "{p}"
            );
        }
        assert!(hit(Vec3A::new(0.5001, 0.5001, 1.0), -Vec3A::Z, TRI).is_none());
        assert!(hit(Vec3A::new(-0.0001, 0.5, 1.0), -Vec3A::Z, TRI).is_none());
    }

    #[test]
    fn both_sides_are_hit_and_parallel_rays_miss() {
        assert!(hit(Vec3A::new(0.2, 0.2, -1.0), Vec3A::Z, TRI).is_some());
        assert!(hit(Vec3A::new(-1.0, 0.2, 0.0), Vec3A::X, TRI).is_none());
        assert!(hit(Vec3A::new(0.2, 0.2, 1.0), Vec3A::Z, TRI).is_none());
    }

    #[test]
    fn a_ray_leaving_the_surface_does_not_hit_it_again() {
        assert!(hit(Vec3A::new(0.2, 0.2, 0.0), Vec3A::new(0.3, 0.1, 1.0).normalize(), TRI).is_none());
    }

    #[test]
    fn no_ray_leaks_between_triangles_that_share_an_edge() {
        // A skewed quad split along its diagonal; rays aimed at points on and near the
        // shared edge, from odd directions, must hit one of the two triangles.
        let q = [
            Vec3A::new(-1.3, -0.7, 0.2),
            Vec3A::new(1.1, -0.9, -0.1),
            Vec3A::new(0.9, 1.2, 0.3),
            Vec3A::new(-1.0, 1.0, -0.2),
        ];
        let mut seed = 12345u32;
        let mut rnd = || {
            seed = seed.wrapping_mul(1664525).wrapping_add(1013904223);
            (seed >> 8) as f32 / (1u32 << 24) as f32
        };
        let mut misses = 0;
        for _ in 0..200_000 {
            let s = rnd();
            let target = q[0] + (q[2] - q[0]) * s;
            let origin = Vec3A::new(rnd() * 4.0 - 2.0, rnd() * 4.0 - 2.0, 3.0 + rnd() * 2.0);
            let d = (target - origin).normalize();
            let a = hit(origin, d, [q[0], q[1], q[2]]);
            let b = hit(origin, d, [q[0], q[2], q[3]]);
            if a.is_none() && b.is_none() {
                misses += 1;
            }
        }
        assert_eq!(misses, 0);
    }

    #[test]
    fn watertight_and_cramer_agree() {
        let mut seed = 777u32;
        let mut rnd = || {
            seed = seed.wrapping_mul(1664525).wrapping_add(1013904223);
            (seed >> 8) as f32 / (1u32 << 24) as f32 * 2.0 - 1.0
        };
        let mut both = 0;
        for _ in 0..50_000 {
            let p = [
                Vec3A::new(rnd(), rnd(), rnd()),
                Vec3A::new(rnd(), rnd(), rnd()),
                Vec3A::new(rnd(), rnd(), rnd()),
            ];
            let o = Vec3A::new(rnd(), rnd(), rnd()) * 3.0;
            let d = (Vec3A::new(rnd(), rnd(), rnd()) * 0.5 - o).normalize();
            let w = hit(o, d, p);
            let c = intersect_cramer(o, d, p[0], p[1], p[2], 1e-4, f32::INFINITY);
            match (w, c) {
                (Some(w), Some(c)) => {
                    both += 1;
                    assert!((w.t - c.t).abs() < 1e-3 * w.t.max(1.0));
                    assert!((w.b1 - c.b1).abs() < 1e-3 && (w.b2 - c.b2).abs() < 1e-3);
                }
                (None, None) => {}
                // They may disagree only within rounding of an edge.
                (Some(h), None) | (None, Some(h)) => {
                    let b0 = 1.0 - h.b1 - h.b2;
                    assert!(b0.abs().min(h.b1.abs()).min(h.b2.abs()) < 1e-4, "{h:?}");
                }
            }
        }
        assert!(both > 1000);
    }
}
