//! Integrators: how the colour seen along a camera ray is computed. One file each —
//! [`whitted`] (`raytracer`), [`analytic_direct`], [`direct`], [`path`] (`pathtracer`) —
//! and [`light_sampling`], the direct-lighting estimators the last two share, with
//! [`shadow_batch`], the shadow rays toward one light traced together. The render loop
//! only knows this trait.

pub mod analytic_direct;
pub mod depth;
pub mod direct;
pub mod light_sampling;
pub mod path;
pub mod shadow_batch;
pub mod whitted;

use crate::hit::{Hit, SurfacePoint};
use crate::math::Color;
use crate::ray::{PreparedRay, Ray};
use crate::sampler::Sampler;
use crate::scene::Scene;

/// What tracing a camera ray counts.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TraceCounts {
    /// Every ray traced: camera, shadow, reflected and refracted rays.
    pub rays: u64,
    /// Branches of ray trees not traced: past a sample's [`whitted::MAX_TREE_RAYS`], or
    /// because too many were waiting at once ([`whitted::MAX_PENDING`]).
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

/// The closest hit of a camera ray, when the renderer has traced it already: camera rays
/// of a tile travel through the BVH together, in packets.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum CameraHit {
    /// Not traced yet: the integrator traces it.
    #[default]
    Untraced,
    Traced(Option<Hit>),
}

impl CameraHit {
    /// The closest hit of `ray` (counting the ray) into `out`: the one found already, else
    /// traced. Leaves `self` untraced, so that it serves the camera ray only. (Into the
    /// caller's answer, which the caller reads by reference: a copy of a hit the search
    /// has just written piece by piece would be read back whole, a stalled store-to-load
    /// forward on every ray.)
    #[inline]
    pub fn take_into(&mut self, scene: &Scene, ray: &Ray, counts: &mut TraceCounts, out: &mut Option<Hit>) {
        counts.rays += 1;
        match std::mem::take(self) {
            CameraHit::Traced(hit) => *out = hit,
            CameraHit::Untraced => scene.closest_hit_into(&PreparedRay::new(*ray), out),
        }
    }
}

/// What a camera ray meets, for the integrators that look at one surface: nothing, a
/// light (the radiance it shows the ray: its front's, black from behind) or an ordinary
/// surface point.
pub(crate) enum FirstHit {
    Nothing,
    Light(Color),
    Surface(Hit, SurfacePoint),
}

/// Traces `ray` (counting it; `camera` may hold its hit already) and says what it meets.
pub(crate) fn first_hit(scene: &Scene, ray: &Ray, camera: &mut CameraHit, counts: &mut TraceCounts) -> FirstHit {
    let mut found = None;
    camera.take_into(scene, ray, counts, &mut found);
    let Some(hit) = &found else {
        return FirstHit::Nothing;
    };
    let sp = scene.surface_point(hit, ray);
    match sp.light {
        Some(light) => FirstHit::Light(scene.lights[light as usize].radiance_seen(ray.dir, sp.normal)),
        None => FirstHit::Surface(*hit, sp),
    }
}

pub trait Integrator: Send + Sync {
    /// Radiance arriving along the camera ray `ray` (whose closest hit `camera` may hold
    /// already); `sampler` gives the sample's random numbers, and `counts` counts what
    /// was traced on the way.
    fn radiance(
        &self,
        scene: &Scene,
        ray: &Ray,
        camera: CameraHit,
        sampler: &mut Sampler,
        counts: &mut TraceCounts,
    ) -> Color;

    /// [`Integrator::radiance`] of a batch of camera samples whose camera rays were
    /// traced together (`hits[k]` the closest hit of `rays[k]`, `samplers[k]` the
    /// sample's numbers), into `out[k]`: each the very colour `radiance` gives. One at a
    /// time unless an integrator traces the next rays of the batch together too (the ray
    /// tracer: [`whitted`]).
    fn radiances(
        &self,
        scene: &Scene,
        rays: &[Ray],
        hits: &[Option<Hit>],
        samplers: &mut [Sampler],
        counts: &mut TraceCounts,
        out: &mut [Color],
    ) {
        one_at_a_time(self, scene, rays, hits, samplers, counts, out);
    }

    fn pixel_sampling(&self) -> PixelSampling {
        PixelSampling::Stratified
    }
}

/// [`Integrator::radiances`] sample by sample: the default, and the ray tracer's where a
/// batch would keep too many shadow rays.
pub fn one_at_a_time<I: Integrator + ?Sized>(
    integrator: &I,
    scene: &Scene,
    rays: &[Ray],
    hits: &[Option<Hit>],
    samplers: &mut [Sampler],
    counts: &mut TraceCounts,
    out: &mut [Color],
) {
    for (k, (ray, hit)) in rays.iter().zip(hits).enumerate() {
        out[k] = integrator.radiance(scene, ray, CameraHit::Traced(*hit), &mut samplers[k], counts);
    }
}
