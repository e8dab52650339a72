//! Scene command `brdf phong` (the default): the modified Phong BRDF of CSE168
//! (SCENE_FORMAT.md §4.7), with `diffuse` kd, `specular` ks and `shininess` s:
//!
//! ```text
//! f = kd/π + ks · (s + 2)/(2π) · max(r·wi, 0)^s,    r = 2 (n·wo) n − wo
//! ```
//!
//! Sampled as a mixture: with probability t = k̄s/(k̄s + k̄d) a Phong lobe around r,
//! otherwise a cosine lobe around n; the density is the mixture's.

use std::f32::consts::FRAC_1_PI;

use super::{mean, BsdfSample};
use crate::math::{Color, Vec3A};
use crate::sampling::frame::Frame;
use crate::sampling::warp::{cosine_hemisphere, cosine_hemisphere_pdf, phong_lobe, phong_lobe_pdf};

#[derive(Clone, Copy, Debug)]
pub struct Phong {
    /// Unit shading normal.
    pub n: Vec3A,
    pub kd: Color,
    pub ks: Color,
    pub shininess: f32,
}

impl Phong {
    /// The probability of drawing from the specular lobe.
    #[inline]
    pub(super) fn specular_share(&self) -> f32 {
        let (d, s) = (mean(self.kd), mean(self.ks));
        if d + s > 0.0 {
            s / (d + s)
        } else {
            0.0
        }
    }

    #[inline]
    fn mirror(&self, wo: Vec3A) -> Vec3A {
        self.n * (2.0 * self.n.dot(wo)) - wo
    }

    pub fn eval(&self, wo: Vec3A, wi: Vec3A) -> Color {
        let mut f = self.kd * FRAC_1_PI;
        if self.ks != Color::ZERO {
            let c = self.mirror(wo).dot(wi).max(0.0);
            f += self.ks * ((self.shininess + 2.0) * 0.5 * FRAC_1_PI * c.powf(self.shininess));
        }
        f
    }

    pub fn pdf(&self, wo: Vec3A, wi: Vec3A) -> f32 {
        let t = self.specular_share();
        let mut p = (1.0 - t) * cosine_hemisphere_pdf(self.n.dot(wi));
        if t > 0.0 {
            p += t * phong_lobe_pdf(self.shininess, self.mirror(wo).dot(wi));
        }
        p
    }

    pub fn sample(&self, wo: Vec3A, pick: f32, u: f32, v: f32) -> Option<BsdfSample> {
        let wi = if pick < self.specular_share() {
            Frame::around(self.mirror(wo).normalize()).to_world(phong_lobe(self.shininess, u, v))
        } else {
            Frame::around(self.n).to_world(cosine_hemisphere(u, v))
        };
        let pdf = self.pdf(wo, wi);
        (pdf > 0.0).then(|| BsdfSample {
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

    fn phong(n: Vec3A, kd: f32, ks: f32, s: f32) -> Phong {
        Phong {
            n,
            kd: Color::splat(kd),
            ks: Color::new(ks, ks * 0.5, ks * 1.5),
            shininess: s,
        }
    }

    #[test]
    fn sampling_follows_the_mixture_density() {
        let (n, views) = normal_and_views();
        for (kd, ks, s) in [
            (0.5, 0.0, 1.0),
            (0.5, 0.3, 5.0),
            (0.2, 0.6, 50.0),
            (0.1, 0.5, 1000.0),
            (0.0, 0.0, 1.0),
        ] {
            for &wo in &views[..3] {
                let b = phong(n, kd, ks, s);
                let mut i = 0;
                chi2_test(
                    &format!("phong kd {kd} ks {ks} s {s} wo·n {:.2}", wo.dot(n)),
                    |u, v| b.sample(wo, pick(&mut i), u, v).map(|s| s.wi),
                    |wi| b.pdf(wo, wi),
                );
            }
        }
    }

    #[test]
    fn a_sample_carries_the_bsdf_value_and_density_of_its_direction() {
        let (n, views) = normal_and_views();
        let b = phong(n, 0.4, 0.5, 20.0);
        for wo in views {
            for k in 0..50 {
                let k = k as f32 / 50.0;
                if let Some(s) = b.sample(wo, k, (k * 7.3).fract(), (k * 3.1).fract()) {
                    assert_eq!(s.f, b.eval(wo, s.wi));
                    assert_eq!(s.pdf, b.pdf(wo, s.wi));
                }
            }
        }
    }

    #[test]
    fn the_formula_is_the_courses_and_conserves_energy() {
        let n = Vec3A::Z;
        let b = phong(n, 0.5, 0.0, 1.0);
        assert!((b.eval(n, Vec3A::X).x - 0.5 / std::f32::consts::PI).abs() < 1e-7);
        // Head on, the mirror direction is n: f(n, n) = kd/π + ks (s+2)/(2π).
        let b = phong(n, 0.2, 0.4, 10.0);
        let want = 0.2 / std::f32::consts::PI + 0.4 * 12.0 / (2.0 * std::f32::consts::PI);
        assert!((b.eval(n, n).x - want).abs() < 1e-5);
        // Albedo by Monte Carlo (cosine sampling) seen from 30°: kd + ks · cos 30° about
        // (the lobe is narrow, and its cosine weight is that of the mirror direction).
        let b = phong(n, 0.5, 0.5, 30.0);
        let wo = Vec3A::new(0.5, 0.0, 0.75f32.sqrt());
        let mut sum = 0.0;
        let m = 200_000;
        for i in 0..m {
            let (u, v) = crate::sampler::Sampler::new(3, i, 0, 0).uniform2();
            let wi = cosine_hemisphere(u, v);
            sum += b.eval(wo, wi).x * std::f32::consts::PI; // f cos / (cos/π)
        }
        let albedo = sum / m as f32;
        let want = 0.5 + 0.5 * 0.75f32.sqrt();
        assert!((albedo - want).abs() < 0.02, "{albedo} vs {want}");
    }
}
