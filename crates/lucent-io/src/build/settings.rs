//! The integrator and what it is told: `integrator`, `maxdepth`, `lightsamples`,
//! `lightstratify`, `nexteventestimation`, `russianroulette`, `importancesampling`; and
//! the work a render of the scene asks for. Settings only other integrators read, and
//! lights the chosen one cannot render, are warnings; work no picture needs is a
//! warning at the setting that asks for it.

use lucent_core::integrator::analytic_direct::AnalyticDirect;
use lucent_core::integrator::depth::DepthControl;
use lucent_core::integrator::direct::Direct;
use lucent_core::integrator::path::{self, Nee, PathTracer, UNBOUNDED_SAFETY_CAP};
use lucent_core::integrator::whitted::{Whitted, MAX_TREE_RAYS};
use lucent_core::integrator::Integrator;
use lucent_core::math::Color;
use lucent_core::scene::Scene;

use crate::desc::{Brdf, DirectionSampling, IntegratorKind, LightKind, NeeMode, SceneDesc, ShapeKind};
use crate::diag::{Diagnostics, Loc};

/// `maxdepth -1` (unbounded) is capped here when nothing else ends a path: a closed
/// mirror box would never end.
pub const UNBOUNDED_DEPTH_CAP: u32 = 100;

/// The integrator the scene asks for, with its settings.
pub enum Chosen {
    Whitted(Whitted),
    AnalyticDirect(AnalyticDirect),
    Direct(Direct),
    PathTracer(PathTracer),
}

impl Chosen {
    pub fn into_box(self) -> Box<dyn Integrator> {
        match self {
            Chosen::Whitted(i) => Box::new(i),
            Chosen::AnalyticDirect(i) => Box::new(i),
            Chosen::Direct(i) => Box::new(i),
            Chosen::PathTracer(i) => Box::new(i),
        }
    }
}

/// The integrator the scene asks for, with its settings; the Whitted integrator's
/// adaptive depth control is set once the scene is built ([`control_depth`]).
pub fn integrator(desc: &SceneDesc, diags: &mut Diagnostics) -> Chosen {
    check_integrator(desc, diags);
    let kind = desc.integrator();
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
    let roulette = desc.russian_roulette.as_ref().is_some_and(|r| r.value);
    let max_depth = match desc.max_depth() {
        -1 if kind == IntegratorKind::PathTracer && roulette => None,
        -1 => {
            let loc = desc.max_depth.as_ref().map(|d| d.loc).unwrap_or(desc.end);
            let why = if kind == IntegratorKind::PathTracer {
                " (without Russian roulette)"
            } else {
                ""
            };
            diags.warning(
                loc,
                format!("maxdepth: -1 (unbounded) is capped at {UNBOUNDED_DEPTH_CAP} bounces{why}"),
            );
            Some(UNBOUNDED_DEPTH_CAP)
        }
        d => Some(d as u32),
    };
    match kind {
        IntegratorKind::RayTracer => Chosen::Whitted(Whitted {
            max_depth: max_depth.unwrap_or(UNBOUNDED_DEPTH_CAP),
            light_samples,
            light_stratify,
            depth: DepthControl::off(),
            max_tree_rays: MAX_TREE_RAYS,
        }),
        IntegratorKind::AnalyticDirect => Chosen::AnalyticDirect(AnalyticDirect),
        IntegratorKind::Direct => Chosen::Direct(Direct {
            max_delta_bounces: u32::try_from(desc.max_depth()).unwrap_or(UNBOUNDED_DEPTH_CAP),
            light_samples,
            light_stratify,
        }),
        IntegratorKind::PathTracer => Chosen::PathTracer(PathTracer {
            max_depth,
            nee: match desc.next_event_estimation.as_ref().map(|n| n.value) {
                None | Some(NeeMode::Off) => Nee::Off,
                Some(NeeMode::On) => Nee::On,
                Some(NeeMode::Mis) => Nee::Mis,
            },
            russian_roulette: roulette,
            sampling: match desc.importance_sampling.as_ref().map(|n| n.value) {
                None | Some(DirectionSampling::Hemisphere) => path::DirectionSampling::Hemisphere,
                Some(DirectionSampling::Cosine) => path::DirectionSampling::Cosine,
                Some(DirectionSampling::Brdf) => path::DirectionSampling::Brdf,
            },
            light_samples,
            light_stratify,
        }),
    }
}

/// Sets the Whitted integrator's adaptive depth control from the built scene and its
/// `gamma`.
pub fn control_depth(chosen: &mut Chosen, scene: &Scene, gamma: f32) {
    if let Chosen::Whitted(whitted) = chosen {
        whitted.depth = DepthControl::for_scene(scene, gamma);
    }
}

/// A render's work: the rays it traces, about, and at most.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Work {
    /// Rays per pixel: camera rays, shadow rays, reflected and refracted rays.
    pub rays_per_pixel: f64,
    /// For the whole image.
    pub rays: f64,
    /// Rays per pixel at most, whatever the scene's surfaces do to the rays: every glass
    /// hit splitting in two, every path going to its last bounce.
    pub most_rays_per_pixel: f64,
    /// The deepest bounce traced: `maxdepth`, or less where adaptive depth control stops
    /// the branches first.
    pub depth: u32,
}

/// Work beyond either is reported: hours of rays (about 3 hours at 1 Mray/s per core on
/// two cores), or more rays for one pixel than any picture needs.
pub const ABSURD_RAYS: f64 = 1e10;
pub const ABSURD_RAYS_PER_PIXEL: f64 = (1u64 << 20) as f64;

/// Warns at the end of the scene when the picture can only be black or empty: no objects
/// at all (a misspelt `sphere` is a warning of its own, easily missed), or nothing that
/// lights them for this integrator.
pub fn warn_if_dark(desc: &SceneDesc, scene: &Scene, diags: &mut Diagnostics) {
    let kind = desc.integrator();
    if scene.geometry.primitives.is_empty() {
        let sky = if scene.environment.is_some() {
            " but the environment map"
        } else {
            ""
        };
        diags.warning(
            desc.end,
            format!("the scene has no objects: the picture will show nothing{sky}"),
        );
        return;
    }
    let glows = desc.materials.iter().any(|m| m.emission != glam::DVec3::ZERO);
    let ambient = desc.materials.iter().any(|m| m.ambient != glam::DVec3::ZERO);
    let quads = scene.lights.iter().any(|l| !l.is_delta());
    let lit = match kind {
        IntegratorKind::RayTracer => !scene.lights.is_empty() || glows || ambient,
        IntegratorKind::AnalyticDirect => quads,
        IntegratorKind::Direct | IntegratorKind::PathTracer => {
            !scene.lights.is_empty()
                || scene.emitters.is_some()
                || !scene.unsampled_emitters.is_empty()
                || scene.environment.is_some()
        }
    };
    if !lit {
        let what = match kind {
            IntegratorKind::AnalyticDirect => "no quad light (the only light integrator analyticdirect renders)",
            IntegratorKind::RayTracer => "no light, and no ambient or emission colour",
            _ => "no light, no emissive object and no environment map",
        };
        diags.warning(desc.end, format!("the scene has {what}: the picture will be black"));
    }
}

/// Estimates the work of rendering the whole image (`pixels` of them), and warns at the
/// setting responsible when it is absurd.
pub fn estimate_work(desc: &SceneDesc, scene: &Scene, chosen: &Chosen, pixels: u64, diags: &mut Diagnostics) -> Work {
    let spp = desc.spp() as f64;
    let bounded = |depth: u32| depth as f64 + 1.0;
    // (rays per sample, at most, shadow rays per shading point, the deepest bounce)
    let (per_sample, most, shadow, depth) = match chosen {
        Chosen::Whitted(w) => whitted_rays(scene, w),
        Chosen::AnalyticDirect(_) => (1.0, 1.0, 0.0, 1),
        Chosen::Direct(d) => {
            let shadow = shadow_rays(scene, d.light_samples);
            // Through up to `maxdepth` mirrors and glass, then the lights' shadow rays.
            let most = bounded(d.max_delta_bounces) + sampled_shadow_rays(scene, d.light_samples);
            (1.0 + shadow, most, shadow, 1)
        }
        Chosen::PathTracer(p) => {
            // A path's segments (about the depth, or a few with Russian roulette) each
            // with their shadow rays.
            let segments = p.max_depth.map_or(8.0, |d| d as f64 + 1.0);
            let (shadow, most_shadow) = match p.nee {
                Nee::Off => (0.0, 0.0),
                Nee::On => (
                    shadow_rays(scene, p.light_samples),
                    sampled_shadow_rays(scene, p.light_samples),
                ),
                Nee::Mis => (1.0, 1.0),
            };
            let depth = p.max_depth.unwrap_or(UNBOUNDED_SAFETY_CAP);
            (
                segments * (1.0 + shadow),
                bounded(depth) * (1.0 + most_shadow),
                shadow,
                depth,
            )
        }
    };
    // The typical count never passes the bound (the tree's cap, chiefly).
    let per_sample = per_sample.min(most);
    let work = Work {
        rays_per_pixel: spp * per_sample,
        rays: spp * per_sample * pixels as f64,
        most_rays_per_pixel: spp * most,
        depth,
    };
    warn_if_absurd(desc, &work, spp, shadow, depth, diags);
    if let Chosen::Whitted(w) = chosen {
        warn_if_cut(desc, scene, w, diags);
    }
    work
}

/// Warns at `maxdepth` when a camera sample's ray tree could pass
/// [`Whitted::max_tree_rays`], where the renderer cuts it.
fn warn_if_cut(desc: &SceneDesc, scene: &Scene, whitted: &Whitted, diags: &mut Diagnostics) {
    if whitted.tree_rays_bound(&scene.materials) < whitted.max_tree_rays as f64 {
        return;
    }
    let loc = desc.max_depth.as_ref().map(|d| d.loc).unwrap_or(desc.end);
    let why = if scene.materials.iter().any(|m| m.transparent != Color::ZERO) {
        "glass splits every ray it meets in two, so "
    } else {
        ""
    };
    diags.warning(
        loc,
        format!(
            "maxdepth: {why}one camera sample may trace more than {} rays; the branches of its ray tree past them are not traced",
            whitted.max_tree_rays
        ),
    );
}

/// Shadow rays per shading point: `samples` per area light, one per delta light.
fn shadow_rays(scene: &Scene, samples: u32) -> f64 {
    scene
        .lights
        .iter()
        .map(|l| if l.is_delta() { 1.0 } else { samples as f64 })
        .sum()
}

/// Shadow rays per shading point of the Monte Carlo integrators, which sample every
/// light of [`Scene::sampled_light`] (the emissive surfaces and the environment too).
fn sampled_shadow_rays(scene: &Scene, samples: u32) -> f64 {
    (0..scene.sampled_light_count())
        .map(|i| {
            if scene.sampled_light(i).is_delta() {
                1.0
            } else {
                samples.max(1) as f64
            }
        })
        .sum()
}

/// Rays per sample (about, and at most), shadow rays per shading point and the deepest
/// bounce of the Whitted ray tracer.
fn whitted_rays(scene: &Scene, whitted: &Whitted) -> (f64, f64, f64, u32) {
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
    let shadow = shadow_rays(scene, whitted.light_samples);
    let glossy = m.iter().filter_map(|m| m.glossy).map(|g| g.samples).max().unwrap_or(1) as f64;
    let split = if m.iter().any(|m| m.transparent != Color::ZERO) {
        2.0
    } else {
        1.0
    };
    // Every hit casts its shadow rays; the first bounce fans out into the glossy rays,
    // later ones follow one ray each; glass splits a path in two.
    let per_sample = (1.0 + shadow) * (1.0 + glossy * depth as f64) * split;
    // Every ray of the tree casts at most a shadow ray per light (`lightsamples` per
    // quad light).
    let most_shadow = shadow_rays(scene, whitted.light_samples.max(1));
    let most = (1.0 + most_shadow) * whitted.tree_rays_bound(m);
    (per_sample, most, shadow, depth)
}

fn warn_if_absurd(desc: &SceneDesc, work: &Work, spp: f64, shadow: f64, depth: u32, diags: &mut Diagnostics) {
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

/// Warnings for what the chosen integrator does not use: switches of other integrators,
/// lights it cannot render, BRDF models it does not shade with.
fn check_integrator(desc: &SceneDesc, diags: &mut Diagnostics) {
    let kind = desc.integrator();
    let name = kind.name();
    let unused = |what: &str, loc, diags: &mut Diagnostics| {
        diags.warning(loc, format!("{what}: has no effect with integrator {name}"));
    };
    if kind != IntegratorKind::PathTracer {
        if let Some(v) = &desc.next_event_estimation {
            unused("nexteventestimation", v.loc, diags);
        }
        if let Some(v) = &desc.russian_roulette {
            unused("russianroulette", v.loc, diags);
        }
        if let Some(v) = &desc.importance_sampling {
            unused("importancesampling", v.loc, diags);
        }
    }
    let nee = desc.next_event_estimation.as_ref().map(|n| n.value);
    let samples_unused = match kind {
        IntegratorKind::AnalyticDirect => true,
        IntegratorKind::PathTracer => nee != Some(NeeMode::On),
        _ => false,
    };
    if samples_unused {
        let why = if kind == IntegratorKind::PathTracer {
            " (only 'nexteventestimation on' reads it)"
        } else {
            ""
        };
        if let Some(v) = &desc.light_samples {
            diags.warning(
                v.loc,
                format!("lightsamples: has no effect with integrator {name}{why}"),
            );
        }
        if let Some(v) = &desc.light_stratify {
            diags.warning(
                v.loc,
                format!("lightstratify: has no effect with integrator {name}{why}"),
            );
        }
    }
    if matches!(kind, IntegratorKind::RayTracer | IntegratorKind::AnalyticDirect) {
        for (brdf, model) in [(Brdf::Ggx, "ggx"), (Brdf::Mirror, "mirror")] {
            if let Some(s) = desc
                .shapes
                .iter()
                .find(|s| desc.materials[s.material as usize].brdf == brdf)
            {
                let how = match kind {
                    IntegratorKind::RayTracer if brdf == Brdf::Mirror => "its mirrors come from 'specular'",
                    IntegratorKind::RayTracer => "it shades with Blinn-Phong",
                    _ => "it shades the diffuse term only",
                };
                diags.warning(
                    s.loc,
                    format!("brdf {model} has no effect with integrator {name} ({how})"),
                );
            }
        }
    }
    if matches!(kind, IntegratorKind::Direct | IntegratorKind::PathTracer) {
        // EXTENSIONS.md: a transparent material is a smooth dielectric there, nothing more.
        if let Some(s) = desc.shapes.iter().find(|s| {
            let m = &desc.materials[s.material as usize];
            m.transparent != glam::DVec3::ZERO && (m.diffuse != glam::DVec3::ZERO || m.specular != glam::DVec3::ZERO)
        }) {
            diags.warning(
                s.loc,
                format!(
                    "transparent: with integrator {name} this object is smooth glass; its diffuse and specular colours are not used"
                ),
            );
        }
        // EXTENSIONS.md: emissive objects are a light that NEE samples by area; an
        // unbounded plane and a quadric have no area to draw from.
        if let Some(s) = desc.shapes.iter().find(|s| {
            desc.materials[s.material as usize].emission != glam::DVec3::ZERO
                && matches!(s.kind, ShapeKind::Plane { .. } | ShapeKind::Quadric { .. })
        }) {
            let what = if matches!(s.kind, ShapeKind::Plane { .. }) {
                "plane"
            } else {
                "quadric"
            };
            diags.warning(
                s.loc,
                format!(
                    "emission: light sampling cannot draw points on a {what}; with integrator {name} only the paths that hit it (and every other object of this material) count its light"
                ),
            );
        }
    }
    if kind == IntegratorKind::AnalyticDirect {
        for l in &desc.lights {
            let what = match l.kind {
                LightKind::Directional { .. } => "directional",
                LightKind::Point { .. } => "point",
                LightKind::Quad { .. } => continue,
            };
            diags.warning(
                l.loc,
                format!("{what}: integrator analyticdirect renders quad lights only; this light is ignored"),
            );
        }
    }
}
