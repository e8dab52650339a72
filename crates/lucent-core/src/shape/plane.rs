//! Ray–plane intersection: the plane through `point` with normal `normal` is hit at
//! `t = (point − o)·n / (d·n)`. Used by scene extensions (`plane`, `disk`, box faces).

use crate::math::Vec3A;

/// `None` when the ray is parallel to the plane or the hit is outside `(t_min, t_max]`.
pub fn intersect_plane(o: Vec3A, d: Vec3A, point: Vec3A, normal: Vec3A, t_min: f32, t_max: f32) -> Option<f32> {
    let denom = d.dot(normal);
    if denom == 0.0 {
        return None;
    }
    let t = (point - o).dot(normal) / denom;
    (t > t_min && t <= t_max).then_some(t)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hits_at_the_analytic_distance() {
        let t = intersect_plane(
            Vec3A::new(0.0, 3.0, 0.0),
            -Vec3A::Y,
            Vec3A::ZERO,
            Vec3A::Y,
            1e-4,
            f32::INFINITY,
        );
        assert_eq!(t, Some(3.0));
        // 45 degrees: distance sqrt(2) * 3, from either side of the plane.
        let d = Vec3A::new(1.0, 1.0, 0.0).normalize();
        let t = intersect_plane(
            Vec3A::new(0.0, -3.0, 0.0),
            d,
            Vec3A::ZERO,
            Vec3A::Y,
            1e-4,
            f32::INFINITY,
        )
        .unwrap();
        assert!((t - 3.0 * 2f32.sqrt()).abs() < 1e-5);
    }

    #[test]
    fn parallel_and_receding_rays_miss() {
        assert!(intersect_plane(
            Vec3A::new(0.0, 1.0, 0.0),
            Vec3A::X,
            Vec3A::ZERO,
            Vec3A::Y,
            1e-4,
            f32::INFINITY
        )
        .is_none());
        assert!(intersect_plane(
            Vec3A::new(0.0, 1.0, 0.0),
            Vec3A::Y,
            Vec3A::ZERO,
            Vec3A::Y,
            1e-4,
            f32::INFINITY
        )
        .is_none());
        // Starting on the plane: the re-intersection at t = 0 is rejected.
        assert!(intersect_plane(Vec3A::ZERO, Vec3A::Y, Vec3A::ZERO, Vec3A::Y, 1e-4, f32::INFINITY).is_none());
    }
}
