//! One `f32` per ray of a packet, side by side: eight lanes with AVX2, sixteen with
//! AVX-512 (F, VL, BW). The packet traversal of [`super::ray_packet`] and the packet
//! triangle and sphere tests of [`super::ray_triangle`] and [`super::ray_sphere`] are
//! written once over this trait.
//!
//! Comparisons return plain bit masks (bit `i` for lane `i`): AVX-512 produces them
//! directly in mask registers, AVX2 through `movemask`. Every operation is the single
//! IEEE instruction it names, and only the box test uses the fused multiply–subtract, so
//! the triangle and sphere tests' lanes compute exactly what the scalar code computes for
//! its ray. The implementations are `#[inline(always)]` and only take effect inside
//! functions compiled for their instruction set (not inside a closure there, which is a
//! function of its own).

use crate::ray::Ray;

/// A vector of one `f32` per ray.
pub trait RayLanes: Copy {
    const N: usize;
    /// Lanes that are set: `(1 << N) - 1`.
    const ALL: u32;
    unsafe fn splat(x: f32) -> Self;
    /// Loads `N` floats from `p` (no alignment needed).
    unsafe fn load(p: *const f32) -> Self;
    /// Stores `N` floats at `p` (no alignment needed).
    unsafe fn store(self, p: *mut f32);
    /// Lane `i` is `*base.add(stride · min(i, last))`: one field of consecutive records.
    unsafe fn gather(base: *const f32, stride: usize, last: usize) -> Self;
    /// Lane `i` is the `f32` at byte `field` of `rays[min(i, len − 1)]` (a field's
    /// `offset_of!` in [`Ray`]). The gather's base pointer is made from the whole slice,
    /// so that it may reach every ray: one made from a reference to the first ray's field
    /// would reach that field alone.
    #[inline(always)]
    unsafe fn gather_field(rays: &[Ray], field: usize) -> Self {
        debug_assert!(!rays.is_empty() && field + 4 <= std::mem::size_of::<Ray>());
        let base = rays.as_ptr().cast::<u8>().add(field).cast::<f32>();
        Self::gather(base, std::mem::size_of::<Ray>() / 4, rays.len() - 1)
    }
    /// `|self|`.
    unsafe fn abs(self) -> Self;
    unsafe fn add(self, o: Self) -> Self;
    unsafe fn sub(self, o: Self) -> Self;
    unsafe fn mul(self, o: Self) -> Self;
    unsafe fn div(self, o: Self) -> Self;
    /// The correctly rounded square root (only the sphere test uses it).
    unsafe fn sqrt(self) -> Self;
    /// `self · b − c` with one rounding (fused; only the box test uses it).
    unsafe fn mul_sub(self, b: Self, c: Self) -> Self;
    /// `self < o ? self : o` (`o` when either is NaN, as `minps`).
    unsafe fn min(self, o: Self) -> Self;
    /// `self > o ? self : o` (`o` when either is NaN, as `maxps`).
    unsafe fn max(self, o: Self) -> Self;
    /// Ordered comparisons (false where either lane is NaN).
    unsafe fn le(self, o: Self) -> u32;
    unsafe fn gt(self, o: Self) -> u32;
    unsafe fn eq(self, o: Self) -> u32;
    /// Lanes whose sign bit is set (NaN lanes included, whatever they mean).
    unsafe fn sign_bits(self) -> u32;
    /// `a` in the lanes of `mask`, `b` elsewhere.
    unsafe fn select(mask: u32, a: Self, b: Self) -> Self;
    /// Bitwise `self ^ o` and `self | o` of the lanes' bit patterns.
    unsafe fn xor(self, o: Self) -> Self;
    unsafe fn or(self, o: Self) -> Self;
    /// The largest and the smallest of the lanes of `mask` (not empty).
    unsafe fn max_of(self, mask: u32) -> f32;
    unsafe fn min_of(self, mask: u32) -> f32;
}

#[cfg(target_arch = "x86_64")]
pub use x86::{Rays16, Rays8};

#[cfg(target_arch = "x86_64")]
mod x86 {
    use super::RayLanes;
    use std::arch::x86_64::*;

    /// The lane-wise arithmetic, each the one intrinsic it names.
    macro_rules! binary_ops {
        ($t:ident: $($op:ident $f:ident),+) => {
            $(
                #[inline(always)]
                unsafe fn $op(self, o: Self) -> Self {
                    $t($f(self.0, o.0))
                }
            )+
        };
    }

    /// Eight rays (AVX2).
    #[derive(Clone, Copy)]
    pub struct Rays8(__m256);

    impl RayLanes for Rays8 {
        const N: usize = 8;
        const ALL: u32 = 0xff;
        #[inline(always)]
        unsafe fn splat(x: f32) -> Self {
            Rays8(_mm256_set1_ps(x))
        }
        #[inline(always)]
        unsafe fn load(p: *const f32) -> Self {
            Rays8(_mm256_loadu_ps(p))
        }
        #[inline(always)]
        unsafe fn store(self, p: *mut f32) {
            _mm256_storeu_ps(p, self.0)
        }
        #[inline(always)]
        unsafe fn gather(base: *const f32, stride: usize, last: usize) -> Self {
            let lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
            let index = _mm256_min_epi32(lane, _mm256_set1_epi32(last as i32));
            Rays8(_mm256_i32gather_ps::<4>(
                base,
                _mm256_mullo_epi32(index, _mm256_set1_epi32(stride as i32)),
            ))
        }
        #[inline(always)]
        unsafe fn abs(self) -> Self {
            Rays8(_mm256_andnot_ps(_mm256_set1_ps(-0.0), self.0))
        }
        binary_ops!(Rays8: add _mm256_add_ps, sub _mm256_sub_ps, mul _mm256_mul_ps, div _mm256_div_ps, min _mm256_min_ps, max _mm256_max_ps);
        #[inline(always)]
        unsafe fn sqrt(self) -> Self {
            Rays8(_mm256_sqrt_ps(self.0))
        }
        #[inline(always)]
        unsafe fn mul_sub(self, b: Self, c: Self) -> Self {
            Rays8(_mm256_fmsub_ps(self.0, b.0, c.0))
        }
        #[inline(always)]
        unsafe fn le(self, o: Self) -> u32 {
            _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(self.0, o.0)) as u32
        }
        #[inline(always)]
        unsafe fn gt(self, o: Self) -> u32 {
            _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_GT_OQ>(self.0, o.0)) as u32
        }
        #[inline(always)]
        unsafe fn eq(self, o: Self) -> u32 {
            _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_EQ_OQ>(self.0, o.0)) as u32
        }
        #[inline(always)]
        unsafe fn sign_bits(self) -> u32 {
            _mm256_movemask_ps(self.0) as u32
        }
        #[inline(always)]
        unsafe fn select(mask: u32, a: Self, b: Self) -> Self {
            let lane = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
            let m = _mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32(mask as i32), lane), lane);
            Rays8(_mm256_blendv_ps(b.0, a.0, _mm256_castsi256_ps(m)))
        }
        #[inline(always)]
        unsafe fn xor(self, o: Self) -> Self {
            Rays8(_mm256_xor_ps(self.0, o.0))
        }
        #[inline(always)]
        unsafe fn or(self, o: Self) -> Self {
            Rays8(_mm256_or_ps(self.0, o.0))
        }
        #[inline(always)]
        unsafe fn max_of(self, mask: u32) -> f32 {
            let v = Self::select(mask, self, Self::splat(f32::NEG_INFINITY)).0;
            let m = _mm_max_ps(_mm256_castps256_ps128(v), _mm256_extractf128_ps::<1>(v));
            let m = _mm_max_ps(m, _mm_movehl_ps(m, m));
            _mm_cvtss_f32(_mm_max_ss(m, _mm_shuffle_ps::<1>(m, m)))
        }
        #[inline(always)]
        unsafe fn min_of(self, mask: u32) -> f32 {
            let v = Self::select(mask, self, Self::splat(f32::INFINITY)).0;
            let m = _mm_min_ps(_mm256_castps256_ps128(v), _mm256_extractf128_ps::<1>(v));
            let m = _mm_min_ps(m, _mm_movehl_ps(m, m));
            _mm_cvtss_f32(_mm_min_ss(m, _mm_shuffle_ps::<1>(m, m)))
        }
    }

    /// Sixteen rays (AVX-512 F; comparisons straight into mask registers).
    #[derive(Clone, Copy)]
    pub struct Rays16(__m512);

    #[inline(always)]
    unsafe fn bits512(x: __m512) -> __m512i {
        _mm512_castps_si512(x)
    }

    impl RayLanes for Rays16 {
        const N: usize = 16;
        const ALL: u32 = 0xffff;
        #[inline(always)]
        unsafe fn splat(x: f32) -> Self {
            Rays16(_mm512_set1_ps(x))
        }
        #[inline(always)]
        unsafe fn load(p: *const f32) -> Self {
            Rays16(_mm512_loadu_ps(p))
        }
        #[inline(always)]
        unsafe fn store(self, p: *mut f32) {
            _mm512_storeu_ps(p, self.0)
        }
        #[inline(always)]
        unsafe fn gather(base: *const f32, stride: usize, last: usize) -> Self {
            let lane = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
            let index = _mm512_min_epi32(lane, _mm512_set1_epi32(last as i32));
            Rays16(_mm512_i32gather_ps::<4>(
                _mm512_mullo_epi32(index, _mm512_set1_epi32(stride as i32)),
                base,
            ))
        }
        #[inline(always)]
        unsafe fn abs(self) -> Self {
            Rays16(_mm512_abs_ps(self.0))
        }
        binary_ops!(Rays16: add _mm512_add_ps, sub _mm512_sub_ps, mul _mm512_mul_ps, div _mm512_div_ps, min _mm512_min_ps, max _mm512_max_ps);
        #[inline(always)]
        unsafe fn sqrt(self) -> Self {
            Rays16(_mm512_sqrt_ps(self.0))
        }
        #[inline(always)]
        unsafe fn mul_sub(self, b: Self, c: Self) -> Self {
            Rays16(_mm512_fmsub_ps(self.0, b.0, c.0))
        }
        #[inline(always)]
        unsafe fn le(self, o: Self) -> u32 {
            _mm512_cmp_ps_mask::<_CMP_LE_OQ>(self.0, o.0) as u32
        }
        #[inline(always)]
        unsafe fn gt(self, o: Self) -> u32 {
            _mm512_cmp_ps_mask::<_CMP_GT_OQ>(self.0, o.0) as u32
        }
        #[inline(always)]
        unsafe fn eq(self, o: Self) -> u32 {
            _mm512_cmp_ps_mask::<_CMP_EQ_OQ>(self.0, o.0) as u32
        }
        #[inline(always)]
        unsafe fn sign_bits(self) -> u32 {
            _mm512_cmplt_epi32_mask(bits512(self.0), _mm512_setzero_si512()) as u32
        }
        #[inline(always)]
        unsafe fn select(mask: u32, a: Self, b: Self) -> Self {
            Rays16(_mm512_mask_blend_ps(mask as __mmask16, b.0, a.0))
        }
        #[inline(always)]
        unsafe fn xor(self, o: Self) -> Self {
            Rays16(_mm512_castsi512_ps(_mm512_xor_si512(bits512(self.0), bits512(o.0))))
        }
        #[inline(always)]
        unsafe fn or(self, o: Self) -> Self {
            Rays16(_mm512_castsi512_ps(_mm512_or_si512(bits512(self.0), bits512(o.0))))
        }
        #[inline(always)]
        unsafe fn max_of(self, mask: u32) -> f32 {
            _mm512_mask_reduce_max_ps(mask as __mmask16, self.0)
        }
        #[inline(always)]
        unsafe fn min_of(self, mask: u32) -> f32 {
            _mm512_mask_reduce_min_ps(mask as __mmask16, self.0)
        }
    }
}
