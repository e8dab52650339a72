//! What the BVH builder moves around: one primitive's box and index in 32 bytes, read
//! with aligned vector loads.

use crate::aabb::Aabb;
use crate::math::Vec3A;

/// A primitive's box and index, as the builder moves them around.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
pub struct BuildRef {
    pub lo: [f32; 3],
    pub prim: u32,
    pub hi: [f32; 3],
    /// The reference's bin along x, y and z at the last binning (8 bits each), so that
    /// the partition reads its side instead of computing it again.
    pub(super) bins: u32,
}

impl BuildRef {
    pub fn new(b: &Aabb, prim: u32) -> BuildRef {
        BuildRef {
            lo: b.min.into(),
            prim,
            hi: b.max.into(),
            bins: 0,
        }
    }
    #[inline(always)]
    pub(super) fn lo(&self) -> Vec3A {
        load_xyz::<0>(self)
    }
    #[inline(always)]
    pub(super) fn hi(&self) -> Vec3A {
        load_xyz::<1>(self)
    }
    pub fn bounds(&self) -> Aabb {
        Aabb {
            min: self.lo(),
            max: self.hi(),
        }
    }
    /// Twice the centroid (the factor ½ cancels in every use).
    #[inline(always)]
    pub(super) fn centroid2(&self) -> Vec3A {
        self.lo() + self.hi()
    }
}

/// Half `HALF` of a reference (0: `lo` and `prim`, 1: `hi` and `bins`) as a vector of
/// its three floats: one aligned load on x86-64, the fourth lane cleared (the builder
/// reads references some hundred million times; assembling three scalars costs more).
#[inline(always)]
fn load_xyz<const HALF: usize>(r: &BuildRef) -> Vec3A {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: a `BuildRef` is 32 bytes, 32-byte aligned, with `lo` at offset 0 and `hi`
    // at 16 (asserted below): both halves are aligned, readable 16-byte groups; the
    // fourth float of each (`prim` or `bins`) is masked off.
    unsafe {
        use std::arch::x86_64::*;
        let xyz = _mm_castsi128_ps(_mm_set_epi32(0, -1, -1, -1));
        let half = (r as *const BuildRef as *const f32).add(4 * HALF);
        Vec3A::from(_mm_and_ps(_mm_load_ps(half), xyz))
    }
    #[cfg(not(target_arch = "x86_64"))]
    Vec3A::from_array(if HALF == 0 { r.lo } else { r.hi })
}

const _: () = assert!(
    std::mem::offset_of!(BuildRef, lo) == 0
        && std::mem::offset_of!(BuildRef, hi) == 16
        && std::mem::size_of::<BuildRef>() == 32
);

impl BuildRef {
    /// Notes the reference's bins along x, y and z (each below 256).
    #[inline(always)]
    pub(super) fn set_bins(&mut self, b: [usize; 3]) {
        self.bins = (b[0] | b[1] << 8 | b[2] << 16) as u32;
    }

    /// The reference's bin along `axis` at the last binning.
    #[inline(always)]
    pub(super) fn bin(&self, axis: usize) -> usize {
        (self.bins >> (8 * axis)) as usize & 0xff
    }
}
