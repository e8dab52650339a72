//! What adaptive sampling (`noisethreshold`, `--noise-threshold`) knows about a pixel:
//! the running sums of its samples' luminance and their squares, and whether it has
//! stopped. Kept in the film, so that a render continued later (`--resume`, or the next
//! pass of one render) carries on each pixel's estimate where it was: the sums are added
//! in sample order, one sample at a time, so the bits are those of a render in one go.

use crate::math::Color;

#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PixelNoise {
    /// The sum of the samples' Rec. 709 luminance (of the linear radiance).
    pub sum: f64,
    /// The sum of their squares.
    pub sum_sq: f64,
    /// The pixel's estimate fell below the threshold: it takes no more samples.
    pub stopped: bool,
}

impl PixelNoise {
    #[inline]
    pub fn add(&mut self, c: Color) {
        let c = c.as_dvec3();
        let y = 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
        self.sum += y;
        self.sum_sq += y * y;
    }

    /// The standard error of the mean over the mean, after `n` samples: 0 for a pixel
    /// whose samples are all the same (black included), infinite for one with a positive
    /// spread and a zero mean.
    pub fn relative_error(&self, n: u32) -> f64 {
        let n = n as f64;
        let mean = self.sum / n;
        let variance = ((self.sum_sq - self.sum * mean) / (n - 1.0).max(1.0)).max(0.0);
        let error = (variance / n).sqrt();
        if error == 0.0 {
            0.0
        } else {
            error / mean.abs()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_error_is_the_standard_error_over_the_mean() {
        let mut p = PixelNoise::default();
        for y in [1.0f32, 3.0] {
            p.add(Color::splat(y));
        }
        // Mean 2, sample variance 2, standard error 1.
        assert!((p.relative_error(2) - 0.5).abs() < 1e-12);
        assert_eq!(PixelNoise::default().relative_error(4), 0.0);
        let mut dark = PixelNoise::default();
        dark.add(Color::splat(1.0));
        dark.add(Color::splat(-1.0));
        assert_eq!(dark.relative_error(2), f64::INFINITY);
    }
}
