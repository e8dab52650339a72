//! Triangle meshes from PLY files (ASCII and binary, either byte order), through
//! `ply-rs-bw`.
//!
//! The `vertex` element gives `x y z`, and `nx ny nz` and texture coordinates (`u v`,
//! `s t` or `texture_u texture_v`) when present; the `face` element gives
//! `vertex_indices` (or `vertex_index`) lists, fan-triangulated in file order. Other
//! elements and properties are read and ignored.
//!
//! Before any payload is read, every element's count is held to what the file can
//! hold (a binary entry takes at least its scalars' and list counts' bytes, an ASCII
//! one at least a byte a property), and the memory the vertices and faces will take is
//! taken from the budget: a header of a few bytes may declare trillions of entries.

use std::io::BufReader;
use std::path::Path;

use glam::{DVec3, Vec2, Vec3};
use lucent_core::geometry::mesh::TriangleMesh;
use lucent_core::tessellate::subdivision::ControlMesh;
use ply_rs_bw::parser::Parser;
use ply_rs_bw::ply::{ElementDef, Encoding, Header, Property, PropertyAccess, PropertyType, ScalarType};

use crate::mesh_file::LoadedMesh;
use crate::resources::input::MAX_MESH_BYTES;
use crate::resources::{open_input, Resources};

/// One `vertex` element: every property lucent understands, `NaN` where absent.
struct Vertex {
    p: [f64; 3],
    n: [f64; 3],
    uv: [f64; 2],
}

struct Face {
    indices: Vec<i64>,
    /// A property that should have been an index list but was not (reported by name).
    bad: Option<String>,
}

/// An entry of an element lucent does not use: read past, and nothing kept.
struct Ignored;

impl PropertyAccess for Ignored {
    fn new() -> Self {
        Ignored
    }
}

/// Bytes of one binary scalar.
fn scalar_bytes(t: &ScalarType) -> u64 {
    match t {
        ScalarType::Char | ScalarType::UChar => 1,
        ScalarType::Short | ScalarType::UShort => 2,
        ScalarType::Int | ScalarType::UInt | ScalarType::Float => 4,
        ScalarType::Double => 8,
    }
}

/// The fewest payload bytes one entry of `element` takes: in a binary file its scalars
/// and its lists' counts (a list may be empty), in an ASCII one a character a property,
/// or the line's end.
fn least_entry_bytes(element: &ElementDef, encoding: &Encoding) -> u64 {
    match encoding {
        Encoding::Ascii => (element.properties.len() as u64).max(1),
        _ => element
            .properties
            .values()
            .map(|p| match &p.data_type {
                PropertyType::Scalar(t) | PropertyType::List(t, _) => scalar_bytes(t),
            })
            .sum(),
    }
}

/// Checks every element's count against the `payload` bytes after the header, and takes
/// from the budget what the vertices and faces will take (ply-rs grows their vectors by
/// doubling, so twice their size; a face's index list is the reading's share, which the
/// caller took). Returns what it took.
fn check_counts(header: &Header, payload: u64, res: &mut Resources) -> Result<u64, String> {
    let mut least_total = 0u64;
    for element in header.elements.values() {
        let count = element.count as u64;
        let least = least_entry_bytes(element, &header.encoding);
        if least == 0 && count > 0 {
            return Err(format!(
                "element '{}' declares {count} entries and no properties: a binary file holds no such entries",
                element.name
            ));
        }
        least_total = least_total.saturating_add(count.saturating_mul(least));
        if least_total > payload {
            return Err(format!(
                "element '{}' declares {count} entries, more than the file's {payload} bytes after its header can hold",
                element.name
            ));
        }
    }
    let entry_bytes = |name: &str| match name {
        "vertex" => 2 * std::mem::size_of::<Vertex>() as u64,
        "face" => 2 * std::mem::size_of::<Face>() as u64,
        _ => 0,
    };
    let taken: u64 = header
        .elements
        .values()
        .map(|e| (e.count as u64).saturating_mul(entry_bytes(&e.name)))
        .fold(0, u64::saturating_add);
    res.budget.take(taken, "the PLY file's vertices and faces")?;
    Ok(taken)
}

fn scalar(p: &Property) -> Option<f64> {
    Some(match *p {
        Property::Char(v) => v as f64,
        Property::UChar(v) => v as f64,
        Property::Short(v) => v as f64,
        Property::UShort(v) => v as f64,
        Property::Int(v) => v as f64,
        Property::UInt(v) => v as f64,
        Property::Float(v) => v as f64,
        Property::Double(v) => v,
        _ => return None,
    })
}

fn integer_list(p: Property) -> Option<Vec<i64>> {
    Some(match p {
        Property::ListChar(v) => v.into_iter().map(i64::from).collect(),
        Property::ListUChar(v) => v.into_iter().map(i64::from).collect(),
        Property::ListShort(v) => v.into_iter().map(i64::from).collect(),
        Property::ListUShort(v) => v.into_iter().map(i64::from).collect(),
        Property::ListInt(v) => v.into_iter().map(i64::from).collect(),
        Property::ListUInt(v) => v.into_iter().map(i64::from).collect(),
        _ => return None,
    })
}

impl PropertyAccess for Vertex {
    fn new() -> Self {
        Vertex {
            p: [f64::NAN; 3],
            n: [f64::NAN; 3],
            uv: [f64::NAN; 2],
        }
    }

    fn set_property(&mut self, key: &str, property: Property) {
        let Some(v) = scalar(&property) else { return };
        match key {
            "x" => self.p[0] = v,
            "y" => self.p[1] = v,
            "z" => self.p[2] = v,
            "nx" => self.n[0] = v,
            "ny" => self.n[1] = v,
            "nz" => self.n[2] = v,
            "u" | "s" | "texture_u" | "texture_s" => self.uv[0] = v,
            "v" | "t" | "texture_v" | "texture_t" => self.uv[1] = v,
            _ => {}
        }
    }
}

impl PropertyAccess for Face {
    fn new() -> Self {
        Face {
            indices: Vec::new(),
            bad: None,
        }
    }

    fn set_property(&mut self, key: &str, property: Property) {
        if key == "vertex_indices" || key == "vertex_index" {
            match integer_list(property) {
                Some(list) => self.indices = list,
                None => self.bad = Some(key.to_string()),
            }
        }
    }
}

/// The vertices and faces of a PLY file, faces checked (at least three corners, every
/// index a vertex); `taken` is what was taken from the budget for them, to be given
/// back once the caller is done with them (also when this fails).
fn read_ply(path: &Path, res: &mut Resources, taken: &mut u64) -> Result<(Vec<Vertex>, Vec<Face>), String> {
    let (file, size) = open_input(path, MAX_MESH_BYTES, &mut res.inputs).map_err(|e| format!("cannot open: {e}"))?;
    let mut reader = BufReader::new(std::io::Read::take(file, size));
    let bad = |e: std::io::Error| format!("malformed PLY file: {e}");
    let vertex_parser = Parser::<Vertex>::new();
    let face_parser = Parser::<Face>::new();
    let other_parser = Parser::<Ignored>::new();
    let header = vertex_parser.read_header(&mut reader).map_err(bad)?;
    // What is left after the header: not yet read from the file, and read but not used.
    let payload = reader.get_ref().limit() + reader.buffer().len() as u64;
    *taken = check_counts(&header, payload, res)?;
    let mut vertices = None;
    let mut faces = None;
    for element in header.elements.values() {
        match element.name.as_str() {
            "vertex" => {
                vertices = Some(
                    vertex_parser
                        .read_payload_for_element(&mut reader, element, &header)
                        .map_err(bad)?,
                )
            }
            "face" => {
                faces = Some(
                    face_parser
                        .read_payload_for_element(&mut reader, element, &header)
                        .map_err(bad)?,
                )
            }
            _ => {
                other_parser
                    .read_payload_for_element(&mut reader, element, &header)
                    .map_err(bad)?;
            }
        }
    }
    let vertices = vertices.ok_or("the PLY file has no 'vertex' element")?;
    let faces = faces.ok_or("the PLY file has no 'face' element")?;

    let n = vertices.len() as i64;
    for (k, f) in faces.iter().enumerate() {
        if let Some(name) = &f.bad {
            return Err(format!("face {k}: property '{name}' is not a list of integers"));
        }
        if f.indices.len() < 3 {
            return Err(format!("face {k} has {} vertices (at least 3 needed)", f.indices.len()));
        }
        if let Some(&i) = f.indices.iter().find(|&&i| i < 0 || i >= n) {
            return Err(format!("face {k} refers to vertex {i} but the file has {n} vertices"));
        }
    }
    if let Some(k) = vertices.iter().position(|v| v.p.iter().any(|c| !c.is_finite())) {
        return Err(format!("vertex {k} has no finite x, y and z"));
    }
    Ok((vertices, faces))
}

/// The polygons of a PLY file as they are (for subdivision).
pub fn load_ply_polygons(path: &Path, res: &mut Resources) -> Result<ControlMesh, String> {
    let mut taken = 0;
    let polygons = read_ply(path, res, &mut taken).map(|(vertices, faces)| ControlMesh {
        positions: vertices.iter().map(|v| DVec3::from_array(v.p)).collect(),
        faces: faces
            .into_iter()
            .map(|f| f.indices.into_iter().map(|i| i as u32).collect())
            .collect(),
    });
    res.budget.give_back(taken);
    polygons
}

pub fn load_ply(path: &Path, res: &mut Resources) -> Result<LoadedMesh, String> {
    let mut taken = 0;
    let mesh = read_ply(path, res, &mut taken).and_then(|(vertices, faces)| triangles(vertices, faces));
    res.budget.give_back(taken);
    mesh
}

/// The PLY file's faces fanned into triangles.
fn triangles(vertices: Vec<Vertex>, faces: Vec<Face>) -> Result<LoadedMesh, String> {
    let mut mesh = TriangleMesh::default();
    for (k, v) in vertices.iter().enumerate() {
        if v.p.iter().any(|c| !c.is_finite()) {
            return Err(format!("vertex {k} has no finite x, y and z"));
        }
        mesh.positions
            .push(Vec3::new(v.p[0] as f32, v.p[1] as f32, v.p[2] as f32));
    }
    if vertices.iter().all(|v| v.n.iter().all(|c| c.is_finite())) {
        mesh.normals = vertices
            .iter()
            .map(|v| Vec3::new(v.n[0] as f32, v.n[1] as f32, v.n[2] as f32).normalize_or_zero())
            .collect();
    }
    if vertices.iter().all(|v| v.uv.iter().all(|c| c.is_finite())) {
        mesh.uvs = vertices
            .iter()
            .map(|v| Vec2::new(v.uv[0] as f32, v.uv[1] as f32))
            .collect();
    }
    for f in &faces {
        for j in 1..f.indices.len() - 1 {
            mesh.indices
                .push([f.indices[0], f.indices[j], f.indices[j + 1]].map(|i| i as u32));
        }
    }
    mesh.check()?;
    Ok(LoadedMesh {
        mesh,
        ..LoadedMesh::default()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const HEADER: &str =
        "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n\
                          property float nx\nproperty float ny\nproperty float nz\nproperty float u\nproperty float v\n\
                          element face 1\nproperty list uchar int vertex_indices\nend_header\n";

    fn write(dir: &crate::TestDir, name: &str, bytes: &[u8]) -> std::path::PathBuf {
        let path = dir.join(name);
        std::fs::write(&path, bytes).unwrap();
        path
    }

    #[test]
    fn ascii_quads_are_fanned_with_normals_and_uvs() {
        let text = format!("{HEADER}0 0 0 0 0 1 0 0\n1 0 0 0 0 1 1 0\n1 1 0 0 0 1 1 1\n0 1 0 0 0 1 0 1\n4 0 1 2 3\n");
        let m = load_ply(
            &write(&crate::TestDir::new("ply-quad"), "quad.ply", text.as_bytes()),
            &mut Resources::new(u64::MAX),
        )
        .unwrap()
        .mesh;
        assert_eq!(m.indices, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(m.normals, vec![Vec3::Z; 4]);
        assert_eq!(m.uvs[2], Vec2::new(1.0, 1.0));
    }

    #[test]
    fn binary_little_endian_with_extra_elements() {
        let mut bytes = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty double x\nproperty double y\n\
                          property double z\nproperty uchar red\nelement face 1\nproperty list uchar uint vertex_indices\n\
                          element edge 1\nproperty int vertex1\nproperty int vertex2\nend_header\n"
            .to_vec();
        for p in [[0.0f64, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 2.0, 0.0]] {
            for c in p {
                bytes.extend(c.to_le_bytes());
            }
            bytes.push(200);
        }
        bytes.push(3);
        for i in [0u32, 1, 2] {
            bytes.extend(i.to_le_bytes());
        }
        bytes.extend(0i32.to_le_bytes());
        bytes.extend(1i32.to_le_bytes());
        let m = load_ply(
            &write(&crate::TestDir::new("ply-bin"), "bin.ply", &bytes),
            &mut Resources::new(u64::MAX),
        )
        .unwrap()
        .mesh;
        assert_eq!(m.indices, vec![[0, 1, 2]]);
        assert_eq!(m.positions[2], Vec3::new(0.0, 2.0, 0.0));
        assert!(m.normals.is_empty() && m.uvs.is_empty());
    }

    #[test]
    fn malformed_files_are_errors() {
        let dir = crate::TestDir::new("ply-bad");
        let cases: [(&str, String); 5] = [
            (
                "header.ply",
                "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n".into(),
            ),
            (
                "oob.ply",
                format!("{HEADER}0 0 0 0 0 1 0 0\n1 0 0 0 0 1 1 0\n1 1 0 0 0 1 1 1\n0 1 0 0 0 1 0 1\n3 0 1 7\n"),
            ),
            ("short.ply", format!("{HEADER}0 0 0 0 0 1 0 0\n")),
            (
                "twogon.ply",
                format!("{HEADER}0 0 0 0 0 1 0 0\n1 0 0 0 0 1 1 0\n1 1 0 0 0 1 1 1\n0 1 0 0 0 1 0 1\n2 0 1\n"),
            ),
            ("text.ply", "not a ply file\n".into()),
        ];
        for (name, text) in cases {
            let e = load_ply(&write(&dir, name, text.as_bytes()), &mut Resources::new(u64::MAX));
            assert!(e.is_err(), "{name}");
        }
        assert!(load_ply(Path::new("/nonexistent/x.ply"), &mut Resources::new(u64::MAX)).is_err());
    }

    #[test]
    fn counts_the_file_cannot_hold_are_refused_before_anything_is_read() {
        let dir = crate::TestDir::new("ply-counts");
        let binary = |elements: &str, payload: &[u8]| {
            let mut bytes = format!("ply\nformat binary_little_endian 1.0\n{elements}end_header\n").into_bytes();
            bytes.extend_from_slice(payload);
            bytes
        };
        let xyz = "property float x\nproperty float y\nproperty float z\n";
        let face = "element face 1\nproperty list uchar uint vertex_indices\n";
        let cases: [(&str, Vec<u8>, &str); 4] = [
            // What the fuzzer found: a vertex element of no properties (each entry zero
            // bytes) with trillions of entries, read until memory ran out.
            (
                "empty_entries.ply",
                binary("element vertex 38111111111111\n", &[0; 64]),
                "no properties",
            ),
            (
                "trillions.ply",
                binary(&format!("element vertex 1000000000000\n{xyz}{face}"), &[0; 64]),
                "more than the file's",
            ),
            // A later element's count counts against what the earlier ones leave.
            (
                "later.ply",
                binary(
                    &format!("element vertex 3\n{xyz}element face 100\nproperty list uchar uint vertex_indices\n"),
                    &[0; 40],
                ),
                "element 'face' declares 100 entries",
            ),
            (
                "ascii.ply",
                format!("ply\nformat ascii 1.0\nelement vertex 1000000\n{xyz}{face}end_header\n0 0 0\n").into_bytes(),
                "element 'vertex' declares 1000000 entries",
            ),
        ];
        for (name, bytes, says) in cases {
            let path = write(&dir, name, &bytes);
            for e in [
                load_ply(&path, &mut Resources::new(u64::MAX)).map(|_| ()),
                load_ply_polygons(&path, &mut Resources::new(u64::MAX)).map(|_| ()),
            ] {
                let e = e.unwrap_err();
                assert!(e.contains(says), "{name}: {e}");
            }
        }
    }

    #[test]
    fn the_vertices_and_faces_are_held_to_the_budget_and_given_back() {
        let dir = crate::TestDir::new("ply-budget");
        let mut text = String::from(
            "ply\nformat ascii 1.0\nelement vertex 300\nproperty float x\nproperty float y\nproperty float z\n\
             element face 100\nproperty list uchar int vertex_indices\nend_header\n",
        );
        for k in 0..300 {
            text += &format!("{} {} 0\n", k % 3, k / 3);
        }
        for k in 0..100 {
            text += &format!("3 {} {} {}\n", 3 * k, 3 * k + 1, 3 * k + 2);
        }
        let path = write(&dir, "grid.ply", text.as_bytes());
        // 300 vertices of 64 bytes and 100 faces, twice over: more than 40 KB.
        let e = load_ply(&path, &mut Resources::new(40_000)).unwrap_err();
        assert!(e.contains("memory budget"), "{e}");
        let mut res = Resources::new(u64::MAX);
        assert_eq!(load_ply(&path, &mut res).unwrap().mesh.indices.len(), 100);
        assert_eq!(res.budget.used(), 0, "what was taken is given back");
        assert_eq!(load_ply_polygons(&path, &mut res).unwrap().faces.len(), 100);
        assert_eq!(res.budget.used(), 0);
    }
}
