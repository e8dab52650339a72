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

use crate::math::{gamma, Vec3A};
use crate::ray::PreparedRay;

/// A hit on a triangle: ray parameter and the barycentric weights of `p1` and `p2`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleHit {
    pub t: f32,
    pub b1: f32,
    pub b2: f32,
}

/// Watertight ray–triangle test. Both sides of the triangle are hit. `t` must lie in
/// `(t_min, t_max]` and, on a triangle [`checks_t_error`] picks, above [`t_error_bound`].
#[inline(always)]
pub fn intersect(r: &PreparedRay, p0: Vec3A, p1: Vec3A, p2: Vec3A, t_max: f32) -> Option<TriangleHit> {
    let o = r.ray.origin;
    let a = p0 - o;
    let b = p1 - o;
    let c = p2 - o;
    let (kx, ky, kz) = (r.kx.index(), r.ky.index(), r.kz.index());
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
    // The bound first: it is false for nearly every hit, and cheaper than the triangle's
    // area (a square root), which is then not needed.
    if t <= t_error_bound([ax, bx, cx], [ay, by, cy], [az, bz, cz], [u, v, w], inv_det) && checks_t_error(p0, p1, p2) {
        return None;
    }
    Some(TriangleHit {
        t,
        b1: v * inv_det,
        b2: w * inv_det,
    })
}

/// Which triangles have their hits checked against [`t_error_bound`]: those whose
/// extent (on their longest axis) cubed exceeds this times twice their area. That is
/// right-angled triangles from 4 units across, equilateral ones from 3.5, thin ones
/// sooner; a fine mesh's triangles, almost never.
///
/// A ray leaving a triangle starts past the rounding error of its hit point, which is
/// proportional to the point's coordinates; the error of the watertight test's `t` grows
/// with the triangle's size and with its thinness (the division by `det`, twice the
/// projected area). On a large triangle the second outgrows the first and the format's
/// ε: the CSE168 dragon's 2,000-unit floor at y = −5 is found again at t ≈ 10⁻⁴ by rays
/// that leave it upward. Rays spawned from random triangles (random planes and floors,
/// at 10⁻³ to 1 of sine to the plane) found theirs only on triangles this rule checks
/// (test `rays_leaving_a_triangle_never_find_it_again`). Checking every hit cost the
/// BVH's SIMD tests 5 % on camera rays of a fine mesh, where it never changes an answer;
/// instead the BVH hands the hits its SIMD tests accept on the triangles this rule picks
/// to this scalar test (see `accel::bvh::packet`), so every structure gives the same
/// answers as the list.
pub const T_CHECK_RATIO: f32 = 4.0;

/// Whether hits on this triangle are checked against [`t_error_bound`] (see
/// [`T_CHECK_RATIO`]).
#[inline(always)]
pub fn checks_t_error(p0: Vec3A, p1: Vec3A, p2: Vec3A) -> bool {
    let extent = (p0.max(p1).max(p2) - p0.min(p1).min(p2)).max_element();
    let twice_area = (p1 - p0).cross(p2 - p0).length();
    extent * extent * extent > T_CHECK_RATIO * twice_area
}

/// A bound on the rounding error of the watertight test's `t` (PBR 4th ed. §6.8.4, the
/// triangle's `δt`), from the sheared corners `x`, `y`, `z` (z already scaled by `sz`),
/// the edge functions `e` and `1/det`. A computed `t` at or below it may be a hit behind
/// the origin. Applied to the triangles [`checks_t_error`] picks, by this scalar test
/// only: the BVH's SIMD tests hand those triangles' hits to it.
#[inline(always)]
pub fn t_error_bound(x: [f32; 3], y: [f32; 3], z: [f32; 3], e: [f32; 3], inv_det: f32) -> f32 {
    let max_abs = |a: [f32; 3]| a[0].abs().max(a[1].abs()).max(a[2].abs());
    let (mx, my, mz, me) = (max_abs(x), max_abs(y), max_abs(z), max_abs(e));
    let dz = gamma(3) * mz;
    let dx = gamma(5) * (mx + mz);
    let dy = gamma(5) * (my + mz);
    let de = 2.0 * (gamma(2) * mx * my + dy * mx + dx * my);
    3.0 * (gamma(3) * me * mz + de * mz + dz * me) * inv_det.abs()
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

    /// Rays spawned from random points of random triangles `size` units across, in random
    /// directions whose sine to the plane is log-uniform in [`min_sin`, 1], from those
    /// triangles that [`checks_t_error`] says `checked`: how many find the triangle they
    /// leave although it lies behind them. `flat` puts the corners on the plane y = −5 (a
    /// floor: the point's error across the plane is then tiny, the error of `t` is not).
    fn false_hits(size: f32, flat: bool, checked: bool, min_sin: f32, n: usize, seed: u64) -> usize {
        use crate::spawn::{barycentric_point, offset_origin};
        use crate::test_rng::Rng;
        let mut rng = Rng(seed);
        let mut found = 0;
        for _ in 0..n {
            let corner = |rng: &mut Rng| {
                let c = rng.vec(size * 0.5);
                if flat {
                    Vec3A::new(c.x, -5.0, c.z)
                } else {
                    c
                }
            };
            let p = [corner(&mut rng), corner(&mut rng), corner(&mut rng)];
            let ng = (p[1] - p[0]).cross(p[2] - p[0]);
            if ng.length() < 1e-3 * size * size || checks_t_error(p[0], p[1], p[2]) != checked {
                continue; // a sliver (its normal mostly rounding), or not of the kind asked
            }
            let ng = ng.normalize();
            let (b1, b2) = (rng.next(), rng.next());
            let (b1, b2) = if b1 + b2 > 1.0 { (1.0 - b1, 1.0 - b2) } else { (b1, b2) };
            let (point, error) = barycentric_point(p, b1, b2);
            let sin = min_sin.powf(rng.next());
            let angle = rng.next() * std::f32::consts::TAU;
            let (t1, t2) = ng.any_orthonormal_pair();
            let along = t1 * angle.cos() + t2 * angle.sin();
            let side = if rng.next() < 0.5 { 1.0 } else { -1.0 };
            let d = (ng * (sin * side) + along * (1.0 - sin * sin).sqrt()).normalize();
            let r = PreparedRay::new(Ray::new(offset_origin(point, error, ng, d), d));
            // The distance to the corners' plane, exactly enough in f64: a sliver's
            // rounded normal can tilt the offset to the wrong side, and then the hit is
            // real (the spawn's error, not the test's).
            let f = |v: Vec3A| v.as_dvec3();
            let n = (f(p[1]) - f(p[0])).cross(f(p[2]) - f(p[0]));
            let behind = n.dot(f(p[0]) - f(r.ray.origin)) / n.dot(f(d)) <= 0.0;
            found += (behind && intersect(&r, p[0], p[1], p[2], f32::INFINITY).is_some()) as usize;
        }
        found
    }

    #[test]
    fn rays_leaving_a_triangle_never_find_it_again() {
        // Without the bound on the error of `t`, of 400,000 rays from checked triangles
        // (sine to the plane down to 10⁻³), 1, 2, 4 and 9 found the triangle they leave
        // at 8, 16, 64 and 1,024 units (random planes), and 13 and 744 at 64 and 1,024
        // units (floors). With it: none. From unchecked triangles, up to 4 units: none,
        // of 85,000 to 380,000 rays per kind.
        for size in [1.0, 4.0, 16.0, 1024.0] {
            for flat in [false, true] {
                for checked in [false, true] {
                    let found = false_hits(size, flat, checked, 1e-3, 40_000, 11 + size as u64);
                    assert_eq!(found, 0, "{size} units, flat: {flat}, checked: {checked}");
                }
            }
        }
    }

    #[test]
    fn a_ray_leaving_a_huge_triangle_does_not_find_it_again() {
        // The CSE168 dragon's floor: 2000 units across, at y = −5 (made by a rotation, so
        // its corners are off the plane by rounding). A shadow ray from a point of it,
        // 3·10⁻⁶ above, going up: the test's `t` has an error near 10⁻⁴ here, and without
        // the bound on it the floor was found again at t = 1.6·10⁻⁴.
        let tilt = (-90f64).to_radians().cos() as f32;
        let corner = |x: f32, y: f32| Vec3A::new(1000.0 * x, -5.0 + 1000.0 * y * tilt, -1000.0 * y);
        let floor = [corner(-1.0, 1.0), corner(1.0, -1.0), corner(1.0, 1.0)];
        let o = Vec3A::new(6.845045, -4.999997, 1.9648917);
        for d in [
            Vec3A::new(-0.27216503, 0.63266283, -0.7250268),
            Vec3A::new(-0.24715658, 0.6176819, -0.74658066),
        ] {
            assert_eq!(hit(o, d, floor), None, "{d:?}");
            // From a unit above, down, the floor is still hit.
            assert!(hit(o + Vec3A::Y, -d, floor).is_some());
        }
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
