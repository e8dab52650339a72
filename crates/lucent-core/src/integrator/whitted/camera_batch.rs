//! The ray tracer over a batch of camera samples whose camera rays were traced together
//! ([`crate::integrator::Integrator::radiances`]): the first hits' shadow rays toward
//! point and directional lights are traced together too, in packets — they start close
//! together and end at one point, nearly as coherent as the camera rays. Each sample's
//! ray tree is otherwise walked as [`Whitted::radiance`] walks it, its colour summed in
//! the same order from the same numbers, so every sample's colour is the same bits.
//!
//! (The mirror rays that leave the first hits were traced in packets too, once: on
//! scene7's dragon they are not coherent enough, and took as long as one at a time.)

use std::cell::RefCell;

use super::light_terms::Deferred;
use super::{Tracing, Whitted};
use crate::hit::{Hit, SurfacePoint, BACKGROUND};
use crate::integrator::{CameraHit, Integrator, TraceCounts};
use crate::math::Color;
use crate::ray::Ray;
use crate::sampler::Sampler;
use crate::scene::Scene;

/// A sample shaded at its first hit, waiting for the shadow rays' answers.
struct Shaded {
    sample: usize,
    sp: SurfacePoint,
    /// The first of the hit's terms, and where its other terms are in the batch's.
    first: Color,
    terms: std::ops::Range<usize>,
    /// Adaptive depth control's spending so far.
    dropped: f32,
}

/// A batch's lists, kept from batch to batch by each thread (a batch is 64 samples:
/// allocating them anew took 1.4 % of scene7's instructions).
#[derive(Default)]
struct Scratch {
    deferred: Deferred,
    shaded: Vec<Shaded>,
}

thread_local! {
    static SCRATCH: RefCell<Scratch> = RefCell::default();
}

impl Whitted {
    /// [`Integrator::radiances`]: `out[k]` is [`Integrator::radiance`] of `rays[k]`.
    pub(super) fn batch(
        &self,
        scene: &Scene,
        rays: &[Ray],
        hits: &[Option<Hit>],
        samplers: &mut [Sampler],
        counts: &mut TraceCounts,
        out: &mut [Color],
    ) {
        SCRATCH.with_borrow_mut(|scratch| {
            let Scratch { deferred, shaded } = scratch;
            deferred.clear();
            shaded.clear();
            for (k, (ray, hit)) in rays.iter().zip(hits).enumerate() {
                let mut t = Tracing {
                    scene,
                    camera: CameraHit::Untraced,
                    sampler: &mut samplers[k],
                    counts,
                    dropped: 0.0,
                    traced: 0,
                };
                // Samples that meet nothing, or whose tree is left out at once, go alone.
                let hit = match hit {
                    Some(hit) if !self.leave_out(&mut t, Color::ONE, &[]) => hit,
                    _ => {
                        out[k] = self.radiance(scene, ray, CameraHit::Traced(*hit), &mut samplers[k], counts);
                        continue;
                    }
                };
                t.counts.rays += 1;
                t.traced += 1;
                let before = deferred.len();
                let sp = self.shade(&mut t, ray, hit, deferred);
                shaded.push(Shaded {
                    sample: k,
                    sp,
                    first: deferred.first,
                    terms: before..deferred.len(),
                    dropped: t.dropped,
                });
            }
            deferred.trace(scene);

            // Each first hit's colour, then the rest of its tree, as `radiance` walks it.
            for s in shaded.drain(..) {
                let k = s.sample;
                let mut t = Tracing {
                    scene,
                    camera: CameraHit::Untraced,
                    sampler: &mut samplers[k],
                    counts,
                    dropped: s.dropped,
                    traced: 1,
                };
                let mut total = BACKGROUND;
                total += Color::ONE * deferred.sum(s.first, s.terms);
                let mut pending = Vec::new();
                if let Some((ray, depth, weight)) = self.next(&mut t, &rays[k], &s.sp, 0, Color::ONE, &mut pending) {
                    self.follow(&mut t, ray, depth, weight, &mut total, &mut pending);
                }
                self.finish_tree(&mut t, &mut total, &mut pending);
                out[k] = total;
            }
        });
    }
}
