//! What the parametric surfaces (Bézier patches, NURBS) share: the normal where the
//! derivatives may vanish, and the triangles of a tessellation grid.

use crate::geometry::mesh::TriangleMesh;
use glam::{DVec3, Vec2, Vec3};

/// The unit normal `S_u × S_v` at `(u, v)`, from `derivatives(u, v) = (S_u, S_v)`.
/// Where it vanishes — at a pole, where a whole row of control points collapses into one —
/// the normal is taken a little way towards `middle`, the centre of the parameter domain.
/// `None` if the surface is degenerate even there.
pub fn normal(
    derivatives: impl Fn(f64, f64) -> (DVec3, DVec3),
    (u, v): (f64, f64),
    middle: (f64, f64),
) -> Option<DVec3> {
    for step in [0.0, 1e-5, 1e-4, 1e-3, 1e-2] {
        let (su, sv) = derivatives(u + (middle.0 - u) * step, v + (middle.1 - v) * step);
        let n = su.cross(sv);
        let scale = su.length_squared().max(sv.length_squared());
        if n.length_squared() > 1e-20 * scale * scale && n.is_finite() {
            return Some(n.normalize());
        }
    }
    None
}

/// The two triangles of each quad of a grid of `(columns + 1) × (rows + 1)` points stored
/// row by row, as indices into that grid, counter-clockwise in `(u, v)`.
pub fn grid_triangles(columns: usize, rows: usize) -> impl Iterator<Item = [usize; 3]> {
    let at = move |i: usize, j: usize| i * (columns + 1) + j;
    (0..rows).flat_map(move |i| {
        (0..columns).flat_map(move |j| {
            [
                [at(i, j), at(i, j + 1), at(i + 1, j + 1)],
                [at(i, j), at(i + 1, j + 1), at(i + 1, j)],
            ]
        })
    })
}

/// A triangle mesh from a grid of `(columns + 1) × (rows + 1)` points with their normals
/// (row by row, as [`grid_triangles`] numbers them); texture coordinates run from 0 to 1
/// across the grid. Triangles collapsed at a pole are dropped; a zero normal (where the
/// surface has none) makes its triangles shade flat.
pub fn grid_mesh(points: &[(Vec3, Vec3)], columns: usize, rows: usize) -> TriangleMesh {
    debug_assert_eq!(points.len(), (columns + 1) * (rows + 1));
    let mut mesh = TriangleMesh {
        positions: points.iter().map(|p| p.0).collect(),
        normals: points.iter().map(|p| p.1.normalize_or_zero()).collect(),
        uvs: (0..=rows)
            .flat_map(|i| (0..=columns).map(move |j| Vec2::new(j as f32 / columns as f32, i as f32 / rows as f32)))
            .collect(),
        indices: grid_triangles(columns, rows).map(|t| t.map(|k| k as u32)).collect(),
        ..TriangleMesh::default()
    };
    mesh.remove_degenerate();
    mesh
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_triangles_cover_every_quad_once() {
        let tris: Vec<[usize; 3]> = grid_triangles(2, 1).collect();
        assert_eq!(tris, [[0, 1, 4], [0, 4, 3], [1, 2, 5], [1, 5, 4]]);
        assert_eq!(grid_triangles(16, 16).count(), 512);
    }
}
