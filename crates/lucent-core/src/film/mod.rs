//! The film: per pixel, the sum of its samples' radiance and their count. Sums, not
//! averages, so that a render can take more samples later and two renders of disjoint
//! pixels or sample ranges can be merged; [`Film::resolve`] divides them into the
//! [`Image`] that is written.
//!
//! The sums are exact ([`ExactSum`]): adding samples in another grouping — the first 64
//! here and the next 64 on another machine, merged — gives the very same bits as adding
//! them one after the other, which floating-point sums would not. A film of one sample
//! per pixel keeps the samples themselves, from which their sums follow exactly
//! ([`Film::one_sample`]). A film may also carry the sums of the auxiliary passes
//! ([`aov`]).

pub mod aov;
pub mod exact;
pub mod noise;

use crate::image::Image;
use crate::math::Color;
pub use aov::{AovImages, AovSample, AovSum};
pub use exact::ExactSum;
pub use noise::PixelNoise;

#[derive(Clone, Debug)]
pub struct Film {
    pub width: u32,
    pub height: u32,
    /// Row-major, top row first.
    pixels: Pixels,
    pub counts: Vec<u32>,
    /// The sums of the auxiliary passes, when the render computes them.
    pub aovs: Option<Vec<AovSum>>,
    /// Adaptive sampling's estimate of every pixel, when the render samples adaptively.
    pub noise: Option<Vec<PixelNoise>>,
}

/// How a film holds its pixels' sums.
#[derive(Clone, Debug)]
enum Pixels {
    /// Any number of samples per pixel: the exact sums (48 bytes a pixel).
    Sums(Vec<ExactSum>),
    /// At most one sample per pixel: its value, from which its exact sum follows without
    /// loss (see [`Film::one_sample`]; 16 bytes a pixel, a padded vector).
    Samples(Vec<Color>),
}

impl Film {
    /// A film without auxiliary passes.
    pub fn new(width: u32, height: u32) -> Film {
        Film::with_aovs(width, height, false)
    }

    /// A film that also keeps the auxiliary passes when `aovs` is set.
    pub fn with_aovs(width: u32, height: u32, aovs: bool) -> Film {
        let n = width as usize * height as usize;
        Film::of(
            width,
            height,
            aovs,
            Pixels::Sums(crate::huge_pages::vec_filled(n, ExactSum::default())),
        )
    }

    /// The bytes a film of `pixels` pixels takes: their sums (or, with `one_sample`, their
    /// samples), counts, auxiliary passes' sums (`aovs`) and adaptive sampling's
    /// estimates (`noise`).
    pub fn bytes(pixels: u64, one_sample: bool, aovs: bool, noise: bool) -> u64 {
        use std::mem::size_of;
        let colour = if one_sample {
            size_of::<Color>()
        } else {
            size_of::<ExactSum>()
        };
        let aov = if aovs { size_of::<AovSum>() } else { 0 };
        let noise = if noise { size_of::<PixelNoise>() } else { 0 };
        pixels * (colour + size_of::<u32>() + aov + noise) as u64
    }

    /// A film for one sample of each pixel (a one-sample pass: the whole of a ray tracer's
    /// render, the first pass of a Monte Carlo one), which keeps each pixel's sample instead
    /// of its exact sum. The sum of one sample converts back without loss: the fixed point
    /// of a sample `v` is `v · 2⁶⁴` exactly when `|v| ≥ 2⁻⁴¹` (24 significant bits), a
    /// multiple `k · 2⁻⁶⁴` with `|k| < 2²³` below that, or the clamp `±2⁴⁰`; each is an f32
    /// whose fixed point is that number again. A film is fresh memory that every render
    /// faults in (a kernel that zeroes each page, under a hypervisor that backs it first:
    /// up to a fifth of a 640 × 480 ray-traced render here), and this one is a quarter of
    /// the size.
    pub fn one_sample(width: u32, height: u32, aovs: bool) -> Film {
        let n = width as usize * height as usize;
        Film::of(
            width,
            height,
            aovs,
            Pixels::Samples(crate::huge_pages::vec_filled(n, Color::ZERO)),
        )
    }

    fn of(width: u32, height: u32, aovs: bool, pixels: Pixels) -> Film {
        let n = width as usize * height as usize;
        Film {
            width,
            height,
            pixels,
            counts: vec![0; n],
            aovs: aovs.then(|| crate::huge_pages::vec_filled(n, AovSum::default())),
            noise: None,
        }
    }

    /// Whether the film keeps one sample per pixel ([`Film::one_sample`]) rather than sums.
    pub fn holds_one_sample(&self) -> bool {
        matches!(self.pixels, Pixels::Samples(_))
    }

    /// The exact sum of pixel `index`'s samples.
    #[inline]
    pub fn sum(&self, index: usize) -> ExactSum {
        match &self.pixels {
            Pixels::Sums(sums) => sums[index],
            Pixels::Samples(samples) => one_sum(samples[index]),
        }
    }

    /// The exact sums, to be written (a film of one sample per pixel turns into one of
    /// sums first).
    pub fn sums_mut(&mut self) -> &mut [ExactSum] {
        self.make_sums();
        match &mut self.pixels {
            Pixels::Sums(sums) => sums,
            Pixels::Samples(_) => unreachable!("made sums above"),
        }
    }

    /// Turns a film of one sample per pixel into one of sums.
    fn make_sums(&mut self) {
        if let Pixels::Samples(samples) = &self.pixels {
            let mut sums = crate::huge_pages::vec_with_capacity(samples.len());
            sums.extend(samples.iter().map(|&c| one_sum(c)));
            self.pixels = Pixels::Sums(sums);
        }
    }

    /// No samples any more (the same pixels, and auxiliary passes if it kept them): the
    /// film of a finished pass made ready for the next in the memory it already has.
    pub fn clear(&mut self) {
        match &mut self.pixels {
            Pixels::Sums(sums) => sums.fill(ExactSum::default()),
            Pixels::Samples(samples) => samples.fill(Color::ZERO),
        }
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
        if let Pixels::Samples(samples) = &mut self.pixels {
            let fits = match count {
                0 => *sum == ExactSum::default(),
                // (The conversion only where a sample is kept.)
                1 if self.counts[index] == 0 => {
                    let sample: Color = sum.value().as_vec3().into();
                    let kept = one_sum(sample) == *sum;
                    if kept {
                        samples[index] = sample;
                    }
                    kept
                }
                _ => false,
            };
            if !fits {
                // More than one sample after all (or a sum that is not one sample's):
                // sums from here on.
                self.make_sums();
            }
        }
        if let Pixels::Sums(sums) = &mut self.pixels {
            sums[index].add(sum);
        }
        self.counts[index] += count;
        if let Some(aovs) = &mut self.aovs {
            aovs[index].add(aov);
        }
    }

    /// [`Film::add`] of a pixel whose last sample was `last` (its only one when `count`
    /// is 1): a film of one sample per pixel keeps that sample, with no conversion.
    #[inline]
    pub fn add_pixel(&mut self, index: usize, sum: &ExactSum, count: u32, last: Color, aov: &AovSum) {
        if let Pixels::Samples(samples) = &mut self.pixels {
            if count == 1 && self.counts[index] == 0 {
                let sample = Color::new(
                    ExactSum::canonical(last.x),
                    ExactSum::canonical(last.y),
                    ExactSum::canonical(last.z),
                );
                debug_assert_eq!(one_sum(sample), *sum, "a sum that is not its last sample's");
                samples[index] = sample;
                self.counts[index] = 1;
                if let Some(aovs) = &mut self.aovs {
                    aovs[index].add(aov);
                }
                return;
            }
        }
        self.add(index, sum, count, aov);
    }

    /// Adds another film of the same pixels (the samples after this one's). Its
    /// adaptive-sampling estimates continued this film's, so they replace them.
    ///
    /// # Panics
    /// If the films differ in size.
    pub fn add_film(&mut self, other: &Film) {
        self.add_samples_of(other);
        if other.noise.is_some() {
            self.noise.clone_from(&other.noise);
        }
    }

    /// Adds the film of the samples before this one's (the same pixels), keeping this
    /// film's adaptive-sampling estimates, which continued the earlier film's: what
    /// `earlier.add_film(self)` holds, in this film's memory.
    ///
    /// # Panics
    /// If the films differ in size.
    pub fn add_earlier(&mut self, earlier: &Film) {
        self.add_samples_of(earlier);
    }

    fn add_samples_of(&mut self, other: &Film) {
        assert_eq!(
            (self.width, self.height),
            (other.width, other.height),
            "films of other pixels"
        );
        self.make_sums();
        let Pixels::Sums(sums) = &mut self.pixels else {
            unreachable!("made sums above")
        };
        for (i, (sum, &n)) in sums.iter_mut().zip(&other.counts).enumerate() {
            sum.add(&other.sum(i));
            self.counts[i] += n;
        }
        if let (Some(mine), Some(theirs)) = (&mut self.aovs, &other.aovs) {
            mine.iter_mut().zip(theirs).for_each(|(a, b)| a.add(b));
        }
    }

    /// The mean of every pixel's samples (black where there are none).
    pub fn resolve(&self) -> Image {
        let pixels = match &self.pixels {
            Pixels::Sums(sums) => sums
                .iter()
                .zip(&self.counts)
                .map(|(s, &n)| match n {
                    0 => Color::ZERO,
                    n => (s.value() / n as f64).as_vec3().into(),
                })
                .collect(),
            // One sample: its value is its mean (`value() / 1`, the same bits).
            Pixels::Samples(samples) => samples.clone(),
        };
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

/// Films are equal when they hold the same samples, however they keep them.
impl PartialEq for Film {
    fn eq(&self, other: &Film) -> bool {
        (self.width, self.height, &self.counts, &self.aovs, &self.noise)
            == (other.width, other.height, &other.counts, &other.aovs, &other.noise)
            && (0..self.counts.len()).all(|i| self.sum(i) == other.sum(i))
    }
}

/// The exact sum of one sample (zero for black, which is also a pixel without one).
#[inline]
fn one_sum(c: Color) -> ExactSum {
    let mut s = ExactSum::default();
    s.add_sample(c);
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_films_bytes_are_what_docs_limits_md_says() {
        assert_eq!(Film::bytes(1, true, false, false), 20);
        assert_eq!(Film::bytes(1, false, false, false), 52);
        assert_eq!(Film::bytes(1, false, true, false), 52 + 128);
        assert_eq!(Film::bytes(1, true, false, true), 20 + 24);
        assert_eq!(Film::bytes(1000, false, true, true), 1000 * (52 + 128 + 24));
    }

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

    /// Samples of every kind the fixed point treats apart: exact (ordinary values, the
    /// smallest exact magnitude 2⁻⁴¹), rounded (below it, and subnormal), clamped (above
    /// 2⁴⁰, infinite), NaN (nothing), negative, zero.
    fn awkward_samples() -> Vec<Color> {
        let v = [
            0.1,
            -0.3,
            1.0 / 3.0,
            2f32.powi(-41),
            3.0 * 2f32.powi(-45),
            -1.7e-20,
            f32::MIN_POSITIVE / 4.0,
            2f32.powi(40),
            3.0e12,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
            0.0,
            -0.0,
            12345.678,
        ];
        (0..v.len())
            .map(|i| Color::new(v[i], v[(i + 5) % v.len()], v[(i + 11) % v.len()]))
            .collect()
    }

    #[test]
    fn a_film_of_one_sample_per_pixel_holds_the_same_sums_and_means_as_one_of_sums() {
        let samples = awkward_samples();
        let n = samples.len() as u32;
        let (mut sums, mut one) = (Film::new(n, 2), Film::one_sample(n, 2, false));
        // The same, handed the samples themselves (as the renderer does).
        let mut handed = Film::one_sample(n, 2, false);
        let none = AovSum::default();
        // The second row has no samples.
        for (i, &c) in samples.iter().enumerate() {
            sums.add(i, &sum_of(&[c]), 1, &none);
            one.add(i, &sum_of(&[c]), 1, &none);
            handed.add_pixel(i, &sum_of(&[c]), 1, c, &none);
        }
        for i in n as usize..2 * n as usize {
            one.add(i, &ExactSum::default(), 0, &none);
            handed.add_pixel(i, &ExactSum::default(), 0, Color::ZERO, &none);
        }
        assert!(
            one.holds_one_sample() && handed.holds_one_sample(),
            "every sum was one sample's"
        );
        assert_eq!(one, sums);
        assert_eq!(handed, sums);
        // The same bits resolved (±0 and rounded samples included).
        let bits = |f: &Film| {
            f.resolve()
                .pixels
                .iter()
                .map(|c| c.to_array().map(f32::to_bits))
                .collect::<Vec<_>>()
        };
        assert_eq!(bits(&one), bits(&sums));
        assert_eq!(bits(&handed), bits(&sums));
        for i in 0..2 * n as usize {
            assert_eq!(one.sum(i), sums.sum(i), "pixel {i}");
        }
        // Either kind added to a film of sums, and a film of sums taking in an earlier
        // film of one sample (keeping its own adaptive estimates): the same.
        let mut later = Film::new(n, 2);
        later.noise = Some(vec![
            PixelNoise {
                sum: 1.0,
                ..Default::default()
            };
            2 * n as usize
        ]);
        for i in 0..n as usize {
            later.add(i, &sum_of(&[Color::splat(0.25), Color::splat(0.5)]), 2, &none);
        }
        let mut a = sums.clone();
        a.add_film(&later);
        let mut b = later.clone();
        b.add_earlier(&one);
        assert_eq!(a, b);
        assert_eq!(b.noise, later.noise);
        // A second sample for a pixel turns the film into one of sums, with nothing lost.
        let mut more = one.clone();
        let extra = sum_of(&[Color::splat(0.75)]);
        more.add(3, &extra, 1, &none);
        assert!(!more.holds_one_sample());
        let mut expected = sums.sum(3);
        expected.add(&extra);
        assert_eq!((more.sum(3), more.counts[3]), (expected, 2));
        assert_eq!(more.sum(4), sums.sum(4));
    }
}
