//! The film: per pixel, the sum of its samples' radiance and their count. Sums, not
//! averages, so that a render can take more samples later and two renders of disjoint
//! pixels or sample ranges can be merged; [`Film::resolve`] divides them into the
//! [`Image`] that is written.
//!
//! The sums are exact ([`ExactSum`]): adding samples in another grouping — the first 64
//! here and the next 64 on another machine, merged — gives the very same bits as adding
//! them one after the other, which floating-point sums would not. A film may also carry
//! the sums of the auxiliary passes ([`aov`]).

pub mod aov;
pub mod exact;
pub mod noise;

use crate::image::Image;
use crate::math::Color;
pub use aov::{AovImages, AovSample, AovSum};
pub use exact::ExactSum;
pub use noise::PixelNoise;

#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    pub width: u32,
    pub height: u32,
    /// Row-major, top row first.
    pub sums: Vec<ExactSum>,
    pub counts: Vec<u32>,
    /// The sums of the auxiliary passes, when the render computes them.
    pub aovs: Option<Vec<AovSum>>,
    /// Adaptive sampling's estimate of every pixel, when the render samples adaptively.
    pub noise: Option<Vec<PixelNoise>>,
}

impl Film {
    /// A film without auxiliary passes.
    pub fn new(width: u32, height: u32) -> Film {
        Film::with_aovs(width, height, false)
    }

    /// A film that also keeps the auxiliary passes when `aovs` is set.
    pub fn with_aovs(width: u32, height: u32, aovs: bool) -> Film {
        let n = width as usize * height as usize;
        Film {
            width,
            height,
            sums: crate::huge_pages::vec_filled(n, ExactSum::default()),
            counts: vec![0; n],
            aovs: aovs.then(|| crate::huge_pages::vec_filled(n, AovSum::default())),
            noise: None,
        }
    }

    /// No samples any more (the same pixels, and auxiliary passes if it kept them): the
    /// film of a finished pass made ready for the next in the memory it already has.
    pub fn clear(&mut self) {
        self.sums.fill(ExactSum::default());
        self.counts.fill(0);
        if let Some(aovs) = &mut self.aovs {
            aovs.fill(AovSum::default());
        }
        self.noise = None;
    }

    /// Adds a pixel's `count` samples, whose radiance sums to `sum` (and whose auxiliary
    /// passes sum to `aov`, kept if the film keeps them).
    #[inline]
    pub fn add(&mut self, index: usize, sum: &ExactSum, count: u32, aov: &AovSum) {
        self.sums[index].add(sum);
        self.counts[index] += count;
        if let Some(aovs) = &mut self.aovs {
            aovs[index].add(aov);
        }
    }

    /// Adds another film of the same pixels (the samples after this one's). Its
    /// adaptive-sampling estimates continued this film's, so they replace them.
    ///
    /// # Panics
    /// If the films differ in size.
    pub fn add_film(&mut self, other: &Film) {
        assert_eq!(
            (self.width, self.height),
            (other.width, other.height),
            "films of other pixels"
        );
        for (i, (sum, &n)) in other.sums.iter().zip(&other.counts).enumerate() {
            self.sums[i].add(sum);
            self.counts[i] += n;
        }
        if let (Some(mine), Some(theirs)) = (&mut self.aovs, &other.aovs) {
            mine.iter_mut().zip(theirs).for_each(|(a, b)| a.add(b));
        }
        if other.noise.is_some() {
            self.noise.clone_from(&other.noise);
        }
    }

    /// The mean of every pixel's samples (black where there are none).
    pub fn resolve(&self) -> Image {
        let pixels = self
            .sums
            .iter()
            .zip(&self.counts)
            .map(|(s, &n)| match n {
                0 => Color::ZERO,
                n => (s.value() / n as f64).as_vec3().into(),
            })
            .collect();
        Image {
            width: self.width,
            height: self.height,
            pixels,
        }
    }

    /// The auxiliary passes averaged, if the film keeps them.
    pub fn resolve_aovs(&self) -> Option<AovImages> {
        let sums = self.aovs.as_ref()?;
        Some(AovImages::resolve(self.width, self.height, sums, &self.counts))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sum_of(samples: &[Color]) -> ExactSum {
        let mut s = ExactSum::default();
        samples.iter().for_each(|&c| s.add_sample(c));
        s
    }

    #[test]
    fn sums_resolve_to_means() {
        let mut f = Film::new(2, 1);
        let none = AovSum::default();
        f.add(0, &sum_of(&[Color::new(1.0, 2.0, 3.0)]), 1, &none);
        f.add(
            0,
            &sum_of(&[Color::new(1.0, 0.0, 1.0), Color::ZERO, Color::ZERO]),
            3,
            &none,
        );
        let img = f.resolve();
        assert_eq!(img.pixels[0], Color::new(0.5, 0.5, 1.0));
        assert_eq!(img.pixels[1], Color::ZERO);
        assert!(f.resolve_aovs().is_none());
        let mut twice = f.clone();
        twice.add_film(&f);
        assert_eq!(twice.resolve(), img);
        assert_eq!(twice.counts, [8, 0]);
    }
}
