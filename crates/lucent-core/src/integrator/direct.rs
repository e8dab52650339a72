//! Scene commands `integrator direct`, `lightsamples N`, `lightstratify on|off` (CSE168
//! homework 2, SCENE_FORMAT.md §4.5): light that reaches the camera after exactly one
//! reflection, estimated with `lightsamples` shadow rays per area light:
//!
//! ```text
//! L = E + Σ_lights (1/N) Σ_m f(x, ωi, ωo) · V(x, y_m) · max(n·ωi, 0) · Le / pdf(ωi)
//! ```
//!
//! with `pdf = R² / (A · cos θ_light)` (a uniform point `y_m` on the parallelogram, on a
//! √N × √N jittered grid with `lightstratify on`) and `f` the material's BRDF. Point and
//! directional lights get one shadow ray each. No ambient term. A camera ray that hits a
//! light sees its radiance from the front and black from behind; one that hits nothing
//! sees the environment (`envmap`). The sum runs over every light of the Monte Carlo
//! integrators: all emissive surfaces together are one, the environment another
//! (EXTENSIONS.md).
//!
//! Light sampling cannot reach through a mirror (`brdf mirror`) or glass (`transparent`):
//! at such a surface the ray follows the delta lobe, up to `maxdepth` times, and the
//! direct light is estimated where it lands (what pbrt's direct-lighting integrator does).

use super::light_sampling::every_light;
use super::{first_hit, CameraHit, FirstHit, Integrator, PixelSampling, TraceCounts};
use crate::math::Color;
use crate::ray::Ray;
use crate::sampler::Sampler;
use crate::scene::Scene;

pub struct Direct {
    /// `maxdepth`: how many mirror or glass surfaces a camera ray may pass through.
    pub max_delta_bounces: u32,
    /// `lightsamples`.
    pub light_samples: u32,
    /// `lightstratify`.
    pub light_stratify: bool,
}

impl Integrator for Direct {
    fn radiance(
        &self,
        scene: &Scene,
        camera_ray: &Ray,
        mut camera: CameraHit,
        sampler: &mut Sampler,
        counts: &mut TraceCounts,
    ) -> Color {
        let mut ray = *camera_ray;
        let mut weight = Color::ONE;
        let mut total = Color::ZERO;
        for bounce in 0.. {
            let (hit, sp) = match first_hit(scene, &ray, &mut camera, counts) {
                FirstHit::Nothing => return total + weight * scene.background(ray.dir),
                FirstHit::Light(radiance) => return total + weight * radiance,
                FirstHit::Surface(hit, sp) => (hit, sp),
            };
            let bsdf = scene.bsdf(&hit, &ray, &sp);
            let emission = scene.materials[sp.material as usize].emission;
            total += weight * emission;
            let wo = -ray.dir;
            if bsdf.is_delta() {
                if bounce >= self.max_delta_bounces {
                    break;
                }
                let Some(d) = bsdf.sample_delta(wo, sampler.uniform()) else {
                    break;
                };
                weight *= d.weight;
                ray = sp.spawn(d.wi);
                continue;
            }
            total += weight
                * every_light(
                    scene,
                    &sp,
                    wo,
                    &bsdf,
                    self.light_samples,
                    self.light_stratify,
                    sampler,
                    counts,
                );
            break;
        }
        total
    }

    fn pixel_sampling(&self) -> PixelSampling {
        PixelSampling::Uniform
    }
}
