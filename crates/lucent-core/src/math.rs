//! Vector and matrix types. glam's SIMD-aligned `Vec3A` is the workhorse of the hot
//! code; `f64` types (`DVec3`, `DAffine3`) are used where a scene is set up, so that a
//! long chain of transforms loses no precision before it is rounded to `f32` once.

pub use glam::{Affine3A, DAffine3, DMat3, DVec3, Mat3A, Vec3, Vec3A};

/// Linear RGB radiance or reflectance.
pub type Color = Vec3A;

/// Component `axis` (0 = x, 1 = y, 2 = z) of a vector.
#[inline(always)]
pub fn component(v: Vec3A, axis: usize) -> f32 {
    match axis {
        0 => v.x,
        1 => v.y,
        _ => v.z,
    }
}

/// Index of the component with the largest absolute value.
#[inline(always)]
pub fn max_abs_axis(v: Vec3A) -> usize {
    let a = v.abs();
    if a.x > a.y {
        if a.x > a.z {
            0
        } else {
            2
        }
    } else if a.y > a.z {
        1
    } else {
        2
    }
}

/// `γ(n)` of Pharr, Jakob & Humphreys: a bound on the relative rounding error of `n`
/// chained `f32` operations. Used to make box tests conservative.
#[inline(always)]
pub const fn gamma(n: i32) -> f32 {
    let eps = f32::EPSILON * 0.5;
    (n as f32 * eps) / (1.0 - n as f32 * eps)
}
