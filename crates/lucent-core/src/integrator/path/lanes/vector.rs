//! The scalar arithmetic of the path tracer's vertices, eight lanes wide, giving the same
//! bits lane by lane: lanes of numbers and vectors in memory ([`L`], [`L3`]) and in AVX2
//! registers ([`F`], [`V`]), glam's vector operations in its order of operations (a dot
//! product is `(x·x' + y·y') + z·z'`, a normalisation a division by the square root of
//! that), `spawn`'s offset origins and one-ulp step, `warp::sin_cos_turns` and the power
//! heuristic in `f64`. Tests compare each with its scalar form.

use std::arch::x86_64::*;

use crate::math::Vec3A;
use crate::sampling::warp::{COS_TURN, SIN_TURN};

/// Paths carried together.
pub(super) const W: usize = 8;

/// Eight lanes of one number.
#[derive(Clone, Copy, Default)]
#[repr(C, align(32))]
pub(super) struct L(pub(super) [f32; W]);

/// Eight lanes of a vector, one array per axis.
#[derive(Clone, Copy, Default)]
pub(super) struct L3 {
    pub(super) x: L,
    pub(super) y: L,
    pub(super) z: L,
}

impl L3 {
    #[inline(always)]
    pub(super) fn set(&mut self, i: usize, v: Vec3A) {
        self.x.0[i] = v.x;
        self.y.0[i] = v.y;
        self.z.0[i] = v.z;
    }

    #[inline(always)]
    pub(super) fn get(&self, i: usize) -> Vec3A {
        Vec3A::new(self.x.0[i], self.y.0[i], self.z.0[i])
    }
}

/// One lane group's numbers.
pub(super) type F = __m256;

/// Three of them: a vector per lane.
#[derive(Clone, Copy)]
pub(super) struct V {
    pub(super) x: F,
    pub(super) y: F,
    pub(super) z: F,
}

impl V {
    /// Zero in every lane.
    #[inline]
    #[target_feature(enable = "avx2")]
    pub(super) fn zero() -> V {
        let z = _mm256_setzero_ps();
        V { x: z, y: z, z }
    }
}

#[inline]
#[target_feature(enable = "avx2")]
pub(super) fn load(l: &L) -> F {
    // SAFETY: `L` is 32-byte aligned and holds eight floats.
    unsafe { _mm256_load_ps(l.0.as_ptr()) }
}

#[inline]
#[target_feature(enable = "avx2")]
pub(super) fn store(l: &mut L, v: F) {
    // SAFETY: as in `load`.
    unsafe { _mm256_store_ps(l.0.as_mut_ptr(), v) }
}

#[inline]
#[target_feature(enable = "avx2")]
pub(super) fn load3(l: &L3) -> V {
    V {
        x: load(&l.x),
        y: load(&l.y),
        z: load(&l.z),
    }
}

#[inline]
#[target_feature(enable = "avx2")]
pub(super) fn store3(l: &mut L3, v: V) {
    store(&mut l.x, v.x);
    store(&mut l.y, v.y);
    store(&mut l.z, v.z);
}

#[inline]
#[target_feature(enable = "avx2")]
pub(super) fn mask(m: F) -> [bool; W] {
    let bits = _mm256_movemask_ps(m);
    std::array::from_fn(|i| bits & (1 << i) != 0)
}

// Vector operations with glam's order of operations (its SSE2 `Vec3A`): a dot product is
// `(x·x' + y·y') + z·z'`, a normalisation a division by the square root of that.

#[inline]
#[target_feature(enable = "avx2")]
pub(super) fn add(a: V, b: V) -> V {
    V {
        x: _mm256_add_ps(a.x, b.x),
        y: _mm256_add_ps(a.y, b.y),
        z: _mm256_add_ps(a.z, b.z),
    }
}

#[inline]
#[target_feature(enable = "avx2")]
pub(super) fn sub(a: V, b: V) -> V {
    V {
        x: _mm256_sub_ps(a.x, b.x),
        y: _mm256_sub_ps(a.y, b.y),
        z: _mm256_sub_ps(a.z, b.z),
    }
}

#[inline]
#[target_feature(enable = "avx2")]
pub(super) fn mul(a: V, b: V) -> V {
    V {
        x: _mm256_mul_ps(a.x, b.x),
        y: _mm256_mul_ps(a.y, b.y),
        z: _mm256_mul_ps(a.z, b.z),
    }
}

#[inline]
#[target_feature(enable = "avx2")]
pub(super) fn scale(a: V, s: F) -> V {
    V {
        x: _mm256_mul_ps(a.x, s),
        y: _mm256_mul_ps(a.y, s),
        z: _mm256_mul_ps(a.z, s),
    }
}

#[inline]
#[target_feature(enable = "avx2")]
pub(super) fn divide(a: V, s: F) -> V {
    V {
        x: _mm256_div_ps(a.x, s),
        y: _mm256_div_ps(a.y, s),
        z: _mm256_div_ps(a.z, s),
    }
}

#[inline]
#[target_feature(enable = "avx2")]
pub(super) fn dot(a: V, b: V) -> F {
    _mm256_add_ps(
        _mm256_add_ps(_mm256_mul_ps(a.x, b.x), _mm256_mul_ps(a.y, b.y)),
        _mm256_mul_ps(a.z, b.z),
    )
}

/// glam's `cross`: `(a.y·b.z − a.z·b.y, a.z·b.x − a.x·b.z, a.x·b.y − a.y·b.x)`.
#[inline]
#[target_feature(enable = "avx2")]
pub(super) fn cross(a: V, b: V) -> V {
    V {
        x: _mm256_sub_ps(_mm256_mul_ps(a.y, b.z), _mm256_mul_ps(a.z, b.y)),
        y: _mm256_sub_ps(_mm256_mul_ps(a.z, b.x), _mm256_mul_ps(a.x, b.z)),
        z: _mm256_sub_ps(_mm256_mul_ps(a.x, b.y), _mm256_mul_ps(a.y, b.x)),
    }
}

/// glam's `normalize`: divided by the square root of the dot product with itself.
#[inline]
#[target_feature(enable = "avx2")]
pub(super) fn normalize(a: V) -> V {
    divide(a, _mm256_sqrt_ps(dot(a, a)))
}

#[inline]
#[target_feature(enable = "avx2")]
pub(super) fn abs(a: V) -> V {
    let m = _mm256_set1_ps(-0.0);
    V {
        x: _mm256_andnot_ps(m, a.x),
        y: _mm256_andnot_ps(m, a.y),
        z: _mm256_andnot_ps(m, a.z),
    }
}

#[inline]
#[target_feature(enable = "avx2")]
pub(super) fn select(m: F, a: V, b: V) -> V {
    V {
        x: _mm256_blendv_ps(b.x, a.x, m),
        y: _mm256_blendv_ps(b.y, a.y, m),
        z: _mm256_blendv_ps(b.z, a.z, m),
    }
}

/// `warp::sin_cos_turns` in every lane: `(sin 2πv, cos 2πv)`, the same operations.
#[inline]
#[target_feature(enable = "avx2")]
pub(super) fn sin_cos_turns(v: F) -> (F, F) {
    let splat = _mm256_set1_ps;
    let q = _mm256_floor_ps(_mm256_add_ps(_mm256_mul_ps(splat(4.0), v), splat(0.5)));
    let r = _mm256_sub_ps(v, _mm256_mul_ps(q, splat(0.25)));
    let z = _mm256_mul_ps(r, r);
    let horner = |k: [f32; 5]| {
        let mut p = splat(k[4]);
        for &c in k[..4].iter().rev() {
            p = _mm256_add_ps(splat(c), _mm256_mul_ps(z, p));
        }
        p
    };
    let s = _mm256_mul_ps(r, horner(SIN_TURN));
    let c = _mm256_add_ps(splat(1.0), _mm256_mul_ps(z, horner(COS_TURN)));
    // Quarter turns: odd ones exchange the two, and the sine is negated in the second
    // half turn (bit 1 of q), the cosine in the second and third quarters (bit 1 of q + 1).
    let q = _mm256_cvttps_epi32(q);
    let sign = _mm256_set1_epi32(i32::MIN);
    let odd = _mm256_castsi256_ps(_mm256_slli_epi32::<31>(q));
    let negate_sin = _mm256_castsi256_ps(_mm256_and_si256(_mm256_slli_epi32::<30>(q), sign));
    let negate_cos = _mm256_castsi256_ps(_mm256_and_si256(
        _mm256_slli_epi32::<30>(_mm256_add_epi32(q, _mm256_set1_epi32(1))),
        sign,
    ));
    (
        _mm256_xor_ps(_mm256_blendv_ps(s, c, odd), negate_sin),
        _mm256_xor_ps(_mm256_blendv_ps(c, s, odd), negate_cos),
    )
}

/// The component of `v` each lane's `axis` (0, 1 or 2) names.
#[inline]
#[target_feature(enable = "avx2")]
pub(super) fn by_axis(axis: __m256i, v: V) -> F {
    let is = |k: i32| _mm256_castsi256_ps(_mm256_cmpeq_epi32(axis, _mm256_set1_epi32(k)));
    _mm256_blendv_ps(_mm256_blendv_ps(v.z, v.y, is(1)), v.x, is(0))
}

/// A mask of the lanes set in `b`.
#[inline]
#[target_feature(enable = "avx2")]
pub(super) fn lane_mask(b: [bool; W]) -> F {
    _mm256_castsi256_ps(_mm256_setr_epi32(
        -(b[0] as i32),
        -(b[1] as i32),
        -(b[2] as i32),
        -(b[3] as i32),
        -(b[4] as i32),
        -(b[5] as i32),
        -(b[6] as i32),
        -(b[7] as i32),
    ))
}

/// `sampling::mis::power_heuristic` in every lane (in `f64`, as it is computed there).
#[inline]
#[target_feature(enable = "avx2")]
pub(super) fn power_heuristic_lanes(pa: F, pb: F) -> F {
    // Four lanes at a time, widened to `f64`.
    let half = |pa: __m128, pb: __m128| -> __m128 {
        let (pa, pb) = (_mm256_cvtps_pd(pa), _mm256_cvtps_pd(pb));
        let (a, b) = (_mm256_mul_pd(pa, pa), _mm256_mul_pd(pb, pb));
        let sum = _mm256_add_pd(a, b);
        let positive = _mm256_cmp_pd::<_CMP_GT_OQ>(sum, _mm256_setzero_pd());
        _mm256_cvtpd_ps(_mm256_and_pd(_mm256_div_pd(a, sum), positive))
    };
    let low = half(_mm256_castps256_ps128(pa), _mm256_castps256_ps128(pb));
    let high = half(_mm256_extractf128_ps::<1>(pa), _mm256_extractf128_ps::<1>(pb));
    let infinite = _mm256_cmp_ps::<_CMP_EQ_OQ>(
        _mm256_andnot_ps(_mm256_set1_ps(-0.0), pa),
        _mm256_set1_ps(f32::INFINITY),
    );
    _mm256_blendv_ps(_mm256_set_m128(high, low), _mm256_set1_ps(1.0), infinite)
}

/// Lanes where `a` is finite (`f32::is_finite`: neither infinite nor NaN).
#[inline]
#[target_feature(enable = "avx2")]
pub(super) fn finite(a: F) -> F {
    _mm256_cmp_ps::<_CMP_LT_OQ>(_mm256_andnot_ps(_mm256_set1_ps(-0.0), a), _mm256_set1_ps(f32::INFINITY))
}

/// Lanes where `a > 0` (false for NaN).
#[inline]
#[target_feature(enable = "avx2")]
pub(super) fn positive(a: F) -> F {
    _mm256_cmp_ps::<_CMP_GT_OQ>(a, _mm256_setzero_ps())
}

/// `x.max(0.0)` as Rust computes it for `f32` (NaN gives 0).
#[inline]
#[target_feature(enable = "avx2")]
pub(super) fn max0(a: F) -> F {
    _mm256_max_ps(a, _mm256_setzero_ps())
}

/// [`crate::spawn::offset_origin`] in every lane.
#[inline]
#[target_feature(enable = "avx2")]
pub(super) fn offset_origin(point: V, error: V, ng: V, dir: V) -> V {
    let distance = dot(abs(ng), error);
    let offset = scale(ng, distance);
    let flip = _mm256_cmp_ps::<_CMP_LT_OQ>(dot(dir, ng), _mm256_setzero_ps());
    let sign = _mm256_and_ps(flip, _mm256_set1_ps(-0.0));
    let offset = V {
        x: _mm256_xor_ps(offset.x, sign),
        y: _mm256_xor_ps(offset.y, sign),
        z: _mm256_xor_ps(offset.z, sign),
    };
    let m = add(point, offset);
    V {
        x: one_ulp_along(m.x, offset.x),
        y: one_ulp_along(m.y, offset.y),
        z: one_ulp_along(m.z, offset.z),
    }
}

/// `m` one ulp further along the sign of `o`, lane by lane (`crate::spawn`'s
/// `one_ulp_along`, eight lanes wide: the same bits).
#[inline]
#[target_feature(enable = "avx2")]
pub(super) fn one_ulp_along(m: F, o: F) -> F {
    let zero = _mm256_setzero_ps();
    let int = _mm256_castps_si256;
    let select = |mask: __m256i, a: __m256i, b: __m256i| _mm256_blendv_epi8(b, a, mask);
    let (up, down) = (
        int(_mm256_cmp_ps::<_CMP_GT_OQ>(o, zero)),
        int(_mm256_cmp_ps::<_CMP_LT_OQ>(o, zero)),
    );
    let outward = _mm256_or_si256(
        _mm256_and_si256(int(_mm256_cmp_ps::<_CMP_GT_OQ>(m, zero)), up),
        _mm256_and_si256(int(_mm256_cmp_ps::<_CMP_LT_OQ>(m, zero)), down),
    );
    let stepped = _mm256_sub_epi32(int(m), _mm256_or_si256(outward, _mm256_set1_epi32(1)));
    let smallest = _mm256_or_si256(
        _mm256_set1_epi32(1),
        _mm256_and_si256(down, _mm256_set1_epi32(i32::MIN)),
    );
    let from_zero = int(_mm256_cmp_ps::<_CMP_EQ_OQ>(m, zero));
    let infinite = int(_mm256_cmp_ps::<_CMP_EQ_OQ>(
        _mm256_andnot_ps(_mm256_set1_ps(-0.0), m),
        _mm256_set1_ps(f32::INFINITY),
    ));
    let keep = _mm256_or_si256(
        _mm256_andnot_si256(_mm256_or_si256(up, down), _mm256_set1_epi32(-1)),
        _mm256_or_si256(
            int(_mm256_cmp_ps::<_CMP_UNORD_Q>(m, m)),
            _mm256_and_si256(infinite, outward),
        ),
    );
    _mm256_castsi256_ps(select(keep, int(m), select(from_zero, smallest, stepped)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spawn::{next_down, next_up};

    #[target_feature(enable = "avx2")]
    fn stepped(m: &L, o: &L) -> L {
        let mut r = L::default();
        store(&mut r, one_ulp_along(load(m), load(o)));
        r
    }

    #[target_feature(enable = "avx2")]
    fn turns(v: &L) -> (L, L) {
        let (s, c) = sin_cos_turns(load(v));
        let (mut a, mut b) = (L::default(), L::default());
        store(&mut a, s);
        store(&mut b, c);
        (a, b)
    }

    #[test]
    fn a_lanes_sine_and_cosine_are_the_scalar_ones_bit_for_bit() {
        if !std::is_x86_feature_detected!("avx2") {
            eprintln!("skipped: no AVX2 on this CPU");
            return;
        }
        let n = 1u32 << 18;
        let values = (0..=n)
            .map(|i| i as f32 / n as f32)
            .chain([crate::spawn::next_down(1.0), f32::from_bits(1)]);
        let values: Vec<f32> = values.collect();
        for chunk in values.chunks(W) {
            let mut v = L::default();
            v.0[..chunk.len()].copy_from_slice(chunk);
            // SAFETY: the CPU has AVX2 (checked above).
            let (s, c) = unsafe { turns(&v) };
            for (k, &x) in chunk.iter().enumerate() {
                let (ws, wc) = crate::sampling::warp::sin_cos_turns(x);
                assert_eq!(
                    (s.0[k].to_bits(), c.0[k].to_bits()),
                    (ws.to_bits(), wc.to_bits()),
                    "v = {x}"
                );
            }
        }
    }

    #[test]
    fn a_lane_steps_one_ulp_as_next_up_and_next_down_do() {
        if !std::is_x86_feature_detected!("avx2") {
            eprintln!("skipped: no AVX2 on this CPU");
            return;
        }
        let (values, offsets) = crate::spawn::tests::ulp_step_cases();
        for (i, chunk) in values.chunks(W).enumerate() {
            let mut m = L::default();
            let mut o = L::default();
            for (k, &v) in chunk.iter().enumerate() {
                m.0[k] = v;
                o.0[k] = offsets[(i + k) % offsets.len()];
            }
            // SAFETY: the CPU has AVX2 (checked above).
            let got = unsafe { stepped(&m, &o) };
            for k in 0..W {
                let (m, o) = (m.0[k], o.0[k]);
                let want = if o > 0.0 {
                    next_up(m)
                } else if o < 0.0 {
                    next_down(m)
                } else {
                    m
                };
                assert_eq!(got.0[k].to_bits(), want.to_bits(), "{m} along {o}");
            }
        }
    }
}
