//! Scene command `integrator analyticdirect` (CSE168 homework 2, SCENE_FORMAT.md §4.4):
//! the exact irradiance from every unoccluded quad light on a diffuse surface, by the
//! irradiance-vector formula (Arvo 1995)
//!
//! ```text
//! Φ = ½ Σ_k Θ_k Γ_k,   Θ_k = ∠(v_k − x, v_{k+1} − x),   Γ_k = normalize((v_k − x) × (v_{k+1} − x))
//! L = E + Σ_lights (kd/π) · Le · (Φ · n)
//! ```
//!
//! over the corners `a, a+ab, a+ab+ac, a+ac`. No visibility, no ambient, no specular; a
//! negative `Φ·n` (a receiver behind a light) is not clamped per light. A camera ray that
//! hits a light sees its radiance from the front and black from behind. Point and
//! directional lights are not used (the build warns).

use std::f32::consts::FRAC_1_PI;

use super::{first_hit, CameraHit, FirstHit, Integrator, PixelSampling, TraceCounts};
use crate::hit::BACKGROUND;
use crate::light::{Light, QuadLight};
use crate::math::{Color, DVec3, Vec3A};
use crate::ray::Ray;
use crate::sampler::Sampler;
use crate::scene::Scene;
use crate::shading::surface;

pub struct AnalyticDirect;

/// The irradiance vector Φ of the light's parallelogram at `x`, in double precision:
/// the angles of corners seen nearly edge-on lose digits in single precision.
pub fn irradiance_vector(q: &QuadLight, x: Vec3A) -> Vec3A {
    let (c, ab, ac, x) = (q.corner.as_dvec3(), q.ab.as_dvec3(), q.ac.as_dvec3(), x.as_dvec3());
    let v = [c, c + ab, c + ab + ac, c + ac];
    let mut phi = DVec3::ZERO;
    for k in 0..4 {
        let (a, b) = (v[k] - x, v[(k + 1) % 4] - x);
        let theta = a.normalize().dot(b.normalize()).clamp(-1.0, 1.0).acos();
        let gamma = a.cross(b).normalize_or_zero();
        phi += gamma * theta;
    }
    (phi * 0.5).as_vec3().into()
}

impl Integrator for AnalyticDirect {
    fn radiance(
        &self,
        scene: &Scene,
        ray: &Ray,
        mut camera: CameraHit,
        _sampler: &mut Sampler,
        counts: &mut TraceCounts,
    ) -> Color {
        let (hit, sp) = match first_hit(scene, ray, &mut camera, counts) {
            FirstHit::Nothing => return BACKGROUND,
            FirstHit::Light(radiance) => return radiance,
            FirstHit::Surface(hit, sp) => (hit, sp),
        };
        let m = &scene.materials[sp.material as usize];
        let shaded = surface::shade(m, &scene.textures, &sp, || scene.tangents(&hit, ray));
        let mut total = m.emission;
        for light in &scene.lights {
            if let Light::Quad(q) = light {
                let phi = irradiance_vector(q, sp.point);
                total += shaded.diffuse * FRAC_1_PI * q.radiance * phi.dot(shaded.normal);
            }
        }
        total
    }

    fn pixel_sampling(&self) -> PixelSampling {
        PixelSampling::Uniform
    }
}
