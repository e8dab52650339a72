//! Acceleration structures: one file per structure, all behind one trait so the
//! renderer and the tests can swap them (`lucent render --accel`).
//!
//! Every structure must return exactly the hit the brute-force [`list::PrimitiveList`]
//! returns. Two rules make that possible: each primitive test is the same function
//! everywhere (so the same ray and primitive give the same `t` to the bit), and ties in
//! `t` go to the primitive that comes first in the scene ([`Hit::is_closer_than`]).

pub mod bvh;
mod cell_walk;
pub mod grid;
pub mod kdtree;
pub mod list;
mod mailbox;
pub mod octree;
pub mod overlap;
#[cfg(test)]
pub(crate) mod test_sets;

use crate::aabb::Aabb;
use crate::hit::Hit;
use crate::math::Vec3A;
use crate::ray::{PreparedRay, Ray};

/// How far past the closest hit so far a structure keeps looking.
///
/// A box's or cell's entry distance and a primitive's hit distance are rounded
/// differently, so a box can appear to start just beyond a hit that lies on its face, and
/// a primitive in it with an equal `t` (a tie the scene order must decide) would be
/// missed. Structures therefore cull boxes and stop early only beyond
/// `t · (1 + 2⁻¹²)`: far more than the rounding of either, and too little to cost
/// measurable speed.
#[inline(always)]
pub fn search_limit(t: f32) -> f32 {
    t * SEARCH_SLACK
}

/// [`search_limit`]'s factor.
pub const SEARCH_SLACK: f32 = 1.0 + 1.0 / 4096.0;

/// What a structure is built over, each item known by its index: the primitives of a
/// scene or of an instanced object, or the triangles of one mesh (both implement it on
/// the geometry floor above).
pub trait PrimitiveSet: Sync {
    fn count(&self) -> usize;
    fn bounds(&self, i: u32) -> Aabb;
    /// The corners of primitive `i` if it is a plain triangle: the BVH packs these into
    /// its SIMD leaves, and cells use them for the exact overlap test.
    fn triangle(&self, i: u32) -> Option<[Vec3A; 3]>;
    /// The hit of `ray` with primitive `i` in `(ray.t_min, t_max]`, with `prim = i`.
    fn intersect(&self, i: u32, ray: &PreparedRay, t_max: f32) -> Option<Hit>;
    /// The world-to-object transform of primitive `i` if it is a sphere (the `sphere`
    /// command's, an ellipsoid under a non-uniform scale), whose hit is
    /// [`crate::shape::sphere::intersect_unit_geometric`] in object space: the BVH tests
    /// such a sphere against all the rays of a packet at once.
    #[inline(always)]
    fn sphere(&self, _i: u32) -> Option<&crate::math::Affine3A> {
        None
    }
    /// Whether primitive `i` has any hit in `(ray.t_min, t_max]`.
    #[inline(always)]
    fn occludes(&self, i: u32, ray: &PreparedRay, t_max: f32) -> bool {
        self.intersect(i, ray, t_max).is_some()
    }
    /// Asks the cache for the data of primitive `i` that shading its hit reads first.
    /// The BVH calls it when it accepts a closest hit: by the time the search has ended,
    /// the line has arrived (in a large scene it is a miss on every hit otherwise).
    #[inline(always)]
    fn prefetch(&self, _i: u32) {}
}

/// Asks the cache for the lines of `x` (a hint: never faults, changes no answer).
#[inline(always)]
pub fn prefetch_value<T>(x: &T) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        let p = (x as *const T).cast::<i8>();
        // SAFETY: SSE is part of x86-64; a prefetch reads nothing the program sees.
        unsafe {
            _mm_prefetch::<_MM_HINT_T0>(p);
            if std::mem::size_of::<T>() > 1 {
                _mm_prefetch::<_MM_HINT_T0>(p.wrapping_add(std::mem::size_of::<T>() - 1));
            }
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = x;
}

/// The primitives a structure holds: every one with finite bounds, as `(index, bounds)`.
/// Unbounded ones (planes) are tested outside any structure, by the primitive set's
/// owner.
pub fn bounded<P: PrimitiveSet + ?Sized>(prims: &P) -> impl Iterator<Item = (u32, Aabb)> + '_ {
    (0..prims.count() as u32).filter_map(|i| {
        let b = prims.bounds(i);
        is_bounded(&b).then_some((i, b))
    })
}

/// Whether a primitive with these bounds belongs in a structure (see [`bounded`]).
pub fn is_bounded(b: &Aabb) -> bool {
    b.min.is_finite() && b.max.is_finite()
}

/// A structure over the primitive set `P` it was built for.
///
/// A ray that is not a line ([`Ray::is_line`]: an infinite or NaN origin or direction
/// component, or a zero direction) finds nothing in every structure, the list included.
/// Such a ray has no answer to agree on, and its infinities and NaNs would turn the
/// structures' own arithmetic against them: a box test whose distances are all NaN
/// enters every slot, the empty ones too, and a walk through cells that never reaches
/// the next wall would not end.
///
/// The answers are the list's for `t_min ≥ 0` (or NaN), as every ray the renderer traces
/// has: the box tests' widening of exit distances is conservative for boxes ahead of the
/// origin, not behind it.
pub trait Accelerator<P: PrimitiveSet + ?Sized>: Send + Sync {
    /// The closest hit with `ray.t_min < t <= ray.t_max`.
    fn closest_hit(&self, prims: &P, r: &PreparedRay) -> Option<Hit>;
    /// [`Accelerator::closest_hit`] into `out`: the same answer, written where the caller
    /// keeps it (the BVH searches in it, and so spares a copy of the hit).
    fn closest_hit_into(&self, prims: &P, r: &PreparedRay, out: &mut Option<Hit>) {
        *out = self.closest_hit(prims, r);
    }
    /// Whether anything lies in `(ray.t_min, ray.t_max]` (shadow rays).
    fn occluded(&self, prims: &P, r: &PreparedRay) -> bool;
    /// Bytes used by the structure itself (not counting the primitives).
    fn memory_bytes(&self) -> usize;
    /// The closest hits of many rays (`out[i]` for `rays[i]`), the same as
    /// [`Accelerator::closest_hit`] ray by ray; a structure that traces coherent rays
    /// together (the BVH's packets) does so here.
    fn closest_hits(&self, prims: &P, rays: &[Ray], out: &mut [Option<Hit>]) {
        for (o, r) in out.iter_mut().zip(rays) {
            *o = self.closest_hit(prims, &PreparedRay::new(*r));
        }
    }
    /// [`Accelerator::occluded`] of many rays, likewise.
    fn occluded_rays(&self, prims: &P, rays: &[Ray], out: &mut [bool]) {
        for (o, r) in out.iter_mut().zip(rays) {
            *o = self.occluded(prims, &PreparedRay::new(*r));
        }
    }
}

/// The structures `lucent render --accel` offers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AccelKind {
    Bvh,
    KdTree,
    Grid,
    Octree,
    List,
}

impl AccelKind {
    pub const ALL: [AccelKind; 5] = [
        AccelKind::Bvh,
        AccelKind::KdTree,
        AccelKind::Grid,
        AccelKind::Octree,
        AccelKind::List,
    ];
    /// The names `--accel` takes, in the order of [`AccelKind::ALL`].
    pub const NAMES: [&'static str; 5] = ["bvh", "kdtree", "grid", "octree", "list"];

    pub fn name(self) -> &'static str {
        AccelKind::NAMES[AccelKind::ALL
            .iter()
            .position(|&k| k == self)
            .expect("every kind is in ALL")]
    }

    pub fn build<P: PrimitiveSet + ?Sized + 'static>(self, prims: &P) -> Box<dyn Accelerator<P>> {
        match self {
            AccelKind::Bvh => Box::new(bvh::Bvh::build(prims)),
            AccelKind::KdTree => Box::new(kdtree::KdTree::build(prims)),
            AccelKind::Grid => Box::new(grid::Grid::build(prims)),
            AccelKind::Octree => Box::new(octree::Octree::build(prims)),
            AccelKind::List => Box::new(list::PrimitiveList::new(prims)),
        }
    }
}

impl std::str::FromStr for AccelKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        AccelKind::ALL.into_iter().find(|k| k.name() == s).ok_or_else(|| {
            format!(
                "unknown acceleration structure '{s}' (expected one of: {})",
                AccelKind::NAMES.join(", ")
            )
        })
    }
}
