//! Integrators: how the colour seen along a camera ray is computed. One file each;
//! the render loop only knows this trait.

pub mod depth;
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

pub trait Integrator: Sync {
    /// Radiance arriving along `ray`; `sampler` gives the sample's random numbers, and
    /// `counts` counts what was traced on the way.
    fn radiance(&self, scene: &Scene, ray: &Ray, sampler: &mut Sampler, counts: &mut TraceCounts) -> Color;
}
