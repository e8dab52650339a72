//! Triangle meshes from Wavefront OBJ files, through `tobj`, with their MTL materials.
//!
//! Polygons are fan-triangulated in file order (`v0 v1 v2`, `v0 v2 v3`, …), so triangle
//! `k` of a mesh is the `k`-th triangle of the file's faces in the order they appear —
//! the numbering the benchmark's answer files use. Every object and group of the file
//! goes into one mesh; vertices that share a position but not a normal or texture
//! coordinate are split (tobj's `single_index`).

use std::cell::RefCell;
use std::path::Path;

use crate::mesh_file::{LoadedMesh, MeshMaterial, NO_MATERIAL};
use crate::resources::input::{MAX_MESH_BYTES, MAX_SMALL_FILE_BYTES};
use crate::resources::{read_input, Resources};
use glam::{DVec3, Vec2, Vec3};
use lucent_core::tessellate::subdivision::ControlMesh;

/// The models of an OBJ file and its MTL library (or why the library could not be
/// read), every file read through [`read_input`] and recorded in `res`.
type Obj = (Vec<tobj::Model>, Result<Vec<tobj::Material>, String>);

fn read_obj(path: &Path, options: &tobj::LoadOptions, res: &mut Resources) -> Result<Obj, String> {
    let bytes = read_input(path, MAX_MESH_BYTES, &mut res.inputs).map_err(|e| format!("cannot open: {e}"))?;
    check_face_references(&bytes)?;
    let dir = path.parent().unwrap_or(Path::new("")).to_path_buf();
    let inputs = RefCell::new(&mut res.inputs);
    // Why the library could not be read, when the reason is ours (tobj only has codes).
    let reason = RefCell::new(None);
    let load_mtl = |name: &Path| {
        let text = read_input(&dir.join(name), MAX_SMALL_FILE_BYTES, &mut inputs.borrow_mut()).map_err(|e| {
            *reason.borrow_mut() = Some(e);
            tobj::LoadError::OpenFileFailed
        })?;
        tobj::load_mtl_buf(&mut &text[..])
    };
    let (models, materials) =
        tobj::load_obj_buf(&mut &bytes[..], options, load_mtl).map_err(|e| format!("cannot read OBJ mesh: {e}"))?;
    let materials = materials.map_err(|e| match reason.take() {
        Some(r) => r,
        None if e == tobj::LoadError::GenericFailure => String::new(),
        None => e.to_string(),
    });
    if let Ok(list) = &materials {
        for m in list {
            check_material(m)?;
        }
    }
    Ok((models, materials))
}

/// An MTL material's numbers must be numbers (`Kd nan` is an error, as in the OBJ).
fn check_material(m: &tobj::Material) -> Result<(), String> {
    let colours = [("Kd", m.diffuse), ("Ks", m.specular), ("Ke", m.emissive)];
    for (key, v) in colours {
        if let Some(v) = v {
            if v.iter().any(|c| !c.is_finite()) {
                return Err(format!(
                    "material '{}': {key} {v:?} is not three finite numbers",
                    m.name
                ));
            }
        }
    }
    if let Some(ns) = m.shininess {
        if !(ns >= 0.0 && ns.is_finite()) {
            return Err(format!("material '{}': Ns {ns} is not a number ≥ 0", m.name));
        }
    }
    Ok(())
}

/// Every face's vertex, texture coordinate and normal references name an element of the
/// file (1-based; negative: counted back from the last one defined before the face).
fn check_face_references(bytes: &[u8]) -> Result<(), String> {
    let text = String::from_utf8_lossy(bytes);
    let lines = || text.lines().map(|l| l.trim_start());
    let count = |key: &str| lines().filter(|l| l.split_whitespace().next() == Some(key)).count() as i64;
    let totals = [count("v"), count("vt"), count("vn")];
    let mut so_far = [0i64; 3];
    const NAMES: [&str; 3] = ["vertex", "texture coordinate", "normal"];
    for (n, line) in lines().enumerate() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => so_far[0] += 1,
            Some("vt") => so_far[1] += 1,
            Some("vn") => so_far[2] += 1,
            Some("f") => {
                for corner in words {
                    for (k, index) in corner.split('/').enumerate().take(3) {
                        if index.is_empty() {
                            continue; // `v//vn`
                        }
                        let Ok(i) = index.parse::<i64>() else {
                            return Err(format!("line {}: '{corner}' is not a face corner", n + 1));
                        };
                        let ok = if i > 0 {
                            i <= totals[k]
                        } else {
                            i < 0 && -i <= so_far[k]
                        };
                        if !ok {
                            return Err(format!(
                                "line {}: a face refers to {} {i}, but the file has {}",
                                n + 1,
                                NAMES[k],
                                totals[k]
                            ));
                        }
                    }
                }
            }
            _ => {}
        }
    }
    Ok(())
}

pub fn load_obj(path: &Path, res: &mut Resources) -> Result<LoadedMesh, String> {
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
    };
    let (models, materials) = read_obj(path, &options, res)?;
    let mut out = LoadedMesh::default();
    match materials {
        Ok(list) => {
            out.library = list
                .into_iter()
                .map(|m| MeshMaterial {
                    name: m.name,
                    diffuse: m.diffuse,
                    specular: m.specular,
                    shininess: m.shininess,
                    emission: m.emissive,
                    diffuse_texture: m.diffuse_texture,
                })
                .collect()
        }
        Err(e) => {
            if models.iter().any(|m| m.mesh.material_id.is_some()) || !e.is_empty() {
                let why = if e.is_empty() { "no library" } else { e.as_str() };
                out.warnings.push(format!(
                    "cannot read the MTL material library ({why}); the current material is used"
                ));
            }
        }
    }
    // Normals and texture coordinates are kept only when every part of the file has them.
    let all_normals = models.iter().all(|m| !m.mesh.normals.is_empty());
    let all_uvs = models.iter().all(|m| !m.mesh.texcoords.is_empty());
    if !all_normals && models.iter().any(|m| !m.mesh.normals.is_empty()) {
        out.warnings
            .push("some faces have vertex normals and some do not: the whole mesh is shaded flat".into());
    }
    let mesh = &mut out.mesh;
    let mut multi_material = false;
    for model in &models {
        let m = &model.mesh;
        let base = mesh.positions.len() as u32;
        let count = m.positions.len() / 3;
        mesh.positions
            .extend(m.positions.chunks_exact(3).map(|p| Vec3::new(p[0], p[1], p[2])));
        if all_normals {
            mesh.normals.extend(
                m.normals
                    .chunks_exact(3)
                    .map(|n| Vec3::new(n[0], n[1], n[2]).normalize_or_zero()),
            );
            mesh.normals.resize(mesh.positions.len(), Vec3::ZERO);
        }
        if all_uvs {
            mesh.uvs
                .extend(m.texcoords.chunks_exact(2).map(|t| Vec2::new(t[0], t[1])));
            mesh.uvs.resize(mesh.positions.len(), Vec2::ZERO);
        }
        let material = match m.material_id {
            Some(i) if i < out.library.len() => {
                multi_material = true;
                i as u32
            }
            _ => NO_MATERIAL,
        };
        for (k, tri) in m.indices.chunks_exact(3).enumerate() {
            if tri.iter().any(|&i| i as usize >= count) {
                return Err(format!(
                    "triangle {k} of object '{}' refers to a vertex that does not exist",
                    model.name
                ));
            }
            mesh.indices.push([base + tri[0], base + tri[1], base + tri[2]]);
            mesh.materials.push(material);
        }
    }
    if !multi_material {
        mesh.materials.clear();
    }
    mesh.check()?;
    Ok(out)
}

/// The polygons of an OBJ file as they are, on shared positions (for subdivision):
/// texture coordinates and normals are left out, since subdivision makes its own.
pub fn load_obj_polygons(path: &Path, res: &mut Resources) -> Result<ControlMesh, String> {
    let options = tobj::LoadOptions {
        triangulate: false,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
    };
    let (models, _) = read_obj(path, &options, res)?;
    let mut out = ControlMesh::default();
    for model in &models {
        let m = &model.mesh;
        let base = out.positions.len() as u32;
        let count = m.positions.len() / 3;
        out.positions.extend(
            m.positions
                .chunks_exact(3)
                .map(|p| DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64)),
        );
        // No arities means every face is a triangle.
        let arities: Vec<usize> = if m.face_arities.is_empty() {
            vec![3; m.indices.len() / 3]
        } else {
            m.face_arities.iter().map(|&a| a as usize).collect()
        };
        let mut at = 0;
        for (k, &n) in arities.iter().enumerate() {
            let face = m.indices.get(at..at + n).ok_or("face list shorter than its sizes")?;
            if face.iter().any(|&i| i as usize >= count) {
                return Err(format!(
                    "face {k} of object '{}' refers to a vertex that does not exist",
                    model.name
                ));
            }
            out.faces.push(face.iter().map(|&i| base + i).collect());
            at += n;
        }
    }
    if let Some(p) = out.positions.iter().find(|p| !p.is_finite()) {
        return Err(format!("vertex {p} is not a finite number"));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp_dir(name: &str) -> crate::TestDir {
        crate::TestDir::new(&format!("obj-{name}"))
    }

    #[test]
    fn polygons_are_fan_triangulated_in_file_order() {
        let dir = temp_dir("fan");
        let path = dir.join("quad.obj");
        std::fs::write(
            &path,
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\n# a quad, then a triangle\nf 1 2 3 4\nf 1 2 5\n",
        )
        .unwrap();
        let m = load_obj(&path, &mut Resources::new(u64::MAX)).unwrap().mesh;
        assert_eq!(m.indices.len(), 3);
        let z = |k: u32| m.corners(k).map(|p| (p.x, p.y, p.z));
        assert_eq!(z(0), [(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (1.0, 1.0, 0.0)]);
        assert_eq!(z(1), [(0.0, 0.0, 0.0), (1.0, 1.0, 0.0), (0.0, 1.0, 0.0)]);
        assert_eq!(z(2), [(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 0.0, 1.0)]);
        assert!(m.normals.is_empty() && m.uvs.is_empty() && m.materials.is_empty());
        assert!(load_obj(&dir.join("missing.obj"), &mut Resources::new(u64::MAX)).is_err());
    }

    #[test]
    fn normals_texture_coordinates_and_materials_are_kept() {
        let dir = temp_dir("mtl");
        std::fs::write(
            dir.join("two.mtl"),
            "newmtl red\nKd 1 0 0\nKs 0.5 0.5 0.5\nNs 20\nnewmtl glow\nKe 1 1 0\n",
        )
        .unwrap();
        std::fs::write(
            dir.join("two.obj"),
            "mtllib two.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 2\n\
             usemtl red\nf 1/1/1 2/2/1 3/3/1\nusemtl glow\nf 1/1/1 3/3/1 2/2/1\n",
        )
        .unwrap();
        let loaded = load_obj(&dir.join("two.obj"), &mut Resources::new(u64::MAX)).unwrap();
        let m = &loaded.mesh;
        assert_eq!(m.indices.len(), 2);
        assert_eq!(m.normals.len(), m.positions.len());
        assert!(m.normals.iter().all(|n| *n == Vec3::Z), "normals are made unit length");
        assert_eq!(m.uvs[m.indices[0][1] as usize], Vec2::new(1.0, 0.0));
        assert_eq!(loaded.library.len(), 2);
        assert_eq!(loaded.library[0].diffuse, Some([1.0, 0.0, 0.0]));
        assert_eq!(loaded.library[0].shininess, Some(20.0));
        assert_eq!(loaded.library[1].emission, Some([1.0, 1.0, 0.0]));
        assert_eq!(m.materials, vec![0, 1]);
        assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);

        // A missing library is a warning; the faces keep the current material.
        std::fs::remove_file(dir.join("two.mtl")).unwrap();
        let loaded = load_obj(&dir.join("two.obj"), &mut Resources::new(u64::MAX)).unwrap();
        assert_eq!(loaded.warnings.len(), 1, "{:?}", loaded.warnings);
        assert!(loaded.mesh.materials.is_empty());
    }

    #[test]
    fn malformed_files_are_errors() {
        let dir = temp_dir("bad");
        for (name, text) in [
            ("oob.obj", "v 0 0 0\nv 1 0 0\nf 1 2 3\n"),
            ("nan.obj", "v 0 0 nan\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"),
            ("face.obj", "v 0 0 0\nf 1 x 3\n"),
        ] {
            std::fs::write(dir.join(name), text).unwrap();
            assert!(
                load_obj(&dir.join(name), &mut Resources::new(u64::MAX)).is_err(),
                "{name}"
            );
        }
    }
}
