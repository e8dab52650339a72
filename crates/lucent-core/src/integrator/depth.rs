//! Adaptive depth control (the classic ray tracer's "fewer rays"): a branch of a ray tree
//! is not traced once what it could still add to the pixel is invisible.
//!
//! A branch of weight `w` (the product of the mirror and transmission colours on its
//! way) adds `w · I` to the pixel, where `I` is the radiance the branch's ray brings
//! back: the local terms of its hit plus, weighted again, those of the branches after it.
//! With `R` the largest local radiance of the scene and `ρ < 1` the largest factor a
//! bounce multiplies a weight by, `|I| ≤ R (1 + ρ + ρ² + …) = R / (1 − ρ)`. A branch is
//! dropped when `max|w| · R / (1 − ρ) < 2⁻¹²`:
//!
//! - in an 8-bit image a channel moves by at most 2⁻¹² — a sixteenth of one step
//!   (1/255) — so a pixel changes by one step at most, and only if its value lies within
//!   2⁻¹² below a step boundary;
//! - in a float image the value moves by less than 2⁻¹² — about 2⁻¹⁴ of a stop at a
//!   value of 1 — below what any display of it can show.
//!
//! `ρ` is a mirror's `|specular|`; for glass, whose branches share what the Fresnel
//! reflectance `F` splits, the larger of `|specular|` and `|specular|·F_min +
//! |transparent|·(1 − F_min)` (F_min: the interface's least reflectance over all
//! angles) — below 1 for clear glass of any index but 1. `R` counts, for every material, `|ambient| + |emission|` plus each light's greatest
//! delivered colour times `|diffuse| · (brightest texel) + |specular|` (a point light at
//! a hundredth of the scene's size, a quad light filling a hemisphere), and the radiance
//! of quad lights and the environment seen directly. When some material reflects or
//! transmits everything (`ρ ≥ 1`) no branch is ever negligible and `maxdepth` alone ends
//! the tree.

use crate::light::Light;
use crate::math::Color;
use crate::scene::Scene;
use crate::shading::material::Material;
use crate::shading::optics::fresnel_dielectric;
use crate::shading::texture::Texture;

/// What a branch may add, at most, and still not be traced.
pub const INVISIBLE: f32 = 1.0 / 4096.0;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DepthControl {
    /// `R`: the largest radiance one shading point of the scene can show.
    pub radiance: f32,
    /// `ρ`: the largest factor one bounce multiplies a branch's weight by.
    pub reflectance: f32,
    /// `R / (1 − ρ)`, infinite when `ρ ≥ 1` (or the scene's radiance is unbounded).
    bound: f32,
}

impl DepthControl {
    pub fn for_scene(scene: &Scene) -> DepthControl {
        let radiance = scene_radiance(scene);
        // Materials share a handful of indices of refraction: each is weighed once.
        let mut fresnel: Vec<(f32, f32)> = Vec::new();
        let mut min_fresnel_of = |ior: f32| match fresnel.iter().find(|(n, _)| *n == ior) {
            Some(&(_, f)) => f,
            None => {
                let f = min_fresnel(ior);
                fresnel.push((ior, f));
                f
            }
        };
        let reflectance = scene
            .materials
            .iter()
            .map(|m| bounce_factor(m, &mut min_fresnel_of))
            .fold(0.0f32, f32::max);
        DepthControl::new(radiance, reflectance)
    }

    pub fn new(radiance: f32, reflectance: f32) -> DepthControl {
        let bound = if reflectance < 1.0 {
            radiance / (1.0 - reflectance)
        } else {
            f32::INFINITY
        };
        DepthControl {
            radiance,
            reflectance,
            bound: if bound.is_nan() { f32::INFINITY } else { bound },
        }
    }

    /// Whether a branch of weight `w` can add nothing visible.
    #[inline(always)]
    pub fn negligible(&self, w: Color) -> bool {
        w.abs().max_element() * self.bound < INVISIBLE
    }

    /// The depth after which every branch is negligible (the weight after `d` bounces is
    /// at most `ρ^d`), if there is one.
    pub fn depth_limit(&self) -> Option<u32> {
        if !self.bound.is_finite() {
            return None;
        }
        if self.bound < INVISIBLE || self.reflectance == 0.0 {
            return Some(0);
        }
        let d = ((INVISIBLE / self.bound).ln() / self.reflectance.ln()).ceil();
        Some(d.clamp(0.0, u32::MAX as f32) as u32)
    }
}

/// The largest factor a bounce off material `m` multiplies a weight by, summed over the
/// branches it makes: `|S|` for a mirror; for glass, the reflected `|S|·F` plus the
/// refracted `|Kt|·(1 − F)`, largest at one end of the Fresnel reflectance's range
/// `[F_min, 1]`.
fn bounce_factor(m: &Material, min_fresnel: &mut impl FnMut(f32) -> f32) -> f32 {
    let s = m.specular.abs();
    if m.transparent == Color::ZERO {
        return s.max_element();
    }
    let f = min_fresnel(m.ior);
    s.max(s * f + m.transparent.abs() * (1.0 - f)).max_element()
}

/// The smallest reflectance of a dielectric interface of index `ior` over every angle,
/// from either side (at normal incidence for common glass; lower, near Brewster's angle,
/// for very high indices), a little less to cover rounding.
fn min_fresnel(ior: f32) -> f32 {
    let steps = 1024;
    let f = (0..=steps)
        .map(|k| (k as f32 / steps as f32 * std::f32::consts::FRAC_PI_2).cos())
        .flat_map(|c| [fresnel_dielectric(c, 1.0, ior), fresnel_dielectric(c, ior, 1.0)])
        .fold(1.0f32, f32::min);
    0.99 * f
}

/// `R`: the largest local radiance of the scene (see the module's documentation).
fn scene_radiance(scene: &Scene) -> f32 {
    let texel_max: Vec<f32> = scene.textures.iter().map(brightest).collect();
    let near = 0.01 * scene_size(scene);
    let lights: f32 = scene.lights.iter().map(|l| light_bound(l, near)).sum();
    let mut radiance = scene
        .materials
        .iter()
        .map(|m| {
            let texture = m.diffuse_map.map_or(1.0, |t| texel_max[t as usize]);
            let lit = m.diffuse.abs() * texture + m.specular.abs();
            (m.ambient.abs() + m.emission.abs() + lit * lights).max_element()
        })
        .fold(0.0f32, f32::max);
    for l in &scene.lights {
        if let Light::Quad(q) = l {
            radiance = radiance.max(q.radiance.abs().max_element());
        }
    }
    if let Some(env) = &scene.environment {
        radiance = radiance.max(env.image.max_channel() * env.intensity.abs());
    }
    radiance
}

/// The greatest colour (any channel) a light delivers to a point at least `near` away.
fn light_bound(light: &Light, near: f32) -> f32 {
    match *light {
        Light::Directional { color, .. } => color.abs().max_element(),
        Light::Point { color, attenuation, .. } => {
            let a = attenuation;
            let att = a.x + a.y * near + a.z * near * near;
            if att > 0.0 {
                color.abs().max_element() / att
            } else {
                f32::INFINITY
            }
        }
        // The solid angle a light can fill seen from one side is at most a hemisphere.
        Light::Quad(q) => q.radiance.abs().max_element() * std::f32::consts::TAU,
    }
}

/// The largest channel value a texture takes.
fn brightest(t: &Texture) -> f32 {
    match t {
        Texture::Image(img) => img.max_channel(),
        Texture::Checker { a, b, .. } => a.abs().max(b.abs()).max_element(),
    }
}

/// The diagonal of the box around the scene's bounded primitives (1 without any).
fn scene_size(scene: &Scene) -> f32 {
    let b = scene
        .geometry
        .primitives
        .iter()
        .map(|p| p.bounds())
        .filter(crate::accel::is_bounded)
        .fold(crate::aabb::Aabb::EMPTY, |a, b| a.union(&b));
    let d = (b.max - b.min).length();
    if d.is_finite() && d > 0.0 {
        d
    } else {
        1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_mirror_chain_stops_where_its_weight_cannot_show() {
        // Mirrors of 0.9 under radiance 1: the tail after d bounces is 0.9^d · 10, which
        // falls below 2⁻¹² after 101 bounces.
        let c = DepthControl::new(1.0, 0.9);
        assert_eq!(c.depth_limit(), Some(101));
        assert!(!c.negligible(Color::splat(0.9f32.powi(100))));
        assert!(c.negligible(Color::splat(0.9f32.powi(101))));
        // A perfect mirror never dies out; nothing bright is always negligible.
        assert_eq!(DepthControl::new(1.0, 1.0).depth_limit(), None);
        assert!(!DepthControl::new(1.0, 1.0).negligible(Color::splat(1e-30)));
        assert_eq!(DepthControl::new(0.0, 0.5).depth_limit(), Some(0));
        assert_eq!(DepthControl::new(f32::NAN, 0.5).depth_limit(), None);
    }

    #[test]
    fn clear_glass_passes_on_less_than_everything() {
        // Glass of index 1.5 reflects at least 4 % at every angle: a bounce keeps at most
        // 96 % of the weight. Index 1 keeps everything.
        let glass = |ior: f32| Material {
            transparent: Color::ONE,
            ior,
            ..Material::default()
        };
        let f = bounce_factor(&glass(1.5), &mut min_fresnel);
        assert!((0.96..0.961).contains(&f), "{f}");
        assert_eq!(bounce_factor(&glass(1.0), &mut min_fresnel), 1.0);
        // Near Brewster's angle a very dense medium reflects less than head on.
        assert!(min_fresnel(10.0) < 0.99 * fresnel_dielectric(1.0, 1.0, 10.0));
    }
}
