//! Triangle meshes stored compactly: one shared array of vertices (positions, and
//! normals and texture coordinates when the mesh has them) and three `u32` indices per
//! triangle, instead of a copy of every corner in every triangle.
//!
//! A mesh is one primitive of the scene ([`MeshShape`]) with an acceleration structure of
//! its own over its triangles: the scene's structure finds the mesh, the mesh's
//! structure finds the triangle. Meshes from files (`mesh`), subdivision surfaces,
//! Bézier patches and NURBS all end up here.

use std::sync::Arc;

use crate::aabb::Aabb;
use crate::accel::{AccelKind, Accelerator, PrimitiveSet};
use crate::hit::{Hit, SurfacePoint};
use crate::math::{Vec3, Vec3A};
use crate::ray::PreparedRay;
use crate::shape::triangle;
use crate::spawn;
use glam::Vec2;

#[derive(Clone, Debug, Default)]
pub struct TriangleMesh {
    pub positions: Vec<Vec3>,
    /// Unit vertex normals, one per position, or empty (flat shading).
    pub normals: Vec<Vec3>,
    /// Texture coordinates, one per position, or empty (barycentric coordinates).
    pub uvs: Vec<Vec2>,
    pub indices: Vec<[u32; 3]>,
    /// Material per triangle, or empty when every triangle has `material`.
    pub materials: Vec<u32>,
    pub material: u32,
}

impl TriangleMesh {
    /// Why the mesh is inconsistent, if it is: an index past the vertices, an attribute
    /// array of the wrong length, a coordinate that is not finite.
    pub fn check(&self) -> Result<(), String> {
        let n = self.positions.len();
        if let Some((k, t)) = self
            .indices
            .iter()
            .enumerate()
            .find(|(_, t)| t.iter().any(|&i| i as usize >= n))
        {
            return Err(format!(
                "triangle {k} refers to vertex {} but the mesh has {n} vertices",
                t.iter().max().unwrap_or(&0)
            ));
        }
        if !self.normals.is_empty() && self.normals.len() != n {
            return Err(format!("{} normals for {n} vertices", self.normals.len()));
        }
        if !self.uvs.is_empty() && self.uvs.len() != n {
            return Err(format!("{} texture coordinates for {n} vertices", self.uvs.len()));
        }
        if !self.materials.is_empty() && self.materials.len() != self.indices.len() {
            return Err(format!(
                "{} materials for {} triangles",
                self.materials.len(),
                self.indices.len()
            ));
        }
        if let Some(p) = self.positions.iter().find(|p| !p.is_finite()) {
            return Err(format!("vertex {p} is not a finite number"));
        }
        Ok(())
    }

    #[inline(always)]
    pub fn corners(&self, k: u32) -> [Vec3A; 3] {
        self.indices[k as usize].map(|i| Vec3A::from(self.positions[i as usize]))
    }

    /// Adds the vertices and triangles of `other` (attributes are kept only if both
    /// meshes have them).
    pub fn append(&mut self, other: TriangleMesh) {
        let base = self.positions.len() as u32;
        let was_empty = self.indices.is_empty() && self.positions.is_empty();
        let keep = |mine: bool, theirs: bool| (was_empty || mine) && theirs;
        let normals = keep(!self.normals.is_empty(), !other.normals.is_empty());
        let uvs = keep(!self.uvs.is_empty(), !other.uvs.is_empty());
        self.positions.extend(other.positions);
        if normals {
            self.normals.extend(other.normals);
        } else {
            self.normals.clear();
        }
        if uvs {
            self.uvs.extend(other.uvs);
        } else {
            self.uvs.clear();
        }
        self.indices.extend(other.indices.iter().map(|t| t.map(|i| i + base)));
        if was_empty {
            self.materials = other.materials;
            self.material = other.material;
        } else {
            debug_assert!(self.materials.is_empty() && other.materials.is_empty());
        }
    }

    /// Drops triangles of zero area (or with non-finite normals from degenerate
    /// corners); returns how many went.
    pub fn remove_degenerate(&mut self) -> usize {
        let before = self.indices.len();
        let keep: Vec<bool> = (0..before as u32)
            .map(|k| {
                let [a, b, c] = self.corners(k);
                let n = (b - a).cross(c - a);
                n.length_squared() > 0.0 && n.is_finite()
            })
            .collect();
        let mut it = keep.iter();
        self.indices.retain(|_| *it.next().expect("one flag per triangle"));
        if !self.materials.is_empty() {
            let mut it = keep.iter();
            self.materials.retain(|_| *it.next().expect("one flag per triangle"));
        }
        before - self.indices.len()
    }

    pub fn bounds(&self) -> Aabb {
        self.positions.iter().fold(Aabb::EMPTY, |b, &p| b.grow(Vec3A::from(p)))
    }

    pub fn memory_bytes(&self) -> usize {
        self.positions.len() * size_of::<Vec3>()
            + self.normals.len() * size_of::<Vec3>()
            + self.uvs.len() * size_of::<Vec2>()
            + self.indices.len() * size_of::<[u32; 3]>()
            + self.materials.len() * size_of::<u32>()
    }

    /// `∂p/∂u`, `∂p/∂v` of triangle `hit.prim` (from its texture coordinates, or its
    /// barycentric ones when the mesh has none).
    pub fn tangents(&self, hit: &Hit) -> (Vec3A, Vec3A) {
        let p = self.corners(hit.prim);
        if self.uvs.is_empty() {
            return (p[1] - p[0], p[2] - p[0]);
        }
        let uv = self.indices[hit.prim as usize].map(|i| self.uvs[i as usize]);
        crate::shape::tangents::triangle_tangents(p, uv)
    }

    /// Shading data at `hit` (whose `prim` is the triangle). The point is rebuilt from
    /// the barycentric weights, not from the ray (see [`crate::spawn`]).
    pub fn surface_point(&self, hit: &Hit) -> SurfacePoint {
        let k = hit.prim as usize;
        let [i0, i1, i2] = self.indices[k].map(|i| i as usize);
        let b0 = 1.0 - hit.b1 - hit.b2;
        let smooth = if self.normals.is_empty() {
            None
        } else {
            let [n0, n1, n2] = [i0, i1, i2].map(|i| self.normals[i]);
            // A zero vertex normal means the surface has none there (a degenerate patch
            // corner), and opposite normals may cancel: both shade flat.
            let n = Vec3A::from(n0 * b0 + n1 * hit.b1 + n2 * hit.b2).normalize();
            (n0 != Vec3::ZERO && n1 != Vec3::ZERO && n2 != Vec3::ZERO && n.is_finite()).then_some(n)
        };
        let p = self.corners(hit.prim);
        let ng = triangle::geometric_normal(p[0], p[1], p[2]);
        let normal = smooth.unwrap_or(ng);
        let uv = if self.uvs.is_empty() {
            Vec2::new(hit.b1, hit.b2)
        } else {
            self.uvs[i0] * b0 + self.uvs[i1] * hit.b1 + self.uvs[i2] * hit.b2
        };
        let (point, error) = spawn::barycentric_point(p, hit.b1, hit.b2);
        SurfacePoint {
            point,
            error,
            geometric_normal: if ng.dot(normal) < 0.0 { -ng } else { ng },
            normal,
            uv,
            material: if self.materials.is_empty() {
                self.material
            } else {
                self.materials[k]
            },
            light: None,
        }
    }
}

impl PrimitiveSet for TriangleMesh {
    #[inline(always)]
    fn count(&self) -> usize {
        self.indices.len()
    }

    fn bounds(&self, i: u32) -> Aabb {
        Aabb::from_points(&self.corners(i))
    }

    fn triangle(&self, i: u32) -> Option<[Vec3A; 3]> {
        Some(self.corners(i))
    }

    #[inline(always)]
    fn intersect(&self, i: u32, ray: &PreparedRay, t_max: f32) -> Option<Hit> {
        let [a, b, c] = self.corners(i);
        triangle::intersect(ray, a, b, c, t_max).map(|h| Hit::new(h.t, i, h.b1, h.b2))
    }

    /// The triangle's vertex indices (its corners are read through them).
    #[inline(always)]
    fn prefetch(&self, i: u32) {
        if let Some(t) = self.indices.get(i as usize) {
            crate::accel::prefetch_value(t);
        }
    }
}

/// A mesh with its own acceleration structure: one primitive of a scene.
pub struct MeshShape {
    pub mesh: TriangleMesh,
    accel: Box<dyn Accelerator<TriangleMesh>>,
    bounds: Aabb,
}

impl std::fmt::Debug for MeshShape {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "MeshShape({} triangles)", self.mesh.indices.len())
    }
}

impl MeshShape {
    pub fn new(mesh: TriangleMesh, accel: AccelKind) -> Arc<MeshShape> {
        debug_assert!(mesh.check().is_ok());
        Arc::new(MeshShape {
            accel: accel.build(&mesh),
            bounds: mesh.bounds(),
            mesh,
        })
    }

    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// The closest hit in `(t_min, t_max]`: `prim` is the triangle.
    #[inline]
    pub fn intersect(&self, ray: &PreparedRay, t_max: f32) -> Option<Hit> {
        self.accel.closest_hit(&self.mesh, &ray.with_t_max(t_max))
    }

    #[inline]
    pub fn occludes(&self, ray: &PreparedRay, t_max: f32) -> bool {
        self.accel.occluded(&self.mesh, &ray.with_t_max(t_max))
    }

    /// The structure over the triangles (not the vertex data).
    pub fn accel_memory_bytes(&self) -> usize {
        self.accel.memory_bytes()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ray::Ray;

    fn quad() -> TriangleMesh {
        TriangleMesh {
            positions: vec![
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0),
            ],
            normals: vec![Vec3::Z; 4],
            uvs: vec![
                Vec2::new(0.0, 0.0),
                Vec2::new(1.0, 0.0),
                Vec2::new(1.0, 1.0),
                Vec2::new(0.0, 1.0),
            ],
            indices: vec![[0, 1, 2], [0, 2, 3]],
            materials: vec![3, 4],
            material: 0,
        }
    }

    #[test]
    fn hits_report_the_triangle_its_texture_coordinates_and_material() {
        let q = quad();
        assert!(q.check().is_ok());
        for accel in AccelKind::ALL {
            let shape = MeshShape::new(q.clone(), accel);
            let ray = Ray::new(Vec3A::new(0.25, 0.75, 1.0), -Vec3A::Z);
            let hit = shape.intersect(&PreparedRay::new(ray), f32::INFINITY).unwrap();
            assert_eq!(hit.prim, 1, "{accel:?}");
            let sp = shape.mesh.surface_point(&hit);
            assert!((sp.uv - Vec2::new(0.25, 0.75)).length() < 1e-6, "{}", sp.uv);
            assert_eq!(sp.material, 4);
            assert!((sp.normal - Vec3A::Z).length() < 1e-6);
            assert!(shape.occludes(&PreparedRay::new(ray), 2.0));
            assert!(!shape.occludes(&PreparedRay::new(ray), 0.5));
        }
    }

    #[test]
    fn inconsistent_meshes_are_reported_and_slivers_removed() {
        let mut q = quad();
        q.indices.push([0, 1, 9]);
        assert!(q.check().unwrap_err().contains("vertex 9"));
        q.indices.pop();
        q.normals.pop();
        assert!(q.check().unwrap_err().contains("3 normals for 4 vertices"));
        let mut q = quad();
        q.indices.push([0, 1, 1]);
        q.materials.push(7);
        assert_eq!(q.remove_degenerate(), 1);
        assert_eq!(q.materials, vec![3, 4]);
    }
}
