//! Eight consecutive draws of the padded Sobol sampler made at once: what
//! [`super::Sampler`] hands out for `sampler sobol`, the same numbers to the bit as eight
//! calls of [`super::sobol::sample2`], computed side by side.
//!
//! A draw's numbers depend on the pixel's key, the draw's dimension and the sample's
//! index, never on what the path did with the draws before it, so a sample's draws can
//! be made before they are asked for. One draw costs about a hundred scalar integer
//! instructions (a 64-bit hash, three scrambles of five multiplies, three bit reversals,
//! which x86-64 has no instruction for); with AVX2 the eight lanes of one vector each
//! make one draw, for little more than one draw's instructions. A path tracer's sample
//! asks for eight to a dozen draws, which made them a tenth of its instructions.
//!
//! Without AVX2 (or off x86-64) the block is made one draw at a time by the scalar code.

use super::sobol::{self, Seeds};

/// Draws made at once.
pub const BLOCK: usize = 8;

/// The numbers of draws `d .. d + BLOCK` of one sample (the first at dimension `d + 1`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Block {
    pub x: [f32; BLOCK],
    pub y: [f32; BLOCK],
}

/// The hash that picks the scrambles of the draw at `dimension` (counted from 1) of the
/// sample whose key is `key`: SplitMix64's finaliser of the two.
#[inline(always)]
pub fn draw_hash(key: u64, dimension: u64) -> u64 {
    super::mix(key ^ dimension.wrapping_mul(DIMENSION_STEP))
}

const DIMENSION_STEP: u64 = 0xd1b5_4a32_d192_ed03;

/// The scrambles of a draw's Sobol sequence, cut from its 64-bit hash.
#[inline(always)]
pub fn seeds(h: u64) -> Seeds {
    Seeds {
        index: h as u32,
        x: (h >> 32) as u32,
        // The middle bits, turned: as well mixed as the others, and not equal to either.
        y: ((h >> 16) as u32).rotate_left(SEED_Y_ROTATION) ^ SEED_Y_XOR,
    }
}

const SEED_Y_ROTATION: u32 = 7;
const SEED_Y_XOR: u32 = 0x9e37_79b9;

/// Draws `first_dimension ..` (eight of them) of the sample of index
/// `i_reversed.reverse_bits()` whose key is `key`.
#[inline]
pub fn draws(key: u64, first_dimension: u64, i_reversed: u32) -> Block {
    #[cfg(target_arch = "x86_64")]
    if std::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2.
        return unsafe { draws_avx2(key, first_dimension, i_reversed) };
    }
    draws_scalar(key, first_dimension, i_reversed)
}

/// The block one draw at a time: the reference the vector code must equal.
pub fn draws_scalar(key: u64, first_dimension: u64, i_reversed: u32) -> Block {
    let mut b = Block::default();
    for k in 0..BLOCK {
        let (x, y) = sobol::sample2(
            i_reversed,
            seeds(draw_hash(key, first_dimension.wrapping_add(k as u64))),
        );
        b.x[k] = x;
        b.y[k] = y;
    }
    b
}

/// [`draws_scalar`] with one draw in each 32-bit lane of an AVX2 vector (the hashes in
/// two vectors of four 64-bit lanes).
///
/// # Safety
/// The CPU must have AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn draws_avx2(key: u64, first_dimension: u64, i_reversed: u32) -> Block {
    use std::arch::x86_64::*;

    // 64-bit lanes times a constant, modulo 2⁶⁴ (AVX2 multiplies 32 × 32 → 64 bits only):
    // the low product plus the two cross products shifted up.
    let mul64 = |a: __m256i, c: u64| -> __m256i {
        let (c_lo, c_hi) = (
            _mm256_set1_epi64x(c as u32 as i64),
            _mm256_set1_epi64x((c >> 32) as i64),
        );
        let lo = _mm256_mul_epu32(a, c_lo);
        let cross = _mm256_add_epi64(
            _mm256_mul_epu32(_mm256_srli_epi64::<32>(a), c_lo),
            _mm256_mul_epu32(a, c_hi),
        );
        _mm256_add_epi64(lo, _mm256_slli_epi64::<32>(cross))
    };
    // `super::mix` (the same shifts and multipliers).
    let [m1, m2] = super::MIX_MULTIPLIERS;
    let mix = |mut z: __m256i| -> __m256i {
        z = mul64(_mm256_xor_si256(z, _mm256_srli_epi64::<30>(z)), m1);
        z = mul64(_mm256_xor_si256(z, _mm256_srli_epi64::<27>(z)), m2);
        _mm256_xor_si256(z, _mm256_srli_epi64::<31>(z))
    };
    // The hashes of draws 0–3 and 4–7: `dimension · step` as the first one's product plus
    // k · step (the same value modulo 2⁶⁴).
    let base = _mm256_set1_epi64x(first_dimension.wrapping_mul(DIMENSION_STEP) as i64);
    let steps = |k: u64| DIMENSION_STEP.wrapping_mul(k) as i64;
    let key_v = _mm256_set1_epi64x(key as i64);
    let hash = |k: u64| {
        let offsets = _mm256_setr_epi64x(steps(k), steps(k + 1), steps(k + 2), steps(k + 3));
        mix(_mm256_xor_si256(key_v, _mm256_add_epi64(base, offsets)))
    };
    let (h0, h1) = (hash(0), hash(4));

    // The low and high 32 bits of the eight hashes, each as a vector of eight lanes in
    // draw order: within each 128-bit half the low words first, then the halves of the
    // two vectors put side by side.
    let split = |v: __m256i| _mm256_permutevar8x32_epi32(v, _mm256_setr_epi32(0, 2, 4, 6, 1, 3, 5, 7));
    let low_words = |a: __m256i, b: __m256i| _mm256_permute2x128_si256::<0x20>(split(a), split(b));
    let high_words = |a: __m256i, b: __m256i| _mm256_permute2x128_si256::<0x31>(split(a), split(b));
    let seed_index = low_words(h0, h1);
    let seed_x = high_words(h0, h1);
    let middle = low_words(_mm256_srli_epi64::<16>(h0), _mm256_srli_epi64::<16>(h1));
    let seed_y = _mm256_xor_si256(
        _mm256_or_si256(
            _mm256_slli_epi32::<{ SEED_Y_ROTATION as i32 }>(middle),
            _mm256_srli_epi32::<{ 32 - SEED_Y_ROTATION as i32 }>(middle),
        ),
        _mm256_set1_epi32(SEED_Y_XOR as i32),
    );

    let s = reverse_bits(scramble(_mm256_set1_epi32(i_reversed as i32), seed_index));
    let x = reverse_bits(scramble(s, seed_x));
    let y = reverse_bits(scramble(sobol_dimension_1(s), seed_y));
    let to_unit = |v: __m256i| {
        _mm256_mul_ps(
            _mm256_cvtepi32_ps(_mm256_srli_epi32::<8>(v)),
            _mm256_set1_ps(1.0 / (1u32 << 24) as f32),
        )
    };
    let mut b = Block::default();
    _mm256_storeu_ps(b.x.as_mut_ptr(), to_unit(x));
    _mm256_storeu_ps(b.y.as_mut_ptr(), to_unit(y));
    b
}

/// [`sobol::scramble_reversed`] in each lane.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
unsafe fn scramble(mut x: std::arch::x86_64::__m256i, seed: std::arch::x86_64::__m256i) -> std::arch::x86_64::__m256i {
    use std::arch::x86_64::*;
    let times = |v: __m256i, c: u32| _mm256_mullo_epi32(v, _mm256_set1_epi32(c as i32));
    let [c0, c1, c2] = sobol::SCRAMBLE_CONSTANTS;
    x = _mm256_xor_si256(x, times(x, c0));
    x = _mm256_add_epi32(x, seed);
    x = _mm256_mullo_epi32(x, _mm256_or_si256(_mm256_srli_epi32::<16>(seed), _mm256_set1_epi32(1)));
    x = _mm256_xor_si256(x, times(x, c1));
    _mm256_xor_si256(x, times(x, c2))
}

/// The bits of each 32-bit lane in reverse order: the bytes reversed by one shuffle, the
/// bits of each byte by two table lookups of a nibble each.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
unsafe fn reverse_bits(v: std::arch::x86_64::__m256i) -> std::arch::x86_64::__m256i {
    use std::arch::x86_64::*;
    // A 16-byte table in both halves (byte shuffles stay within their half).
    let table = |bytes: [u8; 16]| _mm256_broadcastsi128_si256(_mm_loadu_si128(bytes.as_ptr().cast()));
    let bytes = _mm256_shuffle_epi8(v, table([3, 2, 1, 0, 7, 6, 5, 4, 11, 10, 9, 8, 15, 14, 13, 12]));
    // Nibble n reversed, as the low nibble and (shifted up) as the high one.
    let rev_low = table([
        0x0, 0x8, 0x4, 0xc, 0x2, 0xa, 0x6, 0xe, 0x1, 0x9, 0x5, 0xd, 0x3, 0xb, 0x7, 0xf,
    ]);
    let rev_high = _mm256_slli_epi16::<4>(rev_low);
    let nibble = _mm256_set1_epi8(0x0f);
    let low = _mm256_and_si256(bytes, nibble);
    let high = _mm256_and_si256(_mm256_srli_epi16::<4>(bytes), nibble);
    _mm256_or_si256(_mm256_shuffle_epi8(rev_high, low), _mm256_shuffle_epi8(rev_low, high))
}

/// [`sobol::sobol_dimension_1_reversed`] in each lane, without its tables: a sum over
/// supersets (see [`sobol::SUBSET_MASKS`]).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
unsafe fn sobol_dimension_1(mut s: std::arch::x86_64::__m256i) -> std::arch::x86_64::__m256i {
    use std::arch::x86_64::*;
    let step = |s: __m256i, shifted: __m256i, mask: u32| {
        _mm256_xor_si256(s, _mm256_and_si256(shifted, _mm256_set1_epi32(mask as i32)))
    };
    let [m0, m1, m2, m3, m4] = sobol::SUBSET_MASKS;
    s = step(s, _mm256_srli_epi32::<1>(s), m0);
    s = step(s, _mm256_srli_epi32::<2>(s), m1);
    s = step(s, _mm256_srli_epi32::<4>(s), m2);
    s = step(s, _mm256_srli_epi32::<8>(s), m3);
    step(s, _mm256_srli_epi32::<16>(s), m4)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_block_is_eight_draws_of_the_scalar_code() {
        let mut z = 0x0123_4567_89ab_cdefu64;
        for n in 0..2000u64 {
            z = super::super::mix(z ^ n);
            let key = z;
            let dimension = 1 + (z >> 20) % 64;
            let index = (z >> 7) as u32;
            let want = draws_scalar(key, dimension, index);
            for k in 0..BLOCK {
                let one = sobol::sample2(index, seeds(draw_hash(key, dimension + k as u64)));
                assert_eq!((want.x[k], want.y[k]), one);
            }
            assert_eq!(
                draws(key, dimension, index),
                want,
                "key {key:#x}, dimension {dimension}"
            );
        }
        // Dimensions whose products wrap around 2⁶⁴ (the last block's count itself wraps),
        // and the extreme keys.
        for (key, dimension) in [(0, 1), (u64::MAX, u64::MAX - 9), (1 << 63, 1 << 40), (7, u64::MAX - 3)] {
            assert_eq!(draws(key, dimension, 5), draws_scalar(key, dimension, 5));
        }
    }
}
