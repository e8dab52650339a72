//! Meshes from files (`mesh`, `subdivmesh`): what a loader returns, whatever the format,
//! and the choice of loader by the file's extension.

use std::path::Path;

use lucent_core::geometry::mesh::TriangleMesh;

use crate::resources::Resources;

/// What a mesh file gives besides its triangles: the materials it names, and what the
/// loader had to leave out.
#[derive(Debug, Default)]
pub struct LoadedMesh {
    /// In object space; `materials` holds indices into [`LoadedMesh::library`], or
    /// [`NO_MATERIAL`] for faces without one (they take the scene's current material).
    pub mesh: TriangleMesh,
    pub library: Vec<MeshMaterial>,
    pub warnings: Vec<String>,
}

/// A face without a material of its own.
pub const NO_MATERIAL: u32 = u32::MAX;

/// The parts of an MTL material lucent uses; `None` leaves the current material's value.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshMaterial {
    pub name: String,
    pub diffuse: Option<[f32; 3]>,
    pub specular: Option<[f32; 3]>,
    pub shininess: Option<f32>,
    pub emission: Option<[f32; 3]>,
    /// `map_Kd`: a diffuse texture (file name as the MTL gives it).
    pub diffuse_texture: Option<String>,
}

/// Loads an OBJ or PLY file, chosen by its extension; every file read is recorded in
/// `inputs`.
pub fn load_mesh(path: &Path, res: &mut Resources) -> Result<LoadedMesh, String> {
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("obj") => crate::obj::load_obj(path, res),
        Some("ply") => crate::ply::load_ply(path, res),
        _ => Err("unknown mesh format (expected a .obj or .ply file)".into()),
    }
}

/// Loads the polygons of an OBJ or PLY file, untriangulated (for `subdivmesh`).
pub fn load_polygons(
    path: &Path,
    res: &mut Resources,
) -> Result<lucent_core::tessellate::subdivision::ControlMesh, String> {
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("obj") => crate::obj::load_obj_polygons(path, res),
        Some("ply") => crate::ply::load_ply_polygons(path, res),
        _ => Err("unknown mesh format (expected a .obj or .ply file)".into()),
    }
}
