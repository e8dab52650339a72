//! [`PreparedRay::new`] eight lanes wide ([`PreparedLanes`]): the traversal constants of
//! the rays the path lanes trace next, made in AVX2 registers with the scalar form's
//! operations, so every field has its bits (tested field for field).

use std::arch::x86_64::*;

use super::vector::*;
use crate::math::Vec3A;
use crate::ray::{Axis, PreparedRay, Ray, AXES_AROUND, EPSILON};

/// Rays of all lanes with what traversal needs of them ([`PreparedRay::new`], made in
/// the lanes: the same numbers), one array per field.
#[derive(Default)]
pub(super) struct PreparedLanes {
    pub(super) origin: L3,
    pub(super) dir: L3,
    t_max: L,
    inv_dir: L3,
    origin_k: L3,
    shear: L3,
    /// The dominant axis and whether the direction points down it.
    kz: [i32; W],
    down: [i32; W],
}

impl PreparedLanes {
    /// Rays from `origin` along the unit `dir`, from ε to `t_max`.
    #[inline]
    #[target_feature(enable = "avx2")]
    pub(super) fn prepare(&mut self, origin: V, dir: V, t_max: F) {
        let splat = _mm256_set1_ps;
        // `1/d`, an infinite component replaced by `f32::MAX` with `d`'s sign (+ for ±0).
        let fix = |d: F| {
            let r = _mm256_div_ps(splat(1.0), d);
            let signed_max = _mm256_or_ps(splat(f32::MAX), _mm256_and_ps(d, splat(-0.0)));
            let zero = _mm256_cmp_ps::<_CMP_EQ_OQ>(d, _mm256_setzero_ps());
            let fixed = _mm256_blendv_ps(signed_max, splat(f32::MAX), zero);
            _mm256_blendv_ps(fixed, r, finite(r))
        };
        let inv = V {
            x: fix(dir.x),
            y: fix(dir.y),
            z: fix(dir.z),
        };
        // `max_abs_axis`: x where it beats both, else y where it beats z, else z.
        let a = abs(dir);
        let gt = |p: F, q: F| _mm256_cmp_ps::<_CMP_GT_OQ>(p, q);
        let x_wins = _mm256_and_ps(gt(a.x, a.y), gt(a.x, a.z));
        let y_wins = _mm256_andnot_ps(gt(a.x, a.y), gt(a.y, a.z));
        let int = _mm256_castps_si256;
        let kz = _mm256_blendv_epi8(
            _mm256_blendv_epi8(_mm256_set1_epi32(2), _mm256_set1_epi32(1), int(y_wins)),
            _mm256_setzero_si256(),
            int(x_wins),
        );
        let down = _mm256_srli_epi32::<31>(int(_mm256_cmp_ps::<_CMP_LT_OQ>(by_axis(kz, dir), _mm256_setzero_ps())));
        // `AXES_AROUND[2 kz + down]`, as two tables of lanes.
        let row = _mm256_add_epi32(_mm256_add_epi32(kz, kz), down);
        let table = |k: usize| {
            let t = |r: usize| AXES_AROUND[r.min(5)][k].index() as i32;
            _mm256_setr_epi32(t(0), t(1), t(2), t(3), t(4), t(5), 0, 0)
        };
        let kx = _mm256_permutevar8x32_epi32(table(0), row);
        let ky = _mm256_permutevar8x32_epi32(table(1), row);
        let sz = by_axis(kz, inv);
        store3(&mut self.origin, origin);
        store3(&mut self.dir, dir);
        store(&mut self.t_max, t_max);
        store3(&mut self.inv_dir, inv);
        store3(
            &mut self.origin_k,
            V {
                x: by_axis(kx, origin),
                y: by_axis(ky, origin),
                z: by_axis(kz, origin),
            },
        );
        store3(
            &mut self.shear,
            V {
                x: _mm256_mul_ps(by_axis(kx, dir), sz),
                y: _mm256_mul_ps(by_axis(ky, dir), sz),
                z: sz,
            },
        );
        // SAFETY: eight `i32` each.
        unsafe {
            _mm256_storeu_si256(self.kz.as_mut_ptr().cast(), kz);
            _mm256_storeu_si256(self.down.as_mut_ptr().cast(), down);
        }
    }

    /// Lane `i`'s prepared ray.
    #[inline]
    pub(super) fn get(&self, i: usize) -> PreparedRay {
        let dir = self.dir.get(i);
        let k = self.kz[i] as usize;
        let [kx, ky] = AXES_AROUND[2 * k + self.down[i] as usize];
        let kz = Axis::ALL[k];
        let shear = self.shear.get(i);
        let origin_k = self.origin_k.get(i);
        PreparedRay {
            ray: Ray::segment(self.origin.get(i), dir, EPSILON, self.t_max.0[i]),
            inv_dir: self.inv_dir.get(i),
            zero_axes: dir.cmpeq(Vec3A::ZERO),
            kx,
            ky,
            kz,
            origin_k: [origin_k.x, origin_k.y, origin_k.z],
            sx: shear.x,
            sy: shear.y,
            sz: shear.z,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[target_feature(enable = "avx2")]
    fn prepared(origin: &L3, dir: &L3, t_max: &L) -> PreparedLanes {
        let mut p = PreparedLanes::default();
        p.prepare(load3(origin), load3(dir), load(t_max));
        p
    }

    #[test]
    fn rays_prepared_in_lanes_are_prepared_ray_new_field_for_field() {
        if !std::is_x86_feature_detected!("avx2") {
            eprintln!("skipped: no AVX2 on this CPU");
            return;
        }
        let mut rng = crate::test_rng::Rng(0x9e37_79b9);
        // Directions of every sign, along the axes (±0 components), on the diagonals
        // (ties between axes) and at random.
        let mut dirs = vec![Vec3A::X, -Vec3A::X, Vec3A::Y, -Vec3A::Y, Vec3A::Z, -Vec3A::Z];
        dirs.push(Vec3A::new(-0.0, 1.0, 0.0));
        dirs.push(Vec3A::new(1.0, 1.0, 0.0).normalize());
        dirs.push(Vec3A::new(-1.0, 1.0, -1.0).normalize());
        dirs.push(Vec3A::new(0.0, -1.0, -1.0).normalize());
        dirs.push(Vec3A::new(1e-30, 1.0, -1e-39).normalize());
        while dirs.len() < 4000 {
            dirs.push(rng.vec(1.0).normalize());
        }
        for chunk in dirs.chunks(W) {
            let (mut o, mut d, mut t) = (L3::default(), L3::default(), L::default());
            for (i, &dir) in chunk.iter().enumerate() {
                o.set(i, rng.vec(10.0));
                d.set(i, dir);
                t.0[i] = if i % 2 == 0 { f32::INFINITY } else { rng.range(4.0, 6.0) };
            }
            // SAFETY: the CPU has AVX2 (checked above).
            let lanes = unsafe { prepared(&o, &d, &t) };
            for i in 0..chunk.len() {
                let (got, want) = (
                    lanes.get(i),
                    PreparedRay::new(Ray::segment(o.get(i), d.get(i), EPSILON, t.0[i])),
                );
                let bits = |v: Vec3A| [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()];
                assert_eq!(bits(got.ray.origin), bits(want.ray.origin));
                assert_eq!(bits(got.ray.dir), bits(want.ray.dir));
                assert_eq!(got.ray.t_min.to_bits(), want.ray.t_min.to_bits());
                assert_eq!(got.ray.t_max.to_bits(), want.ray.t_max.to_bits());
                assert_eq!(bits(got.inv_dir), bits(want.inv_dir), "{}", d.get(i));
                assert_eq!(got.zero_axes.bitmask(), want.zero_axes.bitmask());
                assert_eq!((got.kx, got.ky, got.kz), (want.kx, want.ky, want.kz), "{}", d.get(i));
                assert_eq!(got.origin_k.map(f32::to_bits), want.origin_k.map(f32::to_bits));
                assert_eq!(
                    [got.sx, got.sy, got.sz].map(f32::to_bits),
                    [want.sx, want.sy, want.sz].map(f32::to_bits)
                );
            }
        }
    }
}
