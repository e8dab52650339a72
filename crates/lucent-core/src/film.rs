//! The film: per pixel, the sum of its samples' radiance (f64, in the order the samples
//! were taken) and their count. Sums, not averages, so that a render can take more
//! samples later and two renders of disjoint pixels or sample ranges can be merged;
//! [`Film::resolve`] divides them into the [`Image`] that is written.

use crate::image::Image;
use crate::math::{Color, DVec3};

#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    pub width: u32,
    pub height: u32,
    /// Row-major, top row first.
    pub sums: Vec<DVec3>,
    pub counts: Vec<u32>,
}

impl Film {
    pub fn new(width: u32, height: u32) -> Film {
        let n = width as usize * height as usize;
        Film {
            width,
            height,
            sums: vec![DVec3::ZERO; n],
            counts: vec![0; n],
        }
    }

    /// Adds a pixel's `count` samples, whose radiance sums to `sum`.
    #[inline]
    pub fn add(&mut self, index: usize, sum: DVec3, count: u32) {
        self.sums[index] += sum;
        self.counts[index] += count;
    }

    /// The mean of every pixel's samples (black where there are none).
    pub fn resolve(&self) -> Image {
        let pixels = self
            .sums
            .iter()
            .zip(&self.counts)
            .map(|(s, &n)| match n {
                0 => Color::ZERO,
                1 => s.as_vec3().into(),
                n => (*s / n as f64).as_vec3().into(),
            })
            .collect();
        Image {
            width: self.width,
            height: self.height,
            pixels,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sums_resolve_to_means() {
        let mut f = Film::new(2, 1);
        f.add(0, DVec3::new(1.0, 2.0, 3.0), 1);
        f.add(0, DVec3::new(1.0, 0.0, 1.0), 3);
        let img = f.resolve();
        assert_eq!(img.pixels[0], Color::new(0.5, 0.5, 1.0));
        assert_eq!(img.pixels[1], Color::ZERO);
    }
}
