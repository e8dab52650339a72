//! Scene commands `brdf ggx` and `roughness α`: the GGX microfacet BRDF of CSE168
//! (SCENE_FORMAT.md §4.7) with a Lambertian base, `diffuse` kd and `specular` ks as the
//! Fresnel reflectance at normal incidence:
//!
//! ```text
//! f = kd/π + F(wi·h) G(wi) G(wo) D(h) / (4 (n·wi)(n·wo))     (0 unless both cosines > 0)
//! D(h)  = α² / (π cos⁴θh (α² + tan²θh)²)       G(v) = 2 / (1 + √(1 + α² tan²θv))
//! F(c)  = ks + (1 − ks)(1 − c)⁵                h = normalize(wi + wo)
//! ```
//!
//! Sampled as a mixture: with probability t = max(0.25, k̄s/(k̄s + k̄d)) a GGX half
//! vector h around n and its mirror direction, otherwise a cosine lobe around n.

use std::f32::consts::FRAC_1_PI;

use super::{mean, BsdfSample};
use crate::math::{Color, Vec3A};
use crate::sampling::frame::Frame;
use crate::sampling::warp::{cosine_hemisphere, cosine_hemisphere_pdf, ggx_d, ggx_half_vector};

#[derive(Clone, Copy, Debug)]
pub struct Ggx {
    /// Unit shading normal.
    pub n: Vec3A,
    pub kd: Color,
    pub ks: Color,
    /// `roughness` α > 0.
    pub alpha: f32,
}

impl Ggx {
    /// The probability of drawing from the microfacet lobe: even a black `specular`
    /// reflects at grazing angles through F.
    #[inline]
    pub(super) fn specular_share(&self) -> f32 {
        let (d, s) = (mean(self.kd), mean(self.ks));
        if d + s > 0.0 {
            (s / (d + s)).max(0.25)
        } else {
            0.25
        }
    }

    /// Smith's shadowing of one direction at cosine `c` to the normal.
    #[inline]
    fn g1(&self, c: f32) -> f32 {
        if !(c > 0.0) {
            return 0.0;
        }
        let tan2 = (1.0 - c * c).max(0.0) / (c * c);
        2.0 / (1.0 + (1.0 + self.alpha * self.alpha * tan2).sqrt())
    }

    pub fn eval(&self, wo: Vec3A, wi: Vec3A) -> Color {
        let (ci, co) = (self.n.dot(wi), self.n.dot(wo));
        if !(ci > 0.0 && co > 0.0) {
            return Color::ZERO;
        }
        let h = (wi + wo).normalize();
        let f = self.ks + (Color::ONE - self.ks) * (1.0 - wi.dot(h)).clamp(0.0, 1.0).powi(5);
        let d = ggx_d(self.alpha, self.n.dot(h));
        let specular = f * (self.g1(ci) * self.g1(co) * d / (4.0 * ci * co));
        let out = self.kd * FRAC_1_PI + specular;
        if out.is_finite() {
            out
        } else {
            self.kd * FRAC_1_PI
        }
    }

    pub fn pdf(&self, wo: Vec3A, wi: Vec3A) -> f32 {
        let t = self.specular_share();
        let mut p = (1.0 - t) * cosine_hemisphere_pdf(self.n.dot(wi));
        let h = (wi + wo).normalize();
        let hi = h.dot(wi).abs();
        if h.is_finite() && hi > 0.0 {
            let ch = self.n.dot(h);
            p += t * ggx_d(self.alpha, ch) * ch.max(0.0) / (4.0 * hi);
        }
        p
    }

    pub fn sample(&self, wo: Vec3A, pick: f32, u: f32, v: f32) -> Option<BsdfSample> {
        let frame = Frame::around(self.n);
        let wi = if pick < self.specular_share() {
            let h = frame.to_world(ggx_half_vector(self.alpha, u, v));
            h * (2.0 * wo.dot(h)) - wo
        } else {
            frame.to_world(cosine_hemisphere(u, v))
        };
        let pdf = self.pdf(wo, wi);
        (pdf > 0.0 && pdf.is_finite()).then(|| BsdfSample {
            wi,
            f: self.eval(wo, wi),
            pdf,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_support::{normal_and_views, pick};
    use super::*;
    use crate::sampling::chi2::chi2_test;

    fn ggx(n: Vec3A, kd: f32, ks: f32, alpha: f32) -> Ggx {
        Ggx {
            n,
            kd: Color::splat(kd),
            ks: Color::new(ks, ks * 0.5, ks * 1.5),
            alpha,
        }
    }

    #[test]
    fn sampling_follows_the_mixture_density() {
        let (n, views) = normal_and_views();
        for (kd, ks, alpha) in [(0.5, 0.2, 0.5), (0.1, 0.8, 0.2), (0.0, 0.9, 0.05), (0.0, 0.0, 1.0)] {
            for &wo in &views[..3] {
                let b = ggx(n, kd, ks, alpha);
                let mut i = 0;
                chi2_test(
                    &format!("ggx kd {kd} ks {ks} alpha {alpha} wo·n {:.2}", wo.dot(n)),
                    |u, v| b.sample(wo, pick(&mut i), u, v).map(|s| s.wi),
                    |wi| b.pdf(wo, wi),
                );
            }
        }
    }

    #[test]
    fn white_microfacets_lose_only_what_shadowing_takes() {
        // ks = 1, kd = 0: the albedo is ∫ G D / (4 cos_o) over the half vectors ≤ 1, near 1
        // for smooth surfaces seen head on (Smith's G loses a little), smaller when rough
        // and grazing.
        let n = Vec3A::Z;
        let albedo = |alpha: f32, deg: f32| {
            let a = deg.to_radians();
            let wo = Vec3A::new(a.sin(), 0.0, a.cos());
            let b = Ggx {
                n,
                kd: Color::ZERO,
                ks: Color::ONE,
                alpha,
            };
            let m = 200_000;
            let mut sum = 0.0f64;
            for i in 0..m {
                let mut s = crate::sampler::Sampler::new(9, i, 0, 0);
                if let Some(x) = b.sample(wo, s.uniform(), s.uniform(), s.uniform()) {
                    sum += (x.f.x * x.wi.dot(n).max(0.0) / x.pdf) as f64;
                }
            }
            sum / m as f64
        };
        let smooth = albedo(0.05, 0.0);
        assert!((0.97..=1.001).contains(&smooth), "{smooth}");
        let rough = albedo(1.0, 75.0);
        assert!(rough < 0.8 && rough > 0.3, "{rough}");
    }

    #[test]
    fn nothing_is_reflected_below_the_surface_or_from_behind_it() {
        let (n, views) = normal_and_views();
        let b = ggx(n, 0.5, 0.5, 0.3);
        assert_eq!(b.eval(views[1], -views[2]), Color::ZERO);
        assert_eq!(b.eval(-views[1], views[2]), Color::ZERO);
        assert!(b.eval(views[1], views[2]).x > 0.0);
    }
}
