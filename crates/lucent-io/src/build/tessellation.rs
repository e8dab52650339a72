//! Surfaces made into triangle meshes, following their recipes: `mesh` files (with their
//! MTL materials), `subdivmesh` (the control mesh refined), `bezierpatches` (each patch a
//! grid of quads) and `nurbs` (fine enough for the camera), displaced by the
//! `displacementmap` current at their command. Mesh files, subdivision surfaces and
//! patches are made and displaced in object space, then moved to world space; a NURBS
//! surface is tessellated and displaced in world space, where its tolerance is known.

use glam::{DVec3, DVec4, Vec3};
use lucent_core::accel::AccelKind;
use lucent_core::geometry::mesh::TriangleMesh;
use lucent_core::shading::texture::Displacement;
use lucent_core::tessellate::displacement::{displace, refined_triangles};
use lucent_core::tessellate::grid::grid_mesh;
use lucent_core::tessellate::nurbs::NurbsSurface;
use lucent_core::tessellate::subdivision::{self, Scheme};
use lucent_core::transform::Transform;

use super::materials::Materials;
use crate::desc::{
    CameraDesc, DisplacementDesc, NurbsDesc, ProjectionDesc, SceneDesc, ShapeDesc, SubdivisionScheme, SurfaceDesc,
    SurfaceRecipe,
};
use crate::diag::Diagnostics;
use crate::mesh_file::{load_mesh, load_polygons, LoadedMesh, NO_MATERIAL};
use crate::resources::budget::BYTES_PER_TRIANGLE;
use crate::resources::input::MAX_SMALL_FILE_BYTES;
use crate::resources::{read_input, Resources};

/// The largest mesh subdivision may make.
const MAX_SUBDIVIDED_TRIANGLES: u64 = 1 << 25;
/// A bound on the grid one NURBS surface may cost (half a million triangles).
const MAX_NURBS_SEGMENTS: usize = 512;

/// What tessellation and mesh structures need to know about the render.
pub struct View {
    pub camera: CameraDesc,
    /// The image's height in pixels.
    pub height: u32,
    pub accel: AccelKind,
}

/// The world-space mesh of the surface shape `shape`, with its materials; `None` after
/// an error, or when it has no triangles (with a warning where the file should have).
pub fn surface_mesh(
    desc: &SceneDesc,
    shape: &ShapeDesc,
    surface: &SurfaceDesc,
    materials: &mut Materials,
    view: &View,
    res: &mut Resources,
    diags: &mut Diagnostics,
) -> Option<TriangleMesh> {
    let t = &desc.transforms[shape.transform as usize];
    let command = match &surface.recipe {
        SurfaceRecipe::MeshFile { .. } => "mesh",
        SurfaceRecipe::Subdivision { .. } => "subdivmesh",
        SurfaceRecipe::BezierPatches { .. } => "bezierpatches",
        SurfaceRecipe::Nurbs(nurbs) => {
            let surf = nurbs_surface(nurbs);
            let (nu, nv) = nurbs_segments(&surf, t, view);
            take_triangles(res, 2 * nu as u64 * nv as u64, shape, "nurbs", diags)?;
            let mut mesh = nurbs_mesh(&surf, t, nu, nv);
            if let Some(d) = &surface.displacement {
                mesh = displaced(&mesh, d, materials, res, shape, "nurbs", diags)?;
                mesh.remove_degenerate();
            }
            mesh.material = shape.material;
            return (!mesh.indices.is_empty()).then_some(mesh);
        }
    };
    let mut mesh = object_mesh(desc, shape, &surface.recipe, materials, res, diags)?;
    if let Some(d) = &surface.displacement {
        mesh = displaced(&mesh, d, materials, res, shape, command, diags)?;
    }
    let removed = mesh.remove_degenerate();
    if removed > 0 && command == "mesh" {
        diags.warning(
            shape.loc,
            format!("mesh: {removed} degenerate triangles (zero area) skipped"),
        );
    }
    if mesh.indices.is_empty() {
        diags.warning(shape.loc, format!("{command}: the surface has no triangles"));
        return None;
    }
    let mesh = world_mesh(&mesh, t, shape.material);
    (!mesh.indices.is_empty()).then_some(mesh)
}

/// Takes the memory reading a mesh file costs (about eight bytes for each byte of it)
/// from the budget, or reports at the file's name that it cannot; returns what was taken.
fn take_reading(
    res: &mut Resources,
    path: &std::path::Path,
    at: crate::diag::Loc,
    command: &str,
    diags: &mut Diagnostics,
) -> Option<u64> {
    let reading = std::fs::metadata(path).map_or(0, |m| m.len()).saturating_mul(8);
    res.budget
        .take(reading, &format!("{command}: reading {}", path.display()))
        .map_err(|e| diags.error(at, e))
        .ok()?;
    Some(reading)
}

/// Takes the memory of `n` triangles (with their structure) from the budget, or reports
/// at the shape's command that it cannot.
fn take_triangles(
    res: &mut Resources,
    n: u64,
    shape: &ShapeDesc,
    command: &str,
    diags: &mut Diagnostics,
) -> Option<()> {
    let what = format!("{command}: a surface of {n} triangles");
    res.budget
        .take(n.saturating_mul(BYTES_PER_TRIANGLE), &what)
        .map_err(|e| diags.error(shape.loc, e))
        .ok()
}

/// The object-space mesh of a mesh file, subdivision surface or patch file.
fn object_mesh(
    desc: &SceneDesc,
    shape: &ShapeDesc,
    recipe: &SurfaceRecipe,
    materials: &mut Materials,
    res: &mut Resources,
    diags: &mut Diagnostics,
) -> Option<TriangleMesh> {
    match recipe {
        SurfaceRecipe::MeshFile { file } => {
            let path = &file.value;
            // Reading takes about eight bytes for each byte of the file; the mesh, once
            // read, its triangles' share.
            let reading = take_reading(res, path, file.loc, "mesh", diags)?;
            let loaded = load_mesh(path, res);
            res.budget.give_back(reading);
            let loaded = loaded
                .map_err(|e| diags.error(file.loc, format!("mesh: {}: {e}", path.display())))
                .ok()?;
            take_triangles(res, loaded.mesh.indices.len() as u64, shape, "mesh", diags)?;
            for w in &loaded.warnings {
                diags.warning(file.loc, format!("mesh: {}: {w}", path.display()));
            }
            let LoadedMesh { mut mesh, library, .. } = loaded;
            if !mesh.materials.is_empty() {
                // Faces with an MTL material take it; the others the captured material.
                let base = &desc.materials[shape.material as usize];
                let mesh_dir = path.parent().unwrap_or(std::path::Path::new("."));
                let ids = materials.add_library(base, &library, mesh_dir, file.loc, res, diags)?;
                for m in &mut mesh.materials {
                    *m = if *m == NO_MATERIAL {
                        shape.material
                    } else {
                        ids[*m as usize]
                    };
                }
            }
            Some(mesh)
        }
        SurfaceRecipe::Subdivision { scheme, levels, file } => {
            let path = &file.value;
            let reading = take_reading(res, path, file.loc, "subdivmesh", diags)?;
            let control = load_polygons(path, res);
            res.budget.give_back(reading);
            let control = control
                .map_err(|e| diags.error(file.loc, format!("subdivmesh: {}: {e}", path.display())))
                .ok()?;
            // Loop refines the fan triangulation, four triangles for one per level;
            // Catmull-Clark makes n quads of an n-gon, then four of each quad per level.
            let corners: u64 = control.faces.iter().map(|f| f.len() as u64).sum();
            let fan = corners - 2 * control.faces.len() as u64;
            let scheme = match scheme {
                SubdivisionScheme::Loop => Scheme::Loop,
                SubdivisionScheme::CatmullClark => Scheme::CatmullClark,
            };
            let total = match (scheme, levels.value) {
                (_, 0) => fan,
                (Scheme::Loop, l) => fan.saturating_mul(4u64.pow(l)),
                (Scheme::CatmullClark, l) => (2 * corners).saturating_mul(4u64.pow(l - 1)),
            };
            if total > MAX_SUBDIVIDED_TRIANGLES {
                diags.error(
                    levels.loc,
                    format!(
                        "subdivmesh: {} levels would make {total} triangles (at most {MAX_SUBDIVIDED_TRIANGLES})",
                        levels.value
                    ),
                );
                return None;
            }
            take_triangles(res, total, shape, "subdivmesh", diags)?;
            subdivision::subdivide(&control, scheme, levels.value)
                .map_err(|e| diags.error(file.loc, format!("subdivmesh: {}: {e}", path.display())))
                .ok()
        }
        SurfaceRecipe::BezierPatches { file, divisions } => {
            let path = &file.value;
            let bytes = read_input(path, MAX_SMALL_FILE_BYTES, &mut res.inputs)
                .map_err(|e| {
                    let msg = format!("bezierpatches: cannot read '{}': {e}", path.display());
                    diags.error(file.loc, msg)
                })
                .ok()?;
            let patches = crate::patches::parse_patches(&String::from_utf8_lossy(&bytes))
                .map_err(|e| {
                    let at = if e.line > 0 {
                        format!(":{}", e.line)
                    } else {
                        String::new()
                    };
                    let msg = format!("bezierpatches: {}{at}: {}", path.display(), e.message);
                    diags.error(file.loc, msg)
                })
                .ok()?;
            let d = *divisions as usize;
            let triangles = patches.patches.len() as u64 * 2 * (d * d) as u64;
            take_triangles(res, triangles, shape, "bezierpatches", diags)?;
            let mut mesh = TriangleMesh::default();
            for patch in &patches.patches {
                let grid: Vec<(Vec3, Vec3)> = lucent_core::tessellate::bezier::tessellate(patch, *divisions)
                    .into_iter()
                    .map(|(p, n)| (p.as_vec3(), n.as_vec3()))
                    .collect();
                mesh.append(grid_mesh(&grid, d, d));
            }
            Some(mesh)
        }
        SurfaceRecipe::Nurbs(_) => unreachable!("tessellated in world space"),
    }
}

/// The mesh displaced by `scale × luminance` of the description's texture, its refined
/// triangles taken from the budget; `None` after an error at the shape's command.
fn displaced(
    mesh: &TriangleMesh,
    d: &DisplacementDesc,
    materials: &Materials,
    res: &mut Resources,
    shape: &ShapeDesc,
    command: &str,
    diags: &mut Diagnostics,
) -> Option<TriangleMesh> {
    let field = Displacement {
        texture: materials.texture(d.texture),
        scale: d.scale as f32,
    };
    take_triangles(res, refined_triangles(mesh, &field) as u64, shape, command, diags)?;
    let displaced = displace(mesh, &field)
        .map_err(|e| diags.error(shape.loc, format!("{command}: displacementmap: {e}")))
        .ok()?;
    // The surface before displacement is dropped.
    res.budget
        .give_back((mesh.indices.len() as u64).saturating_mul(BYTES_PER_TRIANGLE));
    Some(displaced)
}

/// A mesh moved to world space by `t`, with `material` where its triangles have none of
/// their own. Triangles that rounding collapses are dropped.
fn world_mesh(mesh: &TriangleMesh, t: &Transform, material: u32) -> TriangleMesh {
    let mut out = TriangleMesh {
        positions: mesh.positions.iter().map(|p| t.point(p.as_dvec3()).as_vec3()).collect(),
        normals: mesh
            .normals
            .iter()
            .map(|n| t.normal(n.as_dvec3()).normalize_or_zero().as_vec3())
            .collect(),
        uvs: mesh.uvs.clone(),
        indices: mesh.indices.clone(),
        materials: mesh.materials.clone(),
        material,
    };
    out.remove_degenerate();
    out
}

/// The core's surface of a description (control points weighted: `(w·x, w·y, w·z, w)`).
fn nurbs_surface(n: &NurbsDesc) -> NurbsSurface {
    NurbsSurface {
        degree_u: n.u.degree,
        degree_v: n.v.degree,
        count_u: n.u.count,
        count_v: n.v.count,
        knots_u: n.u.knots.clone(),
        knots_v: n.v.knots.clone(),
        points: n
            .points
            .iter()
            .map(|p| DVec4::new(p.x * p.w, p.y * p.w, p.z * p.w, p.w))
            .collect(),
    }
}

/// How finely to tessellate a NURBS surface: no chord may stray more than a quarter of a
/// pixel from the surface where it is nearest to the camera.
fn nurbs_segments(surface: &NurbsSurface, t: &Transform, view: &View) -> (usize, usize) {
    let camera = &view.camera;
    // With positive weights the surface lies in the hull of its control points.
    let corners: Vec<DVec3> = surface.points.iter().map(|p| t.point(p.truncate() / p.w)).collect();
    let (lo, hi) = corners
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        });
    let nearest = (camera.eye.clamp(lo, hi) - camera.eye)
        .length()
        .max(1e-3 * (hi - lo).length());
    let view_height = match camera.projection {
        ProjectionDesc::Perspective { fovy } => 2.0 * nearest * (fovy.to_radians() / 2.0).tan(),
        ProjectionDesc::Orthographic { height } => height,
    };
    let pixel = view_height / view.height as f64;
    // Object-space tolerance: divide by the largest stretch of the transform.
    let m = t.m.matrix3;
    let stretch = m
        .x_axis
        .length()
        .max(m.y_axis.length())
        .max(m.z_axis.length())
        .max(1e-300);
    let (nu, nv) = surface.segments_for(0.25 * pixel / stretch);
    (nu.min(MAX_NURBS_SEGMENTS), nv.min(MAX_NURBS_SEGMENTS))
}

/// A NURBS surface as a world-space grid of `nu × nv` quads, with normals from the exact
/// derivatives.
fn nurbs_mesh(surface: &NurbsSurface, t: &Transform, nu: usize, nv: usize) -> TriangleMesh {
    let grid: Vec<(Vec3, Vec3)> = surface
        .tessellate(nu, nv)
        .into_iter()
        .map(|(p, n)| (t.point(p).as_vec3(), t.normal(n).as_vec3()))
        .collect();
    grid_mesh(&grid, nu, nv)
}
