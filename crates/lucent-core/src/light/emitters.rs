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
//! and spheres, disks, cylinders and cones under their affine transforms. Those are drawn
//! uniformly in object space and kept with probability s / s_max, where s = |det M| ·
//! |M⁻ᵀ n| is how much the transform M stretches the area around the point: uniform by
//! world area (rejection is skipped where s is constant: a disk, a shape under a rotation
//! and uniform scale). Their world area is the object area times the mean of s, by
//! quadrature where s varies (a 128 × 128 midpoint rule on a smooth integrand: error
//! below 10⁻⁵).
//!
//! A `plane` (unbounded) and a `quadric` (no parametrisation) cannot be sampled: a
//! material that emits on one of them is left out of the light, and paths that hit it
//! count its emission in full, in every mode (the builder warns).

use crate::geometry::analytic::AnalyticKind;
use crate::geometry::primitive::{Primitive, Shape};
use crate::light::LightSample;
use crate::math::{Affine3A, Color, Mat3A, Vec3A};
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

/// A surface of object space under an affine transform.
#[derive(Clone, Copy, Debug)]
struct Mapped {
    surface: ObjectSurface,
    to_world: Affine3A,
    /// |det M| · M⁻ᵀ: s(n) = |stretch · n| for a unit object normal n.
    stretch: Mat3A,
    /// An upper bound of s, or `None` where s is constant (no rejection).
    s_max: Option<f32>,
    area: f32,
}

#[derive(Clone, Copy, Debug)]
enum ObjectSurface {
    Sphere,
    Disk { radius: f32 },
    Cylinder { radius: f32, zmin: f32, zmax: f32 },
    Cone { radius: f32, height: f32 },
}

impl ObjectSurface {
    /// A point drawn uniformly by object-space area from `(u, v)`, with its unit normal.
    fn point(&self, u: f32, v: f32) -> (Vec3A, Vec3A) {
        use std::f32::consts::TAU;
        match *self {
            ObjectSurface::Sphere => {
                let z = 1.0 - 2.0 * u;
                let r = (1.0 - z * z).max(0.0).sqrt();
                let (s, c) = (TAU * v).sin_cos();
                let p = Vec3A::new(r * c, r * s, z);
                (p, p)
            }
            ObjectSurface::Disk { radius } => {
                let r = radius * u.sqrt();
                let (s, c) = (TAU * v).sin_cos();
                (Vec3A::new(r * c, r * s, 0.0), Vec3A::Z)
            }
            ObjectSurface::Cylinder { radius, zmin, zmax } => {
                let (s, c) = (TAU * u).sin_cos();
                let z = zmin + (zmax - zmin) * v;
                (Vec3A::new(radius * c, radius * s, z), Vec3A::new(c, s, 0.0))
            }
            ObjectSurface::Cone { radius, height } => {
                // Area grows linearly with the distance from the apex.
                let f = u.sqrt();
                let (s, c) = (TAU * v).sin_cos();
                let k = radius / height;
                let p = Vec3A::new(radius * f * c, radius * f * s, height * (1.0 - f));
                (p, Vec3A::new(c, s, k) / (1.0 + k * k).sqrt())
            }
        }
    }

    fn area(&self) -> f32 {
        use std::f32::consts::PI;
        match *self {
            ObjectSurface::Sphere => 4.0 * PI,
            ObjectSurface::Disk { radius } => PI * radius * radius,
            ObjectSurface::Cylinder { radius, zmin, zmax } => 2.0 * PI * radius * (zmax - zmin).abs(),
            ObjectSurface::Cone { radius, height } => PI * radius * (radius * radius + height * height).sqrt(),
        }
    }
}

impl Mapped {
    fn new(surface: ObjectSurface, to_world: Affine3A) -> Mapped {
        let m = to_world.matrix3;
        let stretch = m.inverse().transpose() * m.determinant().abs();
        // s is constant on a planar surface, and everywhere when M is a rotation times a
        // uniform scale (MᵀM a multiple of the identity).
        let mtm = m.transpose() * m;
        let scale = mtm.x_axis.x.max(mtm.y_axis.y).max(mtm.z_axis.z);
        let off = (mtm - Mat3A::from_diagonal(glam::Vec3::splat(scale))).to_cols_array();
        let conformal = off.iter().all(|e| e.abs() <= 1e-5 * scale);
        let constant = conformal || matches!(surface, ObjectSurface::Disk { .. });
        let s = |n: Vec3A| (stretch * n).length();
        let (mean, s_max) = if constant {
            (s(surface.point(0.5, 0.5).1), None)
        } else {
            const N: usize = 128;
            let mut sum = 0f64;
            for i in 0..N {
                for j in 0..N {
                    let (u, v) = ((i as f32 + 0.5) / N as f32, (j as f32 + 0.5) / N as f32);
                    sum += s(surface.point(u, v).1) as f64;
                }
            }
            // The largest stretch of any direction: |det M| / σ_min(M), σ_min² the
            // smallest eigenvalue of MᵀM (bounded below by Gershgorin's discs), with a
            // margin for rounding.
            let cols = mtm.to_cols_array_2d();
            let min_eig = (0..3)
                .map(|i| cols[i][i] - (0..3).filter(|&j| j != i).map(|j| cols[i][j].abs()).sum::<f32>())
                .fold(f32::INFINITY, f32::min);
            let bound = if min_eig > 0.0 {
                m.determinant().abs() / min_eig.sqrt()
            } else {
                // No useful bound from the discs: the largest s on a fine grid, doubled.
                let mut best = 0f32;
                for i in 0..512 {
                    for j in 0..64 {
                        best = best.max(s(surface.point((i as f32 + 0.5) / 512.0, (j as f32 + 0.5) / 64.0).1));
                    }
                }
                2.0 * best
            };
            ((sum / (N * N) as f64) as f32, Some(bound * 1.0001))
        };
        Mapped {
            surface,
            to_world,
            stretch,
            s_max,
            area: surface.area() * mean,
        }
    }

    /// A point drawn uniformly by world area, from `(u, v)` and, when a draw is
    /// rejected, numbers hashed from them (deterministic). `None` after 64 rejections
    /// in a row (a chance below 10⁻¹⁹ unless the shape is stretched more than 2:1).
    fn point(&self, u: f32, v: f32) -> Option<(Vec3A, Vec3A)> {
        let (mut u, mut v) = (u, v);
        let mut state = ((u.to_bits() as u64) << 32 | v.to_bits() as u64) ^ 0x9e37_79b9_7f4a_7c15;
        for _ in 0..64 {
            let (p, n) = self.surface.point(u, v);
            let accept = match self.s_max {
                None => true,
                Some(max) => {
                    let w = next_unit(&mut state);
                    w * max < (self.stretch * n).length()
                }
            };
            if accept {
                // Normals go to world by M⁻ᵀ (`stretch` is a positive multiple of it).
                return Some((self.to_world.transform_point3a(p), (self.stretch * n).normalize()));
            }
            u = next_unit(&mut state);
            v = next_unit(&mut state);
        }
        None
    }
}

/// A uniform number in [0, 1) from a splitmix64 state.
fn next_unit(state: &mut u64) -> f32 {
    *state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^= z >> 31;
    (z >> 40) as f32 / (1u64 << 24) as f32
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
            |u, v| light.sample_li(x, next_unit(&mut pick_state), u, v).map(|s| s.wi),
            pdf,
        );
    }

    /// The object-space parameters (u, v) of `Mapped::point`'s draw that landed at `p`.
    fn parameters(m: &Mapped, p: Vec3A) -> (f32, f32) {
        let q = m.to_world.inverse().transform_point3a(p);
        let turn = |y: f32, x: f32| (y.atan2(x) / std::f32::consts::TAU).rem_euclid(1.0);
        match m.surface {
            ObjectSurface::Sphere => ((1.0 - q.z) / 2.0, turn(q.y, q.x)),
            ObjectSurface::Disk { radius } => ((q.x * q.x + q.y * q.y) / (radius * radius), turn(q.y, q.x)),
            ObjectSurface::Cylinder { zmin, zmax, .. } => (turn(q.y, q.x), (q.z - zmin) / (zmax - zmin)),
            ObjectSurface::Cone { radius, .. } => ((q.x * q.x + q.y * q.y) / (radius * radius), turn(q.y, q.x)),
        }
    }

    #[test]
    fn curved_emitters_are_uniform_by_world_area() {
        // Points drawn on stretched shapes, binned by their object-space parameters on
        // a 16 × 16 grid: each bin must get its share of the world area, the mean of
        // the stretch s over the bin (by an 8 × 8 midpoint rule) times its object area.
        let shapes = [
            Mapped::new(
                ObjectSurface::Sphere,
                place(Vec3::new(1.0, 0.4, 3.0), Vec3::new(1.0, 1.0, 0.0), 0.7, Vec3::ZERO),
            ),
            Mapped::new(
                ObjectSurface::Cylinder {
                    radius: 0.5,
                    zmin: -1.0,
                    zmax: 2.0,
                },
                Affine3A::from_cols(
                    Vec3A::X,
                    Vec3A::new(0.6, 1.0, 0.0),
                    Vec3A::new(0.0, 0.3, 0.5),
                    Vec3A::ZERO,
                ),
            ),
            Mapped::new(
                ObjectSurface::Cone {
                    radius: 0.8,
                    height: 1.2,
                },
                place(Vec3::new(3.0, 1.0, 0.5), Vec3::Z, 0.3, Vec3::ONE),
            ),
        ];
        const B: usize = 16;
        for (k, m) in shapes.iter().enumerate() {
            assert!(m.s_max.is_some(), "shape {k} is stretched unevenly");
            let s = |u: f32, v: f32| (m.stretch * m.surface.point(u, v).1).length() as f64;
            let mut expected = vec![0f64; B * B];
            for (b, e) in expected.iter_mut().enumerate() {
                let (bu, bv) = ((b / B) as f32, (b % B) as f32);
                for i in 0..8 {
                    for j in 0..8 {
                        *e += s(
                            (bu + (i as f32 + 0.5) / 8.0) / B as f32,
                            (bv + (j as f32 + 0.5) / 8.0) / B as f32,
                        );
                    }
                }
            }
            let n = 400_000;
            let total: f64 = expected.iter().sum();
            expected.iter_mut().for_each(|e| *e *= n as f64 / total);
            let mut observed = vec![0f64; B * B];
            for i in 0..n {
                let (u, v) = crate::sampler::Sampler::new(5, i, 0, 0).uniform2();
                let (p, normal) = m.point(u, v).expect("a point within 64 tries");
                let (pu, pv) = parameters(m, p);
                let (bu, bv) = (
                    ((pu * B as f32) as usize).min(B - 1),
                    ((pv * B as f32) as usize).min(B - 1),
                );
                observed[bu * B + bv] += 1.0;
                // The normal is the surface's: perpendicular to the tangents (central
                // differences of the parametrisation, away from the poles and the apex
                // where it has a square root).
                let eps = 1e-3;
                let at = |u: f32, v: f32| m.to_world.transform_point3a(m.surface.point(u, v).0);
                if !(0.05..0.95).contains(&pu) {
                    continue;
                }
                for t in [at(pu + eps, pv) - at(pu - eps, pv), at(pu, pv + eps) - at(pu, pv - eps)] {
                    if t.length() > 1e-4 {
                        assert!(t.normalize().dot(normal).abs() < 1e-2, "shape {k}: {t} {normal}");
                    }
                }
            }
            let r = crate::sampling::chi2::pearson(&observed, &expected).unwrap();
            eprintln!("shape {k}: {r:?}");
            assert!(r.p_value >= crate::sampling::chi2::SIGNIFICANCE, "shape {k}: {r:?}");
        }
    }

    #[test]
    fn mapped_shapes_have_their_world_area() {
        use std::f32::consts::PI;
        // A prolate spheroid with semi-axes 1, 1, 2: 2π(1 + c·asin(e)/e), e² = 1 − 1/c².
        let spheroid = Mapped::new(ObjectSurface::Sphere, Affine3A::from_scale(Vec3::new(1.0, 1.0, 2.0)));
        let e = (1.0f32 - 0.25).sqrt();
        let exact = 2.0 * PI * (1.0 + 2.0 * e.asin() / e);
        assert!(
            (spheroid.area - exact).abs() < 1e-4 * exact,
            "{} {exact}",
            spheroid.area
        );
        // A cylinder squashed into an elliptic one: the ellipse's perimeter (Ramanujan's
        // second formula is exact to 10⁻⁶ here) times the height.
        let elliptic = Mapped::new(
            ObjectSurface::Cylinder {
                radius: 1.0,
                zmin: 0.0,
                zmax: 3.0,
            },
            Affine3A::from_scale(Vec3::new(2.0, 1.0, 1.0)),
        );
        let (a, b) = (2.0f32, 1.0f32);
        let h = ((a - b) / (a + b)).powi(2);
        let perimeter = PI * (a + b) * (1.0 + 3.0 * h / (10.0 + (4.0 - 3.0 * h).sqrt()));
        assert!(
            (elliptic.area - 3.0 * perimeter).abs() < 1e-4 * elliptic.area,
            "{}",
            elliptic.area
        );
        // Under a rotation and a uniform scale no rejection is needed and the area is exact.
        let sphere = Mapped::new(
            ObjectSurface::Sphere,
            place(Vec3::splat(2.0), Vec3::new(1.0, 2.0, 3.0), 0.9, Vec3::ONE),
        );
        assert!(sphere.s_max.is_none());
        assert!((sphere.area - 16.0 * PI).abs() < 1e-4 * sphere.area);
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
