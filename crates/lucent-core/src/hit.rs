//! What traversal reports about the closest hit, and what shading needs from it.

use crate::math::{Color, Vec3A};
use glam::Vec2;

/// The closest hit found by an acceleration structure.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub t: f32,
    /// Index of the primitive in scene order.
    pub prim: u32,
    /// Barycentric weights of the second and third triangle vertex (0 for other shapes).
    pub b1: f32,
    pub b2: f32,
    /// Where inside `prim` the hit lies, for primitives made of others: the triangle of a
    /// mesh, or the primitive of an instanced object and then (if that is a mesh) its
    /// triangle. Unused levels are [`Hit::NONE`].
    pub inner: [u32; 2],
}

impl Hit {
    /// An unused level of [`Hit::inner`].
    pub const NONE: u32 = u32::MAX;

    /// A hit on a simple primitive (nothing inside it).
    #[inline(always)]
    pub fn new(t: f32, prim: u32, b1: f32, b2: f32) -> Hit {
        Hit {
            t,
            prim,
            b1,
            b2,
            inner: [Hit::NONE; 2],
        }
    }

    /// This hit seen from one level up: it lies inside primitive `outer`.
    #[inline(always)]
    pub fn within(self, outer: u32) -> Hit {
        debug_assert!(self.inner[1] == Hit::NONE, "hits nest at most three levels deep");
        Hit {
            prim: outer,
            inner: [self.prim, self.inner[0]],
            ..self
        }
    }

    /// The hit one level down, as the primitive containing it sees it.
    #[inline(always)]
    pub fn inside(self) -> Hit {
        Hit {
            prim: self.inner[0],
            inner: [self.inner[1], Hit::NONE],
            ..self
        }
    }

    /// The tie-breaking rule every acceleration structure shares, so that all of them
    /// return the same hit as the brute-force list: the smaller `t` wins, and for equal
    /// `t` the primitive that comes first in the scene.
    #[inline(always)]
    pub fn is_closer_than(t: f32, prim: u32, best: &Option<Hit>) -> bool {
        match best {
            None => true,
            Some(b) => t < b.t || (t == b.t && prim < b.prim),
        }
    }
}

/// Everything shading needs about a surface point.
#[derive(Clone, Copy, Debug)]
pub struct SurfacePoint {
    pub point: Vec3A,
    /// A bound on the rounding error of `point`, per axis (see [`crate::spawn`]).
    pub error: Vec3A,
    /// Unit normal of the true surface (the flat triangle, the exact sphere), turned to
    /// the side the shading normal faces; rays leave along it (see [`crate::spawn`]).
    pub geometric_normal: Vec3A,
    /// Unit shading normal, as the scene defines it (never flipped toward the viewer).
    pub normal: Vec3A,
    /// Texture coordinates (conventions in [`crate::shape::texcoord`]).
    pub uv: Vec2,
    pub material: u32,
    /// The light this point emits as, if it belongs to an emitting primitive (index into
    /// the scene's lights).
    pub light: Option<u32>,
}

/// Pixel value of a ray that hits nothing.
pub const BACKGROUND: Color = Color::ZERO;
