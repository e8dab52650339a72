//! The build step: a [`SceneDesc`] becomes a renderable [`Scene`] — world-space
//! triangles, spheres as transformed unit spheres, lights, materials, the camera and the
//! acceleration structure. This is the only module that knows both the description and
//! the core. It reports what the description cannot be rendered as (unsupported
//! features, degenerate geometry) at the location of the command responsible.

use std::sync::Arc;

use glam::{DAffine3, DVec3, Vec3};
use lucent_core::aabb::Aabb;
use lucent_core::accel::AccelKind;
use lucent_core::camera::{Camera, Projection};
use lucent_core::geometry::analytic::{Analytic, AnalyticKind, Sphere};
use lucent_core::geometry::instance::Instance;
use lucent_core::geometry::mesh::{MeshShape, TriangleMesh};
use lucent_core::geometry::primitive::{Primitive, Shape};
use lucent_core::geometry::Geometry;
use lucent_core::integrator::whitted::Whitted;
use lucent_core::integrator::Integrator;
use lucent_core::light::{Light, QuadLight};
use lucent_core::math::{Color, Vec3A};
use lucent_core::scene::{Scene, SceneParts};
use lucent_core::shading::material::Material;
use lucent_core::tessellate::grid::grid_mesh;
use lucent_core::transform::Transform;

use crate::desc::*;
use crate::diag::Diagnostics;

/// `maxdepth -1` (unbounded) is capped here: a closed mirror box would never end.
pub const UNBOUNDED_DEPTH_CAP: u32 = 100;

#[derive(Clone, Copy, Debug)]
pub struct BuildOptions {
    pub accel: AccelKind,
}

impl Default for BuildOptions {
    fn default() -> Self {
        BuildOptions { accel: AccelKind::Bvh }
    }
}

pub struct Built {
    pub scene: Scene,
    pub integrator: Box<dyn Integrator>,
    /// Output encoding exponent (`gamma`, 1 = none).
    pub gamma: f32,
}

/// Builds the scene, or returns `None` after adding errors to `diags`.
pub fn build(desc: &SceneDesc, options: &BuildOptions, diags: &mut Diagnostics) -> Option<Built> {
    check_settings(desc, diags);
    let (Some(size), Some(cam)) = (&desc.size, &desc.camera) else {
        return None; // the parser has reported it
    };
    let (width, height) = size.value;
    let c = cam.value;
    let mut camera = Camera::new(c.eye, c.center, c.up, c.projection, width, height).ok()?;
    if let Some(lens) = &desc.lens {
        let (aperture, focus) = lens.value;
        if matches!(c.projection, Projection::Orthographic { .. }) {
            diags.error(
                lens.loc,
                "lens: depth of field needs the perspective camera (this scene uses orthocamera)",
            );
        } else {
            camera = camera.with_lens(aperture, focus);
        }
    }

    let max_depth = match desc.max_depth() {
        -1 => {
            let loc = desc.max_depth.as_ref().map(|d| d.loc).unwrap_or(desc.end);
            diags.warning(
                loc,
                format!("maxdepth: -1 (unbounded) is capped at {UNBOUNDED_DEPTH_CAP} bounces"),
            );
            UNBOUNDED_DEPTH_CAP
        }
        d => d as u32,
    };

    let view = View {
        camera: c,
        height,
        accel: options.accel,
    };
    // Objects first: instances in the scene refer to them.
    let objects: Vec<Option<(Arc<Geometry>, Aabb)>> = (0..desc.objects.len() as u32)
        .map(|o| {
            let (prims, normals) = build_primitives(desc, Some(o), &[], &view, diags);
            if prims.is_empty() {
                return None;
            }
            let bounds = prims.iter().fold(Aabb::EMPTY, |b, p| b.union(&p.bounds()));
            Some((Arc::new(Geometry::new(prims, normals, options.accel)), bounds))
        })
        .collect();
    let (primitives, vertex_normals) = build_primitives(desc, None, &objects, &view, diags);

    let mut materials: Vec<Material> = desc.materials.iter().map(|m| m.base).collect();
    let mut primitives = primitives;
    let mut lights = Vec::new();
    for l in &desc.lights {
        let t = &desc.transforms[l.transform as usize];
        match l.kind {
            LightKind::Directional { dir, color } => lights.push(Light::Directional {
                direction: to_f32(t.vector(dir).normalize()),
                color: to_f32(color),
            }),
            LightKind::Point {
                position,
                color,
                attenuation,
            } => lights.push(Light::Point {
                position: to_f32(t.point(position)),
                color: to_f32(color),
                attenuation: to_f32(attenuation),
            }),
            LightKind::Quad { a, ab, ac, color } => {
                let (a, ab, ac) = (to_f32(t.point(a)), to_f32(t.vector(ab)), to_f32(t.vector(ac)));
                let Some(q) = QuadLight::new(a, ab, ac, to_f32(color)) else {
                    diags.error(l.loc, "quadLight: the transformed light has no area");
                    continue;
                };
                lights.push(Light::Quad(q));
                // The light is geometry too: seen from its emitting side it shows its
                // radiance, and it casts shadows like anything else.
                materials.push(Material {
                    ambient: Color::ZERO,
                    emission: q.radiance,
                    is_light: true,
                    ..Material::default()
                });
                let material = materials.len() as u32 - 1;
                let (b, c, d) = (a + ab, a + ab + ac, a + ac);
                for p in [[a, b, c], [a, c, d]] {
                    primitives.push(Primitive {
                        shape: Shape::Triangle { p, normals: None },
                        material,
                    });
                }
            }
        }
    }

    if diags.has_errors() {
        return None;
    }
    let parts = SceneParts {
        width,
        height,
        camera,
        primitives,
        materials,
        lights,
        vertex_normals,
        samples_per_pixel: desc.spp.as_ref().map_or(1, |s| s.value),
        textures: desc.textures.iter().map(|t| t.texture.clone()).collect(),
        environment: desc.environment.as_ref().map(|e| e.value.clone()),
    };
    Some(Built {
        scene: Scene::new(parts, options.accel),
        integrator: Box::new(Whitted {
            max_depth,
            light_samples: desc.light_samples.as_ref().map_or(1, |s| s.value),
            light_stratify: desc.light_stratify.as_ref().is_some_and(|s| s.value),
        }),
        gamma: desc.gamma() as f32,
    })
}

/// What tessellation and mesh structures need to know about the render.
struct View {
    camera: CameraDesc,
    height: u32,
    accel: AccelKind,
}

/// The primitives of the scene (`object` `None`) or of one object, with the vertex
/// normals their `trinormal` triangles index.
fn build_primitives(
    desc: &SceneDesc,
    object: Option<u32>,
    objects: &[Option<(Arc<Geometry>, Aabb)>],
    view: &View,
    diags: &mut Diagnostics,
) -> (Vec<Primitive>, Vec<[Vec3A; 3]>) {
    let mut primitives = Vec::new();
    let mut vertex_normals = Vec::new();
    for s in desc.shapes.iter().filter(|s| s.object == object) {
        let t = &desc.transforms[s.transform as usize];
        let shape = match s.kind {
            ShapeKind::Sphere { center, radius } => {
                let m = t.m * DAffine3::from_translation(center) * DAffine3::from_scale(DVec3::splat(radius));
                Shape::Sphere(Sphere::new(Transform::to_f32(&m)))
            }
            ShapeKind::Plane { .. }
            | ShapeKind::Box { .. }
            | ShapeKind::Cylinder { .. }
            | ShapeKind::Disk { .. }
            | ShapeKind::Cone { .. }
            | ShapeKind::Quadric { .. } => {
                Shape::Analytic(Box::new(Analytic::new(Transform::to_f32(&t.m), analytic_kind(&s.kind))))
            }
            ShapeKind::Triangle { v } => {
                let p = v.map(|i| to_f32(t.point(desc.vertices[i as usize])));
                Shape::Triangle { p, normals: None }
            }
            ShapeKind::TriNormal { v } => {
                let p = v.map(|i| to_f32(t.point(desc.vertex_normals[i as usize].0)));
                let n = v.map(|i| to_f32(t.normal(desc.vertex_normals[i as usize].1).normalize()));
                vertex_normals.push(n);
                Shape::Triangle {
                    p,
                    normals: Some(vertex_normals.len() as u32 - 1),
                }
            }
            ShapeKind::Mesh { index } => {
                let mesh = world_mesh(&desc.meshes[index as usize], t, s.material);
                if mesh.indices.is_empty() {
                    continue;
                }
                Shape::Mesh(MeshShape::new(mesh, view.accel))
            }
            ShapeKind::Nurbs { index, displacement } => {
                let mut mesh = nurbs_mesh(&desc.nurbs[index as usize], t, view);
                if let Some((texture, scale)) = displacement {
                    let tex = &desc.textures[texture as usize].texture;
                    match lucent_core::tessellate::displacement::displace(
                        &mesh,
                        &lucent_core::shading::texture::Displacement { texture: tex, scale },
                    ) {
                        Ok(m) => mesh = m,
                        Err(e) => {
                            diags.error(s.loc, format!("nurbs: displacementmap: {e}"));
                            continue;
                        }
                    }
                    mesh.remove_degenerate();
                }
                mesh.material = s.material;
                if mesh.indices.is_empty() {
                    continue;
                }
                Shape::Mesh(MeshShape::new(mesh, view.accel))
            }
            ShapeKind::Instance { object } => match &objects[object as usize] {
                Some((geometry, bounds)) => Shape::Instance(Box::new(Instance::new(
                    geometry.clone(),
                    *bounds,
                    Transform::to_f32(&t.m),
                ))),
                None => continue, // an empty object (objectend warned)
            },
        };
        if let Shape::Triangle { p, normals } = &shape {
            let n = (p[1] - p[0]).cross(p[2] - p[0]);
            if !(n.length_squared() > 0.0) || !n.is_finite() {
                diags.warning(s.loc, "degenerate triangle (zero area) skipped");
                if normals.is_some() {
                    vertex_normals.pop();
                }
                continue;
            }
        }
        primitives.push(Primitive {
            shape,
            material: s.material,
        });
    }
    (primitives, vertex_normals)
}

/// A mesh of the description moved to world space by `t`, with `material` where its
/// triangles have none of their own. Triangles that rounding collapses are dropped.
fn world_mesh(mesh: &TriangleMesh, t: &Transform, material: u32) -> TriangleMesh {
    let mut out = TriangleMesh {
        positions: mesh.positions.iter().map(|p| t.point(p.as_dvec3()).as_vec3()).collect(),
        normals: mesh
            .normals
            .iter()
            .map(|n| t.normal(n.as_dvec3()).normalize_or_zero().as_vec3())
            .collect(),
        uvs: mesh.uvs.clone(),
        indices: mesh.indices.clone(),
        materials: mesh.materials.clone(),
        material,
    };
    out.remove_degenerate();
    out
}

/// Global settings this version cannot honour are errors; settings that only other
/// integrators read are warnings.
fn check_settings(desc: &SceneDesc, diags: &mut Diagnostics) {
    if let Some(i) = &desc.integrator {
        if i.value != IntegratorKind::RayTracer {
            diags.error(
                i.loc,
                format!(
                    "integrator: '{}' is not implemented yet (this version renders 'raytracer')",
                    i.value.name()
                ),
            );
            return;
        }
    }
    let only_for = |name: &str, loc, diags: &mut Diagnostics| {
        diags.warning(loc, format!("{name}: has no effect with integrator raytracer"));
    };
    if let Some(v) = &desc.next_event_estimation {
        only_for("nexteventestimation", v.loc, diags);
    }
    if let Some(v) = &desc.russian_roulette {
        only_for("russianroulette", v.loc, diags);
    }
    if let Some(v) = &desc.importance_sampling {
        only_for("importancesampling", v.loc, diags);
    }
    if let Some(s) = desc
        .shapes
        .iter()
        .find(|s| desc.materials[s.material as usize].brdf == Brdf::Ggx)
    {
        diags.warning(
            s.loc,
            "brdf ggx has no effect with integrator raytracer (it shades with Blinn-Phong)",
        );
    }
}

fn to_f32(v: DVec3) -> Vec3A {
    Vec3A::new(v.x as f32, v.y as f32, v.z as f32)
}

/// The core's object-space description of an analytic shape (rounded to f32 once).
fn analytic_kind(kind: &ShapeKind) -> AnalyticKind {
    let v = |d: DVec3| to_f32(d);
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
        | ShapeKind::Mesh { .. }
        | ShapeKind::Instance { .. }
        | ShapeKind::Nurbs { .. } => {
            unreachable!("not an analytic shape")
        }
    }
}

/// Tessellates a NURBS surface finely enough that no chord strays more than a quarter of
/// a pixel from the surface where it is nearest to the camera, with normals from the
/// exact derivatives, in world space.
fn nurbs_mesh(surface: &lucent_core::tessellate::nurbs::NurbsSurface, t: &Transform, view: &View) -> TriangleMesh {
    let camera = &view.camera;
    // With positive weights the surface lies in the hull of its control points.
    let corners: Vec<DVec3> = surface.points.iter().map(|p| t.point(p.truncate() / p.w)).collect();
    let (lo, hi) = corners
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        });
    let nearest = (camera.eye.clamp(lo, hi) - camera.eye)
        .length()
        .max(1e-3 * (hi - lo).length());
    let view_height = match camera.projection {
        Projection::Perspective { fovy } => 2.0 * nearest * (fovy.to_radians() / 2.0).tan(),
        Projection::Orthographic { height } => height,
    };
    let pixel = view_height / view.height as f64;
    // Object-space tolerance: divide by the largest stretch of the transform.
    let m = t.m.matrix3;
    let stretch = m
        .x_axis
        .length()
        .max(m.y_axis.length())
        .max(m.z_axis.length())
        .max(1e-300);
    let (nu, nv) = surface.segments_for(0.25 * pixel / stretch);
    // A bound on the triangles one surface may cost (half a million).
    let (nu, nv) = (nu.min(512), nv.min(512));
    let grid: Vec<(Vec3, Vec3)> = surface
        .tessellate(nu, nv)
        .into_iter()
        .map(|(p, n)| (t.point(p).as_vec3(), t.normal(n).as_vec3()))
        .collect();
    grid_mesh(&grid, nu, nv)
}
