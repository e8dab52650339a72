//! `x^y` for shading exponents — the Blinn–Phong highlight `max(N·H, 0)^s` of the ray
//! tracer (scene command `shininess`) — sixteen at a time.
//!
//! Why not `f32::powf`: the ray tracer evaluates one highlight per light sample, sixteen
//! per shading point with `lightsamples 16`, and libm's `powf` (a call, its special
//! cases, its tables) took 14–19 % of the showcase render. Here the same quantity is a
//! straight line of `f64` arithmetic without tables or branches, which the compiler turns
//! into vector code: eight lanes per instruction on AVX-512, four on AVX2.
//!
//! Accuracy: `log2 x` and `2^t` are evaluated in `f64` to a relative error near 1e-14,
//! so the `f32` result is the correctly rounded `x^y` except when the exact value lies
//! within about 1e-14 of a halfway point between two floats (the tests count these: a
//! few in a million, and then the other neighbour, one ulp away). Only IEEE additions,
//! multiplications and one division are used, never a fused multiply–add, so every
//! instruction set gives the same bits.
//!
//! Domain: `x` finite and `≥ 0`, `y ≥ 0` (what `shininess` allows); `0^0 = 1`.
//!
//! There is no one-at-a-time version: for a single power libm's `powf` is faster, since
//! this is one long dependency chain (a division, then polynomials of 7 and 11 steps)
//! that pays only when sixteen run side by side.

/// How many powers [`pow_lanes`] computes at once.
pub const LANES: usize = 16;

/// `x[i]^y` for all sixteen lanes.
#[inline]
pub fn pow_lanes(x: &[f32; LANES], y: f32) -> [f32; LANES] {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx512f") {
            // SAFETY: the CPU has AVX-512 F.
            return unsafe { pow_lanes_avx512(x, y) };
        }
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has AVX2.
            return unsafe { pow_lanes_avx2(x, y) };
        }
    }
    pow_lanes_body(x, y)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
unsafe fn pow_lanes_avx512(x: &[f32; LANES], y: f32) -> [f32; LANES] {
    pow_lanes_body(x, y)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn pow_lanes_avx2(x: &[f32; LANES], y: f32) -> [f32; LANES] {
    pow_lanes_body(x, y)
}

#[inline(always)]
fn pow_lanes_body(x: &[f32; LANES], y: f32) -> [f32; LANES] {
    // An infinite exponent as the largest finite one: the same answer for x ≠ 1, and
    // 1^y = 1 (∞ · log2 1 would be NaN).
    let y = y.min(f32::MAX) as f64;
    let mut out = [0.0; LANES];
    for i in 0..LANES {
        out[i] = pow_one(x[i], y);
    }
    out
}

/// Bits of √½: mantissas are brought into [√½, √2), where the series below converge
/// fastest.
const SQRT_HALF_BITS: u64 = 0x3fe6_a09e_667f_3bcd;
/// Adding this to an `f64` of magnitude below 2⁵¹ rounds it to an integer (ties to even)
/// and leaves that integer in the low bits.
const ROUND_MAGIC: f64 = 6_755_399_441_055_744.0; // 1.5 · 2^52

#[inline(always)]
fn pow_one(x: f32, y: f64) -> f32 {
    let xd = x as f64;
    // x = 2^e · m with m in [√½, √2): e from the exponent field of x / √½.
    let bits = xd.to_bits();
    let e = (bits.wrapping_sub(SQRT_HALF_BITS) as i64) >> 52;
    let m = f64::from_bits(bits.wrapping_sub((e as u64) << 52));
    // ln m = 2 atanh z = 2 (z + z³/3 + z⁵/5 + …), z = (m − 1)/(m + 1), |z| ≤ 0.1716: the
    // terms to z¹⁵ leave a relative error below 4e-14.
    let z = (m - 1.0) / (m + 1.0);
    let w = z * z;
    // (Not left to rustfmt, which takes minutes over nested sums this deep.)
    #[rustfmt::skip]
    let series = 1.0
        + w * (1.0 / 3.0
            + w * (1.0 / 5.0
                + w * (1.0 / 7.0 + w * (1.0 / 9.0 + w * (1.0 / 11.0 + w * (1.0 / 13.0 + w * (1.0 / 15.0)))))));
    let log2_x = e as f64 + 2.0 * std::f64::consts::LOG2_E * z * series;
    // 2^t with t clamped where the f32 result is already 0 or ∞ (and the scale below
    // stays a normal f64).
    let t = (y * log2_x).clamp(-160.0, 130.0);
    let shifted = t + ROUND_MAGIC;
    let n = shifted.to_bits().wrapping_sub(ROUND_MAGIC.to_bits()) as i64;
    // f = t − n, in [−½, ½] and exact.
    let f = t - (shifted - ROUND_MAGIC);
    // 2^f = e^g, g = f ln 2 in [−0.347, 0.347]: Taylor to degree 11, error below 1e-14.
    let g = f * std::f64::consts::LN_2;
    #[rustfmt::skip]
    let p = 1.0
        + g * (1.0
            + g * (1.0 / 2.0
                + g * (1.0 / 6.0
                    + g * (1.0 / 24.0
                        + g * (1.0 / 120.0
                            + g * (1.0 / 720.0
                                + g * (1.0 / 5040.0
                                    + g * (1.0 / 40_320.0
                                        + g * (1.0 / 362_880.0
                                            + g * (1.0 / 3_628_800.0 + g * (1.0 / 39_916_800.0)))))))))));
    let scale = f64::from_bits(((n + 1023) as u64) << 52);
    let r = (p * scale) as f32;
    // x = 0: the logarithm above is meaningless; 0^y = 0 for y > 0, 1 for y = 0.
    if x == 0.0 {
        if y == 0.0 {
            1.0
        } else {
            0.0
        }
    } else {
        r
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One lane of [`pow_lanes`].
    fn pow(x: f32, y: f32) -> f32 {
        pow_one(x, y.min(f32::MAX) as f64)
    }

    /// The correctly rounded `x^y` (as `f64`, whose own error is far below an f32 ulp).
    fn exact(x: f32, y: f32) -> f32 {
        (x as f64).powf(y as f64) as f32
    }

    fn ulps(a: f32, b: f32) -> u32 {
        (a.to_bits() as i64 - b.to_bits() as i64).unsigned_abs() as u32
    }

    #[test]
    fn special_values_are_exact() {
        for y in [0.0f32, 0.5, 1.0, 2.0, 40.0, 200.0, 1e6, f32::MAX, f32::INFINITY] {
            assert_eq!(pow(1.0, y), 1.0, "1^{y}");
            assert_eq!(pow(0.0, y), if y == 0.0 { 1.0 } else { 0.0 }, "0^{y}");
        }
        for x in [1e-30f32, 1e-7, 0.25, 0.5, 0.999_999_9, 1.0, 1.000_000_1, 3.0, 1e20] {
            assert_eq!(pow(x, 0.0), 1.0, "{x}^0");
            assert_eq!(pow(x, 1.0), x, "{x}^1");
            assert_eq!(pow(x, f32::INFINITY), exact(x, f32::MAX), "{x}^inf");
        }
        // Underflow to 0, overflow to ∞, subnormal results rounded as f32 rounds.
        assert_eq!(pow(0.5, 200.0), 0.0);
        assert_eq!(pow(2.0, 200.0), f32::INFINITY);
        assert_eq!(pow(0.5, 140.0), exact(0.5, 140.0));
        assert_eq!(pow(0.5, 149.0), f32::from_bits(1));
    }

    #[test]
    fn within_one_ulp_and_almost_always_correctly_rounded() {
        // Cosines across [0, 1] and a little past it (rounding in N·H), with the
        // exponents scenes use and some that are not integers.
        let ys = [
            0.5f32, 1.0, 2.0, 3.7, 10.0, 20.0, 40.0, 60.0, 100.0, 200.0, 1000.0, 5000.0,
        ];
        let (mut off, mut total) = (0u64, 0u64);
        let mut x = 1.0e-4f32;
        while x <= 1.01 {
            for &y in &ys {
                let (got, want) = (pow(x, y), exact(x, y));
                assert!(ulps(got, want) <= 1, "{x}^{y}: {got} against {want}");
                off += (got != want) as u64;
                total += 1;
            }
            x = f32::from_bits(x.to_bits() + 97);
        }
        // The expected rate is about 2e-14 / 2^-24 per value: a few in a million.
        assert!(off * 100_000 <= total, "{off} of {total} not correctly rounded");
    }

    #[test]
    fn the_lanes_give_the_scalar_answers() {
        let mut x = [0.0f32; LANES];
        for (i, v) in x.iter_mut().enumerate() {
            *v = i as f32 / 15.0 * 1.01;
        }
        for y in [0.0f32, 1.0, 17.0, 60.0, 250.5] {
            let lanes = pow_lanes(&x, y);
            for i in 0..LANES {
                assert_eq!(lanes[i].to_bits(), pow(x[i], y).to_bits(), "{}^{y}", x[i]);
            }
        }
    }
}
