//! The auxiliary passes (AOVs) of a render, per pixel: the albedo and the normal of the
//! first surface each camera sample shows (the guides a denoiser wants), the distance to
//! it, and the fraction of samples that hit anything (the alpha channel). They are summed
//! exactly like the colour ([`ExactSum`]), so that they too merge and resume into the
//! bytes of a one-go render. What a sample's values are is decided in
//! [`crate::render::aov`].

use super::exact::ExactSum;
use crate::image::Image;
use crate::math::{Color, Vec3A};

/// What one camera sample shows of the first surface it meets.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AovSample {
    /// The surface's reflectance in [0, 1] (black where the sample sees nothing).
    pub albedo: Color,
    /// Its unit shading normal in world space (zero where the sample sees nothing).
    pub normal: Vec3A,
    /// The distance from the camera to the first surface, if the camera ray hit one.
    pub depth: Option<f32>,
}

/// The sums of a pixel's AOV samples.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct AovSum {
    pub albedo: ExactSum,
    pub normal: ExactSum,
    /// The sum of the depths of the samples that hit a surface (fixed point).
    pub depth: i128,
    /// How many samples hit a surface.
    pub hits: u32,
}

impl AovSum {
    #[inline]
    pub fn add_sample(&mut self, s: &AovSample) {
        self.albedo.add_sample(s.albedo);
        self.normal.add_sample(s.normal);
        if let Some(d) = s.depth {
            self.depth = self.depth.wrapping_add(ExactSum::fixed(d));
            self.hits += 1;
        }
    }

    #[inline]
    pub fn add(&mut self, other: &AovSum) {
        self.albedo.add(&other.albedo);
        self.normal.add(&other.normal);
        self.depth = self.depth.wrapping_add(other.depth);
        self.hits += other.hits;
    }
}

/// The AOVs of a film, averaged over each pixel's samples.
#[derive(Clone, Debug, PartialEq)]
pub struct AovImages {
    /// The mean albedo.
    pub albedo: Image,
    /// The mean of the unit normals (shorter than 1 where a pixel sees several surfaces).
    pub normal: Image,
    /// The mean distance over the samples that hit a surface; +∞ where none did.
    pub depth: Vec<f32>,
    /// The fraction of samples that hit a surface.
    pub alpha: Vec<f32>,
}

impl AovImages {
    /// Averages `sums` over `counts` samples per pixel.
    pub fn resolve(width: u32, height: u32, sums: &[AovSum], counts: &[u32]) -> AovImages {
        let mean = |s: &ExactSum, n: u32| match n {
            0 => Color::ZERO,
            n => (s.value() / n as f64).as_vec3().into(),
        };
        let image = |f: &dyn Fn(&AovSum, u32) -> Color| Image {
            width,
            height,
            pixels: sums.iter().zip(counts).map(|(s, &n)| f(s, n)).collect(),
        };
        AovImages {
            albedo: image(&|s, n| mean(&s.albedo, n)),
            normal: image(&|s, n| mean(&s.normal, n)),
            depth: sums
                .iter()
                .map(|s| match s.hits {
                    0 => f32::INFINITY,
                    h => (ExactSum::to_f64(s.depth) / h as f64) as f32,
                })
                .collect(),
            alpha: sums
                .iter()
                .zip(counts)
                .map(|(s, &n)| if n == 0 { 0.0 } else { (s.hits as f64 / n as f64) as f32 })
                .collect(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn aovs_average_over_samples_and_depth_over_hits() {
        let hit = AovSample {
            albedo: Color::new(0.5, 0.25, 1.0),
            normal: Vec3A::Z,
            depth: Some(3.0),
        };
        let miss = AovSample {
            albedo: Color::ZERO,
            normal: Vec3A::ZERO,
            depth: None,
        };
        let mut a = AovSum::default();
        a.add_sample(&hit);
        a.add_sample(&miss);
        let mut b = AovSum::default();
        b.add_sample(&hit);
        b.add_sample(&AovSample {
            depth: Some(5.0),
            ..hit
        });
        let mut both = a;
        both.add(&b);
        let img = AovImages::resolve(3, 1, &[a, both, AovSum::default()], &[2, 4, 0]);
        assert_eq!(img.albedo.pixels[0], Color::new(0.25, 0.125, 0.5));
        assert_eq!(img.normal.pixels[1], Color::new(0.0, 0.0, 0.75));
        assert_eq!(img.depth, [3.0, 11.0 / 3.0, f32::INFINITY]);
        assert_eq!(img.alpha, [0.5, 0.75, 0.0]);
    }
}
