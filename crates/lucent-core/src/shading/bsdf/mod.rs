//! BSDFs: how a surface point scatters light, as `eval`, `sample` and `pdf` (the shape of
//! pbrt-v4's `BxDF` and Mitsuba 3's `BSDF`, in RGB). One file per model, selected per
//! object by `brdf phong|ggx` (SCENE_FORMAT.md §4.7), plus the delta models of
//! EXTENSIONS.md: `brdf mirror` and `transparent` with `ior` (a smooth dielectric).
//!
//! A delta model scatters into single directions, which no density can describe: its
//! `eval` and `pdf` are zero (a light sample never finds its lobe, and MIS puts no weight
//! on it), and integrators draw its direction with [`Bsdf::sample_delta`].
//!
//! Directions are world-space unit vectors pointing away from the surface: `wo` toward
//! the viewer (the previous vertex), `wi` toward the light or the next vertex. The
//! models are defined by the shading normal and the mirror direction, so they keep
//! the normal and work in world space; directions are drawn in a [`Frame`] around the
//! lobe's axis.
//!
//! [`Frame`]: crate::sampling::frame::Frame

pub mod dielectric;
pub mod ggx;
pub mod mirror;
pub mod phong;

use crate::math::{Color, Vec3A};

pub use dielectric::Dielectric;
pub use ggx::Ggx;
pub use mirror::Mirror;
pub use phong::Phong;

/// A direction drawn from a BSDF: `f(wo, wi)` and the density with which it was drawn
/// (that of the whole mixture, whichever lobe drew it). `wi` may lie below the surface;
/// the integrator gives such a direction no weight.
#[derive(Clone, Copy, Debug)]
pub struct BsdfSample {
    pub wi: Vec3A,
    pub f: Color,
    pub pdf: f32,
}

/// A direction drawn from a delta lobe and the weight it multiplies the path's
/// throughput by (`f · cos θ / pdf`, which for a delta is finite though its parts are not).
#[derive(Clone, Copy, Debug)]
pub struct DeltaSample {
    pub wi: Vec3A,
    pub weight: Color,
    /// Through the surface (refraction) rather than back from it.
    pub transmitted: bool,
}

#[derive(Clone, Copy, Debug)]
pub enum Bsdf {
    Phong(Phong),
    Ggx(Ggx),
    Mirror(Mirror),
    Dielectric(Dielectric),
}

impl Bsdf {
    /// The shading normal the BSDF was built around.
    #[inline]
    pub fn normal(&self) -> Vec3A {
        match self {
            Bsdf::Phong(b) => b.n,
            Bsdf::Ggx(b) => b.n,
            Bsdf::Mirror(b) => b.n,
            Bsdf::Dielectric(b) => b.n,
        }
    }

    /// The colour of the surface for a denoiser's albedo guide: `kd + ks` (at most 1 per
    /// channel) for the glossy models, the reflectance of a mirror, the transmittance of
    /// glass.
    pub fn albedo(&self) -> Color {
        match self {
            Bsdf::Phong(b) => (b.kd + b.ks).min(Color::ONE),
            Bsdf::Ggx(b) => (b.kd + b.ks).min(Color::ONE),
            Bsdf::Mirror(b) => b.ks.min(Color::ONE),
            Bsdf::Dielectric(b) => b.kt.min(Color::ONE),
        }
    }

    /// Whether the BSDF scatters into single directions only (mirror, glass).
    #[inline]
    pub fn is_delta(&self) -> bool {
        matches!(self, Bsdf::Mirror(_) | Bsdf::Dielectric(_))
    }

    /// A direction from a delta BSDF (`pick` chooses between reflection and refraction);
    /// `None` for the others and when nothing is scattered.
    #[inline]
    pub fn sample_delta(&self, wo: Vec3A, pick: f32) -> Option<DeltaSample> {
        match self {
            Bsdf::Mirror(b) => b.sample(wo),
            Bsdf::Dielectric(b) => b.sample(wo, pick),
            Bsdf::Phong(_) | Bsdf::Ggx(_) => None,
        }
    }

    /// `f(wo, wi)`.
    #[inline]
    pub fn eval(&self, wo: Vec3A, wi: Vec3A) -> Color {
        match self {
            Bsdf::Phong(b) => b.eval(wo, wi),
            Bsdf::Ggx(b) => b.eval(wo, wi),
            Bsdf::Mirror(_) | Bsdf::Dielectric(_) => Color::ZERO,
        }
    }

    /// The solid-angle density with which [`Bsdf::sample`] draws `wi`.
    #[inline]
    pub fn pdf(&self, wo: Vec3A, wi: Vec3A) -> f32 {
        match self {
            Bsdf::Phong(b) => b.pdf(wo, wi),
            Bsdf::Ggx(b) => b.pdf(wo, wi),
            Bsdf::Mirror(_) | Bsdf::Dielectric(_) => 0.0,
        }
    }

    /// [`Bsdf::sample`] from two numbers (the path tracer's `importancesampling brdf`):
    /// `u` chooses the lobe (the specular one below its share) and what is left of `u`
    /// within the chosen lobe's share is the direction's first number. A pixel's samples
    /// that choose one lobe are then spread over it as evenly as all of them are over the
    /// square, where a number of its own for the choice gave each lobe a random subset
    /// (as with the light choice of [`crate::integrator::light_sampling::one_light_mis`]).
    /// With one lobe, `u` is used as it is.
    #[inline]
    pub fn sample_reusing(&self, wo: Vec3A, u: f32, v: f32) -> Option<BsdfSample> {
        let share = match self {
            Bsdf::Phong(b) => b.specular_share(),
            Bsdf::Ggx(b) => b.specular_share(),
            Bsdf::Mirror(_) | Bsdf::Dielectric(_) => return None,
        };
        let rest = if u < share {
            u / share
        } else {
            (u - share) / (1.0 - share)
        };
        self.sample(wo, u, rest.clamp(0.0, crate::sampling::ONE_BELOW), v)
    }

    /// A direction drawn in proportion to the BSDF (`importancesampling brdf`): `pick`
    /// chooses the lobe, `(u, v)` the direction in it. `None` when nothing can be drawn
    /// (and for delta BSDFs: see [`Bsdf::sample_delta`]).
    #[inline]
    pub fn sample(&self, wo: Vec3A, pick: f32, u: f32, v: f32) -> Option<BsdfSample> {
        match self {
            Bsdf::Phong(b) => b.sample(wo, pick, u, v),
            Bsdf::Ggx(b) => b.sample(wo, pick, u, v),
            Bsdf::Mirror(_) | Bsdf::Dielectric(_) => None,
        }
    }
}

/// The mean of a colour's components (k̄ in SCENE_FORMAT.md §4.7).
#[inline]
pub(crate) fn mean(c: Color) -> f32 {
    (c.x + c.y + c.z) / 3.0
}

#[cfg(test)]
pub(crate) mod test_support {
    use crate::math::Vec3A;
    use crate::sampler::Sampler;

    /// Viewing directions for the BSDF tests: head on, oblique and grazing, around a
    /// tilted normal.
    pub fn normal_and_views() -> (Vec3A, Vec<Vec3A>) {
        let n = Vec3A::new(0.2, 0.3, 0.9).normalize();
        let f = crate::sampling::frame::Frame::around(n);
        let views = [0.0f32, 35.0, 70.0, 88.0]
            .iter()
            .map(|deg| {
                let a = deg.to_radians();
                f.to_world(Vec3A::new(a.sin() * 0.6, a.sin() * 0.8, a.cos()))
                    .normalize()
            })
            .collect();
        (n, views)
    }

    /// A lobe-choosing number for the `i`-th sample of a χ² test (the harness gives two).
    pub fn pick(i: &mut u32) -> f32 {
        *i += 1;
        Sampler::new(0x91c4, *i, 1, 0).uniform()
    }
}

#[cfg(test)]
mod tests {
    use super::test_support::normal_and_views;
    use super::*;
    use crate::sampling::chi2::chi2_test;

    fn phong(n: Vec3A, kd: f32, ks: f32, shininess: f32) -> Bsdf {
        let (kd, ks) = (Color::splat(kd), Color::splat(ks));
        Bsdf::Phong(phong::Phong { n, kd, ks, shininess })
    }

    fn ggx(n: Vec3A, kd: f32, ks: f32, alpha: f32) -> Bsdf {
        let (kd, ks) = (Color::splat(kd), Color::splat(ks));
        Bsdf::Ggx(ggx::Ggx { n, kd, ks, alpha })
    }

    #[test]
    fn sampling_with_the_lobe_chosen_by_the_first_number_follows_the_mixture_density() {
        // The same densities as `Bsdf::sample` with a number of its own for the lobe: χ²
        // against the mixture's pdf, for Phong and GGX mixtures and single lobes.
        let (n, views) = normal_and_views();
        let bsdfs = [
            phong(n, 0.5, 0.3, 5.0),
            phong(n, 0.1, 0.5, 1000.0),
            phong(n, 0.5, 0.0, 1.0),
            ggx(n, 0.4, 0.4, 0.2),
            ggx(n, 0.0, 0.6, 0.5),
        ];
        for (k, b) in bsdfs.iter().enumerate() {
            for &wo in &views[..3] {
                chi2_test(
                    &format!("bsdf {k}, wo·n {:.2}", wo.dot(n)),
                    |u, v| b.sample_reusing(wo, u, v).map(|s| s.wi),
                    |wi| b.pdf(wo, wi),
                );
            }
        }
    }

    #[test]
    fn one_lobe_uses_the_first_number_as_it_is() {
        let (n, views) = normal_and_views();
        let b = phong(n, 0.5, 0.0, 1.0);
        for k in 0..64 {
            let (u, v) = ((k as f32 * 0.618).fract(), (k as f32 * 0.382).fract());
            let (a, b) = (b.sample_reusing(views[1], u, v), b.sample(views[1], 0.0, u, v));
            assert_eq!(a.map(|s| s.wi), b.map(|s| s.wi));
        }
    }
}
