//! Integrators: how the colour seen along a camera ray is computed. One file each;
//! the render loop only knows this trait.

pub mod whitted;

use crate::math::Color;
use crate::ray::Ray;
use crate::scene::Scene;

pub trait Integrator: Sync {
    /// Radiance arriving along `ray`; `rays` counts every ray traced on the way.
    fn radiance(&self, scene: &Scene, ray: &Ray, rays: &mut u64) -> Color;
}
