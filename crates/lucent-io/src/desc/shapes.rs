//! Shapes as the file gives them: the analytic shapes with their parameters, triangles by
//! their vertex indices, surfaces by the recipe the build follows to make their triangles
//! (a mesh file, a subdivision of one, Bézier patches, a NURBS surface, each possibly
//! displaced), instances of named objects.

use std::path::PathBuf;

use glam::{DVec3, DVec4};

use super::Located;
use crate::diag::Loc;

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ShapeKind {
    /// Centre and radius in object space.
    Sphere { center: DVec3, radius: f64 },
    /// Indices into [`super::SceneDesc::vertices`].
    Triangle { v: [u32; 3] },
    /// Indices into [`super::SceneDesc::vertex_normals`].
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
    /// `quadric a … j x0 y0 z0 x1 y1 z1`: coefficients (not all zero) and the clip box.
    Quadric {
        coefficients: [f64; 10],
        lo: DVec3,
        hi: DVec3,
    },
    /// A surface made into triangles by the build: index into
    /// [`super::SceneDesc::surfaces`].
    Surface { index: u32 },
    /// `instance name`: index into [`super::SceneDesc::objects`].
    Instance { object: u32 },
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShapeDesc {
    pub kind: ShapeKind,
    /// Index into [`super::SceneDesc::transforms`]: the transform current at the command.
    pub transform: u32,
    /// Index into [`super::SceneDesc::materials`]: the material current at the command.
    pub material: u32,
    /// The object (`objectbegin` … `objectend`) the shape belongs to; `None` for the
    /// scene itself.
    pub object: Option<u32>,
    /// The command's name.
    pub loc: Loc,
}

/// A named object: the shapes whose `object` is its index.
#[derive(Clone, Debug, PartialEq)]
pub struct ObjectDesc {
    pub name: String,
    /// The name in the `objectbegin` command.
    pub loc: Loc,
}

/// A surface the build makes into a triangle mesh, and the displacement current at its
/// command.
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceDesc {
    pub recipe: SurfaceRecipe,
    pub displacement: Option<DisplacementDesc>,
}

#[derive(Clone, Debug, PartialEq)]
pub enum SurfaceRecipe {
    /// `mesh file`: an OBJ (with its MTL materials) or PLY file.
    MeshFile { file: Located<PathBuf> },
    /// `subdivmesh scheme levels file`.
    Subdivision {
        scheme: SubdivisionScheme,
        levels: Located<u32>,
        file: Located<PathBuf>,
    },
    /// `bezierpatches file [divisions]`.
    BezierPatches { file: Located<PathBuf>, divisions: u32 },
    /// `nurbs` with its `knotsu`, `knotsv` and `cpoint` lines.
    Nurbs(NurbsDesc),
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SubdivisionScheme {
    Loop,
    CatmullClark,
}

/// A NURBS surface as written: its degree, control point count and knot vector in each
/// parameter direction, and the control points `(x, y, z, w)` with u varying fastest.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct NurbsDesc {
    pub u: NurbsDirection,
    pub v: NurbsDirection,
    pub points: Vec<DVec4>,
}

/// One parameter direction of a NURBS surface.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct NurbsDirection {
    pub degree: usize,
    /// Control points along this direction.
    pub count: usize,
    /// `count + degree + 1` values (empty until the `knotsu` or `knotsv` line).
    pub knots: Vec<f64>,
}

/// `displacementmap name scale`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DisplacementDesc {
    /// Index into the description's textures.
    pub texture: u32,
    pub scale: f64,
}
