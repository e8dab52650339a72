//! Rays, and the per-ray data that traversal precomputes once.

use crate::math::{max_abs_axis, Vec3A};
use glam::BVec3A;

/// The distance a secondary ray skips to avoid hitting the surface it leaves
/// (SCENE_FORMAT.md §4.2: world units, unit-length directions).
pub const EPSILON: f32 = 1e-4;

#[derive(Clone, Copy, Debug)]
pub struct Ray {
    pub origin: Vec3A,
    /// Unit length for every ray the renderer traces.
    pub dir: Vec3A,
    /// Hits count only for `t_min < t <= t_max`.
    pub t_min: f32,
    pub t_max: f32,
}

impl Ray {
    pub fn new(origin: Vec3A, dir: Vec3A) -> Ray {
        Ray {
            origin,
            dir,
            t_min: EPSILON,
            t_max: f32::INFINITY,
        }
    }

    pub fn segment(origin: Vec3A, dir: Vec3A, t_min: f32, t_max: f32) -> Ray {
        Ray {
            origin,
            dir,
            t_min,
            t_max,
        }
    }

    pub fn at(&self, t: f32) -> Vec3A {
        self.origin + self.dir * t
    }

    /// Whether the ray describes a line: a finite origin and a finite, non-zero
    /// direction. Structures find nothing along any other ray
    /// ([`crate::accel::Accelerator`]).
    #[inline]
    pub fn is_line(&self) -> bool {
        self.origin.is_finite() && self.dir.is_finite() && self.dir != Vec3A::ZERO
    }
}

/// A coordinate axis. As an index it is known to be below three, so indexing a
/// three-element array or a vector by it needs no bounds check (the traversal's leaf
/// test indexes by the ray's axes at every call).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum Axis {
    X = 0,
    Y = 1,
    Z = 2,
}

impl Axis {
    pub const ALL: [Axis; 3] = [Axis::X, Axis::Y, Axis::Z];

    /// `0`, `1` or `2`.
    #[inline(always)]
    pub const fn index(self) -> usize {
        self as usize
    }

    /// The component of `v` along this axis.
    #[inline(always)]
    pub fn of(self, v: &Vec3A) -> f32 {
        AsRef::<[f32; 3]>::as_ref(v)[self.index()]
    }
}

/// `[kx, ky]` for the dominant axis `kz` (index `2·kz`), and exchanged for a direction
/// that points down `kz` (index `2·kz + 1`): the next two axes in cyclic order.
pub(crate) const AXES_AROUND: [[Axis; 2]; 6] = {
    use Axis::*;
    [[Y, Z], [Z, Y], [Z, X], [X, Z], [X, Y], [Y, X]]
};

/// A ray with what every box and triangle test needs, computed once per ray: the
/// reciprocal direction for slab tests and the shear of the watertight triangle test
/// (Woop, Benthin & Wald 2013).
#[derive(Clone, Copy, Debug)]
pub struct PreparedRay {
    pub ray: Ray,
    /// `1/dir`, with zero components replaced by `+f32::MAX` so that `0 · inv` is never
    /// NaN in a slab test (the sign of a zero must not matter: a ray that does not move
    /// along an axis is inside that slab exactly when its origin is).
    pub inv_dir: Vec3A,
    /// The axes along which the ray does not move (`dir` component ±0).
    pub zero_axes: BVec3A,
    /// Axis permutation: `kz` is the dominant axis of the direction.
    pub kx: Axis,
    pub ky: Axis,
    pub kz: Axis,
    /// The origin's components along `kx`, `ky`, `kz` (picked once per ray, not once
    /// per triangle: choosing by a per-ray axis is a branch or a round trip through memory).
    pub origin_k: [f32; 3],
    /// Shear constants that map the ray to +z.
    pub sx: f32,
    pub sy: f32,
    pub sz: f32,
}

impl PreparedRay {
    /// The same ray with another far limit (what a structure inside a primitive is asked).
    #[inline(always)]
    pub fn with_t_max(&self, t_max: f32) -> PreparedRay {
        let mut r = *self;
        r.ray.t_max = t_max;
        r
    }

    #[inline]
    pub fn new(ray: Ray) -> PreparedRay {
        // Rebuilt field by field: a copy of the whole struct read its last 16 bytes (the
        // two limits and padding) in one load, which the CPU cannot forward from the
        // narrower stores of a ray its caller has just made.
        let ray = Ray::segment(ray.origin, ray.dir, ray.t_min, ray.t_max);
        let d = ray.dir;
        // One vector division; the rare zero or subnormal components are fixed after.
        let mut inv_dir = Vec3A::ONE / d;
        if !inv_dir.is_finite() {
            let fix = |c: f32, r: f32| {
                if r.is_finite() {
                    r
                } else if c == 0.0 {
                    f32::MAX
                } else {
                    f32::MAX.copysign(c)
                }
            };
            inv_dir = Vec3A::new(fix(d.x, inv_dir.x), fix(d.y, inv_dir.y), fix(d.z, inv_dir.z));
        }
        let k = max_abs_axis(d);
        // Keep the winding of the projected triangle: exchange kx and ky when looking
        // down −z. The axes and the components are picked without a branch: for
        // incoherent rays each branch on the axis was mispredicted a third of the time,
        // and made a query that misses the scene about 30 % slower. (Components are read
        // by index from each vector's own bytes: building arrays of them took a shuffle
        // per component.)
        let negative = d.cmplt(Vec3A::ZERO).bitmask() as usize >> k & 1;
        let [kx, ky] = AXES_AROUND[2 * k + negative];
        let kz = Axis::ALL[k];
        // `1/d[kz]` is `inv_dir[kz]`: the dominant component of a non-zero direction is
        // not zero, so its reciprocal was not replaced.
        let sz = kz.of(&inv_dir);
        PreparedRay {
            ray,
            inv_dir,
            zero_axes: d.cmpeq(Vec3A::ZERO),
            kx,
            ky,
            kz,
            origin_k: [kx.of(&ray.origin), ky.of(&ray.origin), kz.of(&ray.origin)],
            sx: kx.of(&d) * sz,
            sy: ky.of(&d) * sz,
            sz,
        }
    }
}
