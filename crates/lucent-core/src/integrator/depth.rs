//! Adaptive depth control (the classic ray tracer's "fewer rays"): a branch of a ray tree
//! is not traced once what it could still add to the pixel is invisible.
//!
//! A branch of weight `w` (the product of the mirror and transmission colours on its
//! way) adds `w · I` to the pixel, where `I` is the radiance the branch's ray brings
//! back: the local terms of its hit plus, weighted again, those of the branches after it.
//! With `R` the largest local radiance of the scene and `ρ < 1` the largest factor a
//! bounce multiplies a weight by, `|I| ≤ R (1 + ρ + ρ² + …) = R / (1 − ρ)`, so leaving
//! the branch out changes the pixel by at most its *cost* `max|w| · R / (1 − ρ)`.
//!
//! Each camera sample has an **error budget** `τ`: branches are left out only while the
//! sum of their costs stays within it, so the whole sample — and so the pixel, their
//! mean — moves by at most `τ` in every channel. Where the scene draws random numbers
//! after the camera ray (quad-light samples, glossy directions), only branches after
//! which nothing else is traced may go: a branch left out earlier would not draw its
//! numbers, and every branch after it would get others. `τ` is what the 8-bit encoding cannot
//! show: a change of at most 2⁻¹² after `gamma`, a sixteenth of one step (1/255), which
//! moves a truncated value by one step at most and only when it lies within 2⁻¹² below a
//! step. For `gamma g ≥ 1` the encoding `c^(1/g)` is steepest at black, so `τ = 2^(−12 g)`;
//! for `g < 1` it is steepest at white, with slope `1/g`, so `τ = g · 2⁻¹²`. A float image
//! moves by less than `τ ≤ 2⁻¹²`, invisible on any display.
//!
//! `ρ` is a mirror's `|specular|`; for glass, whose branches share what the Fresnel
//! reflectance `F` splits, the larger of `|specular|` and `|specular|·F_min +
//! |transparent|·(1 − F_min)` (F_min: the interface's least reflectance over all angles) —
//! below 1 for clear glass of any index but 1. `R` counts, for every material, `|ambient|
//! + |emission|` plus each light's greatest delivered colour times `|diffuse| ·
//! (brightest texel) + |specular|`, and the radiance of quad lights and the environment
//! seen directly. Two lights deliver without bound near them, and `R` takes them where
//! scenes have their surfaces: a point light whose attenuation falls with distance at a
//! hundredth of the scene's size, a quad light as filling a hemisphere (its samples'
//! mean; one sample close to the light can exceed it). When some material reflects or
//! transmits everything (`ρ ≥ 1`) no branch is ever left out and `maxdepth` alone ends
//! the tree.

use crate::light::Light;
use crate::math::Color;
use crate::scene::Scene;
use crate::shading::material::Material;
use crate::shading::optics::fresnel_dielectric;
use crate::shading::texture::Texture;

/// What a sample may lose to left-out branches in a linear 8-bit encoding: 2⁻¹².
pub const INVISIBLE: f32 = 1.0 / 4096.0;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DepthControl {
    /// `R`: the largest radiance one shading point of the scene can show.
    pub radiance: f32,
    /// `ρ`: the largest factor one bounce multiplies a branch's weight by.
    pub reflectance: f32,
    /// `τ`: what a camera sample may lose to left-out branches.
    pub budget: f32,
    /// Only the last branches of a sample may be left out: the scene draws random numbers
    /// after the camera ray (quad-light samples, glossy directions), and a left-out branch
    /// would take its numbers away from every branch after it, changing them by more than
    /// the budget.
    pub tails_only: bool,
    /// `R / (1 − ρ)`, infinite when `ρ ≥ 1` (or the scene's radiance is unbounded).
    bound: f32,
}

impl DepthControl {
    /// The control for `scene` whose image is encoded with `gamma`.
    pub fn for_scene(scene: &Scene, gamma: f32) -> DepthControl {
        let radiance = scene_radiance(scene);
        let reflectance = largest_bounce_factor(&scene.materials);
        let draws = scene.lights.iter().any(|l| matches!(l, Light::Quad(_)))
            || scene.materials.iter().any(|m| m.glossy.is_some());
        DepthControl {
            tails_only: draws,
            ..DepthControl::new(radiance, reflectance, gamma)
        }
    }

    pub fn new(radiance: f32, reflectance: f32, gamma: f32) -> DepthControl {
        let bound = if reflectance < 1.0 {
            radiance / (1.0 - reflectance)
        } else {
            f32::INFINITY
        };
        let budget = if gamma >= 1.0 {
            INVISIBLE.powf(gamma)
        } else if gamma > 0.0 {
            INVISIBLE * gamma
        } else {
            0.0
        };
        DepthControl {
            radiance,
            reflectance,
            budget,
            tails_only: false,
            bound: if bound.is_nan() { f32::INFINITY } else { bound },
        }
    }

    /// No branch is ever left out (for tests, and scenes built without the control).
    pub fn off() -> DepthControl {
        DepthControl::new(f32::INFINITY, 1.0, 1.0)
    }

    /// What leaving out a branch of weight `w` can change in a channel, at most (infinite
    /// for a weight that is not a number).
    #[inline(always)]
    pub fn cost(&self, w: Color) -> f32 {
        if !w.is_finite() {
            return f32::INFINITY;
        }
        w.abs().max_element() * self.bound
    }

    /// The depth after which a single chain of branches is left out (the weight after
    /// `d` bounces is at most `ρ^d`), if there is one.
    pub fn depth_limit(&self) -> Option<u32> {
        if !self.bound.is_finite() {
            return None;
        }
        if self.bound <= self.budget || self.reflectance == 0.0 {
            return Some(0);
        }
        let d = ((self.budget / self.bound).ln() / self.reflectance.ln()).ceil();
        Some(d.clamp(0.0, u32::MAX as f32) as u32)
    }
}

/// `ρ`: the largest factor a bounce off any of `materials` multiplies a weight by (see
/// [`bounce_factor`]); infinite where a material's factor is not a number.
pub fn largest_bounce_factor(materials: &[Material]) -> f32 {
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
    materials
        .iter()
        .map(|m| bounce_factor(m, &mut min_fresnel_of))
        .map(|f| if f.is_nan() { f32::INFINITY } else { f })
        .fold(0.0f32, f32::max)
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
/// from either side, a little less to cover rounding. It is at normal incidence for
/// common glass; for very high (or low) indices it is lower, near Brewster's angle
/// `atan(n)` or `atan(1/n)`, which then comes close to grazing or to normal incidence:
/// angles are searched on a coarse grid, and on geometric grids around both Brewster
/// angles and their complements (as fine near 0 and π/2 as those angles are).
fn min_fresnel(ior: f32) -> f32 {
    // Up to an index of 3.7 (down to 1/3.7) the least is head on (checked to 3.733):
    // every transparent material of this world but a few crystals, at no search.
    if (1.0 / 3.7..=3.7).contains(&ior) {
        return 0.99 * fresnel_dielectric(1.0, 1.0, ior);
    }
    let half_pi = std::f32::consts::FRAC_PI_2;
    let f = |theta: f32| {
        let c = theta.clamp(0.0, half_pi).cos();
        fresnel_dielectric(c, 1.0, ior).min(fresnel_dielectric(c, ior, 1.0))
    };
    let coarse = (0..=1024).map(|k| k as f32 / 1024.0 * half_pi);
    let near_brewster = [ior.atan(), (1.0 / ior).atan()]
        .into_iter()
        .flat_map(|b| [b, half_pi - b])
        .flat_map(|base| (0..=512).map(move |k| base * 0.5 * 4f32.powf(k as f32 / 512.0)))
        .flat_map(|t| [t, half_pi - t]);
    let least = coarse.chain(near_brewster).map(f).fold(1.0f32, f32::min);
    0.99 * least
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
        // Mirrors of 0.9 under radiance 1: the tail after d bounces costs 0.9^d · 10,
        // which falls below 2⁻¹² after 101 bounces.
        let c = DepthControl::new(1.0, 0.9, 1.0);
        assert_eq!(c.budget, INVISIBLE);
        assert_eq!(c.depth_limit(), Some(101));
        assert!(c.cost(Color::splat(0.9f32.powi(100))) > c.budget);
        assert!(c.cost(Color::splat(0.9f32.powi(101))) <= c.budget);
        // With gamma 2.2 the budget is what the encoding cannot show near black.
        let g = DepthControl::new(1.0, 0.9, 2.2);
        assert!((g.budget - INVISIBLE.powf(2.2)).abs() < 1e-12 && g.depth_limit() > Some(190));
        assert_eq!(DepthControl::new(1.0, 0.9, 0.5).budget, INVISIBLE * 0.5);
        // A perfect mirror never dies out; nothing bright is always negligible.
        assert_eq!(DepthControl::new(1.0, 1.0, 1.0).depth_limit(), None);
        assert_eq!(
            DepthControl::new(1.0, 1.0, 1.0).cost(Color::splat(1e-30)),
            f32::INFINITY
        );
        assert_eq!(DepthControl::new(0.0, 0.5, 1.0).depth_limit(), Some(0));
        assert_eq!(DepthControl::new(f32::NAN, 0.5, 1.0).depth_limit(), None);
        assert_eq!(DepthControl::off().depth_limit(), None);
        // A weight that is not a number is never left out.
        assert_eq!(c.cost(Color::new(f32::NAN, 0.0, 0.0)), f32::INFINITY);
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
        // Near Brewster's angle a very dense medium reflects less than head on; the
        // search finds it even for an index of 10⁴, where the angle is near grazing.
        assert!(min_fresnel(10.0) < 0.99 * fresnel_dielectric(1.0, 1.0, 10.0));
        for ior in [1.2f32, 2.4, 3.7, 1.0 / 3.7, 10.0, 1e3, 1e4, 1e-3] {
            let exact = (0..200_000)
                .map(|k| (k as f32 / 200_000.0 * std::f32::consts::FRAC_PI_2).cos())
                .map(|c| fresnel_dielectric(c, 1.0, ior).min(fresnel_dielectric(c, ior, 1.0)))
                .fold(1.0f32, f32::min);
            assert!(min_fresnel(ior) <= exact, "ior {ior}: {} > {exact}", min_fresnel(ior));
        }
    }
}
