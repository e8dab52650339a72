//! The integrator and what it is told: `integrator`, `maxdepth`, `lightsamples`,
//! `lightstratify`. Settings this version cannot honour are errors; settings only other
//! integrators read are warnings.

use lucent_core::integrator::whitted::Whitted;
use lucent_core::integrator::Integrator;

use crate::desc::{Brdf, IntegratorKind, SceneDesc};
use crate::diag::Diagnostics;

/// `maxdepth -1` (unbounded) is capped here: a closed mirror box would never end.
pub const UNBOUNDED_DEPTH_CAP: u32 = 100;

/// The integrator the scene asks for, with its settings.
pub fn integrator(desc: &SceneDesc, diags: &mut Diagnostics) -> Box<dyn Integrator> {
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
    Box::new(Whitted {
        max_depth,
        light_samples,
        light_stratify,
    })
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
