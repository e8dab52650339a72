//! Scene commands `integrator pathtracer`, `maxdepth N`, `nexteventestimation
//! off|on|mis`, `russianroulette on|off`, `importancesampling hemisphere|cosine|brdf`
//! (CSE168 homeworks 3 and 4, SCENE_FORMAT.md §4.6).
//!
//! The camera ray is segment 0; it hits x1; scattering at x_k makes segment k, which
//! hits x_{k+1}. β is the throughput, the product of `f · cos θ / pdf` of the scattering
//! events so far. `maxdepth` N bounds the number of scattering events (−1: unbounded,
//! ended by Russian roulette). The lights a segment can find (EXTENSIONS.md): the front
//! of a quad light (a path ends there), either side of an emissive surface (`emission`,
//! which also scatters) and the environment (`envmap`, when the segment escapes).
//!
//! - **`off`**: a light found by any segment adds `β · Le`; every ordinary hit scatters
//!   while k ≤ N.
//! - **`on`**: a light adds `Le` only when the camera sees it; every ordinary hit x_k with
//!   k ≤ N adds `β · L_direct` (the `direct` integrator's estimator over every light,
//!   with `lightsamples` and `lightstratify`) and scatters while k < N.
//! - **`mis`**: at x_k (k ≤ N), one light sample (one light chosen uniformly) and one
//!   BSDF sample, weighted by the power heuristic; the BSDF sample is also the direction
//!   the path goes on in (while k < N), and a light it finds adds its weighted share.
//!
//! An emissive shape that light sampling cannot draw (a plane, a quadric) is counted in
//! full by the paths that find it, in every mode.
//!
//! Directions are drawn uniformly on the hemisphere around the shading normal, in
//! proportion to the cosine, or from the BSDF (`importancesampling`); one below the
//! surface ends the path. A delta BSDF (`brdf mirror`, `transparent` glass) is never
//! light-sampled: the path follows its lobe, and a light that segment finds adds in full
//! in every mode (EXTENSIONS.md), even past the last scattering event. Russian
//! roulette, when about to go on, ends the path with probability `q = 1 − min(1, max(β))` and divides β by `1 − q` otherwise.
//!
//! The camera samples of a batch are taken one path at a time, or eight at a time in
//! vector lanes ([`lanes`]) for Lambertian scenes lit by quad lights with MIS (such as
//! the diffuse versions of the course's Cornell box and dragon that the comparison with
//! Mitsuba renders): the same numbers either way.

#[cfg(target_arch = "x86_64")]
mod lanes;

use super::light_sampling::{every_light, one_light_mis};
use super::{CameraHit, Integrator, PixelSampling, TraceCounts};
use crate::hit::{Hit, SurfacePoint};
use crate::math::{Color, Vec3A};
use crate::ray::Ray;
use crate::sampler::Sampler;
use crate::sampling::frame::Frame;
use crate::sampling::mis::power_heuristic;
use crate::sampling::warp;
use crate::scene::Scene;
use crate::shading::bsdf::Bsdf;

/// `nexteventestimation`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Nee {
    Off,
    On,
    Mis,
}

/// `importancesampling`: where the next direction of a path comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DirectionSampling {
    Hemisphere,
    Cosine,
    Brdf,
}

/// Scattering events of a path with no depth limit, at most: only a path whose
/// throughput never drops (white, lossless walls) gets there, where Russian roulette
/// would never end it.
pub const UNBOUNDED_SAFETY_CAP: u32 = 1 << 12;

pub struct PathTracer {
    /// `maxdepth`: scattering events, `None` for −1 (unbounded).
    pub max_depth: Option<u32>,
    pub nee: Nee,
    pub russian_roulette: bool,
    pub sampling: DirectionSampling,
    /// `lightsamples` and `lightstratify` for `nexteventestimation on`.
    pub light_samples: u32,
    pub light_stratify: bool,
}

/// A direction drawn for the path to go on in, with `f`, the cosine at the surface and
/// the density.
struct Bounce {
    wi: Vec3A,
    f: Color,
    cos: f32,
    pdf: f32,
}

impl PathTracer {
    /// The density with which [`PathTracer::bounce`] draws `wi`.
    fn direction_pdf(&self, bsdf: &Bsdf, wo: Vec3A, wi: Vec3A) -> f32 {
        let cos = bsdf.normal().dot(wi);
        match self.sampling {
            DirectionSampling::Hemisphere => warp::uniform_hemisphere_pdf(cos),
            DirectionSampling::Cosine => warp::cosine_hemisphere_pdf(cos),
            DirectionSampling::Brdf => bsdf.pdf(wo, wi),
        }
    }

    /// The next direction, or `None` when the path ends (nothing drawn, or a direction
    /// below the surface: by the shading normal or by the true surface at `x`).
    fn bounce(&self, x: &SurfacePoint, bsdf: &Bsdf, wo: Vec3A, sampler: &mut Sampler) -> Option<Bounce> {
        let n = bsdf.normal();
        let (u, v) = sampler.uniform2();
        let (wi, f, pdf) = match self.sampling {
            DirectionSampling::Hemisphere => {
                let wi = Frame::around(n).to_world(warp::uniform_hemisphere(u, v));
                (wi, bsdf.eval(wo, wi), warp::uniform_hemisphere_pdf(n.dot(wi)))
            }
            DirectionSampling::Cosine => {
                let wi = Frame::around(n).to_world(warp::cosine_hemisphere(u, v));
                (wi, bsdf.eval(wo, wi), warp::cosine_hemisphere_pdf(n.dot(wi)))
            }
            DirectionSampling::Brdf => {
                let s = bsdf.sample_reusing(wo, u, v)?;
                (s.wi, s.f, s.pdf)
            }
        };
        let cos = n.dot(wi);
        (cos > 0.0 && pdf > 0.0 && x.above_geometry(wi)).then_some(Bounce { wi, f, cos, pdf })
    }

    /// Russian roulette on the throughput `beta` of a path about to go on (not after its
    /// last scattering event, whose segment only looks for a light); whether it goes on.
    #[inline]
    fn go_on(&self, beta: &mut Color, last: bool, sampler: &mut Sampler) -> bool {
        if self.russian_roulette && !last {
            let q = 1.0 - beta.max_element().min(1.0);
            if sampler.uniform() < q {
                return false;
            }
            *beta /= 1.0 - q;
        }
        beta.is_finite() && *beta != Color::ZERO
    }

    /// The weight of the light a path segment finds, which left its vertex as `came`
    /// says: in full without NEE, after the camera and after a delta lobe, and for a
    /// light that light sampling never draws (`sampled` false); nothing after a BSDF
    /// sample with NEE on (it counted that light); with MIS, the power heuristic against
    /// `p_light`, the density with which light sampling draws the same direction.
    #[inline]
    fn found_weight(&self, came: Came, sampled: bool, p_light: impl FnOnce() -> f32) -> f32 {
        match (self.nee, came) {
            (Nee::Off, _) | (_, Came::Camera | Came::Delta) => 1.0,
            _ if !sampled => 1.0,
            (Nee::On, Came::Bsdf(_)) => 0.0,
            (Nee::Mis, Came::Bsdf(p_bsdf)) => power_heuristic(p_bsdf, p_light()),
        }
    }

    /// Whether scattering event `k` (at x_k) may happen.
    #[inline]
    fn within_depth(&self, k: u32) -> bool {
        match self.max_depth {
            Some(n) => k <= n,
            None => k <= UNBOUNDED_SAFETY_CAP,
        }
    }
}

/// How the segment being traced left its last vertex: what a light it finds adds.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Came {
    /// The camera ray: a light seen directly adds in full.
    Camera,
    /// A delta lobe (mirror, glass), which light sampling cannot reach: a light found
    /// adds in full.
    Delta,
    /// A BSDF sample of this density (MIS weighs a light it finds against the light
    /// strategy).
    Bsdf(f32),
}

impl Integrator for PathTracer {
    fn radiance(
        &self,
        scene: &Scene,
        camera_ray: &Ray,
        mut camera: CameraHit,
        sampler: &mut Sampler,
        counts: &mut TraceCounts,
    ) -> Color {
        let mut total = Color::ZERO;
        let mut beta = Color::ONE;
        let mut ray = *camera_ray;
        let mut came = Came::Camera;
        // The index of the vertex the current segment will hit.
        let mut k = 1u32;
        loop {
            let mut found = None;
            camera.take_into(scene, &ray, counts, &mut found);
            let Some(hit) = &found else {
                // The environment (black without one), a light like any other.
                if let Some(env) = &scene.environment {
                    let le = env.radiance(ray.dir);
                    if le != Color::ZERO {
                        let p_light = || {
                            scene.environment_light.as_ref().map_or(0.0, |l| l.pdf_li(ray.dir))
                                / scene.sampled_light_count() as f32
                        };
                        total += beta * le * self.found_weight(came, scene.environment_light.is_some(), p_light);
                    }
                }
                break;
            };
            let sp = scene.surface_point(&hit, &ray);
            if let Some(index) = sp.light {
                let light = &scene.lights[index as usize];
                let le = light.radiance_seen(ray.dir, sp.normal);
                if le != Color::ZERO {
                    let p_light = || light.pdf_li(hit.t, ray.dir) / scene.sampled_light_count() as f32;
                    total += beta * le * self.found_weight(came, true, p_light);
                }
                break;
            }
            let m = &scene.materials[sp.material as usize];
            if m.emission != Color::ZERO {
                // An emissive surface: part of the emitters' light unless its shape
                // cannot be sampled (then only paths find it, and count it in full).
                let light = scene.emitters.as_ref().filter(|e| e.samples(sp.material));
                let p_light = || {
                    light.map_or(0.0, |e| e.pdf_li(m.emission, sp.geometric_normal, hit.t, ray.dir))
                        / scene.sampled_light_count() as f32
                };
                total += beta * m.emission * self.found_weight(came, light.is_some(), p_light);
            }
            // Past the last scattering event a path only looks for light.
            if !self.within_depth(k) {
                break;
            }
            let bsdf = scene.bsdf(&hit, &ray, &sp);
            let wo = -ray.dir;
            let last = !self.within_depth(k + 1);
            if bsdf.is_delta() {
                // No light sampling through a delta lobe: the path follows it, whatever
                // `importancesampling` says, and counts the light it finds in full.
                let Some(d) = bsdf.sample_delta(wo, sampler.uniform()) else {
                    break;
                };
                beta *= d.weight;
                if !self.go_on(&mut beta, last, sampler) {
                    break;
                }
                ray = sp.spawn(d.wi);
                came = Came::Delta;
                k += 1;
                continue;
            }
            match self.nee {
                Nee::Off => {}
                Nee::On => {
                    total += beta
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
                }
                Nee::Mis => {
                    let pdf = |wi| self.direction_pdf(&bsdf, wo, wi);
                    total += beta * one_light_mis(scene, &sp, wo, &bsdf, pdf, sampler, counts);
                }
            }
            // With NEE the last scattering event's light is already counted (unless
            // some emitter cannot be light-sampled: then the path looks for it); MIS
            // still traces its BSDF sample to find the light that strategy weighs.
            if last && self.nee == Nee::On && scene.unsampled_emitters.is_empty() {
                break;
            }
            let Some(b) = self.bounce(&sp, &bsdf, wo, sampler) else {
                break;
            };
            beta *= b.f * (b.cos / b.pdf);
            if !self.go_on(&mut beta, last, sampler) {
                break;
            }
            ray = sp.spawn(b.wi);
            came = Came::Bsdf(b.pdf);
            k += 1;
        }
        total
    }

    /// A batch of camera samples: eight paths at a time in vector lanes where the scene
    /// and settings allow ([`lanes`]), else one at a time; the same colours either way.
    fn radiances(
        &self,
        scene: &Scene,
        rays: &[Ray],
        hits: &[Option<Hit>],
        samplers: &mut [Sampler],
        counts: &mut TraceCounts,
        out: &mut [Color],
    ) {
        #[cfg(target_arch = "x86_64")]
        if lanes::applies(self, scene) {
            return lanes::radiances(self, scene, rays, hits, samplers, counts, out);
        }
        super::one_at_a_time(self, scene, rays, hits, samplers, counts, out);
    }

    fn pixel_sampling(&self) -> PixelSampling {
        PixelSampling::Uniform
    }
}
