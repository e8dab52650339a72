//! Scene command: `cylinder radius zmin zmax` — an open cylinder around the object z
//! axis: `x² + y² = r²`, `zmin ≤ z ≤ zmax`.

use super::quadratic::{first_root, solve};
use crate::math::Vec3A;

pub fn intersect(radius: f32, zmin: f32, zmax: f32, o: Vec3A, d: Vec3A, t_min: f32, t_max: f32) -> Option<f32> {
    let (ox, oy, oz) = (o.x as f64, o.y as f64, o.z as f64);
    let (dx, dy, dz) = (d.x as f64, d.y as f64, d.z as f64);
    let a = dx * dx + dy * dy;
    if a == 0.0 {
        return None; // along the axis: never crosses the side
    }
    let b = 2.0 * (ox * dx + oy * dy);
    let c = ox * ox + oy * oy - (radius as f64) * (radius as f64);
    first_root(solve(a, b, c), t_min, t_max, |t| {
        let z = oz + t * dz;
        z >= zmin as f64 && z <= zmax as f64
    })
}

/// Outward normal at a point of the side.
pub fn normal(p: Vec3A) -> Vec3A {
    Vec3A::new(p.x, p.y, 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hit(o: Vec3A, d: Vec3A) -> Option<f32> {
        intersect(2.0, -1.0, 1.0, o, d, 1e-4, f32::INFINITY)
    }

    #[test]
    fn analytic_hits_inside_start_and_the_ends() {
        assert_eq!(hit(Vec3A::new(5.0, 0.0, 0.0), -Vec3A::X), Some(3.0));
        // From inside: the far wall.
        assert_eq!(hit(Vec3A::ZERO, Vec3A::Y), Some(2.0));
        // Above the top rim going down the axis: the open cylinder has no caps.
        assert_eq!(hit(Vec3A::new(0.0, 0.0, 5.0), -Vec3A::Z), None);
        // Aimed at the side beyond zmax: misses; through the open end onto the far wall.
        assert_eq!(hit(Vec3A::new(5.0, 0.0, 3.0), -Vec3A::X), None);
        let d = Vec3A::new(1.0, 0.0, -1.0).normalize();
        let t = hit(Vec3A::new(0.0, 0.0, 2.0), d).unwrap();
        assert!((t - 2.0 * 2f32.sqrt()).abs() < 1e-5, "{t}"); // (2, 0, 0)
        assert_eq!(normal(Vec3A::new(2.0, 0.0, 0.5)), Vec3A::new(2.0, 0.0, 0.0));
    }

    #[test]
    fn grazing_parallel_and_leaving_rays() {
        // Tangent to the side: one double root, a hit.
        assert_eq!(hit(Vec3A::new(2.0, -5.0, 0.0), Vec3A::Y), Some(5.0));
        // Parallel to the axis, outside or on the surface: no crossing.
        assert_eq!(hit(Vec3A::new(3.0, 0.0, -5.0), Vec3A::Z), None);
        // Leaving the surface outward: the root at t ≈ 0 is skipped, nothing else.
        assert_eq!(hit(Vec3A::new(2.0, 0.0, 0.0), Vec3A::X), None);
        // Leaving it inward: the opposite wall at t = 4.
        let t = hit(Vec3A::new(2.0, 0.0, 0.0), -Vec3A::X).unwrap();
        assert!((t - 4.0).abs() < 1e-6);
    }
}
