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

/// Index of the component with the largest absolute value (ties go to the later axis).
/// Branch-free: for incoherent rays a branch here would be mispredicted half the time.
#[inline(always)]
pub fn max_abs_axis(v: Vec3A) -> usize {
    let a = v.abs();
    let x_wins = (a.x > a.y) & (a.x > a.z);
    let y_wins = !(a.x > a.y) & (a.y > a.z);
    // x → 0, y → 1, z → 2.
    (!x_wins as usize) * (1 + !y_wins as usize)
}

/// `γ(n)` of Pharr, Jakob & Humphreys: a bound on the relative rounding error of `n`
/// chained `f32` operations. Used to make box tests conservative.
#[inline(always)]
pub const fn gamma(n: i32) -> f32 {
    let eps = f32::EPSILON * 0.5;
    (n as f32 * eps) / (1.0 - n as f32 * eps)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn max_abs_axis_picks_the_dominant_component() {
        assert_eq!(max_abs_axis(Vec3A::new(-3.0, 1.0, 2.0)), 0);
        assert_eq!(max_abs_axis(Vec3A::new(0.5, -4.0, 2.0)), 1);
        assert_eq!(max_abs_axis(Vec3A::new(0.5, 1.0, -2.0)), 2);
        // Ties go to the later axis, as in the branching form this replaced.
        assert_eq!(max_abs_axis(Vec3A::new(1.0, 1.0, 0.0)), 1);
        assert_eq!(max_abs_axis(Vec3A::new(1.0, 0.0, 1.0)), 2);
        assert_eq!(max_abs_axis(Vec3A::new(1.0, 1.0, 1.0)), 2);
        assert_eq!(max_abs_axis(Vec3A::ZERO), 2);
    }
}
