//! What a render is asked to make, apart from the scene it is made of: the whole image's
//! resolution, the rectangle of pixels to compute, the samples to take in each of them
//! and the seed of their random numbers. The scene file supplies the defaults (`size`,
//! `spp`); a crop, a range of samples or another seed is another job over the same scene.

use std::ops::Range;

use crate::camera::Resolution;
use crate::sampler::SamplerKind;

/// A rectangle of pixels, `x0 ≤ x < x1`, `y0 ≤ y < y1` (row 0 at the top).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PixelRect {
    pub x0: u32,
    pub y0: u32,
    pub x1: u32,
    pub y1: u32,
}

impl PixelRect {
    pub fn whole(resolution: Resolution) -> PixelRect {
        PixelRect {
            x0: 0,
            y0: 0,
            x1: resolution.width,
            y1: resolution.height,
        }
    }

    pub fn width(&self) -> u32 {
        self.x1 - self.x0
    }

    pub fn height(&self) -> u32 {
        self.y1 - self.y0
    }

    pub fn pixels(&self) -> u64 {
        self.width() as u64 * self.height() as u64
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct RenderJob {
    /// The whole image the camera's view is divided into.
    pub resolution: Resolution,
    /// The pixels to compute: the whole image, or a part of it. Each pixel's value
    /// depends only on the pixel, so a part is exactly that part of the whole.
    pub pixels: PixelRect,
    /// Samples per pixel of the complete picture (`spp`): where in the pixel each sample
    /// falls depends on it (one per cell of a √spp × √spp grid when it is a square).
    pub spp: u32,
    /// The sample indices taken in every pixel, within `0..spp`; the pixel's value is
    /// their average.
    pub samples: Range<u32>,
    /// Picks the random numbers of every sample; 0 is the default.
    pub seed: u64,
    /// Where the random numbers come from (`sampler`).
    pub sampler: SamplerKind,
    /// Adaptive sampling (`noisethreshold`, `--noise-threshold`): a pixel stops taking
    /// samples once the estimated relative standard error of its mean luminance is
    /// below this, after at least [`MIN_ADAPTIVE_SAMPLES`] (or all of them); `None`
    /// takes every sample.
    pub noise_threshold: Option<f32>,
    /// Also compute the auxiliary passes (albedo, normal, depth, alpha) of every sample
    /// ([`super::aov`]).
    pub aovs: bool,
}

/// The fewest samples a pixel takes before adaptive sampling may stop it: fewer do not
/// estimate the spread of its samples well enough (one lucky run of dark samples would
/// look converged).
pub const MIN_ADAPTIVE_SAMPLES: u32 = 16;

impl RenderJob {
    /// The whole image with every one of its `spp` samples, independent random numbers.
    pub fn whole(resolution: Resolution, spp: u32) -> RenderJob {
        RenderJob {
            resolution,
            pixels: PixelRect::whole(resolution),
            spp,
            samples: 0..spp,
            seed: 0,
            sampler: SamplerKind::Independent,
            noise_threshold: None,
            aovs: false,
        }
    }

    /// A small part of the job: at most `side × side` pixels at the image's centre and
    /// its first `samples` samples (for tests and fuzzing, which want what a scene makes
    /// the renderer do without the time of a whole picture).
    pub fn probe(&self, side: u32, samples: u32) -> RenderJob {
        let (w, h) = (self.resolution.width, self.resolution.height);
        let (x0, y0) = (w.saturating_sub(side) / 2, h.saturating_sub(side) / 2);
        RenderJob {
            pixels: PixelRect {
                x0,
                y0,
                x1: (x0 + side).min(w),
                y1: (y0 + side).min(h),
            },
            samples: self.samples.start..self.samples.end.min(self.samples.start + samples.max(1)),
            ..self.clone()
        }
    }

    /// Why the job cannot be rendered, if it cannot: an empty or out-of-image
    /// rectangle, or a sample range that is empty or outside `0..spp`.
    pub fn check(&self) -> Result<(), String> {
        let (r, p) = (self.resolution, self.pixels);
        if r.width == 0 || r.height == 0 {
            return Err(format!("the image has no pixels ({} x {})", r.width, r.height));
        }
        if !(p.x0 < p.x1 && p.y0 < p.y1 && p.x1 <= r.width && p.y1 <= r.height) {
            return Err(format!(
                "pixels {}..{} x {}..{} are not a rectangle inside the {} x {} image",
                p.x0, p.x1, p.y0, p.y1, r.width, r.height
            ));
        }
        // (Ranges are quoted as users give them, `--samples FIRST..LAST`: inclusive.)
        if self.samples.start >= self.samples.end {
            return Err("the sample range is empty".into());
        }
        if self.samples.end > self.spp {
            return Err(format!(
                "samples {}..{} are not within the {} samples per pixel (0..{})",
                self.samples.start,
                self.samples.end - 1,
                self.spp,
                self.spp.saturating_sub(1)
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn jobs_outside_the_image_or_its_samples_are_refused() {
        let resolution = Resolution { width: 40, height: 30 };
        let whole = RenderJob::whole(resolution, 16);
        assert!(whole.check().is_ok());
        assert_eq!((whole.pixels.pixels(), whole.samples.len()), (1200, 16));
        let mut crop = whole.clone();
        crop.pixels = PixelRect {
            x0: 10,
            y0: 0,
            x1: 41,
            y1: 30,
        };
        assert!(crop.check().unwrap_err().contains("not a rectangle inside"));
        crop.pixels = PixelRect {
            x0: 10,
            y0: 5,
            x1: 10,
            y1: 30,
        };
        assert!(crop.check().is_err(), "empty");
        let mut samples = whole.clone();
        samples.samples = 8..17;
        assert_eq!(
            samples.check().unwrap_err(),
            "samples 8..16 are not within the 16 samples per pixel (0..15)"
        );
        samples.samples = 3..3;
        assert!(samples.check().is_err(), "empty");
        let probe = whole.probe(2, 4);
        assert_eq!(
            probe.pixels,
            PixelRect {
                x0: 19,
                y0: 14,
                x1: 21,
                y1: 16
            }
        );
        assert_eq!(probe.samples, 0..4);
        assert!(RenderJob::whole(Resolution { width: 1, height: 1 }, 1)
            .probe(2, 4)
            .check()
            .is_ok());
    }
}
