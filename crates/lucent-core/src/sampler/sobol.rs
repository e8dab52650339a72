//! An Owen-scrambled Sobol sequence in one and two dimensions, for the padded Sobol
//! sampler of [`super::Sampler`] (`sampler sobol`).
//!
//! The first two dimensions of Sobol's sequence form a (0, 2)-sequence in base 2: every
//! aligned block of 2ᵏ consecutive points has exactly one point in each of the 2ᵏ
//! rectangles of any shape 2⁻ᵃ × 2⁻ᵇ (a + b = k) that tile the unit square. Owen
//! scrambling (a random permutation of each binary digit that depends on the digits above
//! it) keeps that property and makes every point uniformly distributed, so estimates stay
//! unbiased; shuffling the indices the same way gives a different, independent sequence
//! for every seed. Both use Burley's hash-based scramble ("Practical Hash-based Owen
//! Scrambling", JCGT 2020) with the improved Laine–Karras-style hash published by
//! N. Vegdahl ("Building a Better LK Hash", 2021).
//!
//! Written here rather than taken from the `sobol_burley` crate: that crate computes any of
//! 256 dimensions and costs about 27 ns a number on this project's machines; the padded
//! sampler only ever needs dimensions 0 and 1, which cost a few nanoseconds.

/// A nested uniform scramble of the bits of `x` given in reverse order (the lowest bit is
/// the most significant digit): each output bit depends only on the same and lower input
/// bits and the seed, which is what Owen scrambling asks.
#[inline(always)]
fn scramble_reversed(mut x: u32, seed: u32) -> u32 {
    let [c0, c1, c2] = SCRAMBLE_CONSTANTS;
    // Multiplying and adding carry only upwards: lower bits decide higher ones.
    x ^= x.wrapping_mul(c0);
    x = x.wrapping_add(seed);
    x = x.wrapping_mul((seed >> 16) | 1);
    x ^= x.wrapping_mul(c1);
    x ^= x.wrapping_mul(c2);
    x
}

/// The multipliers of [`scramble_reversed`] (shared with the vector code of
/// [`super::sobol_block`]).
pub(super) const SCRAMBLE_CONSTANTS: [u32; 3] = [0x3d20_adea, 0x0552_6c56, 0x53a2_2864];

/// The direction numbers of Sobol's second dimension as 32-bit binary fractions: the
/// columns of the Pascal matrix mod 2 (v₀ = ½, vₖ = vₖ₋₁ ⊕ vₖ₋₁/2).
const fn directions() -> [u32; 32] {
    let mut v = [0u32; 32];
    v[0] = 1 << 31;
    let mut k = 1;
    while k < 32 {
        v[k] = v[k - 1] ^ (v[k - 1] >> 1);
        k += 1;
    }
    v
}

/// Sobol's second dimension for every value of one byte of the index, one table per
/// byte, with the bits of each value reversed (the order the scramble works in): the
/// point of index i is the XOR of four lookups.
const fn byte_tables() -> [[u32; 256]; 4] {
    let v = directions();
    let mut t = [[0u32; 256]; 4];
    let mut byte = 0;
    while byte < 4 {
        let mut b = 0;
        while b < 256 {
            let mut x = 0u32;
            let mut bit = 0;
            while bit < 8 {
                if b & (1 << bit) != 0 {
                    x ^= v[byte * 8 + bit];
                }
                bit += 1;
            }
            t[byte][b] = x.reverse_bits();
            b += 1;
        }
        byte += 1;
    }
    t
}

static DIMENSION_1: [[u32; 256]; 4] = byte_tables();

/// Sobol's second dimension of point `i`, as a 32-bit binary fraction with its bits
/// reversed.
#[inline(always)]
pub(super) fn sobol_dimension_1_reversed(i: u32) -> u32 {
    let t = &DIMENSION_1;
    t[0][(i & 0xff) as usize]
        ^ t[1][(i >> 8 & 0xff) as usize]
        ^ t[2][(i >> 16 & 0xff) as usize]
        ^ t[3][(i >> 24) as usize]
}

/// The positions j whose bit t is clear, for t = 0..5: with them
/// [`sobol_dimension_1_reversed`] needs no tables (for vector code, which has no cheap
/// table lookup). Reversed, direction number k is row k of Pascal's triangle mod 2: bit j
/// is set when j's bits are a subset of k's (Lucas). So bit j of the result is the
/// parity of the set bits of the index at the positions k ⊇ j: a sum over supersets,
/// made one bit of the position at a time (at step t, each position j without bit t
/// adds position j + 2ᵗ: `i ^= (i >> 2ᵗ) & SUBSET_MASKS[t]`).
#[cfg_attr(not(any(test, target_arch = "x86_64")), allow(dead_code))]
pub(super) const SUBSET_MASKS: [u32; 5] = [0x5555_5555, 0x3333_3333, 0x0f0f_0f0f, 0x00ff_00ff, 0x0000_ffff];

/// [`sobol_dimension_1_reversed`] by [`SUBSET_MASKS`], one lane of the vector code.
#[cfg(test)]
fn dimension_1_by_subsets(mut i: u32) -> u32 {
    for (t, mask) in SUBSET_MASKS.iter().enumerate() {
        i ^= (i >> (1 << t)) & mask;
    }
    i
}

/// A 32-bit binary fraction as a float in [0, 1): its 24 leading bits, exactly.
#[inline(always)]
fn to_unit(x: u32) -> f32 {
    (x >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
}

/// The three scrambles of one sequence: of its indices and of its two coordinates. Any
/// three well-mixed words will do (the sampler cuts them from one 64-bit hash).
#[derive(Clone, Copy, Debug)]
pub struct Seeds {
    pub index: u32,
    pub x: u32,
    pub y: u32,
}

/// The index of a point with its bits reversed, shuffled by a nested uniform scramble
/// that keeps aligned blocks of 2ᵏ indices together, so that every such block of the
/// shuffled sequence is again an aligned block of 2ᵏ Sobol points.
#[inline(always)]
fn shuffled(i_reversed: u32, seed: u32) -> u32 {
    scramble_reversed(i_reversed, seed).reverse_bits()
}

/// The point of index `i_reversed.reverse_bits()` in the two-dimensional scrambled Sobol
/// sequence picked by `seeds`. The index comes reversed because the sampler reverses it
/// once for all its draws. Its first number alone is the point of the one-dimensional
/// scrambled Sobol (van der Corput) sequence: what the sampler draws one number from.
#[inline(always)]
pub fn sample2(i_reversed: u32, seeds: Seeds) -> (f32, f32) {
    let s = shuffled(i_reversed, seeds.index);
    // Dimension 0 is the index with its bits reversed: in reversed order, the index itself.
    let x = scramble_reversed(s, seeds.x);
    let y = scramble_reversed(sobol_dimension_1_reversed(s), seeds.y);
    let (x, y) = reverse_both(x, y);
    (to_unit(x), to_unit(y))
}

/// `(x.reverse_bits(), y.reverse_bits())` by one 64-bit reversal: x86-64 has no bit
/// reversal instruction, and a 64-bit one costs what a 32-bit one does.
#[inline(always)]
fn reverse_both(x: u32, y: u32) -> (u32, u32) {
    let r = ((x as u64) << 32 | y as u64).reverse_bits();
    (r as u32, (r >> 32) as u32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn both_reversed_at_once_are_each_reversed() {
        let mut x = 0x1234_5678u32;
        for _ in 0..10_000 {
            x = x.wrapping_mul(0x9e37_79b9).wrapping_add(0x7f4a_7c15);
            let y = x.rotate_left(13) ^ 0xdead_beef;
            assert_eq!(reverse_both(x, y), (x.reverse_bits(), y.reverse_bits()));
        }
    }

    #[test]
    fn the_second_dimension_by_subsets_is_the_tables() {
        let mut i = 0u32;
        for n in 0..100_000u32 {
            assert_eq!(dimension_1_by_subsets(i), sobol_dimension_1_reversed(i), "index {i:#x}");
            i = i.wrapping_mul(0x2c1b_3c6d).wrapping_add(n | 1);
        }
        for i in [0, 1, u32::MAX, 1 << 31, 0xffff, 0xffff_0000] {
            assert_eq!(dimension_1_by_subsets(i), sobol_dimension_1_reversed(i), "index {i:#x}");
        }
    }

    #[test]
    fn the_unscrambled_second_dimension_is_sobols() {
        // Sobol's second dimension, points 0..8 (Joe and Kuo's direction numbers).
        let want = [0.0, 0.5, 0.75, 0.25, 0.625, 0.125, 0.375, 0.875];
        for (i, w) in want.iter().enumerate() {
            assert_eq!(
                sobol_dimension_1_reversed(i as u32).reverse_bits() as f64 / 2f64.powi(32),
                *w,
                "point {i}"
            );
        }
    }

    /// Whether `points` has exactly one point in every 2⁻ᵃ × 2⁻ᵇ rectangle for a + b = k
    /// (a (0, k, 2)-net), where `points.len() = 2ᵏ`.
    fn is_a_net(points: &[(f32, f32)]) -> bool {
        let k = points.len().trailing_zeros();
        (0..=k).all(|a| {
            let mut seen = vec![false; points.len()];
            points.iter().all(|&(x, y)| {
                let cx = (x * (1u32 << a) as f32) as usize;
                let cy = (y * (1u32 << (k - a)) as f32) as usize;
                !std::mem::replace(&mut seen[cy << a | cx], true)
            })
        })
    }

    fn seeds(k: u32) -> Seeds {
        Seeds {
            index: k.wrapping_mul(0x9e37_79b9) ^ 0x79c6_8e4a,
            x: k.wrapping_mul(0x85eb_ca6b) ^ 0x1b87_3593,
            y: k.wrapping_mul(0xc2b2_ae35) ^ 0xe654_6b64,
        }
    }

    #[test]
    fn every_aligned_block_of_a_power_of_two_points_is_a_net() {
        for seed in [0u32, 1, 0xdead_beef, 12345] {
            let points: Vec<(f32, f32)> = (0..1024).map(|i| sample2(u32::reverse_bits(i), seeds(seed))).collect();
            for size in [4usize, 16, 64, 256, 1024] {
                for block in points.chunks(size) {
                    assert!(is_a_net(block), "seed {seed}, a block of {size}");
                }
            }
            // In one dimension: one point in each of the 2ᵏ intervals.
            let mut seen = [false; 64];
            for i in 64..128 {
                let c = (sample2(u32::reverse_bits(i), seeds(seed)).0 * 64.0) as usize;
                assert!(!std::mem::replace(&mut seen[c], true), "seed {seed}");
            }
        }
    }

    #[test]
    fn another_seed_gives_another_sequence() {
        let a: Vec<_> = (0..16).map(|i| sample2(u32::reverse_bits(i), seeds(1))).collect();
        let b: Vec<_> = (0..16).map(|i| sample2(u32::reverse_bits(i), seeds(2))).collect();
        assert!(a.iter().zip(&b).all(|(p, q)| p != q));
        // The scramble moves points off the unscrambled lattice of multiples of 1/16.
        assert!(a.iter().any(|p| (p.0 * 16.0).fract() != 0.0));
    }

    #[test]
    fn points_over_many_seeds_are_uniform_and_independent_of_each_other() {
        // Point 3 of 65,536 sequences in an 8 × 8 grid: χ² with 63 degrees of freedom.
        // 120 is beyond its 0.99999 quantile (about 112); a fault (a point pinned to a
        // stratum, x tied to y) gives thousands.
        let n = 65_536u32;
        let mut bins = [0u32; 64];
        for seed in 0..n {
            let (x, y) = sample2(3u32.reverse_bits(), seeds(seed));
            bins[(y * 8.0) as usize * 8 + (x * 8.0) as usize] += 1;
        }
        let expected = n as f64 / 64.0;
        let chi2: f64 = bins.iter().map(|&b| (b as f64 - expected).powi(2) / expected).sum();
        assert!(chi2 < 120.0, "χ² = {chi2}, bins {bins:?}");
    }
}
