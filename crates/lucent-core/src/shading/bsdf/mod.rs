//! BSDFs: how a surface point scatters light, as `eval`, `sample` and `pdf` (the shape of
//! pbrt-v4's `BxDF` and Mitsuba 3's `BSDF`, in RGB). One file per model, selected per
//! object by `brdf phong|ggx` (SCENE_FORMAT.md §4.7).
//!
//! Directions are world-space unit vectors pointing away from the surface: `wo` toward
//! the viewer (the previous vertex), `wi` toward the light or the next vertex. The
//! models are defined by the shading normal and the mirror direction, so they keep
//! the normal and work in world space; directions are drawn in a [`Frame`] around the
//! lobe's axis.
//!
//! [`Frame`]: crate::sampling::frame::Frame

pub mod ggx;
pub mod phong;

use crate::math::{Color, Vec3A};

pub use ggx::Ggx;
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

#[derive(Clone, Copy, Debug)]
pub enum Bsdf {
    Phong(Phong),
    Ggx(Ggx),
}

impl Bsdf {
    /// The shading normal the BSDF was built around.
    #[inline]
    pub fn normal(&self) -> Vec3A {
        match self {
            Bsdf::Phong(b) => b.n,
            Bsdf::Ggx(b) => b.n,
        }
    }

    /// `f(wo, wi)`.
    #[inline]
    pub fn eval(&self, wo: Vec3A, wi: Vec3A) -> Color {
        match self {
            Bsdf::Phong(b) => b.eval(wo, wi),
            Bsdf::Ggx(b) => b.eval(wo, wi),
        }
    }

    /// The solid-angle density with which [`Bsdf::sample`] draws `wi`.
    #[inline]
    pub fn pdf(&self, wo: Vec3A, wi: Vec3A) -> f32 {
        match self {
            Bsdf::Phong(b) => b.pdf(wo, wi),
            Bsdf::Ggx(b) => b.pdf(wo, wi),
        }
    }

    /// A direction drawn in proportion to the BSDF (`importancesampling brdf`): `pick`
    /// chooses the lobe, `(u, v)` the direction in it. `None` when nothing can be drawn.
    #[inline]
    pub fn sample(&self, wo: Vec3A, pick: f32, u: f32, v: f32) -> Option<BsdfSample> {
        match self {
            Bsdf::Phong(b) => b.sample(wo, pick, u, v),
            Bsdf::Ggx(b) => b.sample(wo, pick, u, v),
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
