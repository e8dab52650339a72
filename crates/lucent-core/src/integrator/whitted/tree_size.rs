//! How many rays one camera sample's ray tree may trace: the cap, and a bound that
//! `lucent check`, the warning about absurd work and the fuzzers rely on.
//!
//! Glass splits every ray it meets into a reflected and a refracted branch, so a tree
//! can double with each bounce: a glass sphere in a mirror box with `maxdepth 5000` can
//! ask for up to 2⁵⁰⁰⁰ rays. Adaptive depth control ([`crate::integrator::depth`]) prunes such trees
//! only while a bounce loses weight; a material that reflects more than it receives
//! (`specular 0 0 30`) never lets it. So a camera sample traces at most
//! [`MAX_TREE_RAYS`] rays of its tree (shadow rays come on top, a bounded number at each
//! hit); branches past that are not traced and are counted, like those cut by
//! [`super::MAX_PENDING`], and the render warns about them.
//!
//! The bound: with `G` the most glossy rays a material fans out into at the first hit
//! (1 without glossy materials), level 1 of the tree holds at most `G + 1` rays (`G`
//! without glass); every later ray makes at most two (glass) or one (anything else). A
//! single chain (no glass, no glossy fan) also ends where adaptive depth control leaves
//! its next bounce out ([`crate::integrator::depth::DepthControl::depth_limit`]).
//! Where no bounce gains weight (`ρ ≤ 1`, [`largest_bounce_factor`]), each
//! channel's weights at one level sum to at most 1, and glass keeps a branch only when a
//! channel's weight exceeds `MIN_WEIGHT` (2⁻¹¹): so at most `3 · 2048 − 1` rays of a
//! level come from glass, and a level holds at most 6,143 rays more than the one before.

use super::{Whitted, MIN_WEIGHT};
use crate::integrator::depth::largest_bounce_factor;
use crate::math::Color;
use crate::shading::material::Material;

/// The rays (not counting shadow rays) one camera sample's tree traces at most: under a
/// second of one core's work (0.3 s in the fuzzer's scene); glass that gains no weight may reach it only past 29
/// bounces. No scene of the course or of this project comes near.
pub const MAX_TREE_RAYS: u32 = 1 << 20;

impl Whitted {
    /// The most rays of one camera sample's tree, shadow rays left out (at most
    /// [`Whitted::max_tree_rays`]; see the module's documentation).
    pub fn tree_rays_bound(&self, materials: &[Material]) -> f64 {
        let cap = self.max_tree_rays as f64;
        let reflects = materials
            .iter()
            .any(|m| m.specular != Color::ZERO || m.transparent != Color::ZERO);
        if !reflects || self.max_depth == 0 {
            return 1.0f64.min(cap);
        }
        let fan = materials
            .iter()
            .filter(|m| m.specular != Color::ZERO)
            .filter_map(|m| m.glossy)
            .map(|g| g.samples.max(1))
            .max()
            .unwrap_or(1) as f64;
        let glass = materials.iter().any(|m| m.transparent != Color::ZERO);
        let depth = self.max_depth as f64;
        if !glass {
            // One chain for each of the first hit's rays. A single chain ends where adaptive
            // depth control leaves its next bounce out: nothing else spends the budget.
            let depth = match self.depth.depth_limit() {
                Some(limit) if fan == 1.0 => depth.min(limit as f64),
                _ => depth,
            };
            return (1.0 + fan * depth).min(cap);
        }
        // Each level's weights sum to at most 1 in every channel: glass keeps fewer than
        // this many branches of a level.
        let heavy = if largest_bounce_factor(materials) <= 1.0 {
            (3.0 / MIN_WEIGHT as f64).ceil() - 1.0
        } else {
            f64::INFINITY
        };
        let mut level = fan + 1.0;
        let mut total = 1.0 + level;
        let mut d = 1;
        // The total grows by at least 1 a level, by `heavy` once the levels are that
        // wide: the cap is reached within a few hundred levels.
        while d < self.max_depth && total < cap {
            level += level.min(heavy);
            total += level;
            d += 1;
        }
        total.min(cap)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrator::depth::DepthControl;
    use crate::shading::material::Glossy;

    fn whitted(max_depth: u32) -> Whitted {
        Whitted {
            max_depth,
            light_samples: 1,
            light_stratify: false,
            depth: DepthControl::off(),
            max_tree_rays: MAX_TREE_RAYS,
        }
    }

    #[test]
    fn the_bound_counts_chains_fans_and_doublings() {
        let mirror = Material {
            specular: Color::splat(0.5),
            ..Material::default()
        };
        let glossy = Material {
            glossy: Some(Glossy {
                exponent: 10.0,
                samples: 16,
            }),
            ..mirror
        };
        let glass = Material {
            transparent: Color::ONE,
            ior: 1.5,
            ..mirror
        };
        // Matte scenes trace the camera ray alone.
        assert_eq!(whitted(5).tree_rays_bound(&[Material::default()]), 1.0);
        // A mirror chain of five bounces; sixteen of them after a glossy first hit.
        assert_eq!(whitted(5).tree_rays_bound(&[mirror]), 6.0);
        assert_eq!(whitted(5).tree_rays_bound(&[glossy]), 81.0);
        // Glass doubles each level: 1 + 2 + 4 + 8 + 16 + 32.
        assert_eq!(whitted(5).tree_rays_bound(&[glass]), 63.0);
        // With a glossy fan: 1 + 17 + 34 + 68 + 136 + 272.
        let both = [glossy, glass];
        assert_eq!(whitted(5).tree_rays_bound(&both), 528.0);
        // Where no bounce gains weight, a level past 6,143 rays grows by at most 6,143:
        // 2^d rays up to level 13 (8,192), then 8,192 + 6,143 (d − 13).
        let lossless = |depth: u32| whitted(depth).tree_rays_bound(&[glass]);
        let levels = |depth: u32| -> f64 {
            (0..=depth)
                .map(|d| {
                    if d <= 13 {
                        (1u64 << d) as f64
                    } else {
                        8192.0 + 6143.0 * (d - 13) as f64
                    }
                })
                .sum()
        };
        assert_eq!(lossless(25), levels(25));
        assert_eq!(lossless(29), levels(29));
        assert!(levels(29) < MAX_TREE_RAYS as f64 && levels(30) > MAX_TREE_RAYS as f64);
        assert_eq!(lossless(30), MAX_TREE_RAYS as f64);
        // A material that gains weight doubles up to the cap; so does a deep lossless tree.
        let gaining = Material {
            specular: Color::new(0.0, 0.0, 30.0),
            ..glass
        };
        assert_eq!(whitted(25).tree_rays_bound(&[gaining]), MAX_TREE_RAYS as f64);
        assert_eq!(whitted(5001).tree_rays_bound(&[glass]), MAX_TREE_RAYS as f64);
        // A perfect mirror's chain goes to the cap, however deep; a mirror of 0.9 ends
        // where adaptive depth control leaves it out (101 bounces under radiance 1).
        assert_eq!(whitted(1 << 30).tree_rays_bound(&[mirror]), MAX_TREE_RAYS as f64);
        let controlled = Whitted {
            depth: DepthControl::new(1.0, 0.9, 1.0),
            ..whitted(1 << 30)
        };
        assert_eq!(controlled.tree_rays_bound(&[mirror]), 102.0);
    }
}
