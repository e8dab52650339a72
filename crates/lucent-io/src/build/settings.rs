//! The integrator and what it is told: `integrator`, `maxdepth`, `lightsamples`,
//! `lightstratify`; and the work a render of the scene asks for. Settings this version
//! cannot honour are errors; settings only other integrators read are warnings; work no
//! picture needs is a warning at the setting that asks for it.

use lucent_core::integrator::depth::DepthControl;
use lucent_core::integrator::whitted::Whitted;
use lucent_core::light::Light;
use lucent_core::math::Color;
use lucent_core::scene::Scene;

use crate::desc::{Brdf, IntegratorKind, SceneDesc};
use crate::diag::{Diagnostics, Loc};

/// `maxdepth -1` (unbounded) is capped here: a closed mirror box would never end.
pub const UNBOUNDED_DEPTH_CAP: u32 = 100;

/// The integrator the scene asks for, with its settings; its adaptive depth control is
/// set once the scene is built ([`control_depth`]).
pub fn integrator(desc: &SceneDesc, diags: &mut Diagnostics) -> Whitted {
    check_integrator(desc, diags);
    let max_depth = match desc.max_depth() {
        -1 => {
            let loc = desc.max_depth.as_ref().map(|d| d.loc).unwrap_or(desc.end);
            diags.warning(
                loc,
                format!("maxdepth: -1 (unbounded) is capped at {UNBOUNDED_DEPTH_CAP} bounces"),
            );
            UNBOUNDED_DEPTH_CAP
        }
        d => d as u32,
    };
    let light_samples = desc.light_samples();
    let light_stratify = desc.light_stratify();
    if light_stratify {
        let root = (light_samples as f64).sqrt().round() as u64;
        if root * root != light_samples as u64 {
            let loc = match (&desc.light_samples, &desc.light_stratify) {
                (Some(l), _) => l.loc,
                (None, Some(s)) => s.loc,
                (None, None) => desc.end,
            };
            diags.error(
                loc,
                format!("lightsamples: 'lightstratify on' needs a perfect square, got {light_samples}"),
            );
        }
    }
    Whitted {
        max_depth,
        light_samples,
        light_stratify,
        depth: DepthControl::off(),
    }
}

/// Sets the integrator's adaptive depth control from the built scene and its `gamma`.
pub fn control_depth(whitted: &mut Whitted, scene: &Scene, gamma: f32) {
    whitted.depth = DepthControl::for_scene(scene, gamma);
}

/// A render's work: the rays it traces, about.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Work {
    /// Rays per pixel: camera rays, shadow rays, reflected and refracted rays.
    pub rays_per_pixel: f64,
    /// For the whole image.
    pub rays: f64,
    /// The deepest bounce traced: `maxdepth`, or less where adaptive depth control stops
    /// the branches first.
    pub depth: u32,
}

/// Work beyond either is reported: hours of rays (about 3 hours at 1 Mray/s per core on
/// two cores), or more rays for one pixel than any picture needs.
pub const ABSURD_RAYS: f64 = 1e10;
pub const ABSURD_RAYS_PER_PIXEL: f64 = (1u64 << 20) as f64;

/// Estimates the work of rendering the whole image (`pixels` of them), and warns at the
/// setting responsible when it is absurd.
pub fn estimate_work(desc: &SceneDesc, scene: &Scene, whitted: &Whitted, pixels: u64, diags: &mut Diagnostics) -> Work {
    let m = &scene.materials;
    let reflects = m
        .iter()
        .any(|m| m.specular != Color::ZERO || m.transparent != Color::ZERO);
    let depth = if reflects {
        whitted
            .depth
            .depth_limit()
            .map_or(whitted.max_depth, |d| d.min(whitted.max_depth))
    } else {
        0
    };
    let shadow: f64 = scene
        .lights
        .iter()
        .map(|l| match l {
            Light::Quad(_) => whitted.light_samples as f64,
            _ => 1.0,
        })
        .sum();
    let glossy = m.iter().filter_map(|m| m.glossy).map(|g| g.samples).max().unwrap_or(1) as f64;
    let split = if m.iter().any(|m| m.transparent != Color::ZERO) {
        2.0
    } else {
        1.0
    };
    let spp = desc.spp() as f64;
    // Every hit casts its shadow rays; the first bounce fans out into the glossy rays,
    // later ones follow one ray each; glass splits a path in two.
    let per_sample = (1.0 + shadow) * (1.0 + glossy * depth as f64) * split;
    let work = Work {
        rays_per_pixel: spp * per_sample,
        rays: spp * per_sample * pixels as f64,
        depth,
    };
    if work.rays > ABSURD_RAYS || work.rays_per_pixel > ABSURD_RAYS_PER_PIXEL {
        let (loc, what) = culprit(desc, spp, shadow, depth);
        diags.warning(
            loc,
            format!(
                "{what}: this render traces about {:.1e} rays ({:.1e} per pixel){}; Ctrl-C stops it",
                work.rays,
                work.rays_per_pixel,
                if work.rays > ABSURD_RAYS {
                    ", hours of work"
                } else {
                    ", far more than a picture needs"
                }
            ),
        );
    }
    work
}

/// The setting that contributes the largest factor to the work, and its name.
fn culprit(desc: &SceneDesc, spp: f64, shadow: f64, depth: u32) -> (Loc, &'static str) {
    let at = |l: Option<Loc>| l.unwrap_or(desc.end);
    let candidates = [
        (spp, at(desc.spp.as_ref().map(|s| s.loc)), "spp"),
        (shadow, at(desc.light_samples.as_ref().map(|s| s.loc)), "lightsamples"),
        (depth as f64, at(desc.max_depth.as_ref().map(|s| s.loc)), "maxdepth"),
    ];
    let best = candidates
        .into_iter()
        .max_by(|a, b| a.0.total_cmp(&b.0))
        .expect("three candidates");
    if best.0 > 1.0 {
        (best.1, best.2)
    } else {
        (at(desc.size.as_ref().map(|s| s.loc)), "size")
    }
}

fn check_integrator(desc: &SceneDesc, diags: &mut Diagnostics) {
    if let Some(i) = &desc.integrator {
        if i.value != IntegratorKind::RayTracer {
            diags.error(
                i.loc,
                format!(
                    "integrator: '{}' is not implemented yet (this version renders 'raytracer')",
                    i.value.name()
                ),
            );
            return;
        }
    }
    let only_for = |name: &str, loc, diags: &mut Diagnostics| {
        diags.warning(loc, format!("{name}: has no effect with integrator raytracer"));
    };
    if let Some(v) = &desc.next_event_estimation {
        only_for("nexteventestimation", v.loc, diags);
    }
    if let Some(v) = &desc.russian_roulette {
        only_for("russianroulette", v.loc, diags);
    }
    if let Some(v) = &desc.importance_sampling {
        only_for("importancesampling", v.loc, diags);
    }
    if let Some(s) = desc
        .shapes
        .iter()
        .find(|s| desc.materials[s.material as usize].brdf == Brdf::Ggx)
    {
        diags.warning(
            s.loc,
            "brdf ggx has no effect with integrator raytracer (it shades with Blinn-Phong)",
        );
    }
}
