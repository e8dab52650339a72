//! Shapes become primitives: spheres as transformed unit spheres, the analytic shapes
//! under their transforms, triangles in world space, surfaces as meshes with their own
//! structure ([`super::tessellation`]), and objects as shared geometry that instances
//! place. Objects are built first, since the scene's instances refer to them.

use std::sync::Arc;

use glam::{DAffine3, DVec3};
use lucent_core::aabb::Aabb;
use lucent_core::geometry::analytic::{Analytic, AnalyticKind, Sphere};
use lucent_core::geometry::instance::Instance;
use lucent_core::geometry::mesh::MeshShape;
use lucent_core::geometry::primitive::{Primitive, Shape};
use lucent_core::geometry::Geometry;
use lucent_core::math::{Affine3A, Vec3A};
use lucent_core::transform::Transform;

use super::materials::Materials;
use super::tessellation::{surface_mesh, View};
use super::to_f32;
use crate::desc::{SceneDesc, ShapeKind};
use crate::diag::{Diagnostics, Loc};
use crate::resources::Resources;

/// Memory a shape given in the scene file costs once built: its primitive (176 bytes),
/// its share of the structure and of the build's temporaries, and what its description
/// costs beyond the text's own estimate. Measured at the peak of a render of 600,000
/// spheres of 31.5 bytes of text each: 662 bytes a sphere in all, of which the text's
/// estimate (8 bytes a byte) covers 252; a shape of the shortest text (`sphere 0 0 0 1`,
/// 15 bytes) must still be covered: 120 + 640.
const BYTES_PER_SHAPE: u64 = 640;

/// The scene's primitives, and the vertex normals their `trinormal` triangles index.
pub struct Primitives {
    pub primitives: Vec<Primitive>,
    pub vertex_normals: Vec<[Vec3A; 3]>,
}

/// An object's geometry and the bounds of its bounded primitives; `None` if it is empty.
type Object = Option<(Arc<Geometry>, Aabb)>;

/// The scene's primitives (objects built on the way).
pub fn primitives(
    desc: &SceneDesc,
    materials: &mut Materials,
    view: &View,
    res: &mut Resources,
    diags: &mut Diagnostics,
) -> Primitives {
    let objects: Vec<Object> = (0..desc.objects.len() as u32)
        .map(|o| {
            let p = shapes(desc, Some(o), &[], materials, view, res, diags);
            if p.primitives.is_empty() {
                return None;
            }
            let bounds = p.primitives.iter().fold(Aabb::EMPTY, |b, p| b.union(&p.bounds()));
            Some((
                Arc::new(Geometry::new(p.primitives, p.vertex_normals, view.accel)),
                bounds,
            ))
        })
        .collect();
    shapes(desc, None, &objects, materials, view, res, diags)
}

/// The primitives of the scene (`object` `None`) or of one object.
fn shapes(
    desc: &SceneDesc,
    object: Option<u32>,
    objects: &[Object],
    materials: &mut Materials,
    view: &View,
    res: &mut Resources,
    diags: &mut Diagnostics,
) -> Primitives {
    let mut out = Primitives {
        primitives: Vec::new(),
        vertex_normals: Vec::new(),
    };
    let shapes = desc.shapes.iter().filter(|s| s.object == object);
    let count = shapes.clone().count() as u64;
    if let Err(e) = res
        .budget
        .take(count.saturating_mul(BYTES_PER_SHAPE), &format!("{count} shapes"))
    {
        diags.error(desc.end, e);
        return out;
    }
    for s in shapes {
        let t = &desc.transforms[s.transform as usize];
        let name = command_name(&s.kind);
        let shape = match s.kind {
            ShapeKind::Sphere { center, radius } => {
                let m = t.m * DAffine3::from_translation(center) * DAffine3::from_scale(DVec3::splat(radius));
                let Some(m) = single_precision(m, s.loc, name, diags) else {
                    continue;
                };
                Shape::Sphere(Box::new(Sphere::new(m)))
            }
            ShapeKind::Plane { .. }
            | ShapeKind::Box { .. }
            | ShapeKind::Cylinder { .. }
            | ShapeKind::Disk { .. }
            | ShapeKind::Cone { .. }
            | ShapeKind::Quadric { .. } => {
                let Some(m) = single_precision(t.m, s.loc, name, diags) else {
                    continue;
                };
                Shape::Analytic(Box::new(Analytic::new(m, analytic_kind(&s.kind))))
            }
            ShapeKind::Triangle { v } => {
                let p = v.map(|i| to_f32(t.point(desc.vertices[i as usize])));
                Shape::Triangle { p, normals: None }
            }
            ShapeKind::TriNormal { v } => {
                let p = v.map(|i| to_f32(t.point(desc.vertex_normals[i as usize].0)));
                let n = v.map(|i| to_f32(t.normal(desc.vertex_normals[i as usize].1).normalize()));
                out.vertex_normals.push(n);
                Shape::Triangle {
                    p,
                    normals: Some(out.vertex_normals.len() as u32 - 1),
                }
            }
            ShapeKind::Surface { index } => {
                let surface = &desc.surfaces[index as usize];
                let Some(mesh) = surface_mesh(desc, s, surface, materials, view, res, diags) else {
                    continue;
                };
                Shape::Mesh(MeshShape::new(mesh, view.accel))
            }
            ShapeKind::Instance { object } => {
                let Some((geometry, bounds)) = &objects[object as usize] else {
                    continue; // an empty object (objectend warned)
                };
                let Some(m) = single_precision(t.m, s.loc, name, diags) else {
                    continue;
                };
                Shape::Instance(Box::new(Instance::new(geometry.clone(), *bounds, m)))
            }
        };
        if let Shape::Triangle { p, normals } = &shape {
            let n = (p[1] - p[0]).cross(p[2] - p[0]);
            if !(n.length_squared() > 0.0) || !n.is_finite() {
                diags.warning(s.loc, "degenerate triangle (zero area) skipped");
                if normals.is_some() {
                    out.vertex_normals.pop();
                }
                continue;
            }
        }
        out.primitives.push(Primitive::new(shape, s.material));
    }
    out
}

/// The transform `m` in single precision, which the shape inverts there: an error at the
/// shape's command if it is singular in double precision or becomes so when rounded.
fn single_precision(m: DAffine3, loc: Loc, name: &str, diags: &mut Diagnostics) -> Option<Affine3A> {
    let single = Transform::new(m).map(|_| Transform::to_f32(&m));
    let invertible = single.is_some_and(|f| {
        let det = f.matrix3.determinant();
        det.is_finite() && det != 0.0 && f.inverse().is_finite()
    });
    if !invertible {
        diags.error(
            loc,
            format!("{name}: the current transform is singular (in single precision)"),
        );
        return None;
    }
    single
}

/// The command that made a shape of this kind (for messages).
fn command_name(kind: &ShapeKind) -> &'static str {
    match kind {
        ShapeKind::Sphere { .. } => "sphere",
        ShapeKind::Triangle { .. } => "tri",
        ShapeKind::TriNormal { .. } => "trinormal",
        ShapeKind::Plane { .. } => "plane",
        ShapeKind::Box { .. } => "box",
        ShapeKind::Cylinder { .. } => "cylinder",
        ShapeKind::Disk { .. } => "disk",
        ShapeKind::Cone { .. } => "cone",
        ShapeKind::Quadric { .. } => "quadric",
        ShapeKind::Surface { .. } => "surface",
        ShapeKind::Instance { .. } => "instance",
    }
}

/// The core's object-space description of an analytic shape (rounded to f32 once).
fn analytic_kind(kind: &ShapeKind) -> AnalyticKind {
    let v = to_f32;
    let f = |x: f64| x as f32;
    match *kind {
        ShapeKind::Plane { point, normal } => AnalyticKind::Plane {
            point: v(point),
            normal: v(normal),
        },
        ShapeKind::Box { lo, hi } => AnalyticKind::Cuboid(Aabb::new(v(lo), v(hi))),
        ShapeKind::Cylinder { radius, zmin, zmax } => AnalyticKind::Cylinder {
            radius: f(radius),
            zmin: f(zmin),
            zmax: f(zmax),
        },
        ShapeKind::Disk { radius } => AnalyticKind::Disk { radius: f(radius) },
        ShapeKind::Cone { radius, height } => AnalyticKind::Cone {
            radius: f(radius),
            height: f(height),
        },
        ShapeKind::Quadric { coefficients, lo, hi } => AnalyticKind::Quadric {
            coefficients: coefficients.map(f),
            clip: Aabb::new(v(lo), v(hi)),
        },
        ShapeKind::Sphere { .. }
        | ShapeKind::Triangle { .. }
        | ShapeKind::TriNormal { .. }
        | ShapeKind::Surface { .. }
        | ShapeKind::Instance { .. } => unreachable!("not an analytic shape"),
    }
}
