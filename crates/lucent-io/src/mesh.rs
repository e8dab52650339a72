//! Triangle meshes from files: Wavefront OBJ through `tobj`.
//!
//! Polygons are fan-triangulated in file order (`v0 v1 v2`, `v0 v2 v3`, …), so triangle
//! `k` of a mesh is the `k`-th triangle of the file's faces in the order they appear —
//! the numbering the benchmark's answer files use.

use std::path::Path;

use lucent_core::math::Vec3A;

/// An indexed triangle mesh.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    pub positions: Vec<Vec3A>,
    pub triangles: Vec<[u32; 3]>,
}

impl Mesh {
    /// The three corners of triangle `k`.
    pub fn corners(&self, k: usize) -> [Vec3A; 3] {
        self.triangles[k].map(|i| self.positions[i as usize])
    }
}

/// Loads every object and group of an OBJ file into one mesh. Materials are ignored.
pub fn load_obj(path: &Path) -> Result<Mesh, String> {
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
    };
    let (models, _materials) =
        tobj::load_obj(path, &options).map_err(|e| format!("{}: cannot read OBJ mesh: {e}", path.display()))?;
    let mut mesh = Mesh::default();
    for model in models {
        let m = model.mesh;
        let base = mesh.positions.len() as u32;
        mesh.positions
            .extend(m.positions.chunks_exact(3).map(|p| Vec3A::new(p[0], p[1], p[2])));
        for (k, tri) in m.indices.chunks_exact(3).enumerate() {
            if tri.iter().any(|&i| i as usize >= m.positions.len() / 3) {
                return Err(format!(
                    "{}: triangle {k} of object '{}' refers to a vertex that does not exist",
                    path.display(),
                    model.name
                ));
            }
            mesh.triangles.push([base + tri[0], base + tri[1], base + tri[2]]);
        }
    }
    if let Some(p) = mesh.positions.iter().find(|p| !p.is_finite()) {
        return Err(format!("{}: vertex {p} is not a finite number", path.display()));
    }
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn polygons_are_fan_triangulated_in_file_order() {
        let dir = std::env::temp_dir().join(format!("lucent-mesh-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("quad.obj");
        std::fs::write(
            &path,
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\n# a quad, then a triangle\nf 1 2 3 4\nf 1 2 5\n",
        )
        .unwrap();
        let mesh = load_obj(&path).unwrap();
        assert_eq!(mesh.triangles.len(), 3);
        let z = |k: usize| mesh.corners(k).map(|p| (p.x, p.y, p.z));
        assert_eq!(z(0), [(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (1.0, 1.0, 0.0)]);
        assert_eq!(z(1), [(0.0, 0.0, 0.0), (1.0, 1.0, 0.0), (0.0, 1.0, 0.0)]);
        assert_eq!(z(2), [(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 0.0, 1.0)]);
        assert!(load_obj(&dir.join("missing.obj")).is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
