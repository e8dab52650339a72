//! The scene description: plain data recording what a scene file says, with the location
//! of every command. The parser fills it; [`crate::build`] turns it into a renderable
//! scene. Nothing here is specific to one file format.

use glam::DVec3;
use lucent_core::shading::material::Material;
use lucent_core::transform::Transform;

use crate::diag::{Loc, SourceMap};

/// A value and where the file gave it.
#[derive(Clone, Debug, PartialEq)]
pub struct Located<T> {
    pub value: T,
    pub loc: Loc,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraDesc {
    pub eye: DVec3,
    pub center: DVec3,
    pub up: DVec3,
    /// `camera` (field of view) or `orthocamera` (view height).
    pub projection: lucent_core::camera::Projection,
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
pub enum Brdf {
    Phong,
    Ggx,
}

/// The current material as objects capture it: the Whitted terms plus the CSE168 BRDF.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MaterialDesc {
    pub base: Material,
    pub brdf: Brdf,
    pub roughness: f64,
}

impl Default for MaterialDesc {
    fn default() -> Self {
        MaterialDesc {
            base: Material::default(),
            brdf: Brdf::Phong,
            roughness: 1.0,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ShapeKind {
    /// Centre and radius in object space.
    Sphere { center: DVec3, radius: f64 },
    /// Indices into [`SceneDesc::vertices`].
    Triangle { v: [u32; 3] },
    /// Indices into [`SceneDesc::vertex_normals`].
    TriNormal { v: [u32; 3] },
    /// `plane px py pz nx ny nz` (object space; the normal is not zero).
    Plane { point: DVec3, normal: DVec3 },
    /// `box`: the corners sorted so that `lo < hi` along every axis.
    Box { lo: DVec3, hi: DVec3 },
    /// `cylinder radius zmin zmax`, `radius > 0`, `zmin < zmax`.
    Cylinder { radius: f64, zmin: f64, zmax: f64 },
    /// `disk radius`, `radius > 0`.
    Disk { radius: f64 },
    /// `cone radius height`, `radius > 0`, `height ≠ 0`.
    Cone { radius: f64, height: f64 },
    /// A triangle mesh (`mesh`, `subdivmesh`, `bezierpatches`): index into
    /// [`SceneDesc::meshes`].
    Mesh { index: u32 },
    /// `instance name`: index into [`SceneDesc::objects`].
    Instance { object: u32 },
    /// A NURBS surface: index into [`SceneDesc::nurbs`], and the `displacementmap`
    /// (texture index and scale) current at its `nurbs` command.
    Nurbs {
        index: u32,
        displacement: Option<(u32, f32)>,
    },
    /// `quadric a … j x0 y0 z0 x1 y1 z1`: coefficients (not all zero) and the clip box.
    Quadric {
        coefficients: [f64; 10],
        lo: DVec3,
        hi: DVec3,
    },
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShapeDesc {
    pub kind: ShapeKind,
    /// Index into [`SceneDesc::transforms`]: the transform current at the command.
    pub transform: u32,
    /// Index into [`SceneDesc::materials`]: the material current at the command.
    pub material: u32,
    /// The object (`objectbegin` … `objectend`) the shape belongs to; `None` for the
    /// scene itself.
    pub object: Option<u32>,
    pub loc: Loc,
}

/// A named texture.
#[derive(Clone, Debug)]
pub struct TextureDesc {
    pub name: String,
    pub texture: lucent_core::shading::texture::Texture,
    pub loc: Loc,
}

/// A named object: the shapes whose `object` is its index.
#[derive(Clone, Debug, PartialEq)]
pub struct ObjectDesc {
    pub name: String,
    /// The `objectbegin` command.
    pub loc: Loc,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LightKind {
    /// `dir` points toward the light.
    Directional { dir: DVec3, color: DVec3 },
    Point {
        position: DVec3,
        color: DVec3,
        attenuation: DVec3,
    },
    Quad {
        a: DVec3,
        ab: DVec3,
        ac: DVec3,
        color: DVec3,
    },
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightDesc {
    pub kind: LightKind,
    pub transform: u32,
    pub loc: Loc,
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

/// Everything a scene file says.
#[derive(Clone, Debug, Default)]
pub struct SceneDesc {
    pub sources: SourceMap,
    /// Where the description ends (for "missing command" errors).
    pub end: Loc,

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
    pub gamma: Option<Located<f64>>,
    /// `lens aperture focusdistance`.
    pub lens: Option<Located<(f64, f64)>>,

    /// The `vertex` pile, untransformed.
    pub vertices: Vec<DVec3>,
    /// The `vertexnormal` pile: position and normal, untransformed.
    pub vertex_normals: Vec<(DVec3, DVec3)>,
    /// Triangle meshes in object space. Per-triangle materials, when present, are
    /// indices into `materials` (from an OBJ file's MTL library); otherwise the mesh
    /// takes the material its shape captured.
    pub meshes: Vec<lucent_core::geometry::mesh::TriangleMesh>,
    pub objects: Vec<ObjectDesc>,
    /// `texture` and `checker`, in the order defined; materials refer to them by index.
    pub textures: Vec<TextureDesc>,
    /// `envmap file [intensity]`.
    pub environment: Option<Located<lucent_core::shading::texture::EnvironmentMap>>,
    /// NURBS surfaces (`nurbs` with its `knotsu`, `knotsv` and `cpoint` lines), in object
    /// space; tessellated when the scene is built, when the camera says how fine.
    pub nurbs: Vec<lucent_core::tessellate::nurbs::NurbsSurface>,
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
}
