//! Scene commands: `directional dx dy dz r g b`, `point px py pz r g b`,
//! `attenuation c0 c1 c2` (SCENE_FORMAT.md §3.5) and `quadLight a ab ac Le` (§3.7): a
//! one-sided parallelogram of radiance `Le`, sampled by `lightsamples` shadow rays
//! (stratified with `lightstratify on`).
//!
//! Every light can be sampled from a receiving point ([`Light::sample_li`]: a direction,
//! the radiance arriving along it and its solid-angle density, or a delta for point and
//! directional lights); a quad light also gives the density of a direction that a BSDF
//! sample found it along ([`QuadLight::pdf_li`]), for multiple importance sampling.
//!
//! The Monte Carlo integrators have two more lights: every emissive surface together
//! ([`emitters`]: `emission`, OBJ `Ke`) and the environment ([`environment`]: `envmap`).
//! [`SampledLight`] is any of them, as light sampling sees it.

pub mod emitters;
pub mod environment;
mod mapped_surface;

use crate::math::{Color, Vec3A};
use crate::shading::texture::EnvironmentMap;
use emitters::EmissiveSurfaces;
use environment::EnvironmentLight;

/// A light that next-event estimation draws from: a light of the scene's list, all
/// emissive surfaces, or the environment.
#[derive(Clone, Copy, Debug)]
pub enum SampledLight<'a> {
    Listed(&'a Light),
    Emitters(&'a EmissiveSurfaces),
    Environment(&'a EnvironmentLight, &'a EnvironmentMap),
}

impl SampledLight<'_> {
    pub fn is_delta(&self) -> bool {
        matches!(self, SampledLight::Listed(l) if l.is_delta())
    }

    /// Whether a sample needs `pick` (a choice among the light's pieces) besides its
    /// point `(u, v)`.
    pub fn has_pieces(&self) -> bool {
        matches!(self, SampledLight::Emitters(_))
    }

    /// A sample of the light seen from `x` (see [`LightSample`]).
    #[inline]
    pub fn sample_li(&self, x: Vec3A, pick: f32, u: f32, v: f32) -> Option<LightSample> {
        match self {
            SampledLight::Listed(l) => l.sample_li(x, u, v),
            SampledLight::Emitters(e) => e.sample_li(x, pick, u, v),
            SampledLight::Environment(e, map) => e.sample_li(map, u, v),
        }
    }
}

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
    /// `None` for a degenerate parallelogram (zero area) and for one whose area (or
    /// an edge's cross product) is beyond `f32`.
    pub fn new(corner: Vec3A, ab: Vec3A, ac: Vec3A, radiance: Color) -> Option<QuadLight> {
        let n = ab.cross(ac);
        let (normal, area) = match n.length() {
            area if area > 0.0 && area.is_finite() => (n / area, area),
            _ => {
                // Scaled before squaring: a cross product of components beyond
                // 1.8·10¹⁹ is representable, but the sum of their squares is not.
                let scale = n.abs().max_element();
                if !(scale > 0.0 && scale.is_finite()) {
                    return None;
                }
                let unit = n / scale;
                (unit.normalize(), scale * unit.length())
            }
        };
        area.is_finite().then_some(QuadLight {
            corner,
            ab,
            ac,
            radiance,
            normal,
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

/// A light sample seen from a receiving point: the unit direction `wi` toward it, the
/// distance to the sampled point (infinite for directional lights), the radiance that
/// arrives along `wi` (a delta light's attenuated intensity) and the solid-angle density
/// of `wi` (1 for delta lights, which only one direction reaches).
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    pub wi: Vec3A,
    pub distance: f32,
    pub radiance: Color,
    pub pdf: f32,
    pub is_delta: bool,
}

impl QuadLight {
    /// A point drawn uniformly on the light by `(u, v)`, as seen from `x`: `None` when
    /// `x` sees the light's back or edge (it receives nothing from there).
    #[inline]
    pub fn sample_li(&self, x: Vec3A, u: f32, v: f32) -> Option<LightSample> {
        let to_light = self.point(u, v) - x;
        let r2 = to_light.length_squared();
        let distance = r2.sqrt();
        let wi = to_light / distance;
        // Density by area 1/A, in solid angle r² / (A cos θ_light) = r³ / (A n·(y − x)):
        // `n·(y − x)` is made beside the square root, not after the division by it (a
        // chain of square root, division, dot product and division before the density).
        let cos_times_distance = self.normal.dot(to_light);
        let pdf = r2 * distance / (self.area * cos_times_distance);
        (cos_times_distance > 0.0 && pdf.is_finite()).then_some(LightSample {
            wi,
            distance,
            radiance: self.radiance,
            pdf,
            is_delta: false,
        })
    }

    /// The solid-angle density with which [`QuadLight::sample_li`] draws the direction
    /// `wi` that meets the light at `distance` (0 from behind).
    #[inline]
    pub fn pdf_li(&self, distance: f32, wi: Vec3A) -> f32 {
        let cos_light = self.normal.dot(wi);
        if cos_light > 0.0 {
            distance * distance / (self.area * cos_light)
        } else {
            0.0
        }
    }

    /// Where the ray from `x` along `wi` meets the parallelogram (either side), if it does
    /// (the χ² test's density of a direction; rendering finds lights by tracing).
    #[cfg(test)]
    pub fn intersect(&self, x: Vec3A, wi: Vec3A) -> Option<f32> {
        let n = self.ab.cross(self.ac);
        let denom = n.dot(wi);
        if denom == 0.0 {
            return None;
        }
        let t = n.dot(self.corner - x) / denom;
        if !(t > 0.0) {
            return None;
        }
        let p = x + wi * t - self.corner;
        // Coordinates of p in (ab, ac): p × ac · n / |n|² and ab × p · n / |n|².
        let nn = n.length_squared();
        let u = p.cross(self.ac).dot(n) / nn;
        let v = self.ab.cross(p).dot(n) / nn;
        ((0.0..=1.0).contains(&u) && (0.0..=1.0).contains(&v)).then_some(t)
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
    /// Point and directional lights: light from a single direction, which no BSDF
    /// sample can find.
    pub fn is_delta(&self) -> bool {
        !matches!(self, Light::Quad(_))
    }

    /// A sample of the light seen from `x` (see [`LightSample`]); `(u, v)` picks the
    /// point of an area light. `None` when nothing arrives.
    #[inline]
    pub fn sample_li(&self, x: Vec3A, u: f32, v: f32) -> Option<LightSample> {
        match self {
            Light::Quad(q) => q.sample_li(x, u, v),
            _ => {
                let inc = self.incidence(x);
                (inc.distance > 0.0 && inc.dir.is_finite()).then_some(LightSample {
                    wi: inc.dir,
                    distance: inc.distance,
                    radiance: inc.intensity,
                    pdf: 1.0,
                    is_delta: true,
                })
            }
        }
    }

    /// The solid-angle density with which [`Light::sample_li`] draws `wi`, which meets
    /// the light at `distance`: 0 for delta lights, which no found direction is.
    #[inline]
    pub fn pdf_li(&self, distance: f32, wi: Vec3A) -> f32 {
        match self {
            Light::Quad(q) => q.pdf_li(distance, wi),
            _ => 0.0,
        }
    }

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
    use crate::sampling::chi2::chi2_test_edged;

    #[test]
    fn quad_lights_of_every_size_single_precision_holds_have_their_area() {
        let white = Color::ONE;
        for (edge, area) in [(1e-12f32, 1e-24f32), (1.0, 1.0), (2e18, 4e36), (1.8e19, 3.24e38)] {
            let q = QuadLight::new(Vec3A::ZERO, Vec3A::X * edge, Vec3A::Y * edge, white)
                .unwrap_or_else(|| panic!("edges of {edge}"));
            assert!((q.area / area - 1.0).abs() < 1e-6, "edges of {edge}: area {}", q.area);
            assert!(
                (q.normal - Vec3A::Z).length() < 1e-6,
                "edges of {edge}: normal {}",
                q.normal
            );
        }
        assert!(QuadLight::new(Vec3A::ZERO, Vec3A::X * 2e19, Vec3A::Y * 2e19, white).is_none());
        assert!(QuadLight::new(Vec3A::ZERO, Vec3A::X, Vec3A::X * 2.0, white).is_none());
    }

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

    #[test]
    fn quad_light_samples_follow_their_solid_angle_density() {
        // Lights seen head on, obliquely, large and near, sheared and to the side (the
        // bins are fixed, so a light must cover a good many of them).
        let x = Vec3A::new(0.1, -0.2, 0.05);
        let lights = [
            (Vec3A::new(-0.5, 1.0, -0.5), Vec3A::Z, Vec3A::X),
            (
                Vec3A::new(0.3, 0.4, -1.0),
                Vec3A::new(0.0, 0.3, 1.0),
                Vec3A::new(1.5, 0.2, 0.0),
            ),
            (Vec3A::new(-3.0, 0.5, -3.0), Vec3A::Z * 6.0, Vec3A::new(6.0, 1.0, 0.0)),
            (
                Vec3A::new(1.0, 1.5, 0.2),
                Vec3A::new(0.0, 0.0, 1.0),
                Vec3A::new(0.8, -0.2, 0.3),
            ),
        ];
        for (k, (a, ab, ac)) in lights.into_iter().enumerate() {
            let q = QuadLight::new(a, ab, ac, Color::ONE).unwrap();
            // Seen from the emitting side (swap ab and ac when x is behind).
            let q = if q.normal.dot(q.point(0.5, 0.5) - x) > 0.0 {
                q
            } else {
                QuadLight::new(a, ac, ab, Color::ONE).unwrap()
            };
            chi2_test_edged(
                &format!("quad light {k}"),
                |u, v| q.sample_li(x, u, v).map(|s| s.wi),
                |wi| q.intersect(x, wi).map_or(0.0, |t| q.pdf_li(t, wi)),
            );
            // The sample's own density is the one pdf_li gives its direction.
            for (u, v) in [(0.1, 0.2), (0.7, 0.9), (0.5, 0.5)] {
                let s = q.sample_li(x, u, v).unwrap();
                let p = q.pdf_li(s.distance, s.wi);
                assert!((s.pdf - p).abs() <= 1e-4 * p, "{} {}", s.pdf, p);
                let t = q.intersect(x, s.wi).unwrap();
                assert!((t - s.distance).abs() < 1e-4 * t);
            }
        }
    }
}
