//! Displacement mapping (`displacementmap name scale`): a tessellated surface is refined
//! until its triangles are about a texel wide, then every vertex moves along its normal
//! by `scale × luminance` of the texture, and the normals are recomputed from the
//! displaced surface — before any acceleration structure sees it.

use std::collections::HashMap;

use crate::geometry::mesh::TriangleMesh;
use crate::math::Vec3A;
use glam::{Vec2, Vec3};

/// What displaces a surface: a height at each vertex, and the size of the finest detail
/// it has (which decides how far the surface is refined first). Textures provide it on
/// the shading floor (`crate::shading::texture::Displacement`).
pub trait HeightField {
    /// The height at a vertex with texture coordinates `uv` (zero when the mesh has
    /// none) and object-space position `p`.
    fn height(&self, uv: Vec2, p: Vec3A) -> f32;
    fn detail(&self) -> Detail;
}

/// The size of a height field's finest detail.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Detail {
    /// A texel, this wide in texture coordinates: looked up at the vertices' texture
    /// coordinates, which the mesh must have.
    Texel(f32),
    /// A feature this large in the mesh's own space, looked up at the vertices'
    /// positions.
    Solid(f32),
}

/// Refinement stops at this many triangles, texel size or not.
pub const MAX_DISPLACED_TRIANGLES: usize = 1 << 21;

/// Splits every triangle into four at its edge midpoints (shared between neighbours, so
/// the mesh stays watertight); normals and texture coordinates are interpolated.
fn split(mesh: &TriangleMesh) -> TriangleMesh {
    let mut out = TriangleMesh {
        positions: mesh.positions.clone(),
        normals: mesh.normals.clone(),
        uvs: mesh.uvs.clone(),
        indices: Vec::with_capacity(mesh.indices.len() * 4),
        materials: Vec::new(),
        material: mesh.material,
    };
    let mut midpoints: HashMap<(u32, u32), u32> = HashMap::new();
    let mut midpoint = |a: u32, b: u32, out: &mut TriangleMesh| -> u32 {
        *midpoints.entry((a.min(b), a.max(b))).or_insert_with(|| {
            let (a, b) = (a as usize, b as usize);
            out.positions.push((out.positions[a] + out.positions[b]) * 0.5);
            if !out.normals.is_empty() {
                let n = (out.normals[a] + out.normals[b]).normalize_or_zero();
                out.normals.push(n);
            }
            if !out.uvs.is_empty() {
                out.uvs.push((out.uvs[a] + out.uvs[b]) * 0.5);
            }
            out.positions.len() as u32 - 1
        })
    };
    for (k, &[a, b, c]) in mesh.indices.iter().enumerate() {
        let (ab, bc, ca) = (
            midpoint(a, b, &mut out),
            midpoint(b, c, &mut out),
            midpoint(c, a, &mut out),
        );
        out.indices
            .extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        if !mesh.materials.is_empty() {
            out.materials.extend([mesh.materials[k]; 4]);
        }
    }
    out
}

/// Area-weighted vertex normals of the mesh's faces.
pub fn vertex_normals(mesh: &TriangleMesh) -> Vec<Vec3> {
    let mut normals = vec![Vec3::ZERO; mesh.positions.len()];
    for &[a, b, c] in &mesh.indices {
        let [pa, pb, pc] = [a, b, c].map(|i| mesh.positions[i as usize]);
        let n = (pb - pa).cross(pc - pa);
        for i in [a, b, c] {
            normals[i as usize] += n;
        }
    }
    normals.iter().map(|n| n.normalize_or_zero()).collect()
}

/// How many times to split so that triangle edges span about one unit of detail (a
/// texel in texture space, or a solid feature in the mesh's own space), with no more
/// than [`MAX_DISPLACED_TRIANGLES`] as a result.
fn levels_for(mesh: &TriangleMesh, detail: Detail) -> u32 {
    let edges = || {
        mesh.indices
            .iter()
            .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
    };
    let edge = match detail {
        Detail::Texel(texel) if !mesh.uvs.is_empty() => {
            let span = edges()
                .map(|(a, b)| (mesh.uvs[a as usize] - mesh.uvs[b as usize]).abs().max_element())
                .fold(0.0f32, f32::max);
            span / texel
        }
        Detail::Solid(size) => {
            let span = edges()
                .map(|(a, b)| (mesh.positions[a as usize] - mesh.positions[b as usize]).length())
                .fold(0.0f32, f32::max);
            span / size
        }
        Detail::Texel(_) => 1.0,
    };
    let mut levels = 0;
    let mut triangles = mesh.indices.len();
    let mut e = edge;
    while e > 1.0 && triangles * 4 <= MAX_DISPLACED_TRIANGLES && levels < 12 {
        e *= 0.5;
        triangles *= 4;
        levels += 1;
    }
    levels
}

/// How many triangles [`displace`] makes of `mesh` (so that their memory can be weighed
/// before they are made).
pub fn refined_triangles(mesh: &TriangleMesh, field: &impl HeightField) -> usize {
    mesh.indices.len() << (2 * levels_for(mesh, field.detail()))
}

/// The mesh refined and displaced by the height field along its normals (computed from
/// the faces where the mesh has none), with normals recomputed from the displaced faces.
pub fn displace(mesh: &TriangleMesh, field: &impl HeightField) -> Result<TriangleMesh, String> {
    let detail = field.detail();
    if matches!(detail, Detail::Texel(_)) && mesh.uvs.is_empty() {
        return Err("the surface has no texture coordinates to look the image up at".into());
    }
    let mut m = mesh.clone();
    if m.normals.is_empty() {
        m.normals = vertex_normals(&m);
    }
    for _ in 0..levels_for(mesh, detail) {
        m = split(&m);
    }
    for i in 0..m.positions.len() {
        let p = m.positions[i];
        let uv = m.uvs.get(i).copied().unwrap_or(Vec2::ZERO);
        let h = field.height(uv, Vec3A::from(p));
        m.positions[i] = p + m.normals[i] * h;
    }
    m.normals = vertex_normals(&m);
    Ok(m)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Height `scale × u` sampled like a texture `texels` wide.
    struct Ramp {
        texels: u32,
        scale: f32,
    }

    impl HeightField for Ramp {
        fn height(&self, uv: Vec2, _: Vec3A) -> f32 {
            // The texel centres' values, interpolated (and wrapped) as bilinear filtering does.
            let n = self.texels as f32;
            let x = (uv.x - uv.x.floor()) * n - 0.5;
            let (i, f) = (x.floor(), x - x.floor());
            let value = |k: f32| (k.rem_euclid(n) + 0.5) / n;
            self.scale * (value(i) * (1.0 - f) + value(i + 1.0) * f)
        }
        fn detail(&self) -> Detail {
            Detail::Texel(1.0 / self.texels as f32)
        }
    }

    /// Alternating heights 0 and `scale` in cubes of side `cell`.
    struct Blocks {
        cell: f32,
    }

    impl HeightField for Blocks {
        fn height(&self, _: Vec2, p: Vec3A) -> f32 {
            let c = (p / self.cell).floor();
            (c.x + c.y + c.z).rem_euclid(2.0) * 0.1
        }
        fn detail(&self) -> Detail {
            Detail::Solid(0.25 * self.cell)
        }
    }

    fn square(n: usize) -> TriangleMesh {
        let points: Vec<(Vec3, Vec3)> = (0..=n)
            .flat_map(|i| (0..=n).map(move |j| (Vec3::new(j as f32 / n as f32, i as f32 / n as f32, 0.0), Vec3::Z)))
            .collect();
        crate::tessellate::grid::grid_mesh(&points, n, n)
    }

    #[test]
    fn a_ramp_lifts_the_square_into_a_slope_and_keeps_it_watertight() {
        // Height 0.5·u across 16 texels: the square becomes z ≈ 0.5·u.
        let out = displace(&square(1), &Ramp { texels: 16, scale: 0.5 }).unwrap();
        assert!(
            out.indices.len() >= 2 * 16 * 16,
            "refined to about a texel: {}",
            out.indices.len()
        );
        for (p, uv) in out.positions.iter().zip(&out.uvs) {
            // Bilinear wrapping at the edges aside, height follows u.
            if uv.x > 0.05 && uv.x < 0.95 {
                assert!((p.z - 0.5 * uv.x).abs() < 0.02, "{p} at {uv}");
            }
        }
        // Shared midpoints: every interior edge has two triangles.
        let mut edges = HashMap::new();
        for t in &out.indices {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                *edges.entry((a.min(b), a.max(b))).or_insert(0) += 1;
            }
        }
        assert!(edges.values().all(|&n| n <= 2));
        let boundary = edges.values().filter(|&&n| n == 1).count();
        assert_eq!(boundary, 4 * (out.indices.len() as f64 / 2.0).sqrt() as usize);
        // The recomputed normals lean back against the slope: (−0.5, 0, 1) normalised.
        let mid = out
            .positions
            .iter()
            .position(|p| (p.x - 0.5).abs() < 0.02 && (p.y - 0.5).abs() < 0.02)
            .unwrap();
        let expect = Vec3::new(-0.5, 0.0, 1.0).normalize();
        assert!((out.normals[mid] - expect).length() < 0.05, "{}", out.normals[mid]);
    }

    #[test]
    fn texel_detail_needs_texture_coordinates_and_solid_detail_refines_by_size() {
        let mut m = square(2);
        m.uvs.clear();
        assert!(displace(&m, &Ramp { texels: 1, scale: 1.0 }).is_err());
        let out = displace(&m, &Blocks { cell: 0.5 }).unwrap();
        // Refined until edges are below a quarter of a cell: the diagonals (0.71) of the
        // 2 × 2 quads are halved three times, so the 8 triangles become 8 · 4³.
        assert_eq!(out.indices.len(), 8 * 64);
    }
}
