//! Texture coordinates `(u, v)` of the shapes, computed from the object-space hit point.
//! Conventions (z is every round shape's axis, as in the scene commands):
//!
//! | shape | u | v |
//! |---|---|---|
//! | sphere (unit, object space) | longitude `atan2(y, x) / 2π` in [0, 1) | `acos(z) / π`: 0 at the +z pole, 1 at −z |
//! | cylinder | longitude | `(z − zmin) / (zmax − zmin)` |
//! | disk | longitude | distance from the centre / radius |
//! | cone | longitude | `z / height`: 0 at the base, 1 at the apex |
//! | box | along the face's first other axis, 0…1 over the box | along its second other axis |
//! | quadric | `(x − x0) / (x1 − x0)` | `(y − y0) / (y1 − y0)` |
//! | plane | distance along a tangent `t₁` from the plane's point (repeats, not 0…1) | along `t₂ = n × t₁` |
//! | triangle | barycentric weight of the second vertex | of the third vertex |

use std::f32::consts::{PI, TAU};

use crate::aabb::Aabb;
use crate::math::{max_abs_axis, Vec3A};
use glam::Vec2;

/// Longitude around the z axis in [0, 1).
pub fn longitude(p: Vec3A) -> f32 {
    let phi = p.y.atan2(p.x);
    let u = if phi < 0.0 { phi + TAU } else { phi } / TAU;
    if u >= 1.0 {
        0.0
    } else {
        u
    }
}

pub fn sphere(p: Vec3A) -> Vec2 {
    Vec2::new(longitude(p), p.z.clamp(-1.0, 1.0).acos() / PI)
}

pub fn cylinder(p: Vec3A, zmin: f32, zmax: f32) -> Vec2 {
    Vec2::new(longitude(p), (p.z - zmin) / (zmax - zmin))
}

pub fn disk(p: Vec3A, radius: f32) -> Vec2 {
    Vec2::new(longitude(p), (p.x * p.x + p.y * p.y).sqrt() / radius)
}

pub fn cone(p: Vec3A, height: f32) -> Vec2 {
    Vec2::new(longitude(p), p.z / height)
}

/// On the face of `b` whose normal is `n` (an axis direction).
pub fn cuboid(b: &Aabb, n: Vec3A, p: Vec3A) -> Vec2 {
    let k = max_abs_axis(n);
    let (a0, a1) = ((k + 1) % 3, (k + 2) % 3);
    let e = b.extent();
    Vec2::new((p[a0] - b.min[a0]) / e[a0], (p[a1] - b.min[a1]) / e[a1])
}

pub fn quadric(clip: &Aabb, p: Vec3A) -> Vec2 {
    let e = clip.extent();
    Vec2::new((p.x - clip.min.x) / e.x, (p.y - clip.min.y) / e.y)
}

pub fn plane(point: Vec3A, normal: Vec3A, p: Vec3A) -> Vec2 {
    let n = normal.normalize();
    let t1 = n.cross(if n.x.abs() < 0.9 { Vec3A::X } else { Vec3A::Y }).normalize();
    let t2 = n.cross(t1);
    let r = p - point;
    Vec2::new(r.dot(t1), r.dot(t2))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Vec2, b: Vec2) -> bool {
        (a - b).abs().max_element() < 1e-5
    }

    #[test]
    fn round_shapes() {
        // At the poles only v is defined.
        assert!(sphere(Vec3A::Z).y.abs() < 1e-6);
        assert!((sphere(-Vec3A::Z).y - 1.0).abs() < 1e-6);
        assert!(close(sphere(Vec3A::Y), Vec2::new(0.25, 0.5)));
        assert!(close(sphere(-Vec3A::X), Vec2::new(0.5, 0.5)));
        assert!(close(sphere(-Vec3A::Y), Vec2::new(0.75, 0.5)));
        assert!(close(
            cylinder(Vec3A::new(2.0, 0.0, 1.0), -1.0, 3.0),
            Vec2::new(0.0, 0.5)
        ));
        assert!(close(disk(Vec3A::new(0.0, -1.0, 0.0), 2.0), Vec2::new(0.75, 0.5)));
        assert!(close(cone(Vec3A::new(-0.5, 0.0, 1.0), 2.0), Vec2::new(0.5, 0.5)));
        // Just below the seam the longitude is just below 1, never 1.
        let u = longitude(Vec3A::new(1.0, -1e-9, 0.0));
        assert!((0.0..1.0).contains(&u));
    }

    #[test]
    fn flat_shapes() {
        let b = Aabb::new(Vec3A::ZERO, Vec3A::new(2.0, 4.0, 8.0));
        // The +z face: u along x, v along y.
        assert!(close(
            cuboid(&b, Vec3A::Z, Vec3A::new(1.0, 1.0, 8.0)),
            Vec2::new(0.5, 0.25)
        ));
        // The −x face: u along y, v along z.
        assert!(close(
            cuboid(&b, -Vec3A::X, Vec3A::new(0.0, 2.0, 2.0)),
            Vec2::new(0.5, 0.25)
        ));
        let clip = Aabb::new(Vec3A::splat(-1.0), Vec3A::splat(1.0));
        assert!(close(quadric(&clip, Vec3A::new(0.0, 0.5, 0.3)), Vec2::new(0.5, 0.75)));
        // The plane's coordinates are distances in the plane, orthogonal to each other.
        let (o, n) = (Vec3A::new(1.0, 2.0, 3.0), Vec3A::new(0.0, 0.0, 2.0));
        let a = plane(o, n, o + Vec3A::new(3.0, 0.0, 0.0));
        let c = plane(o, n, o + Vec3A::new(0.0, 4.0, 0.0));
        assert!((a.length() - 3.0).abs() < 1e-5 && (c.length() - 4.0).abs() < 1e-5);
        assert!(a.dot(c).abs() < 1e-4);
        assert!(close(plane(o, n, o), Vec2::ZERO));
    }
}
