//! Shadow rays from one point toward one light, traced together: the `lightsamples`
//! rays toward an area light in the ray tracer ([`super::whitted`]) and in direct
//! lighting over every light ([`super::light_sampling`]). They are coherent, so they
//! travel through the BVH in packets ([`Scene::occluded_rays`]); each unblocked
//! sample's light is added in sample order, so the sum is the one a ray at a time gives.

use super::TraceCounts;
use crate::math::{Color, Vec3A};
use crate::ray::Ray;
use crate::scene::Scene;

/// At most this many shadow rays wait before they are traced.
const BATCH: usize = 64;

pub struct ShadowBatch {
    rays: [Ray; BATCH],
    /// What each ray's sample adds when nothing blocks it.
    lit: [Color; BATCH],
    made: usize,
    sum: Color,
}

impl ShadowBatch {
    pub fn new() -> ShadowBatch {
        ShadowBatch {
            rays: [Ray::new(Vec3A::ZERO, Vec3A::Z); BATCH],
            lit: [Color::ZERO; BATCH],
            made: 0,
            sum: Color::ZERO,
        }
    }

    /// A sample whose shadow ray is `ray` and which adds `lit` unless it is blocked
    /// (the ray is counted).
    #[inline]
    pub fn add(&mut self, scene: &Scene, ray: Ray, lit: Color, counts: &mut TraceCounts) {
        counts.rays += 1;
        self.rays[self.made] = ray;
        self.lit[self.made] = lit;
        self.made += 1;
        if self.made == BATCH {
            self.trace(scene);
        }
    }

    /// The sum of the unblocked samples' light, in sample order.
    pub fn sum(mut self, scene: &Scene) -> Color {
        self.trace(scene);
        self.sum
    }

    fn trace(&mut self, scene: &Scene) {
        if self.made == 0 {
            return;
        }
        let mut blocked = [false; BATCH];
        scene.occluded_rays(&self.rays[..self.made], &mut blocked[..self.made]);
        for (&lit, &b) in self.lit[..self.made].iter().zip(&blocked) {
            if !b {
                self.sum += lit;
            }
        }
        self.made = 0;
    }
}

impl Default for ShadowBatch {
    fn default() -> ShadowBatch {
        ShadowBatch::new()
    }
}
