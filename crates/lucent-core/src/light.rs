//! Scene commands: `directional dx dy dz r g b`, `point px py pz r g b` and
//! `attenuation c0 c1 c2` (SCENE_FORMAT.md §3.5).

use crate::math::{Color, Vec3A};

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    /// Light from infinitely far away; `direction` is the unit vector toward the light.
    /// Never attenuated.
    Directional { direction: Vec3A, color: Color },
    /// Received intensity `color / (c0 + c1 r + c2 r²)` at distance r.
    Point {
        position: Vec3A,
        color: Color,
        attenuation: Vec3A,
    },
}

/// What a light delivers to a point: the unit direction toward it, the distance to it
/// (infinite for directional lights) and the attenuated colour.
#[derive(Clone, Copy, Debug)]
pub struct Incidence {
    pub dir: Vec3A,
    pub distance: f32,
    pub intensity: Color,
}

impl Light {
    pub fn incidence(&self, x: Vec3A) -> Incidence {
        match *self {
            Light::Directional { direction, color } => Incidence {
                dir: direction,
                distance: f32::INFINITY,
                intensity: color,
            },
            Light::Point {
                position,
                color,
                attenuation,
            } => {
                let to_light = position - x;
                let r = to_light.length();
                let att = attenuation.x + attenuation.y * r + attenuation.z * r * r;
                Incidence {
                    dir: to_light / r,
                    distance: r,
                    intensity: color / att,
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn point_lights_attenuate_and_directional_lights_do_not() {
        let p = Light::Point {
            position: Vec3A::new(0.0, 2.0, 0.0),
            color: Color::ONE,
            attenuation: Vec3A::new(1.0, 0.5, 0.25),
        };
        let i = p.incidence(Vec3A::ZERO);
        assert_eq!(i.distance, 2.0);
        assert_eq!(i.dir, Vec3A::Y);
        assert!((i.intensity.x - 1.0 / 3.0).abs() < 1e-7);
        let d = Light::Directional {
            direction: Vec3A::Y,
            color: Color::ONE,
        };
        assert_eq!(d.incidence(Vec3A::splat(100.0)).intensity, Color::ONE);
    }
}
