//! Scene command: `box x0 y0 z0 x1 y1 z1` — an axis-aligned box in object space (the
//! current transform may rotate and shear it), intersected by slabs.

use crate::aabb::Aabb;
use crate::math::Vec3A;

/// The first crossing of the box's surface in `(t_min, t_max]`: where the ray enters,
/// or, from inside, where it leaves.
pub fn intersect(b: &Aabb, o: Vec3A, d: Vec3A, t_min: f32, t_max: f32) -> Option<f32> {
    let (mut near, mut far) = (f32::NEG_INFINITY, f32::INFINITY);
    for axis in 0..3 {
        if d[axis] == 0.0 {
            // Parallel to this pair of faces: inside the slab or never.
            if o[axis] < b.min[axis] || o[axis] > b.max[axis] {
                return None;
            }
            continue;
        }
        let inv = 1.0 / d[axis];
        let (t0, t1) = ((b.min[axis] - o[axis]) * inv, (b.max[axis] - o[axis]) * inv);
        near = near.max(t0.min(t1));
        far = far.min(t0.max(t1));
    }
    if near > far {
        return None;
    }
    [near, far].into_iter().find(|&t| t > t_min && t <= t_max)
}

/// Outward normal of the face nearest to `p` (a point on the surface).
pub fn normal(b: &Aabb, p: Vec3A) -> Vec3A {
    let size = b.extent().max(Vec3A::splat(f32::MIN_POSITIVE));
    let mut best = (f32::INFINITY, Vec3A::X);
    for axis in 0..3 {
        let mut unit = Vec3A::ZERO;
        unit[axis] = 1.0;
        for (face, sign) in [(b.min[axis], -1.0), (b.max[axis], 1.0)] {
            let dist = (p[axis] - face).abs() / size[axis];
            if dist < best.0 {
                best = (dist, unit * sign);
            }
        }
    }
    best.1
}

#[cfg(test)]
mod tests {
    use super::*;

    const B: Aabb = Aabb {
        min: Vec3A::new(-1.0, -2.0, -3.0),
        max: Vec3A::new(1.0, 2.0, 3.0),
    };

    #[test]
    fn hits_faces_from_outside_and_inside() {
        let t = intersect(&B, Vec3A::new(0.0, 0.0, 10.0), -Vec3A::Z, 1e-4, f32::INFINITY);
        assert_eq!(t, Some(7.0));
        assert_eq!(normal(&B, Vec3A::new(0.0, 0.0, 3.0)), Vec3A::Z);
        // From inside, the exit.
        assert_eq!(intersect(&B, Vec3A::ZERO, Vec3A::X, 1e-4, f32::INFINITY), Some(1.0));
        assert_eq!(normal(&B, Vec3A::new(1.0, 0.5, 0.5)), Vec3A::X);
        assert_eq!(normal(&B, Vec3A::new(0.2, -2.0, 0.5)), -Vec3A::Y);
        // A segment that ends before the box.
        assert_eq!(intersect(&B, Vec3A::new(0.0, 0.0, 10.0), -Vec3A::Z, 1e-4, 5.0), None);
    }

    #[test]
    fn parallel_grazing_and_leaving_rays() {
        // Parallel to the x faces, outside their slab: miss; inside: hit the y face.
        assert_eq!(
            intersect(&B, Vec3A::new(5.0, 0.0, 0.0), Vec3A::Y, 1e-4, f32::INFINITY),
            None
        );
        assert_eq!(
            intersect(&B, Vec3A::new(0.5, -5.0, 0.0), Vec3A::Y, 1e-4, f32::INFINITY),
            Some(3.0)
        );
        // Grazing along an edge counts (faces are closed).
        assert_eq!(
            intersect(&B, Vec3A::new(1.0, -5.0, 3.0), Vec3A::Y, 1e-4, f32::INFINITY),
            Some(3.0)
        );
        // Leaving the surface outward never hits it again.
        assert_eq!(
            intersect(&B, Vec3A::new(0.0, 0.0, 3.0), Vec3A::Z, 1e-4, f32::INFINITY),
            None
        );
        // Leaving it inward hits the opposite face.
        assert_eq!(
            intersect(&B, Vec3A::new(0.0, 0.0, 3.0), -Vec3A::Z, 1e-4, f32::INFINITY),
            Some(6.0)
        );
    }
}
