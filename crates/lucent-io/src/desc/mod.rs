//! The scene description: plain data recording what a scene file says, with the location
//! of every command. The parser fills it; [`crate::build`] turns it into a renderable
//! scene. It holds values as the file gave them, names of the files it refers to and
//! recipes for the surfaces the build will make — no decoded images, no meshes, no core
//! objects (of `lucent-core` it uses only the math: vectors and the transform matrices
//! the transform stack composes). Nothing here is specific to one file format.

mod lights;
mod materials;
mod shapes;

pub use lights::*;
pub use materials::*;
pub use shapes::*;

use glam::DVec3;
use lucent_core::transform::Transform;

use crate::diag::{Loc, SourceMap};

/// A value and where the file gave it.
#[derive(Clone, Debug, PartialEq)]
pub struct Located<T> {
    pub value: T,
    pub loc: Loc,
}

/// `camera` or `orthocamera`, as given (the build checks that it makes a camera).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraDesc {
    pub eye: DVec3,
    pub center: DVec3,
    pub up: DVec3,
    pub projection: ProjectionDesc,
    /// Where its arguments are, for the build's diagnostics.
    pub spans: CameraSpans,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ProjectionDesc {
    /// `camera … fovy`: the full vertical field of view in degrees.
    Perspective { fovy: f64 },
    /// `orthocamera … height`: the world-space height of the view.
    Orthographic { height: f64 },
}

/// The argument spans of a camera command: eye and look-at point, up vector, and the
/// field of view or view height.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct CameraSpans {
    pub eye_center: Loc,
    pub up: Loc,
    pub angle: Loc,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IntegratorKind {
    RayTracer,
    AnalyticDirect,
    Direct,
    PathTracer,
}

impl IntegratorKind {
    pub const ALL: [(&'static str, IntegratorKind); 4] = [
        ("raytracer", IntegratorKind::RayTracer),
        ("analyticdirect", IntegratorKind::AnalyticDirect),
        ("direct", IntegratorKind::Direct),
        ("pathtracer", IntegratorKind::PathTracer),
    ];

    pub fn name(self) -> &'static str {
        Self::ALL.iter().find(|(_, k)| *k == self).map_or("?", |(n, _)| n)
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NeeMode {
    Off,
    On,
    Mis,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DirectionSampling {
    Hemisphere,
    Cosine,
    Brdf,
}

/// `sampler independent|sobol`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SampleSource {
    Independent,
    Sobol,
}

/// Everything a scene file says.
#[derive(Clone, Debug, Default)]
pub struct SceneDesc {
    pub sources: SourceMap,
    /// Where the description ends (for "missing command" errors).
    pub end: Loc,
    /// The files `include` read (their text is in `sources`).
    pub included: Vec<std::path::PathBuf>,

    pub size: Option<Located<(u32, u32)>>,
    pub camera: Option<Located<CameraDesc>>,
    pub output: Option<Located<String>>,
    pub max_depth: Option<Located<i32>>,
    pub integrator: Option<Located<IntegratorKind>>,
    pub spp: Option<Located<u32>>,
    pub light_samples: Option<Located<u32>>,
    pub light_stratify: Option<Located<bool>>,
    pub next_event_estimation: Option<Located<NeeMode>>,
    pub russian_roulette: Option<Located<bool>>,
    pub importance_sampling: Option<Located<DirectionSampling>>,
    /// `sampler independent|sobol`.
    pub sampler: Option<Located<SampleSource>>,
    /// `noisethreshold t` (0: off).
    pub noise_threshold: Option<Located<f64>>,
    pub gamma: Option<Located<f64>>,
    /// `lens aperture focusdistance`.
    pub lens: Option<Located<(f64, f64)>>,

    /// The `vertex` pile, untransformed.
    pub vertices: Vec<DVec3>,
    /// The `vertexnormal` pile: position and normal, untransformed.
    pub vertex_normals: Vec<(DVec3, DVec3)>,
    /// Surfaces the build makes into triangle meshes (`mesh`, `subdivmesh`,
    /// `bezierpatches`, `nurbs`), each with the recipe to make it.
    pub surfaces: Vec<SurfaceDesc>,
    pub objects: Vec<ObjectDesc>,
    /// `texture` and `checker`, in the order defined; materials refer to them by index.
    pub textures: Vec<TextureDesc>,
    /// `envmap file [intensity]`.
    pub environment: Option<Located<EnvironmentDesc>>,
    /// Transforms captured by shapes and lights (deduplicated while parsing).
    pub transforms: Vec<Transform>,
    /// Materials captured by shapes (deduplicated while parsing).
    pub materials: Vec<MaterialDesc>,
    pub shapes: Vec<ShapeDesc>,
    pub lights: Vec<LightDesc>,
}

impl SceneDesc {
    pub fn max_depth(&self) -> i32 {
        self.max_depth.as_ref().map_or(5, |d| d.value)
    }

    pub fn integrator(&self) -> IntegratorKind {
        self.integrator.as_ref().map_or(IntegratorKind::RayTracer, |i| i.value)
    }

    pub fn gamma(&self) -> f64 {
        self.gamma.as_ref().map_or(1.0, |g| g.value)
    }

    pub fn spp(&self) -> u32 {
        self.spp.as_ref().map_or(1, |s| s.value)
    }

    /// The source of random numbers: the scene's `sampler`, else Sobol numbers for the
    /// Monte Carlo integrators and independent ones for the others (whose pictures
    /// were made with them).
    pub fn sampler(&self) -> SampleSource {
        match (&self.sampler, self.integrator()) {
            (Some(s), _) => s.value,
            (None, IntegratorKind::Direct | IntegratorKind::PathTracer) => SampleSource::Sobol,
            (None, _) => SampleSource::Independent,
        }
    }

    pub fn light_samples(&self) -> u32 {
        self.light_samples.as_ref().map_or(1, |s| s.value)
    }

    pub fn light_stratify(&self) -> bool {
        self.light_stratify.as_ref().is_some_and(|s| s.value)
    }

    /// The files the description names (textures, mesh and patch files, the environment
    /// map), resolved against the scene's folder. (MTL libraries and their images are
    /// named by the mesh files.)
    pub fn named_files(&self) -> Vec<&std::path::Path> {
        let textures = self.textures.iter().filter_map(|t| match &t.source {
            TextureSource::Image(f) => Some(f.value.as_path()),
            TextureSource::Checker { .. } => None,
        });
        let surfaces = self.surfaces.iter().filter_map(|s| match &s.recipe {
            SurfaceRecipe::MeshFile { file }
            | SurfaceRecipe::Subdivision { file, .. }
            | SurfaceRecipe::BezierPatches { file, .. } => Some(file.value.as_path()),
            SurfaceRecipe::Nurbs(_) => None,
        });
        let env = self.environment.iter().map(|e| e.value.file.value.as_path());
        let included = self.included.iter().map(|p| p.as_path());
        textures.chain(surfaces).chain(env).chain(included).collect()
    }
}
