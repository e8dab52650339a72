//! The work a render of the scene asks for: the rays it traces, about and at most, and
//! the warnings when that is more than any picture needs (the settings that ask for
//! it: `spp`, `lightsamples`, `maxdepth`, `size`). The build estimates the whole picture
//! at the scene's `spp`; a render warns about its own part of it ([`Work::of_render`],
//! [`warn_if_absurd`]): a region, a sample range, a task, another `--spp`.
//!
//! "At most" follows from the settings and the materials alone (every glass hit
//! splitting, every path going to its last bounce). "About" is measured where that is
//! cheap: a probe traces one sample at 64 pixels spread over the image, as the render
//! would, and counts their rays; the settings alone would take every pixel to see the
//! scene's glass, and warned of hours of work for a gallery scene that takes seconds.

use lucent_core::accel::AccelKind;
use lucent_core::camera::Resolution;
use lucent_core::integrator::path::{Nee, UNBOUNDED_SAFETY_CAP};
use lucent_core::integrator::whitted::Whitted;
use lucent_core::integrator::{CameraHit, Integrator, TraceCounts};
use lucent_core::math::Color;
use lucent_core::sampler::Sampler;
use lucent_core::scene::Scene;

use super::settings::Chosen;
use crate::desc::SceneDesc;
use crate::diag::{Diagnostics, Loc};

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
    /// The samples per pixel these figures are for.
    pub spp: f64,
    /// Shadow rays per shading point (what `lightsamples` weighs in the warning).
    pub shadow: f64,
}

impl Work {
    /// The work of a render of this scene of `pixels` pixels with `samples` samples each:
    /// a region, a sample range, another `--spp`.
    pub fn of_render(&self, pixels: u64, samples: u32) -> Work {
        let per_pixel = |v: f64| v / self.spp * samples as f64;
        Work {
            rays_per_pixel: per_pixel(self.rays_per_pixel),
            rays: per_pixel(self.rays_per_pixel) * pixels as f64,
            most_rays_per_pixel: per_pixel(self.most_rays_per_pixel),
            spp: samples as f64,
            ..*self
        }
    }
}

/// Work beyond either is reported: hours of rays (about 3 hours at 1 Mray/s per core on
/// two cores), or more rays for one pixel than any picture needs.
pub const ABSURD_RAYS: f64 = 1e10;
pub const ABSURD_RAYS_PER_PIXEL: f64 = (1u64 << 20) as f64;

/// The probe's pixels: one at a fixed random place in each cell of a `PROBE_GRID` ×
/// `PROBE_GRID` grid over the image. (At the cells' centres, a scene could hide its
/// costly parts from the probe: thin boxes on the eight probed rows, mirrors everywhere
/// else, made a render of hours look like one of 66,000 rays.)
const PROBE_GRID: u32 = 8;

/// The rays the probe traces, about at most (twice this at the very most): a
/// millisecond or two of one core.
const PROBE_RAYS: u64 = 1 << 16;

/// Estimates the work of rendering the whole image (at `resolution`), and warns at the
/// setting responsible when it is absurd.
pub fn estimate_work(
    desc: &SceneDesc,
    scene: &Scene,
    chosen: &Chosen,
    resolution: Resolution,
    diags: &mut Diagnostics,
) -> Work {
    let pixels = resolution.width as u64 * resolution.height as u64;
    let spp = desc.spp() as f64;
    let bounded = |depth: u32| depth as f64 + 1.0;
    // The ray tracer, and the most rays of one sample's tree (shadow rays left out).
    let mut whitted_tree = None;
    // (rays per sample, at most, shadow rays per shading point, the deepest bounce)
    let (per_sample, most, shadow, depth) = match chosen {
        Chosen::Whitted(w) => {
            let tree = w.tree_rays_bound(&scene.materials);
            whitted_tree = Some((w, tree));
            whitted_rays(scene, w, tree)
        }
        Chosen::AnalyticDirect(_) => (1.0, 1.0, 0.0, 1),
        Chosen::Direct(d) => {
            let shadow = shadow_rays(scene, d.light_samples);
            // Through up to `maxdepth` mirrors and glass, then the lights' shadow rays.
            let most = bounded(d.max_delta_bounces) + sampled_shadow_rays(scene, d.light_samples);
            if scene.materials.iter().any(|m| m.is_delta()) {
                // A mirror sphere keeps every ray to the last bounce.
                (most, most, shadow, d.max_delta_bounces)
            } else {
                (1.0 + shadow, most, shadow, 1)
            }
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
    let per_sample = probe(scene, chosen, resolution, most).unwrap_or(per_sample);
    // The typical count never passes the bound (the tree's cap, chiefly).
    let per_sample = per_sample.min(most);
    let work = Work {
        rays_per_pixel: spp * per_sample,
        rays: spp * per_sample * pixels as f64,
        most_rays_per_pixel: spp * most,
        depth,
        spp,
        shadow,
    };
    if let Some((w, tree)) = whitted_tree {
        warn_if_cut(desc, scene, w, tree, diags);
    }
    work
}

/// The rays one camera sample traces on average, measured on one sample at each of the
/// probe's pixels, if that is cheap: `None` where one sample could take more than
/// [`PROBE_RAYS`] (bounded by `most` rays, or a ray tree that the probe had to cut
/// short), where the probe's samples together take more, and where the list's rays test
/// every primitive and there are many.
fn probe(scene: &Scene, chosen: &Chosen, resolution: Resolution, most: f64) -> Option<f64> {
    // Every ray of the list tests every primitive: the budget shrinks with their count.
    let cost = match scene.accel_kind() {
        AccelKind::List => (scene.geometry.primitives.len() as u64 / 256).max(1),
        _ => 1,
    };
    let budget = PROBE_RAYS / cost;
    let shortened;
    let integrator: &dyn Integrator = match chosen {
        Chosen::Whitted(w) => {
            // Each probe sample's tree is cut short of the budget: a sample that gets
            // there cannot be measured.
            let per_ray = 1.0 + shadow_rays(scene, w.light_samples.max(1));
            let cap = (budget as f64 / per_ray).min(w.max_tree_rays as f64);
            if cap < 1.0 {
                return None;
            }
            shortened = Whitted {
                max_tree_rays: cap as u32,
                ..*w
            };
            &shortened
        }
        _ if most > budget as f64 => return None,
        Chosen::AnalyticDirect(i) => i,
        Chosen::Direct(i) => i,
        Chosen::PathTracer(i) => i,
    };
    let mut counts = TraceCounts::default();
    let (w, h) = (resolution.width, resolution.height);
    for j in 0..PROBE_GRID {
        for i in 0..PROBE_GRID {
            // The first rows alone would not stand for the image.
            if counts.rays >= budget {
                return None;
            }
            let (u, v) = Sampler::new(0x9e0b_e5ca_77e4, i, j, 0).uniform2();
            let place = |k: u32, u: f32, size: u32| {
                (((k as f64 + u as f64) * size as f64 / PROBE_GRID as f64) as u32).min(size - 1)
            };
            let (x, y) = (place(i, u, w), place(j, v, h));
            let ray = scene.camera.ray(resolution, x as f64 + 0.5, y as f64 + 0.5, (0.5, 0.5));
            let mut sampler = Sampler::new(0x5eed_0f_9a7e, x, y, 0);
            integrator.radiance(scene, &ray, CameraHit::Untraced, &mut sampler, &mut counts);
        }
    }
    let samples = PROBE_GRID * PROBE_GRID;
    (counts.cut_branches == 0).then(|| counts.rays as f64 / samples as f64)
}

/// Warns at `maxdepth` when a camera sample's ray tree could pass
/// [`Whitted::max_tree_rays`], where the renderer cuts it (`tree`: the most rays of one,
/// [`Whitted::tree_rays_bound`]).
fn warn_if_cut(desc: &SceneDesc, scene: &Scene, whitted: &Whitted, tree: f64, diags: &mut Diagnostics) {
    if tree < whitted.max_tree_rays as f64 {
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

/// Rays per sample (about, and at most, from `tree`, the most rays of one sample's tree),
/// shadow rays per shading point and the deepest bounce of the Whitted ray tracer.
fn whitted_rays(scene: &Scene, whitted: &Whitted, tree: f64) -> (f64, f64, f64, u32) {
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
    let most = (1.0 + most_shadow) * tree;
    (per_sample, most, shadow, depth)
}

/// Warns, at the setting that asks for most of it, when `work` (the build's, or
/// [`Work::of_render`]'s for a part of the picture) is more than any picture needs.
pub fn warn_if_absurd(desc: &SceneDesc, work: &Work, diags: &mut Diagnostics) {
    if work.rays > ABSURD_RAYS || work.rays_per_pixel > ABSURD_RAYS_PER_PIXEL {
        let (loc, what) = culprit(desc, work.spp, work.shadow, work.depth);
        diags.warning(
            loc,
            format!(
                "{what}: this render traces about {:.1e} rays ({:.1e} per pixel, {} {} each){}; Ctrl-C stops it",
                work.rays,
                work.rays_per_pixel,
                work.spp,
                if work.spp == 1.0 { "sample" } else { "samples" },
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
