//! Integrators: how the colour seen along a camera ray is computed. One file each;
//! the render loop only knows this trait.

pub mod whitted;

use crate::math::Color;
use crate::ray::Ray;
use crate::sampler::Sampler;
use crate::scene::Scene;

pub trait Integrator: Sync {
    /// Radiance arriving along `ray`; `sampler` gives the sample's random numbers, and
    /// `rays` counts every ray traced on the way.
    fn radiance(&self, scene: &Scene, ray: &Ray, sampler: &mut Sampler, rays: &mut u64) -> Color;
}
