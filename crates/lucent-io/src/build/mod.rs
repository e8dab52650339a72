//! The build step: a [`SceneDesc`] becomes a renderable [`Scene`], an integrator and the
//! settings of the render the file asks for. This is the only module that knows both the
//! description and the core, and the only one that reads the files a scene names. It
//! reports what the description cannot be rendered as (files that cannot be read,
//! degenerate cameras and geometry, unsupported features) at the location of the command
//! responsible, in the order of the file.
//!
//! One file per concern, in the order they run: [`settings`] (the integrator and what it
//! is told), [`camera`], [`materials`] (textures, the environment map, materials),
//! [`geometry`] (shapes to primitives, objects and instances) with [`tessellation`]
//! (the surfaces made of triangles), and [`lights`] (with the primitives that are a
//! light's surface).

mod camera;
mod geometry;
mod lights;
mod materials;
mod settings;
mod tessellation;
mod work;

use lucent_core::accel::AccelKind;
use lucent_core::camera::Resolution;
use lucent_core::integrator::Integrator;
use lucent_core::render::job::RenderJob;
use lucent_core::sampler::SamplerKind;
use lucent_core::scene::{Scene, SceneParts};

use crate::desc::{IntegratorKind, SampleSource, SceneDesc};
use crate::diag::Diagnostics;
use crate::resources::Resources;

pub use settings::UNBOUNDED_DEPTH_CAP;
pub use work::{warn_if_absurd, Work};

#[derive(Clone, Copy, Debug)]
pub struct BuildOptions {
    pub accel: AccelKind,
}

impl Default for BuildOptions {
    fn default() -> Self {
        BuildOptions { accel: AccelKind::Bvh }
    }
}

/// What the scene file asks of the render, apart from the scene itself.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderSettings {
    /// `size`.
    pub resolution: Resolution,
    /// `spp`.
    pub spp: u32,
    /// `gamma`: the exponent of the 8-bit encoding (1 = none).
    pub gamma: f32,
    /// `sampler`, or the integrator's default.
    pub sampler: SamplerKind,
    /// `noisethreshold`, when positive.
    pub noise_threshold: Option<f32>,
}

pub struct Built {
    pub scene: Scene,
    pub integrator: Box<dyn Integrator>,
    pub settings: RenderSettings,
    /// What rendering the whole image costs, about.
    pub work: work::Work,
}

impl Built {
    /// The render the file asks for: the whole image with all its samples.
    pub fn job(&self) -> RenderJob {
        RenderJob {
            sampler: self.settings.sampler,
            noise_threshold: self.settings.noise_threshold,
            ..RenderJob::whole(self.settings.resolution, self.settings.spp)
        }
    }
}

/// Builds the scene, or returns `None` after adding errors to `diags`. Every file read is
/// recorded in `inputs`.
pub fn build(desc: &SceneDesc, options: &BuildOptions, res: &mut Resources, diags: &mut Diagnostics) -> Option<Built> {
    let first = diags.items.len();
    let built = build_parts(desc, options, res, diags);
    // The build runs by concern; its messages are shown in the order of the file.
    diags.items[first..].sort_by_key(|d| (d.loc.file, d.loc.line, d.loc.col));
    built.filter(|_| !diags.has_errors())
}

fn build_parts(
    desc: &SceneDesc,
    options: &BuildOptions,
    res: &mut Resources,
    diags: &mut Diagnostics,
) -> Option<Built> {
    let mut integrator = settings::integrator(desc, diags);
    let (Some(size), Some(_)) = (&desc.size, &desc.camera) else {
        return None; // the parser has reported it
    };
    let (width, height) = size.value;
    let camera = camera::camera(desc, diags);
    let mut materials = materials::Materials::new(desc, res, diags);
    let environment = materials::environment(desc, res, diags);
    let view = tessellation::View {
        camera: desc.camera.as_ref()?.value,
        height,
        accel: options.accel,
    };
    let mut geometry = geometry::primitives(desc, &mut materials, &view, res, diags);
    let lights = lights::lights(desc, &mut geometry.primitives, &mut materials.materials, diags);
    let camera = camera?;
    // The Monte Carlo integrators sample emissive surfaces and the environment as lights.
    let sampled_lights = matches!(desc.integrator(), IntegratorKind::Direct | IntegratorKind::PathTracer);
    if let (true, Some(env), Some(desc_env)) = (sampled_lights, &environment, &desc.environment) {
        let cells = 64 * env.image.width as u64 * env.image.height as u64;
        if let Err(e) = res.budget.take(cells, "the environment light's sampling tables") {
            diags.error(desc_env.value.file.loc, format!("envmap: {e}"));
        }
    }
    if diags.has_errors() {
        return None;
    }
    let parts = SceneParts {
        camera,
        primitives: geometry.primitives,
        materials: materials.materials,
        lights,
        vertex_normals: geometry.vertex_normals,
        textures: materials.textures,
        environment,
        sampled_lights,
    };
    let scene = Scene::new(parts, options.accel);
    settings::control_depth(&mut integrator, &scene, desc.gamma() as f32);
    settings::warn_if_dark(desc, &scene, diags);
    let work = work::estimate_work(desc, &scene, &integrator, Resolution { width, height }, diags);
    Some(Built {
        scene,
        integrator: integrator.into_box(),
        settings: RenderSettings {
            resolution: Resolution { width, height },
            spp: desc.spp(),
            gamma: desc.gamma() as f32,
            sampler: match desc.sampler() {
                SampleSource::Independent => SamplerKind::Independent,
                SampleSource::Sobol => SamplerKind::Sobol,
            },
            noise_threshold: desc
                .noise_threshold
                .as_ref()
                .map(|t| t.value as f32)
                .filter(|&t| t > 0.0),
        },
        work,
    })
}

/// A description vector in the core's single precision (rounded once).
fn to_f32(v: glam::DVec3) -> lucent_core::math::Vec3A {
    lucent_core::math::Vec3A::new(v.x as f32, v.y as f32, v.z as f32)
}
