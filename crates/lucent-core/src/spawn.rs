//! Rays that leave a surface, without finding it again by mistake.
//!
//! A hit point is computed in `f32`, so it lies a little off the true surface, on either
//! side. A ray leaving it that starts on the wrong side meets the surface it leaves: the
//! dark dots and notches of "shadow acne", strongest where rays leave at a grazing angle
//! (a sphere near its silhouette, a reflection off a smooth-shaded mesh). The course's
//! remedy — skip hits closer than ε — fails exactly there, because a grazing ray can stay
//! inside a rounding-sized sliver for much longer than ε.
//!
//! pbrt-v4's remedy (Pharr, Jakob & Humphreys, *Physically Based Rendering*, 4th ed.,
//! §6.8) is used here: every shape reports with its hit point a conservative bound on
//! the point's rounding error per axis, computed so that it does not depend on the error
//! of `t` (triangles rebuild the point from its barycentric weights, spheres project it
//! back onto the sphere). A spawned ray starts at the point moved along the geometric
//! normal, past that bound, to the side its direction leaves by; the true surface is then
//! certainly behind it. The ray keeps the format's `t > ε` (SCENE_FORMAT.md §4.2) on top,
//! so the course images keep their meaning. What the offset cannot cover is the error of
//! the triangle test's own `t`, which grows with the triangle's size: hits on large
//! triangles are checked against pbrt's bound on it (`shape::triangle::checks_t_error`).

use crate::hit::SurfacePoint;
use crate::math::{gamma, Affine3A, Vec3A};
use crate::ray::{Ray, EPSILON};

/// The smallest `f32` above `x` (`x` itself for +∞ and NaN).
#[inline]
pub fn next_up(x: f32) -> f32 {
    if x.is_nan() || x == f32::INFINITY {
        return x;
    }
    if x == 0.0 {
        return f32::from_bits(1); // the smallest positive subnormal, for +0 and −0
    }
    let bits = x.to_bits();
    f32::from_bits(if x > 0.0 { bits + 1 } else { bits - 1 })
}

/// The largest `f32` below `x`.
#[inline]
pub fn next_down(x: f32) -> f32 {
    -next_up(-x)
}

/// `p0·b0 + p1·b1 + p2·b2` with `b0 = 1 − b1 − b2`, and the bound on its rounding error.
/// Any weights that sum to one give a point of the triangle's plane, so the point's
/// distance from the plane is rounding alone, whatever the error of the weights.
#[inline]
pub fn barycentric_point(p: [Vec3A; 3], b1: f32, b2: f32) -> (Vec3A, Vec3A) {
    let b0 = 1.0 - b1 - b2;
    let (a, b, c) = (p[0] * b0, p[1] * b1, p[2] * b2);
    let point = a + b + c;
    // γ7 covers the products and sums (PBR 4th ed. §6.8.5); one more for b0's rounding.
    let error = (a.abs() + b.abs() + c.abs()) * gamma(8);
    (point, error)
}

/// `m · p` and the bound on its error, given the bound `error` on `p`'s (PBR 4th ed.
/// §6.8.6, transforming points with error).
#[inline]
pub fn transform_point(m: &Affine3A, p: Vec3A, error: Vec3A) -> (Vec3A, Vec3A) {
    let point = m.transform_point3a(p);
    let abs = |v: Vec3A| v.abs();
    let (cx, cy, cz) = (abs(m.matrix3.x_axis), abs(m.matrix3.y_axis), abs(m.matrix3.z_axis));
    // The rounding of this product, then the incoming error carried through it.
    let own = (cx * p.x.abs() + cy * p.y.abs() + cz * p.z.abs() + m.translation.abs()) * gamma(3);
    let carried = (cx * error.x + cy * error.y + cz * error.z) * (1.0 + gamma(3));
    (point, own + carried)
}

/// The origin of a ray leaving `point` (rounding error at most `error` per axis) toward
/// `dir`, on a surface with geometric normal `ng`: moved along `ng` past the error bound
/// to the side `dir` leaves by, and rounded away from the surface.
#[inline]
pub fn offset_origin(point: Vec3A, error: Vec3A, ng: Vec3A, dir: Vec3A) -> Vec3A {
    let distance = ng.abs().dot(error);
    let mut offset = ng * distance;
    if dir.dot(ng) < 0.0 {
        offset = -offset;
    }
    // Rounding the sum could bring it back toward the surface: step one ulp further.
    one_ulp_along(point + offset, offset)
}

/// Each component of `m` one ulp further along the sign of the same component of `o`
/// ([`next_up`] where it is positive, [`next_down`] where it is negative, unchanged where
/// it is zero).
#[inline(always)]
fn one_ulp_along(m: Vec3A, o: Vec3A) -> Vec3A {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: SSE2 is part of x86-64.
    unsafe {
        one_ulp_along_sse2(m, o)
    }
    #[cfg(not(target_arch = "x86_64"))]
    Vec3A::new(
        one_ulp_toward(m.x, o.x),
        one_ulp_toward(m.y, o.y),
        one_ulp_toward(m.z, o.z),
    )
}

/// One component of [`one_ulp_along`] (the portable form, and the test's reference).
#[cfg_attr(all(target_arch = "x86_64", not(test)), allow(dead_code))]
fn one_ulp_toward(m: f32, o: f32) -> f32 {
    if o > 0.0 {
        next_up(m)
    } else if o < 0.0 {
        next_down(m)
    } else {
        m
    }
}

/// [`one_ulp_along`] without a branch: the sign of each offset component follows the
/// surface's normal, which no branch predictor foresees (the per-component branches were
/// a fifth of a path-traced Cornell box's mispredictions in callgrind's simulation). The
/// same bits as [`next_up`] and [`next_down`] (a test compares them on every kind of
/// float).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn one_ulp_along_sse2(m: Vec3A, o: Vec3A) -> Vec3A {
    use std::arch::x86_64::*;
    let (m, o): (__m128, __m128) = (m.into(), o.into());
    let zero = _mm_setzero_ps();
    let int = _mm_castps_si128;
    let select =
        |mask: __m128i, a: __m128i, b: __m128i| _mm_or_si128(_mm_and_si128(mask, a), _mm_andnot_si128(mask, b));
    let (up, down) = (int(_mm_cmpgt_ps(o, zero)), int(_mm_cmplt_ps(o, zero)));
    // Moving away from zero adds one to the bits, toward it subtracts one.
    let outward = _mm_or_si128(
        _mm_and_si128(int(_mm_cmpgt_ps(m, zero)), up),
        _mm_and_si128(int(_mm_cmplt_ps(m, zero)), down),
    );
    // `outward | 1` is −1 where it moves away from zero and 1 where it moves toward it.
    let stepped = _mm_sub_epi32(int(m), _mm_or_si128(outward, _mm_set1_epi32(1)));
    // From ±0: the smallest subnormal on the offset's side.
    let smallest = _mm_or_si128(_mm_set1_epi32(1), _mm_and_si128(down, _mm_set1_epi32(i32::MIN)));
    let from_zero = int(_mm_cmpeq_ps(m, zero));
    // Unchanged: no offset, NaN, or an infinity moved further out.
    let infinite = int(_mm_cmpeq_ps(
        _mm_andnot_ps(_mm_set1_ps(-0.0), m),
        _mm_set1_ps(f32::INFINITY),
    ));
    let keep = _mm_or_si128(
        _mm_andnot_si128(_mm_or_si128(up, down), _mm_set1_epi32(-1)),
        _mm_or_si128(int(_mm_cmpunord_ps(m, m)), _mm_and_si128(infinite, outward)),
    );
    let r = select(keep, int(m), select(from_zero, smallest, stepped));
    Vec3A::from(_mm_castsi128_ps(r))
}

impl SurfacePoint {
    /// A ray leaving this point in direction `dir` (unit length), that cannot find this
    /// surface again by rounding error.
    #[inline]
    pub fn spawn(&self, dir: Vec3A) -> Ray {
        Ray::new(offset_origin(self.point, self.error, self.geometric_normal, dir), dir)
    }

    /// A shadow ray toward a point `distance` away in direction `dir`: it stops ε short.
    #[inline]
    pub fn spawn_segment(&self, dir: Vec3A, distance: f32) -> Ray {
        let origin = offset_origin(self.point, self.error, self.geometric_normal, dir);
        Ray::segment(origin, dir, EPSILON, distance - EPSILON)
    }

    /// Whether direction `w` leaves on the side of the geometric surface that the
    /// shading normal faces. A smooth-shaded or bump-mapped surface can put directions
    /// above the shading normal's horizon that go into the true (flat) surface; every
    /// integrator gives those no light, so that no ray is sent into the object it leaves.
    #[inline]
    pub fn above_geometry(&self, w: Vec3A) -> bool {
        w.dot(self.geometric_normal) > 0.0
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    #[test]
    fn next_up_and_down_step_one_ulp() {
        assert_eq!(next_up(1.0), 1.0 + f32::EPSILON);
        assert_eq!(next_down(1.0), 1.0 - f32::EPSILON / 2.0);
        assert!(next_up(0.0) > 0.0 && next_down(0.0) < 0.0);
        assert_eq!(next_up(-1.0), -(1.0 - f32::EPSILON / 2.0));
        assert_eq!(next_up(f32::INFINITY), f32::INFINITY);
    }

    #[test]
    fn a_whole_vector_steps_as_each_component_does() {
        let (values, offsets) = ulp_step_cases();
        for (i, &m) in values.iter().enumerate() {
            for (j, &o) in offsets.iter().enumerate() {
                let (m3, o3) = (
                    Vec3A::new(m, values[(i + 1) % values.len()], values[(i + 7) % values.len()]),
                    Vec3A::new(o, offsets[(j + 3) % offsets.len()], offsets[(j + 5) % offsets.len()]),
                );
                let got = one_ulp_along(m3, o3);
                for a in 0..3 {
                    let want = one_ulp_toward(m3[a], o3[a]);
                    assert_eq!(got[a].to_bits(), want.to_bits(), "{} along {}", m3[a], o3[a]);
                }
            }
        }
    }

    /// Values to step one ulp (every kind of float: zeros, subnormals, the largest,
    /// infinities, NaN, then 3,000 random bit patterns) and offsets whose signs say the
    /// way: what the tests of every form of the step share.
    pub(crate) fn ulp_step_cases() -> (Vec<f32>, [f32; 8]) {
        let special = [
            0.0,
            -0.0,
            1.0,
            -1.0,
            f32::MIN_POSITIVE,
            -f32::MIN_POSITIVE,
            f32::from_bits(1),
            -f32::from_bits(1),
            f32::MAX,
            f32::MIN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
            1e-30,
            -3.5e7,
        ];
        let offsets = [0.0, -0.0, 1e-6, -1e-6, 1.0, -1.0, f32::NAN, f32::INFINITY];
        let mut x = 0x9e37_79b9u32;
        let mut random = || {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            f32::from_bits(x)
        };
        let values = special.iter().copied().chain((0..3000).map(|_| random())).collect();
        (values, offsets)
    }
}
