//! Integrators: how the colour seen along a camera ray is computed. One file each —
//! [`whitted`] (`raytracer`), [`analytic_direct`], [`direct`], [`path`] (`pathtracer`) —
//! and [`light_sampling`], the direct-lighting estimators the last two share. The render
//! loop only knows this trait.

pub mod analytic_direct;
pub mod depth;
pub mod direct;
pub mod light_sampling;
pub mod path;
pub mod whitted;

use crate::math::Color;
use crate::ray::Ray;
use crate::sampler::Sampler;
use crate::scene::Scene;

/// What tracing a camera ray counts.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TraceCounts {
    /// Every ray traced: camera, shadow, reflected and refracted rays.
    pub rays: u64,
    /// Branches of ray trees not traced because too many were waiting at once.
    pub cut_branches: u64,
}

/// Where in its pixel each camera sample goes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PixelSampling {
    /// The Whitted ray tracer's antialiasing (EXTENSIONS.md): one sample through the
    /// centre; more on a jittered √spp × √spp grid when spp is a square, uniform
    /// otherwise.
    Stratified,
    /// The Monte Carlo integrators (SCENE_FORMAT.md §4.1 allows it): with `spp 1` the
    /// pixel centre, with more every sample at a uniform random point. Sample i is then
    /// the same whatever the total (above 1), so more samples can be added to a render,
    /// and the pixel's estimate is unbiased at any count — a first sample fixed at the
    /// centre (§4.1's other reading) would weigh the centre 1/spp and add an error that
    /// falls like 1/spp at edges.
    Uniform,
}

pub trait Integrator: Sync {
    /// Radiance arriving along `ray`; `sampler` gives the sample's random numbers, and
    /// `counts` counts what was traced on the way.
    fn radiance(&self, scene: &Scene, ray: &Ray, sampler: &mut Sampler, counts: &mut TraceCounts) -> Color;

    fn pixel_sampling(&self) -> PixelSampling {
        PixelSampling::Stratified
    }
}
