//! Lights in world space: `directional` and `point` lights, and `quadLight`s, whose
//! parallelogram is also geometry — two triangles that cast shadows and that a ray sees
//! as the light itself. Those triangles name their light (a surface point on them knows
//! which light it is); they are appended after every other primitive.

use lucent_core::geometry::primitive::{Primitive, Shape};
use lucent_core::light::{Light, QuadLight};
use lucent_core::math::{Color, Vec3A};
use lucent_core::shading::material::Material;

use super::to_f32;
use crate::desc::{LightKind, SceneDesc};
use crate::diag::Diagnostics;

/// The scene's lights; the surfaces of quad lights are added to `primitives`, with one
/// material (black, reflecting nothing) added to `materials` for them.
pub fn lights(
    desc: &SceneDesc,
    primitives: &mut Vec<Primitive>,
    materials: &mut Vec<Material>,
    diags: &mut Diagnostics,
) -> Vec<Light> {
    let mut lights = Vec::new();
    let mut surface_material = None;
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
                    let why = if ab.cross(ac) == Vec3A::ZERO {
                        "has no area"
                    } else {
                        "is too large: its area, or its edges' products, beyond single precision (about 3.4e38)"
                    };
                    diags.error(l.loc, format!("quadLight: the transformed light {why}"));
                    continue;
                };
                lights.push(Light::Quad(q));
                let light = Some(lights.len() as u32 - 1);
                let material = *surface_material.get_or_insert_with(|| {
                    materials.push(Material {
                        ambient: Color::ZERO,
                        ..Material::default()
                    });
                    materials.len() as u32 - 1
                });
                let (b, c, d) = (a + ab, a + ab + ac, a + ac);
                for p in [[a, b, c], [a, c, d]] {
                    primitives.push(Primitive {
                        shape: Shape::Triangle { p, normals: None },
                        material,
                        light,
                    });
                }
            }
        }
    }
    lights
}
