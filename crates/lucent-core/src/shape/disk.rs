//! Scene command: `disk radius` — the disk `x² + y² ≤ r²` in the object z = 0 plane,
//! normal +z.

use crate::math::Vec3A;

pub fn intersect(radius: f32, o: Vec3A, d: Vec3A, t_min: f32, t_max: f32) -> Option<f32> {
    if d.z == 0.0 {
        return None;
    }
    let t = -o.z / d.z;
    if !(t > t_min && t <= t_max) {
        return None;
    }
    let (x, y) = (o.x + t * d.x, o.y + t * d.y);
    (x * x + y * y <= radius * radius).then_some(t)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hits_inside_the_radius_from_both_sides() {
        assert_eq!(
            intersect(1.0, Vec3A::new(0.5, 0.0, 2.0), -Vec3A::Z, 1e-4, f32::INFINITY),
            Some(2.0)
        );
        assert_eq!(
            intersect(1.0, Vec3A::new(0.5, 0.0, -3.0), Vec3A::Z, 1e-4, f32::INFINITY),
            Some(3.0)
        );
        assert_eq!(
            intersect(1.0, Vec3A::new(1.5, 0.0, 2.0), -Vec3A::Z, 1e-4, f32::INFINITY),
            None
        );
        // The rim counts.
        assert_eq!(
            intersect(1.0, Vec3A::new(1.0, 0.0, 2.0), -Vec3A::Z, 1e-4, f32::INFINITY),
            Some(2.0)
        );
    }

    #[test]
    fn parallel_and_leaving_rays_miss() {
        assert_eq!(
            intersect(1.0, Vec3A::new(0.0, 0.0, 1.0), Vec3A::X, 1e-4, f32::INFINITY),
            None
        );
        assert_eq!(intersect(1.0, Vec3A::ZERO, Vec3A::X, 1e-4, f32::INFINITY), None);
        assert_eq!(intersect(1.0, Vec3A::ZERO, Vec3A::Z, 1e-4, f32::INFINITY), None);
    }
}
