//! What a camera sample shows of the first surface it meets, for the auxiliary passes
//! (`--aov albedo,normal,depth,alpha`, and the guides of `--denoise`): the surface's
//! albedo ([`Bsdf::albedo`]) and shading normal, the distance to it, and whether the ray
//! hit anything at all. The same for every integrator.
//!
//! Mirrors and glass are seen through, as Open Image Denoise asks of its guides: the ray
//! follows the delta lobe (the refracted ray through glass, unless the light is totally
//! reflected; the reflected ray off a mirror) to the first surface that is not a delta,
//! up to [`MAX_DELTA_CHAIN`] times, and that surface gives the albedo and normal — the
//! depth stays that of the first hit. A ray that leaves the scene after a delta chain
//! shows the environment, clamped to [0, 1], as its albedo.
//!
//! [`Bsdf::albedo`]: crate::shading::bsdf::Bsdf::albedo

use crate::film::AovSample;
use crate::integrator::TraceCounts;
use crate::math::{Color, Vec3A};
use crate::ray::Ray;
use crate::scene::Scene;

/// The most delta surfaces (mirror, glass) followed before the last one's own albedo and
/// normal are taken.
pub const MAX_DELTA_CHAIN: u32 = 8;

/// The AOV sample of the camera ray `camera_ray` (whose direction is a unit vector),
/// counting the rays traced.
pub fn first_surface(scene: &Scene, camera_ray: &Ray, counts: &mut TraceCounts) -> AovSample {
    let mut ray = *camera_ray;
    let mut depth = None;
    for chain in 0..=MAX_DELTA_CHAIN {
        counts.rays += 1;
        let Some(hit) = scene.closest_hit(&ray) else {
            let albedo = if depth.is_some() {
                scene.background(ray.dir).clamp(Color::ZERO, Color::ONE)
            } else {
                Color::ZERO
            };
            return AovSample {
                albedo,
                normal: Vec3A::ZERO,
                depth,
            };
        };
        depth.get_or_insert(hit.t);
        let sp = scene.surface_point(&hit, &ray);
        if let Some(light) = sp.light {
            let le = scene.lights[light as usize].radiance_seen(ray.dir, sp.normal);
            return AovSample {
                albedo: le.clamp(Color::ZERO, Color::ONE),
                normal: sp.normal,
                depth,
            };
        }
        let bsdf = scene.bsdf(&hit, &ray, &sp);
        let wo = -ray.dir;
        // Through glass (a pick of 1 refracts unless the light is totally reflected,
        // then 0 reflects) or off a mirror.
        let through = bsdf.sample_delta(wo, 1.0).or_else(|| bsdf.sample_delta(wo, 0.0));
        match through {
            Some(d) if chain < MAX_DELTA_CHAIN => ray = sp.spawn(d.wi),
            _ => {
                return AovSample {
                    albedo: bsdf.albedo(),
                    normal: bsdf.normal(),
                    depth,
                }
            }
        }
    }
    unreachable!("the last link of the chain returns")
}
