//! Shadow rays from one point toward one light, traced together: the `lightsamples`
//! rays toward an area light in the ray tracer ([`super::whitted`]) and in direct
//! lighting over every light ([`super::light_sampling`]). They are coherent, so they
//! travel through the BVH in packets ([`Scene::occluded_rays`]); each unblocked
//! sample's light is added in sample order, so the sum is the one a ray at a time gives.

use std::mem::MaybeUninit;

use super::TraceCounts;
use crate::math::Color;
use crate::ray::Ray;
use crate::scene::Scene;

/// At most this many shadow rays wait before they are traced.
const BATCH: usize = 64;

pub struct ShadowBatch {
    /// The first `made` are written. Left uninitialised until then: a batch is made for
    /// every shading point and light, and filling (then moving) its 4 KB cost more than
    /// the few rays most batches hold.
    rays: [MaybeUninit<Ray>; BATCH],
    /// What each ray's sample adds when nothing blocks it (the first `made` are written).
    lit: [MaybeUninit<Color>; BATCH],
    made: usize,
    sum: Color,
}

impl ShadowBatch {
    pub fn new() -> ShadowBatch {
        ShadowBatch {
            rays: [const { MaybeUninit::uninit() }; BATCH],
            lit: [const { MaybeUninit::uninit() }; BATCH],
            made: 0,
            sum: Color::ZERO,
        }
    }

    /// A sample whose shadow ray is `ray` and which adds `lit` unless it is blocked
    /// (the ray is counted).
    #[inline]
    pub fn add(&mut self, scene: &Scene, ray: Ray, lit: Color, counts: &mut TraceCounts) {
        counts.rays += 1;
        self.rays[self.made].write(ray);
        self.lit[self.made].write(lit);
        self.made += 1;
        if self.made == BATCH {
            self.trace(scene);
        }
    }

    /// The sum of the unblocked samples' light, in sample order.
    pub fn sum(&mut self, scene: &Scene) -> Color {
        self.trace(scene);
        self.sum
    }

    fn trace(&mut self, scene: &Scene) {
        if self.made == 0 {
            return;
        }
        // SAFETY: entries `..made` were written by `add` (MaybeUninit<T> has T's layout).
        let (rays, lit) = unsafe {
            (
                std::slice::from_raw_parts(self.rays.as_ptr().cast::<Ray>(), self.made),
                std::slice::from_raw_parts(self.lit.as_ptr().cast::<Color>(), self.made),
            )
        };
        let mut blocked = [false; BATCH];
        scene.occluded_rays(rays, &mut blocked[..self.made]);
        for (&lit, &b) in lit.iter().zip(&blocked) {
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
