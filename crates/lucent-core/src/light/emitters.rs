//! Scene command `emission r g b` (and OBJ `Ke`) on any object, as a light of the Monte
//! Carlo integrators (EXTENSIONS.md): every emissive primitive emits its radiance E from
//! both sides of its surface, and all of them together are one light. Next-event
//! estimation picks a piece with probability area × luminance(E) / P (P the sum over all
//! pieces) and then a point uniformly by area, so that the density by area of any point
//! of any piece is luminance(E) / P: a path that hits an emissive surface knows its
//! light-sampling density from the material alone, without finding the piece.
//!
//! The pieces are world-space triangles (plain triangles, every emissive triangle of a
//! mesh — a 100,000-triangle mesh is 100,000 pieces in one alias table, drawn in
//! constant time — the twelve triangles of a `box`, and all of these inside instances),
//! and spheres, disks, cylinders and cones under their affine transforms, drawn uniformly
//! by world area as [`super::mapped_surface`] says.
//!
//! A `plane` (unbounded) and a `quadric` (no parametrisation) cannot be sampled: a
//! material that emits on one of them is left out of the light, and paths that hit it
//! count its emission in full, in every mode (the builder warns).

use super::mapped_surface::{Mapped, ObjectSurface};
use crate::geometry::analytic::AnalyticKind;
use crate::geometry::primitive::{Primitive, Shape};
use crate::light::LightSample;
use crate::math::{Affine3A, Color, Vec3A};
use crate::sampling::distribution::AliasTable;
use crate::shading::material::Material;
use crate::shading::texture::luminance;

/// Every emissive surface of the scene that can be sampled.
#[derive(Clone, Debug)]
pub struct EmissiveSurfaces {
    pieces: Vec<Piece>,
    /// Each piece's radiance (its material's emission).
    radiance: Vec<Color>,
    choose: AliasTable,
    /// Σ area × luminance(E) over the pieces.
    power: f64,
    /// Per material: whether its emission is part of this light.
    sampled: Vec<bool>,
}

/// What [`EmissiveSurfaces::find`] found.
pub struct Emitters {
    pub light: Option<EmissiveSurfaces>,
    /// Materials that emit on a plane or a quadric, which no light sampling can reach:
    /// `(material, shape name)`.
    pub unsampled: Vec<(u32, &'static str)>,
}

#[derive(Clone, Debug)]
enum Piece {
    Triangle([Vec3A; 3]),
    /// Boxed: a triangle (48 bytes) should not pay for its size.
    Mapped(Box<Mapped>),
}

impl Piece {
    fn area(&self) -> f32 {
        match self {
            Piece::Triangle(p) => 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length(),
            Piece::Mapped(m) => m.area,
        }
    }

    /// A point drawn uniformly by area, with the unit normal there.
    fn point(&self, u: f32, v: f32) -> Option<(Vec3A, Vec3A)> {
        match self {
            Piece::Triangle(p) => {
                // Uniform on the triangle (the square folded along its diagonal).
                let (b1, b2) = if u + v > 1.0 { (1.0 - u, 1.0 - v) } else { (u, v) };
                let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
                Some((p[0] + e1 * b1 + e2 * b2, e1.cross(e2).normalize()))
            }
            Piece::Mapped(m) => m.point(u, v),
        }
    }
}

/// Collects the emissive pieces of `prims` seen through `to_world` (the identity at the
/// top; an instance's transform inside it).
fn collect(
    prims: &[Primitive],
    to_world: Option<&Affine3A>,
    materials: &[Material],
    out: &mut Vec<(Piece, u32)>,
    unsampled: &mut Vec<(u32, &'static str)>,
) {
    let emits = |m: u32| materials.get(m as usize).is_some_and(|m| luminance(m.emission) > 0.0);
    let world = |p: Vec3A| to_world.map_or(p, |t| t.transform_point3a(p));
    let compose = |t: Affine3A| to_world.map_or(t, |w| *w * t);
    for prim in prims {
        if prim.light.is_some() {
            continue; // the surface of a quad light, which is a light of its own
        }
        match &prim.shape {
            Shape::Triangle { p, .. } if emits(prim.material) => {
                out.push((Piece::Triangle(p.map(world)), prim.material));
            }
            Shape::Sphere(s) if emits(prim.material) => {
                out.push((
                    Piece::Mapped(Box::new(Mapped::new(ObjectSurface::Sphere, compose(s.object_to_world)))),
                    prim.material,
                ));
            }
            Shape::Analytic(a) if emits(prim.material) => {
                let to = compose(a.world_to_object.inverse());
                let surface = match a.kind {
                    AnalyticKind::Disk { radius } => ObjectSurface::Disk { radius },
                    AnalyticKind::Cylinder { radius, zmin, zmax } => ObjectSurface::Cylinder { radius, zmin, zmax },
                    AnalyticKind::Cone { radius, height } => ObjectSurface::Cone { radius, height },
                    AnalyticKind::Cuboid(b) => {
                        let c = |i: usize| {
                            let pick = |bit: usize, lo: f32, hi: f32| if i >> bit & 1 == 1 { hi } else { lo };
                            to.transform_point3a(Vec3A::new(
                                pick(0, b.min.x, b.max.x),
                                pick(1, b.min.y, b.max.y),
                                pick(2, b.min.z, b.max.z),
                            ))
                        };
                        // Each face as two triangles, by the corners' bit patterns.
                        for face in [
                            [0, 1, 3, 2],
                            [4, 5, 7, 6],
                            [0, 1, 5, 4],
                            [2, 3, 7, 6],
                            [0, 2, 6, 4],
                            [1, 3, 7, 5],
                        ] {
                            out.push((Piece::Triangle([c(face[0]), c(face[1]), c(face[2])]), prim.material));
                            out.push((Piece::Triangle([c(face[0]), c(face[2]), c(face[3])]), prim.material));
                        }
                        continue;
                    }
                    AnalyticKind::Plane { .. } => {
                        unsampled.push((prim.material, "plane"));
                        continue;
                    }
                    AnalyticKind::Quadric { .. } => {
                        unsampled.push((prim.material, "quadric"));
                        continue;
                    }
                };
                out.push((Piece::Mapped(Box::new(Mapped::new(surface, to))), prim.material));
            }
            Shape::Mesh(m) => {
                let mesh = &m.mesh;
                for (k, tri) in mesh.indices.iter().enumerate() {
                    let material = mesh.materials.get(k).copied().unwrap_or(mesh.material);
                    if emits(material) {
                        let p = tri.map(|i| world(Vec3A::from(mesh.positions[i as usize])));
                        out.push((Piece::Triangle(p), material));
                    }
                }
            }
            Shape::Instance(i) => {
                collect(
                    &i.object.primitives,
                    Some(&compose(i.object_to_world)),
                    materials,
                    out,
                    unsampled,
                );
            }
            _ => {}
        }
    }
}

impl EmissiveSurfaces {
    /// The emissive surfaces of `primitives` (whose materials are `materials`).
    pub fn find(primitives: &[Primitive], materials: &[Material]) -> Emitters {
        let mut found = Vec::new();
        let mut unsampled = Vec::new();
        collect(primitives, None, materials, &mut found, &mut unsampled);
        let mut sampled: Vec<bool> = materials.iter().map(|m| luminance(m.emission) > 0.0).collect();
        for &(m, _) in &unsampled {
            sampled[m as usize] = false;
        }
        found.retain(|(_, m)| sampled[*m as usize]);
        let weights: Vec<f32> = found
            .iter()
            .map(|(p, m)| p.area() * luminance(materials[*m as usize].emission))
            .collect();
        let power: f64 = weights.iter().map(|&w| w as f64).sum();
        let light = AliasTable::new(&weights).map(|choose| {
            let (pieces, piece_materials): (Vec<Piece>, Vec<u32>) = found.into_iter().unzip();
            EmissiveSurfaces {
                radiance: piece_materials
                    .iter()
                    .map(|&m| materials[m as usize].emission)
                    .collect(),
                pieces,
                power,
                choose,
                sampled,
            }
        });
        unsampled.sort();
        unsampled.dedup();
        Emitters { light, unsampled }
    }

    /// How many pieces the light is made of.
    pub fn piece_count(&self) -> usize {
        self.pieces.len()
    }

    /// Whether a surface of this material is part of the light (a path that hits it
    /// weighs its emission against light sampling).
    #[inline]
    pub fn samples(&self, material: u32) -> bool {
        self.sampled.get(material as usize).copied().unwrap_or(false)
    }

    /// A point of the light seen from `x`: `pick` chooses the piece, `(u, v)` the point.
    #[inline]
    pub fn sample_li(&self, x: Vec3A, pick: f32, u: f32, v: f32) -> Option<LightSample> {
        let i = self.choose.sample(pick);
        let (y, normal) = self.pieces[i].point(u, v)?;
        let to_light = y - x;
        let r2 = to_light.length_squared();
        let distance = r2.sqrt();
        let wi = to_light / distance;
        let pdf = self.pdf_li(self.radiance[i], normal, distance, wi);
        (pdf > 0.0 && pdf.is_finite()).then_some(LightSample {
            wi,
            distance,
            radiance: self.radiance[i],
            pdf,
            is_delta: false,
        })
    }

    /// The solid-angle density of reaching, along `wi`, a point at `distance` of a
    /// surface that emits `radiance` and has unit normal `normal` there (either side).
    #[inline]
    pub fn pdf_li(&self, radiance: Color, normal: Vec3A, distance: f32, wi: Vec3A) -> f32 {
        let cos = normal.dot(wi).abs();
        let p_area = (luminance(radiance) as f64 / self.power) as f32;
        if cos > 0.0 {
            p_area * distance * distance / cos
        } else {
            0.0
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::AccelKind;
    use crate::geometry::analytic::{Analytic, Sphere};
    use crate::geometry::Geometry;
    use crate::ray::Ray;
    use crate::sampling::chi2::chi2_test_edged;
    use glam::{Quat, Vec3};

    fn material(e: f32) -> Material {
        Material {
            emission: Color::new(e, 0.5 * e, 0.2 * e),
            ..Material::default()
        }
    }

    fn place(scale: Vec3, axis: Vec3, angle: f32, at: Vec3) -> Affine3A {
        Affine3A::from_scale_rotation_translation(scale, Quat::from_axis_angle(axis.normalize(), angle), at)
    }

    fn analytic(to_world: Affine3A, kind: AnalyticKind, material: u32) -> Primitive {
        Primitive::new(Shape::Analytic(Box::new(Analytic::new(to_world, kind))), material)
    }

    /// Emissive shapes of every kind that can be sampled, around the origin, with
    /// different radiances (material 0 does not emit).
    fn emissive_shapes() -> Vec<Primitive> {
        let shear = Affine3A::from_cols(
            Vec3A::new(1.0, 0.0, 0.0),
            Vec3A::new(0.6, 1.0, 0.0),
            Vec3A::new(0.0, 0.3, 0.5),
            Vec3A::new(2.5, 0.5, -0.5),
        );
        vec![
            // An ellipsoid, a sphere, a sheared cylinder, a cone, a disk, a box, a
            // triangle, and a sphere that does not emit.
            Primitive::new(
                Shape::Sphere(Box::new(Sphere::new(place(
                    Vec3::new(1.0, 0.4, 0.7),
                    Vec3::new(1.0, 1.0, 0.0),
                    0.7,
                    Vec3::new(-2.0, 0.0, 0.0),
                )))),
                1,
            ),
            Primitive::new(
                Shape::Sphere(Box::new(Sphere::new(place(
                    Vec3::splat(0.3),
                    Vec3::X,
                    0.0,
                    Vec3::new(0.0, 2.0, 0.5),
                )))),
                2,
            ),
            analytic(
                shear,
                AnalyticKind::Cylinder {
                    radius: 0.5,
                    zmin: -1.0,
                    zmax: 1.0,
                },
                1,
            ),
            analytic(
                place(Vec3::ONE, Vec3::new(0.0, 1.0, 1.0), 1.2, Vec3::new(0.0, -2.0, 0.0)),
                AnalyticKind::Cone {
                    radius: 0.8,
                    height: 1.2,
                },
                3,
            ),
            analytic(
                place(Vec3::new(1.0, 2.0, 1.0), Vec3::X, 0.4, Vec3::new(0.0, 0.0, -2.5)),
                AnalyticKind::Disk { radius: 0.6 },
                2,
            ),
            analytic(
                place(Vec3::new(1.0, 0.5, 2.0), Vec3::Y, 0.5, Vec3::new(-1.0, -1.0, 2.0)),
                AnalyticKind::Cuboid(crate::aabb::Aabb::new(Vec3A::splat(-0.3), Vec3A::splat(0.3))),
                3,
            ),
            Primitive::new(
                Shape::Triangle {
                    p: [
                        Vec3A::new(1.5, 1.5, 1.0),
                        Vec3A::new(2.5, 1.0, 1.5),
                        Vec3A::new(1.8, 2.5, 0.5),
                    ],
                    normals: None,
                },
                1,
            ),
            Primitive::new(
                Shape::Sphere(Box::new(Sphere::new(place(
                    Vec3::splat(0.2),
                    Vec3::X,
                    0.0,
                    Vec3::new(0.0, 0.5, 0.0),
                )))),
                0,
            ),
        ]
    }

    fn materials() -> Vec<Material> {
        vec![Material::default(), material(1.0), material(4.0), material(0.5)]
    }

    #[test]
    fn flat_emitters_are_drawn_with_their_solid_angle_density() {
        // A disk, a box (twelve triangles) and a triangle of different radiances: the
        // piece chosen by power, the point by area. The density of a direction is the
        // sum over every emissive point along it (the light draws points on the far
        // faces of the box too), found by tracing through the shapes one after the
        // other. (Curved shapes have silhouettes where the density grows like 1/cos θ,
        // which the binned integral of the χ² test cannot follow: they are tested by
        // area below.)
        let prims: Vec<Primitive> = emissive_shapes().into_iter().skip(4).collect();
        let mats = materials();
        let light = EmissiveSurfaces::find(&prims, &mats).light.unwrap();
        assert_eq!(light.piece_count(), 1 + 12 + 1);
        let geometry = Geometry::new(prims, Vec::new(), AccelKind::Bvh);
        let x = Vec3A::new(0.1, 0.05, 0.2);
        let pdf = |wi: Vec3A| {
            let mut total = 0.0;
            let mut t_min = 0.0;
            loop {
                let ray = Ray::segment(x, wi, t_min, f32::INFINITY);
                let Some(hit) = geometry.closest_hit(&ray) else { break };
                let sp = geometry.surface_point(&hit, x, wi);
                let e = mats[sp.material as usize].emission;
                if e != Color::ZERO {
                    total += light.pdf_li(e, sp.geometric_normal, hit.t, wi);
                }
                t_min = hit.t * (1.0 + 1e-5) + 1e-6;
            }
            total
        };
        // The piece is chosen by a third number, hashed from a counter.
        let mut pick_state = 7u64;
        chi2_test_edged(
            "emissive surfaces",
            |u, v| {
                light
                    .sample_li(x, super::super::mapped_surface::next_unit(&mut pick_state), u, v)
                    .map(|s| s.wi)
            },
            pdf,
        );
    }

    #[test]
    fn shapes_that_cannot_be_sampled_leave_their_material_to_the_paths() {
        let plane = analytic(
            Affine3A::IDENTITY,
            AnalyticKind::Plane {
                point: Vec3A::ZERO,
                normal: Vec3A::Y,
            },
            2,
        );
        let mut prims = emissive_shapes();
        prims.push(plane);
        let found = EmissiveSurfaces::find(&prims, &materials());
        assert_eq!(found.unsampled, vec![(2, "plane")]);
        let light = found.light.unwrap();
        assert!(light.samples(1) && light.samples(3));
        assert!(!light.samples(2) && !light.samples(0));
        assert_eq!(
            light.piece_count(),
            4 + 12,
            "the sphere and the disk of material 2 are out"
        );
        // Nothing emits: no light.
        assert!(EmissiveSurfaces::find(&emissive_shapes(), &[Material::default(); 4])
            .light
            .is_none());
    }
}
