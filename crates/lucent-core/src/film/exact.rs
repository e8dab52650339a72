//! Exact sums of samples: fixed-point numbers whose additions do not depend on their
//! order or grouping, so that a render cut into parts and merged is the very bits of the
//! one-go render.

use crate::math::{Color, DVec3};

/// A sum of radiance samples that does not depend on the order or grouping of the
/// additions: each channel is a fixed-point number with 64 fractional bits in an i128.
/// A sample's f32 value is converted exactly when it is at least 2⁻⁴¹ (below, it is
/// rounded to a multiple of 2⁻⁶⁴, the same way every time) and clamped to ±2⁴⁰ (10¹², a
/// radiance no scene makes), so that even 2²³ samples at that clamp cannot overflow.
/// Additions wrap (they are exact modulo 2¹²⁸, which is still associative): parts whose
/// sums overflow on the way (states read from files) still add up to the exact total,
/// and nothing panics.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct ExactSum(pub [i128; 3]);

/// 2⁶⁴: the fixed point's unit.
const ONE: f64 = 18_446_744_073_709_551_616.0;
const LIMIT: f64 = 1_099_511_627_776.0; // 2⁴⁰
/// The smallest magnitude converted exactly (below it, values are rounded to a multiple
/// of 2⁻⁶⁴): 2⁻⁴¹.
const SMALLEST_EXACT: f32 = 1.0 / 2_199_023_255_552.0;
/// The clamp in the fixed point: 2⁴⁰ · 2⁶⁴.
const LIMIT_FIXED: i128 = (LIMIT as i128) << 64;

impl ExactSum {
    /// `v` in the fixed point (clamped to ±2⁴⁰; NaN is 0): `round(v · 2⁶⁴)`, ties away
    /// from zero, which [`ExactSum::fixed_reference`] says in floating point. Computed
    /// from the float's bits instead: without SSE4.1, `round` and the f64-to-i128
    /// conversion are library calls, six per sample.
    #[inline]
    pub fn fixed(v: f32) -> i128 {
        let bits = v.to_bits();
        let biased = (bits >> 23 & 0xff) as i32;
        let frac = bits & 0x7f_ffff;
        let magnitude: i128 = if biased == 0xff {
            // Infinity clamps; NaN counts as nothing.
            if frac == 0 {
                LIMIT_FIXED
            } else {
                0
            }
        } else if biased >= 127 + 41 {
            // 2⁴¹ and beyond: clamped to 2⁴⁰.
            LIMIT_FIXED
        } else {
            // |v| = m · 2^e exactly, so |v| · 2⁶⁴ = m · 2^(e + 64).
            let (m, e) = if biased == 0 {
                (frac as u64, -149)
            } else {
                ((frac | 0x80_0000) as u64, biased - 150)
            };
            let shift = e + 64;
            if shift >= 0 {
                // Below 2⁴¹, so at most 2¹⁰⁵: clamp the part above 2⁴⁰.
                ((m as i128) << shift).min(LIMIT_FIXED)
            } else if shift > -32 {
                // Adding half before cutting the bits rounds ties away from zero.
                ((m + (1 << (-shift - 1))) >> -shift) as i128
            } else {
                // Below 2⁻³² · 2²⁴ = ½ (m < 2²⁴): rounds to zero.
                0
            }
        };
        if bits >> 31 != 0 {
            -magnitude
        } else {
            magnitude
        }
    }

    /// [`ExactSum::fixed`] in floating point: what it computes, for the tests.
    #[cfg(test)]
    fn fixed_reference(v: f32) -> i128 {
        ((v as f64).clamp(-LIMIT, LIMIT) * ONE).round() as i128
    }

    /// The f32 whose fixed point is that of `v` and that the sum of `v` alone resolves to
    /// (`to_f64(fixed(v))` as f32, which is exact): `v` itself where the conversion is
    /// exact and not clamped, +0 for ±0, the rounded or clamped value elsewhere.
    #[inline]
    pub fn canonical(v: f32) -> f32 {
        let a = v.abs();
        if (SMALLEST_EXACT..=LIMIT as f32).contains(&a) {
            v
        } else if a == 0.0 {
            0.0
        } else {
            Self::to_f64(Self::fixed(v)) as f32
        }
    }

    /// A fixed-point number as f64 (rounded once, to nearest).
    #[inline]
    pub fn to_f64(v: i128) -> f64 {
        v as f64 / ONE
    }

    /// Adds one sample (a finite colour).
    #[inline]
    pub fn add_sample(&mut self, c: Color) {
        // Black, such as a ray tracer's background, adds nothing (`fixed(±0) = 0`).
        if c == Color::ZERO {
            return;
        }
        self.0[0] = self.0[0].wrapping_add(Self::fixed(c.x));
        self.0[1] = self.0[1].wrapping_add(Self::fixed(c.y));
        self.0[2] = self.0[2].wrapping_add(Self::fixed(c.z));
    }

    /// Adds another sum (of other samples of the same pixel).
    #[inline]
    pub fn add(&mut self, other: &ExactSum) {
        for k in 0..3 {
            self.0[k] = self.0[k].wrapping_add(other.0[k]);
        }
    }

    /// Whether the sum could be that of `count` samples: no channel beyond `count` times
    /// the clamp.
    pub fn within(&self, count: u32) -> bool {
        let most = (count as i128).saturating_mul(LIMIT_FIXED);
        self.0.iter().all(|&v| v >= -most && v <= most)
    }

    /// The sum as f64 (rounded once, to nearest).
    pub fn value(&self) -> DVec3 {
        DVec3::new(self.0[0] as f64 / ONE, self.0[1] as f64 / ONE, self.0[2] as f64 / ONE)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sum_of(samples: &[Color]) -> ExactSum {
        let mut s = ExactSum::default();
        samples.iter().for_each(|&c| s.add_sample(c));
        s
    }

    #[test]
    fn exact_sums_do_not_depend_on_grouping() {
        // Values of every magnitude, where f64 sums in two groups and in one go differ.
        let mut x = 0x1234_5678u32;
        let samples: Vec<Color> = (0..1000)
            .map(|_| {
                x = x.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
                let e = (x >> 24) as i32 % 40 - 20;
                Color::splat((x & 0xffff) as f32 / 65536.0 * 2f32.powi(e))
            })
            .collect();
        let whole = sum_of(&samples);
        for cut in [1, 333, 999] {
            let mut parts = sum_of(&samples[..cut]);
            parts.add(&sum_of(&samples[cut..]));
            assert_eq!(parts, whole, "cut at {cut}");
        }
        // Exact for ordinary values: 0.1 + 0.2 in f32, converted once.
        let s = sum_of(&[Color::splat(0.1), Color::splat(0.2)]);
        assert_eq!(s.value().x, 0.1f32 as f64 + 0.2f32 as f64);
        // Huge values are clamped, not wrapped.
        let big = sum_of(&[Color::splat(f32::MAX), Color::splat(f32::MAX)]);
        assert_eq!(big.value().x, 2.0 * LIMIT);
    }

    #[test]
    fn parts_that_overflow_on_the_way_still_add_up_to_the_total() {
        // Two parts beyond i128 on their own (as a state file could hold), whose total fits.
        let big = ExactSum([i128::MAX - 5, i128::MIN + 7, 1 << 100]);
        let back = ExactSum([-(i128::MAX - 9), i128::MAX, -(1 << 100)]);
        let (mut a, mut b) = (big, back);
        a.add(&ExactSum([10, -10, 0]));
        a.add(&back);
        b.add(&big);
        b.add(&ExactSum([10, -10, 0]));
        assert_eq!(a, ExactSum([14, -4, 0]));
        assert_eq!(a, b);
        assert!(ExactSum([LIMIT_FIXED * 3, -LIMIT_FIXED * 3, 0]).within(3));
        assert!(!ExactSum([LIMIT_FIXED * 3 + 1, 0, 0]).within(3));
        assert!(ExactSum::default().within(0) && !ExactSum([1, 0, 0]).within(0));
    }

    #[test]
    fn the_conversion_from_bits_is_the_floating_point_one() {
        // Every float near the places where the rules change (subnormals, the rounding
        // of values below 2⁻⁴¹, ties, the clamp, infinities and NaN), then a stride
        // through all 2³² bit patterns. (All of them agreed when the bit version was
        // written; that check takes a minute.)
        let edges = [
            0u32,
            1,
            0x7f_ffff,
            0x80_0000,
            0x2c00_0000,
            0x2b00_0000,
            0x1f80_0000,
            0x5380_0000,
            0x5400_0000,
        ];
        let near = edges
            .iter()
            .flat_map(|&e| (0..4096u32).map(move |k| e.wrapping_add(k).wrapping_sub(2048)));
        let specials = [
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
            -f32::NAN,
            f32::MAX,
            f32::MIN,
            2f32.powi(40),
            2f32.powi(-65),
            3.0 * 2f32.powi(-66),
        ];
        let strided = (0..=u32::MAX / 65_521).map(|k| k.wrapping_mul(65_521));
        for bits in near.chain(strided).chain(specials.iter().map(|v| v.to_bits())) {
            for b in [bits, bits | 1 << 31] {
                let v = f32::from_bits(b);
                assert_eq!(ExactSum::fixed(v), ExactSum::fixed_reference(v), "{v:e} ({b:#010x})");
            }
        }
    }
}
