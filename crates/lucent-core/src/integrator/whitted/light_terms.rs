//! Where a shading point's local terms go: summed at once, each point or directional
//! light's shadow ray traced as it comes ([`Immediate`]), or kept with the shadow rays
//! untraced, so that the shadow rays of many camera hits travel together in packets
//! ([`Deferred`], [`super::camera_batch`]). Either way the colour is the same sum, in
//! the same order.

use crate::math::Color;
use crate::ray::Ray;
use crate::scene::Scene;

/// What [`super::Whitted::shade`] finds at a hit, in order: the first term (ambient
/// plus emission, or a light's own radiance), then one term per light.
pub trait LightTerms {
    /// The first term.
    fn start(&mut self, c: Color);
    /// A term added whatever the shadows (an area light's shadowed sum).
    fn add(&mut self, c: Color);
    /// A term added unless `shadow` is blocked.
    fn add_unless_blocked(&mut self, shadow: Ray, c: Color);
}

/// The terms summed as they come.
pub struct Immediate<'a> {
    pub scene: &'a Scene,
    pub color: Color,
}

impl LightTerms for Immediate<'_> {
    fn start(&mut self, c: Color) {
        self.color = c;
    }

    fn add(&mut self, c: Color) {
        self.color += c;
    }

    fn add_unless_blocked(&mut self, shadow: Ray, c: Color) {
        if !self.scene.occluded(&shadow) {
            self.color += c;
        }
    }
}

/// No shadow ray: the term is always added.
const ALWAYS: u32 = u32::MAX;

/// The terms of several hits, kept with their shadow rays until those are traced
/// together ([`Deferred::trace`]); each hit's colour is then [`Deferred::sum`] of its
/// range of terms.
#[derive(Default)]
pub struct Deferred {
    /// The first term of the hit being shaded.
    pub first: Color,
    /// Each term and the index of its shadow ray in `rays` (or [`ALWAYS`]).
    terms: Vec<(Color, u32)>,
    rays: Vec<Ray>,
    /// Which of its hit's shadow rays each ray is (0 for the first): rays of the same
    /// rank go toward the same light as a rule, so they are traced side by side.
    rank: Vec<u32>,
    /// The rank the next shadow ray of the hit being shaded gets.
    next_rank: u32,
    blocked: Vec<bool>,
}

impl Deferred {
    /// Forgets every term and ray (keeping the storage).
    pub fn clear(&mut self) {
        self.terms.clear();
        self.rays.clear();
        self.rank.clear();
    }

    /// How many terms are kept: a hit's terms are those between the counts before and
    /// after its shading.
    pub fn len(&self) -> usize {
        self.terms.len()
    }

    /// Traces every shadow ray kept, those toward one light side by side.
    pub fn trace(&mut self, scene: &Scene) {
        let n = self.rays.len();
        self.blocked.clear();
        self.blocked.resize(n, false);
        if self.rank.iter().all(|&r| r == 0) {
            // One ray per hit at most: they are in order already.
            scene.occluded_rays(&self.rays, &mut self.blocked);
            return;
        }
        let mut order: Vec<u32> = (0..n as u32).collect();
        order.sort_by_key(|&i| self.rank[i as usize]);
        let rays: Vec<Ray> = order.iter().map(|&i| self.rays[i as usize]).collect();
        let mut blocked = vec![false; n];
        scene.occluded_rays(&rays, &mut blocked);
        for (&i, &b) in order.iter().zip(&blocked) {
            self.blocked[i as usize] = b;
        }
    }

    /// The colour of a hit whose first term is `first` and whose terms are
    /// `terms` (after [`Deferred::trace`]): the sum [`Immediate`] makes.
    pub fn sum(&self, first: Color, terms: std::ops::Range<usize>) -> Color {
        let mut color = first;
        for &(c, ray) in &self.terms[terms] {
            if ray == ALWAYS || !self.blocked[ray as usize] {
                color += c;
            }
        }
        color
    }
}

impl LightTerms for Deferred {
    fn start(&mut self, c: Color) {
        self.first = c;
        self.next_rank = 0;
    }

    fn add(&mut self, c: Color) {
        self.terms.push((c, ALWAYS));
    }

    fn add_unless_blocked(&mut self, shadow: Ray, c: Color) {
        self.terms.push((c, self.rays.len() as u32));
        self.rays.push(shadow);
        self.rank.push(self.next_rank);
        self.next_rank += 1;
    }
}
