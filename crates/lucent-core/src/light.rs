//! Scene commands: `directional dx dy dz r g b`, `point px py pz r g b`,
//! `attenuation c0 c1 c2` (SCENE_FORMAT.md §3.5) and `quadLight a ab ac Le` (§3.7): a
//! one-sided parallelogram of radiance `Le`, sampled by `lightsamples` shadow rays
//! (stratified with `lightstratify on`).

use crate::math::{Color, Vec3A};

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    /// Light from infinitely far away; `direction` is the unit vector toward the light.
    /// Never attenuated.
    Directional {
        direction: Vec3A,
        color: Color,
    },
    /// Received intensity `color / (c0 + c1 r + c2 r²)` at distance r.
    Point {
        position: Vec3A,
        color: Color,
        attenuation: Vec3A,
    },
    Quad(QuadLight),
}

/// The parallelogram with corners `a, a+ab, a+ab+ac, a+ac`, emitting radiance `radiance`
/// toward the side `ac × ab` points to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QuadLight {
    pub corner: Vec3A,
    pub ab: Vec3A,
    pub ac: Vec3A,
    pub radiance: Color,
    /// `normalize(ab × ac)`: a receiver sees the emitting face when the direction from it
    /// to the light has a positive component along this.
    pub normal: Vec3A,
    pub area: f32,
}

impl QuadLight {
    /// `None` for a degenerate parallelogram (zero area).
    pub fn new(corner: Vec3A, ab: Vec3A, ac: Vec3A, radiance: Color) -> Option<QuadLight> {
        let n = ab.cross(ac);
        let area = n.length();
        (area > 0.0 && area.is_finite()).then(|| QuadLight {
            corner,
            ab,
            ac,
            radiance,
            normal: n / area,
            area,
        })
    }

    /// The point at `(u, v)` of the unit square mapped onto the light.
    pub fn point(&self, u: f32, v: f32) -> Vec3A {
        self.corner + self.ab * u + self.ac * v
    }

    /// What the light point `y` delivers to `x`: the direction and distance to it, and
    /// `Le · A · cos θ_light / r²` — the radiance times the solid angle the whole light
    /// would have if it looked like this point from `x` (a sample's share is this divided
    /// by the number of samples). Zero from behind the light.
    pub fn incidence(&self, x: Vec3A, y: Vec3A) -> Incidence {
        let to_light = y - x;
        let r2 = to_light.length_squared();
        let r = r2.sqrt();
        let dir = to_light / r;
        let cos_light = self.normal.dot(dir).max(0.0);
        Incidence {
            dir,
            distance: r,
            intensity: self.radiance * (self.area * cos_light / r2),
        }
    }
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
    /// The radiance a ray travelling along `dir` sees where it meets the light's surface
    /// with normal `normal`: a quad light's radiance on its emitting side, black from
    /// behind (and nothing for lights that have no surface).
    pub fn radiance_seen(&self, dir: Vec3A, normal: Vec3A) -> Color {
        match self {
            Light::Quad(q) if dir.dot(normal) > 0.0 => q.radiance,
            _ => Color::ZERO,
        }
    }

    /// What a point or directional light delivers to `x` (area lights are sampled
    /// point by point: [`QuadLight::incidence`]).
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
            Light::Quad(q) => q.incidence(x, q.point(0.5, 0.5)),
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

    #[test]
    fn quad_lights_weigh_samples_by_solid_angle_and_shine_one_way() {
        // A 0.1 × 0.1 light facing down (ac × ab = −y), 2 above the receiver.
        let q = QuadLight::new(
            Vec3A::new(-0.05, 2.0, -0.05),
            Vec3A::Z * 0.1,
            Vec3A::X * 0.1,
            Color::ONE,
        )
        .unwrap();
        assert_eq!(q.normal, Vec3A::Y);
        let i = q.incidence(Vec3A::ZERO, q.point(0.5, 0.5));
        // Solid angle of a small light straight above: A / r².
        assert!((i.intensity.x - 0.01 / 4.0).abs() < 1e-7, "{}", i.intensity);
        assert!((i.dir - Vec3A::Y).length() < 1e-6);
        // From above the light, nothing.
        let above = q.incidence(Vec3A::new(0.0, 4.0, 0.0), q.point(0.5, 0.5));
        assert_eq!(above.intensity, Color::ZERO);
        assert!(QuadLight::new(Vec3A::ZERO, Vec3A::X, Vec3A::X * 2.0, Color::ONE).is_none());
    }
}
