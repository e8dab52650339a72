//! The integrator and what it is told: `integrator`, `maxdepth`, `lightsamples`,
//! `lightstratify`, `nexteventestimation`, `russianroulette`, `importancesampling`.
//! Settings only other integrators read, and lights the chosen one cannot render, are
//! warnings; so is a picture that can only be black. The work a render asks for is
//! [`super::work`]'s.

use lucent_core::integrator::analytic_direct::AnalyticDirect;
use lucent_core::integrator::depth::DepthControl;
use lucent_core::integrator::direct::Direct;
use lucent_core::integrator::path::{self, Nee, PathTracer};
use lucent_core::integrator::whitted::{Whitted, MAX_TREE_RAYS};
use lucent_core::integrator::Integrator;
use lucent_core::scene::Scene;

use crate::desc::{Brdf, DirectionSampling, IntegratorKind, LightKind, NeeMode, SceneDesc, ShapeKind};
use crate::diag::Diagnostics;

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
