//! Scene command: `cone radius height` — an open cone with its base circle of `radius`
//! at z = 0 and its apex at z = `height`: `x² + y² = (r·(h − z)/h)²` between the base
//! and the apex.

use super::quadratic::{first_root, solve};
use crate::math::Vec3A;

pub fn intersect(radius: f32, height: f32, o: Vec3A, d: Vec3A, t_min: f32, t_max: f32) -> Option<f32> {
    let (ox, oy, oz) = (o.x as f64, o.y as f64, o.z as f64);
    let (dx, dy, dz) = (d.x as f64, d.y as f64, d.z as f64);
    let h = height as f64;
    let k2 = (radius as f64 / h).powi(2);
    let w = h - oz; // distance below the apex along z
    let a = dx * dx + dy * dy - k2 * dz * dz;
    let b = 2.0 * (ox * dx + oy * dy + k2 * w * dz);
    let c = ox * ox + oy * oy - k2 * w * w;
    let (lo, hi) = if h > 0.0 { (0.0, h) } else { (h, 0.0) };
    first_root(solve(a, b, c), t_min, t_max, |t| {
        let z = oz + t * dz;
        z >= lo && z <= hi
    })
}

/// Outward normal at a point of the side (the gradient of `x² + y² − k²(h − z)²`).
pub fn normal(radius: f32, height: f32, p: Vec3A) -> Vec3A {
    let k2 = (radius / height) * (radius / height);
    let n = Vec3A::new(p.x, p.y, k2 * (height - p.z));
    // At the apex the gradient vanishes: take the axis.
    if n == Vec3A::ZERO {
        Vec3A::Z * height.signum()
    } else {
        n
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hit(o: Vec3A, d: Vec3A) -> Option<f32> {
        intersect(1.0, 2.0, o, d, 1e-4, f32::INFINITY)
    }

    #[test]
    fn analytic_hits() {
        // At z = 1 the radius is 0.5.
        let t = hit(Vec3A::new(5.0, 0.0, 1.0), -Vec3A::X).unwrap();
        assert!((t - 4.5).abs() < 1e-6, "{t}");
        // Down the axis from above: the apex.
        let t = hit(Vec3A::new(0.0, 0.0, 5.0), -Vec3A::Z).unwrap();
        assert!((t - 3.0).abs() < 1e-6, "{t}");
        // Below the base the double cone is clipped away; the open base lets a ray in.
        assert_eq!(hit(Vec3A::new(5.0, 0.0, -0.5), -Vec3A::X), None);
        let t = hit(Vec3A::new(0.0, 0.0, -1.0), Vec3A::Z).unwrap();
        assert!((t - 3.0).abs() < 1e-6, "{t}"); // up the axis, from inside, to the apex
                                                // The normal leans up: (x, y, k²(h − z)) at (0.5, 0, 1) is (0.5, 0, 0.25).
        let n = normal(1.0, 2.0, Vec3A::new(0.5, 0.0, 1.0));
        assert!((n - Vec3A::new(0.5, 0.0, 0.25)).length() < 1e-6);
    }

    #[test]
    fn grazing_parallel_and_leaving_rays() {
        // Along a generator line (a = 0): the line lies in the surface — one solution at
        // most, never a panic or NaN.
        let d = Vec3A::new(-0.5, 0.0, 1.0).normalize();
        let r = hit(Vec3A::new(1.0, 0.0, 0.0) - d, d);
        assert!(r.is_none_or(|t| t.is_finite()));
        // Parallel to a generator, offset outside: hits the far side once or misses.
        let r = hit(Vec3A::new(3.0, 0.0, 0.0), d);
        assert!(r.is_none_or(|t| t.is_finite() && t > 0.0));
        // Leaving the surface outward at z = 1 (radius 0.5): no second hit.
        assert_eq!(hit(Vec3A::new(0.5, 0.0, 1.0), Vec3A::X), None);
        // Leaving inward: the opposite side at x = -0.5.
        let t = hit(Vec3A::new(0.5, 0.0, 1.0), -Vec3A::X).unwrap();
        assert!((t - 1.0).abs() < 1e-6, "{t}");
    }
}
