//! A few `f32` lanes side by side, and the handful of operations the box test needs,
//! written once per instruction set: plain `f32` (one lane), SSE (four), AVX (eight,
//! with fused multiply–add) and AVX-512 VL (eight, comparing into a mask register). The
//! box tests of [`super::traverse`] are written once over this trait, so a wider
//! instruction set costs one implementation here, not another copy of the test.
//!
//! Every operation is the single instruction it names (`max`/`min` return the second
//! operand when either is NaN, as `maxps`/`minps` do); the implementations are
//! `#[inline(always)]` and only take effect inside functions compiled for their
//! instruction set.

/// A vector of `N` lanes.
pub trait Lanes: Copy {
    const N: usize;
    /// The result of a comparison, one flag per lane.
    type Mask: Copy;
    unsafe fn splat(x: f32) -> Self;
    /// Loads `N` floats from `p`, aligned to `N · 4` bytes.
    unsafe fn load(p: *const f32) -> Self;
    /// Stores `N` floats at `p` (no alignment needed).
    unsafe fn store(self, p: *mut f32);
    unsafe fn sub(self, other: Self) -> Self;
    unsafe fn mul(self, other: Self) -> Self;
    /// `self > other ? self : other`.
    unsafe fn max(self, other: Self) -> Self;
    /// `self < other ? self : other`.
    unsafe fn min(self, other: Self) -> Self;
    unsafe fn le(self, other: Self) -> Self::Mask;
    unsafe fn and(a: Self::Mask, b: Self::Mask) -> Self::Mask;
    unsafe fn all() -> Self::Mask;
    /// Bit `i` set where lane `i` is set.
    unsafe fn bits(m: Self::Mask) -> u32;
}

/// Lanes with a fused multiply–subtract.
pub trait FusedLanes: Lanes {
    /// `self · b − c` with one rounding.
    unsafe fn mul_sub(self, b: Self, c: Self) -> Self;
}

/// One lane: the portable fallback.
impl Lanes for f32 {
    const N: usize = 1;
    type Mask = bool;
    #[inline(always)]
    unsafe fn splat(x: f32) -> f32 {
        x
    }
    #[inline(always)]
    unsafe fn load(p: *const f32) -> f32 {
        *p
    }
    #[inline(always)]
    unsafe fn store(self, p: *mut f32) {
        *p = self
    }
    #[inline(always)]
    unsafe fn sub(self, other: f32) -> f32 {
        self - other
    }
    #[inline(always)]
    unsafe fn mul(self, other: f32) -> f32 {
        self * other
    }
    #[inline(always)]
    unsafe fn max(self, other: f32) -> f32 {
        if self > other {
            self
        } else {
            other
        }
    }
    #[inline(always)]
    unsafe fn min(self, other: f32) -> f32 {
        if self < other {
            self
        } else {
            other
        }
    }
    #[inline(always)]
    unsafe fn le(self, other: f32) -> bool {
        self <= other
    }
    #[inline(always)]
    unsafe fn and(a: bool, b: bool) -> bool {
        a & b
    }
    #[inline(always)]
    unsafe fn all() -> bool {
        true
    }
    #[inline(always)]
    unsafe fn bits(m: bool) -> u32 {
        m as u32
    }
}

#[cfg(target_arch = "x86_64")]
pub use x86::{Avx, Avx512Vl8, Sse};

#[cfg(target_arch = "x86_64")]
mod x86 {
    use super::{FusedLanes, Lanes};
    use std::arch::x86_64::*;

    /// A [`Lanes`] type over an x86 vector, from the intrinsic of each operation; `$mask`
    /// is what a comparison gives (a vector of lane masks, or an AVX-512 mask register).
    macro_rules! x86_lanes {
        (
            $(#[$doc:meta])* $name:ident($vector:ty, $mask:ty, $n:literal):
            splat $splat:expr, load $load:expr, store $store:expr,
            [$($op:ident $op_fn:expr),+],
            le $le:expr, and $and:expr, all $all:expr, bits $bits:expr
        ) => {
            $(#[$doc])*
            #[derive(Clone, Copy)]
            pub struct $name($vector);

            impl Lanes for $name {
                const N: usize = $n;
                type Mask = $mask;
                #[inline(always)]
                unsafe fn splat(x: f32) -> $name {
                    $name($splat(x))
                }
                #[inline(always)]
                unsafe fn load(p: *const f32) -> $name {
                    $name($load(p))
                }
                #[inline(always)]
                unsafe fn store(self, p: *mut f32) {
                    $store(p, self.0)
                }
                $(
                    #[inline(always)]
                    unsafe fn $op(self, other: $name) -> $name {
                        $name($op_fn(self.0, other.0))
                    }
                )+
                #[inline(always)]
                unsafe fn le(self, other: $name) -> $mask {
                    $le(self.0, other.0)
                }
                #[inline(always)]
                unsafe fn and(a: $mask, b: $mask) -> $mask {
                    $and(a, b)
                }
                #[inline(always)]
                unsafe fn all() -> $mask {
                    $all
                }
                #[inline(always)]
                unsafe fn bits(m: $mask) -> u32 {
                    $bits(m) as u32
                }
            }
        };
    }

    x86_lanes! {
        /// Four lanes (SSE, part of every x86-64).
        Sse(__m128, __m128, 4):
        splat _mm_set1_ps, load _mm_load_ps, store _mm_storeu_ps,
        [sub _mm_sub_ps, mul _mm_mul_ps, max _mm_max_ps, min _mm_min_ps],
        le _mm_cmple_ps, and _mm_and_ps, all _mm_castsi128_ps(_mm_set1_epi32(-1)), bits _mm_movemask_ps
    }

    x86_lanes! {
        /// Eight lanes (AVX; the fused form needs FMA, which every AVX2 CPU has).
        Avx(__m256, __m256, 8):
        splat _mm256_set1_ps, load _mm256_load_ps, store _mm256_storeu_ps,
        [sub _mm256_sub_ps, mul _mm256_mul_ps, max _mm256_max_ps, min _mm256_min_ps],
        le _mm256_cmp_ps::<_CMP_LE_OQ>, and _mm256_and_ps,
        all _mm256_castsi256_ps(_mm256_set1_epi32(-1)), bits _mm256_movemask_ps
    }

    impl FusedLanes for Avx {
        #[inline(always)]
        unsafe fn mul_sub(self, b: Avx, c: Avx) -> Avx {
            Avx(_mm256_fmsub_ps(self.0, b.0, c.0))
        }
    }

    x86_lanes! {
        /// Eight lanes with AVX-512 VL: [`Avx`]'s operations, but comparisons into a mask
        /// register. (On an Intel Xeon, `Avx` compiled for AVX-512, which compares into a
        /// vector and moves its signs out, traced closest hits 1.17× slower over nodes of
        /// sixteen. A sixteen-lane type over `__m512`, a whole node in one group, traced
        /// any-hit queries 1.07–1.19× slower there; on an AMD EPYC, Zen 4, it had been
        /// 1.037× faster than two groups of `Avx`: see `run_avx512`.)
        Avx512Vl8(__m256, __mmask8, 8):
        splat _mm256_set1_ps, load _mm256_load_ps, store _mm256_storeu_ps,
        [sub _mm256_sub_ps, mul _mm256_mul_ps, max _mm256_max_ps, min _mm256_min_ps],
        le _mm256_cmp_ps_mask::<_CMP_LE_OQ>, and (|a: __mmask8, b: __mmask8| a & b), all 0xff,
        bits std::convert::identity
    }

    impl FusedLanes for Avx512Vl8 {
        #[inline(always)]
        unsafe fn mul_sub(self, b: Avx512Vl8, c: Avx512Vl8) -> Avx512Vl8 {
            Avx512Vl8(_mm256_fmsub_ps(self.0, b.0, c.0))
        }
    }
}
