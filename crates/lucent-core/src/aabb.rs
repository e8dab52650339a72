//! Axis-aligned bounding boxes and the ray–box test by slabs.

use crate::math::{gamma, Vec3A};
use crate::ray::PreparedRay;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    pub min: Vec3A,
    pub max: Vec3A,
}

impl Aabb {
    /// The empty box: the identity of `union`.
    pub const EMPTY: Aabb = Aabb {
        min: Vec3A::splat(f32::INFINITY),
        max: Vec3A::splat(f32::NEG_INFINITY),
    };

    pub fn new(a: Vec3A, b: Vec3A) -> Aabb {
        Aabb {
            min: a.min(b),
            max: a.max(b),
        }
    }

    pub fn from_points(points: &[Vec3A]) -> Aabb {
        points.iter().fold(Aabb::EMPTY, |b, &p| b.grow(p))
    }

    /// A box holding this one after `m`: the bounds of its eight transformed corners,
    /// widened by a few units in the last place so that rounding in the transform (of
    /// the box or of a ray) cannot put a surface point outside it. Empty stays empty.
    pub fn transformed(&self, m: &crate::math::Affine3A) -> Aabb {
        if self.is_empty() {
            return Aabb::EMPTY;
        }
        let corners: Vec<Vec3A> = (0..8)
            .map(|i| {
                let c = Vec3A::new(
                    if i & 1 == 0 { self.min.x } else { self.max.x },
                    if i & 2 == 0 { self.min.y } else { self.max.y },
                    if i & 4 == 0 { self.min.z } else { self.max.z },
                );
                m.transform_point3a(c)
            })
            .collect();
        let b = Aabb::from_points(&corners);
        let pad = 1e-6 * (b.extent().max_element() + b.min.abs().max(b.max.abs()).max_element());
        Aabb {
            min: b.min - Vec3A::splat(pad),
            max: b.max + Vec3A::splat(pad),
        }
    }

    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x || self.min.y > self.max.y || self.min.z > self.max.z
    }

    pub fn grow(&self, p: Vec3A) -> Aabb {
        Aabb {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }

    pub fn union(&self, o: &Aabb) -> Aabb {
        Aabb {
            min: self.min.min(o.min),
            max: self.max.max(o.max),
        }
    }

    pub fn centroid(&self) -> Vec3A {
        (self.min + self.max) * 0.5
    }

    pub fn extent(&self) -> Vec3A {
        (self.max - self.min).max(Vec3A::ZERO)
    }

    /// Surface area (0 for an empty box): the SAH's probability measure.
    pub fn surface_area(&self) -> f32 {
        if self.is_empty() {
            return 0.0;
        }
        let e = self.extent();
        2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
    }

    pub fn largest_axis(&self) -> usize {
        let e = self.extent();
        if e.x >= e.y && e.x >= e.z {
            0
        } else if e.y >= e.z {
            1
        } else {
            2
        }
    }

    /// Ray–box test by slabs. Returns the parameter interval in which the ray is inside
    /// the box, clipped to `[ray.t_min, t_max]`, or `None`. Faces count as inside, and the
    /// far distance is widened by `1 + 2γ(3)` (Ize 2013) so that rounding never culls a
    /// hit that a primitive test inside the box would report. Along an axis the ray does
    /// not move, the slab is everything or nothing depending on where the origin is (the
    /// arithmetic alone gets this wrong when the origin lies exactly on a face plane).
    #[inline(always)]
    pub fn intersect(&self, r: &PreparedRay, t_max: f32) -> Option<(f32, f32)> {
        let o = r.ray.origin;
        let t0 = (self.min - o) * r.inv_dir;
        let t1 = (self.max - o) * r.inv_dir;
        let mut near = t0.min(t1);
        let mut far = t0.max(t1) * (1.0 + 2.0 * gamma(3));
        if r.zero_axes.any() {
            let inside = self.min.cmple(o) & o.cmple(self.max);
            if (r.zero_axes & !inside).any() {
                return None;
            }
            near = Vec3A::select(r.zero_axes, Vec3A::NEG_INFINITY, near);
            far = Vec3A::select(r.zero_axes, Vec3A::INFINITY, far);
        }
        let enter = near.max_element().max(r.ray.t_min);
        let exit = far.min_element().min(t_max);
        (enter <= exit).then_some((enter, exit))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ray::Ray;

    fn unit_box() -> Aabb {
        Aabb::new(Vec3A::splat(-1.0), Vec3A::splat(1.0))
    }

    fn slab(b: &Aabb, o: Vec3A, d: Vec3A) -> Option<(f32, f32)> {
        b.intersect(&PreparedRay::new(Ray::segment(o, d, 0.0, f32::INFINITY)), f32::INFINITY)
    }

    #[test]
    fn slabs_give_entry_and_exit() {
        let (t0, t1) = slab(&unit_box(), Vec3A::new(-5.0, 0.0, 0.0), Vec3A::X).unwrap();
        assert!((t0 - 4.0).abs() < 1e-6 && (t1 - 6.0).abs() < 1e-5);
        // Diagonal: enters at the corner region, distance sqrt(3)*(5-1).
        let d = Vec3A::ONE.normalize();
        let (t0, _) = slab(&unit_box(), Vec3A::splat(-5.0), d).unwrap();
        assert!((t0 - 4.0 * 3f32.sqrt()).abs() < 1e-5);
    }

    #[test]
    fn misses_and_boxes_behind_the_ray() {
        assert!(slab(&unit_box(), Vec3A::new(-5.0, 2.0, 0.0), Vec3A::X).is_none());
        assert!(slab(&unit_box(), Vec3A::new(5.0, 0.0, 0.0), Vec3A::X).is_none());
    }

    #[test]
    fn origin_inside_starts_at_t_min() {
        let (t0, t1) = slab(&unit_box(), Vec3A::ZERO, Vec3A::Z).unwrap();
        assert_eq!(t0, 0.0);
        assert!((t1 - 1.0).abs() < 1e-5);
    }

    #[test]
    fn axis_parallel_ray_on_a_face_plane_is_inside() {
        // The ray runs inside the plane x = 1 of the box's face: 0·inv must not be NaN.
        assert!(slab(&unit_box(), Vec3A::new(1.0, 0.0, -5.0), Vec3A::Z).is_some());
        assert!(slab(&unit_box(), Vec3A::new(1.0001, 0.0, -5.0), Vec3A::Z).is_none());
        assert!(slab(&unit_box(), Vec3A::new(-1.0, 1.0, -5.0), Vec3A::new(-0.0, 0.0, 1.0)).is_some());
        // A flat box (zero thickness) is still hit.
        let flat = Aabb::new(Vec3A::new(-1.0, 0.0, -1.0), Vec3A::new(1.0, 0.0, 1.0));
        assert!(slab(&flat, Vec3A::new(0.0, 5.0, 0.0), -Vec3A::Y).is_some());
    }

    #[test]
    fn union_and_surface_area() {
        let b = unit_box().union(&Aabb::new(Vec3A::splat(2.0), Vec3A::splat(3.0)));
        assert_eq!(b.max, Vec3A::splat(3.0));
        assert_eq!(unit_box().surface_area(), 24.0);
        assert_eq!(Aabb::EMPTY.surface_area(), 0.0);
    }
}
