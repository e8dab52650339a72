//! Shapes placed by an affine transform: the sphere (and so the ellipsoid) and the
//! geometry extensions `plane`, `box`, `cylinder`, `disk`, `cone` and `quadric`. Rays go
//! into object space unnormalised, so `t` is the same in both spaces; normals come back
//! by the inverse transpose. The intersection routines themselves are in `crate::shape`.

use crate::aabb::Aabb;
use crate::math::{Affine3A, Mat3A, Vec3A};
use crate::shape::{cone, cuboid, cylinder, disk, plane, quadric, texcoord};
use glam::Vec2;

/// A sphere or ellipsoid: the unit sphere mapped by an affine object-to-world transform.
#[derive(Clone, Copy, Debug)]
pub struct Sphere {
    pub world_to_object: Affine3A,
    /// Carries the hit point, projected onto the unit sphere, back to world space.
    pub object_to_world: Affine3A,
    /// Inverse transpose of the object-to-world linear part: carries normals to world.
    pub normal_to_world: Mat3A,
    pub bounds: Aabb,
}

impl Sphere {
    /// `object_to_world` maps the unit sphere at the origin onto the sphere.
    pub fn new(object_to_world: Affine3A) -> Sphere {
        let world_to_object = object_to_world.inverse();
        // Exact bounds of an affinely mapped unit sphere: along world axis i the half
        // extent is the length of row i of the linear part.
        let m = object_to_world.matrix3;
        let rows = m.transpose();
        let half = Vec3A::new(rows.x_axis.length(), rows.y_axis.length(), rows.z_axis.length());
        let c = object_to_world.translation;
        Sphere {
            world_to_object,
            object_to_world,
            normal_to_world: world_to_object.matrix3.transpose(),
            bounds: Aabb::new(c - half, c + half),
        }
    }
}

/// A shape of the geometry extensions in its object space (see `crate::shape`).
#[derive(Clone, Copy, Debug)]
pub enum AnalyticKind {
    /// The plane through `point` with normal `normal`: unbounded, so it is kept out of
    /// the acceleration structures and tested on its own.
    Plane {
        point: Vec3A,
        normal: Vec3A,
    },
    Cuboid(Aabb),
    Cylinder {
        radius: f32,
        zmin: f32,
        zmax: f32,
    },
    Disk {
        radius: f32,
    },
    Cone {
        radius: f32,
        height: f32,
    },
    Quadric {
        coefficients: quadric::Coefficients,
        clip: Aabb,
    },
}

impl AnalyticKind {
    /// Bounds in object space; `None` for the unbounded plane.
    pub(super) fn object_bounds(&self) -> Option<Aabb> {
        let z = |lo: f32, hi: f32, r: f32| Aabb::new(Vec3A::new(-r, -r, lo), Vec3A::new(r, r, hi));
        match *self {
            AnalyticKind::Plane { .. } => None,
            AnalyticKind::Cuboid(b) => Some(b),
            AnalyticKind::Cylinder { radius, zmin, zmax } => Some(z(zmin, zmax, radius)),
            AnalyticKind::Disk { radius } => Some(z(0.0, 0.0, radius)),
            AnalyticKind::Cone { radius, height } => Some(z(0.0, height, radius)),
            AnalyticKind::Quadric { clip, .. } => Some(clip),
        }
    }

    pub(super) fn intersect(&self, o: Vec3A, d: Vec3A, t_min: f32, t_max: f32) -> Option<f32> {
        match self {
            AnalyticKind::Plane { point, normal } => plane::intersect_plane(o, d, *point, *normal, t_min, t_max),
            AnalyticKind::Cuboid(b) => cuboid::intersect(b, o, d, t_min, t_max),
            AnalyticKind::Cylinder { radius, zmin, zmax } => {
                cylinder::intersect(*radius, *zmin, *zmax, o, d, t_min, t_max)
            }
            AnalyticKind::Disk { radius } => disk::intersect(*radius, o, d, t_min, t_max),
            AnalyticKind::Cone { radius, height } => cone::intersect(*radius, *height, o, d, t_min, t_max),
            AnalyticKind::Quadric { coefficients, clip } => quadric::intersect(coefficients, clip, o, d, t_min, t_max),
        }
    }

    /// Texture coordinates at an object-space surface point with object normal `n`.
    pub(super) fn uv(&self, p: Vec3A, n: Vec3A) -> Vec2 {
        match self {
            AnalyticKind::Plane { point, normal } => texcoord::plane(*point, *normal, p),
            AnalyticKind::Cuboid(b) => texcoord::cuboid(b, n, p),
            AnalyticKind::Cylinder { zmin, zmax, .. } => texcoord::cylinder(p, *zmin, *zmax),
            AnalyticKind::Disk { radius } => texcoord::disk(p, *radius),
            AnalyticKind::Cone { height, .. } => texcoord::cone(p, *height),
            AnalyticKind::Quadric { clip, .. } => texcoord::quadric(clip, p),
        }
    }

    /// Object-space normal (not normalised) at a surface point.
    pub(super) fn normal(&self, p: Vec3A) -> Vec3A {
        match self {
            AnalyticKind::Plane { normal, .. } => *normal,
            AnalyticKind::Cuboid(b) => cuboid::normal(b, p),
            AnalyticKind::Cylinder { .. } => cylinder::normal(p),
            AnalyticKind::Disk { .. } => Vec3A::Z,
            AnalyticKind::Cone { radius, height } => cone::normal(*radius, *height, p),
            AnalyticKind::Quadric { coefficients, .. } => quadric::normal(coefficients, p),
        }
    }
}

/// An analytic shape placed by an affine object-to-world transform. Rays go into object
/// space unnormalised, so `t` is the same in both spaces; normals come back by the
/// inverse transpose.
#[derive(Clone, Copy, Debug)]
pub struct Analytic {
    pub world_to_object: Affine3A,
    pub normal_to_world: Mat3A,
    /// World bounds; infinite for the plane.
    pub bounds: Aabb,
    pub kind: AnalyticKind,
}

impl Analytic {
    pub fn new(object_to_world: Affine3A, kind: AnalyticKind) -> Analytic {
        let world_to_object = object_to_world.inverse();
        let bounds = match kind.object_bounds() {
            Some(b) => b.transformed(&object_to_world),
            None => Aabb {
                min: Vec3A::NEG_INFINITY,
                max: Vec3A::INFINITY,
            },
        };
        Analytic {
            world_to_object,
            normal_to_world: world_to_object.matrix3.transpose(),
            bounds,
            kind,
        }
    }
}
