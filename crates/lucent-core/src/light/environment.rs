//! Scene command `envmap file [s]` as a light of the Monte Carlo integrators
//! (EXTENSIONS.md): an infinitely distant sphere of radiance s × texel around the scene,
//! seen by every ray that escapes, and sampled by next-event estimation in proportion to
//! luminance × sin θ.
//!
//! The map is looked up with bilinear filtering, so its radiance is a bilinear function
//! on each quarter of a texel (between the texel centres and the edges halfway to the
//! next ones). The light samples it that way: a quarter-texel cell is chosen in
//! proportion to the integral of its luminance (the mean of its corners) × sin θ at the
//! cell's centre, and then a point inside the cell with a density proportional to the
//! bilinear luminance (pbrt-v4's bilinear warp). So L / pdf is nearly constant over a
//! small bright sun — a piecewise-constant density would leave it varying several-fold
//! across the sun's filtered edge, the noise of the shadows it casts — and the density
//! is positive wherever the map shows any light, so light sampling alone
//! (`nexteventestimation on`) misses none of it. Memory: about 64 bytes per texel of
//! the map (four cells of 12 bytes, their corners), 130 MB for a 2048 × 1024 map.
//!
//! A direction d maps to u = ½ + atan2(d.x, −d.z) / 2π, v = θ / π with cos θ = d.y (the
//! lookup of [`EnvironmentMap::radiance`]); a density p(u, v) on the square is
//! p(u, v) / (2π² sin θ) in solid angle.

use std::f32::consts::PI;

use crate::light::LightSample;
use crate::math::Vec3A;
use crate::sampling::distribution::Distribution2D;
use crate::shading::texture::{luminance, EnvironmentMap};

#[derive(Clone, Debug)]
pub struct EnvironmentLight {
    cells: Distribution2D,
    /// Luminance at the corners of the quarter-texel cells, (2W + 1) × (2H + 1).
    corners: Vec<f32>,
    /// Cells across and down: 2W × 2H.
    width: usize,
    height: usize,
}

/// A density ∝ (1 − x)·a + x·b on [0, 1): x from `u`.
#[inline]
fn sample_linear(u: f32, a: f32, b: f32) -> f32 {
    if a == b {
        return u;
    }
    let x = u * (a + b) / (a + ((1.0 - u) * a * a + u * b * b).sqrt());
    x.min(crate::sampling::ONE_BELOW)
}

impl EnvironmentLight {
    /// `None` for a map that is black everywhere (it lights nothing).
    pub fn new(map: &EnvironmentMap) -> Option<EnvironmentLight> {
        if !(map.intensity > 0.0) {
            return None;
        }
        let img = &map.image;
        let (w, h) = (2 * img.width as usize, 2 * img.height as usize);
        // The lookup's luminance at every cell corner: texel coordinates (i/2, j/2), the
        // rows clamped to the centres of the first and last texel rows as the lookup does.
        let mut corners = Vec::with_capacity((w + 1) * (h + 1));
        for j in 0..=h {
            let y = (j as f32 / 2.0).clamp(0.5, img.height as f32 - 0.5);
            for i in 0..=w {
                corners.push(luminance(img.bilinear(i as f32 / 2.0, y)).max(0.0));
            }
        }
        let mut weights = Vec::with_capacity(w * h);
        for j in 0..h {
            let sin_theta = (PI * (j as f32 + 0.5) / h as f32).sin();
            for i in 0..w {
                let c = |di: usize, dj: usize| corners[(j + dj) * (w + 1) + i + di];
                weights.push(0.25 * (c(0, 0) + c(1, 0) + c(0, 1) + c(1, 1)) * sin_theta);
            }
        }
        let cells = Distribution2D::new(w, h, &weights)?;
        Some(EnvironmentLight {
            cells,
            corners,
            width: w,
            height: h,
        })
    }

    /// The cell of `(u, v)`, the point's place in it, and the cell's corner values
    /// (top left, top right, bottom left, bottom right). (Inlined always: returned out of
    /// line, its six numbers were written one by one and read back as a vector, a stalled
    /// store-to-load forward on every draw.)
    #[inline(always)]
    fn cell(&self, u: f32, v: f32) -> ((f32, f32), [f32; 4]) {
        let (x, y) = (u * self.width as f32, v * self.height as f32);
        let (i, j) = ((x as usize).min(self.width - 1), (y as usize).min(self.height - 1));
        let c = |di: usize, dj: usize| self.corners[(j + dj) * (self.width + 1) + i + di];
        let local = ((x - i as f32).clamp(0.0, 1.0), (y - j as f32).clamp(0.0, 1.0));
        (local, [c(0, 0), c(1, 0), c(0, 1), c(1, 1)])
    }

    /// The bilinear density inside a cell (mean 1 over the cell).
    #[inline]
    fn within(local: (f32, f32), c: [f32; 4]) -> f32 {
        let (x, y) = local;
        let mean = 0.25 * (c[0] + c[1] + c[2] + c[3]);
        let value = (1.0 - y) * ((1.0 - x) * c[0] + x * c[1]) + y * ((1.0 - x) * c[2] + x * c[3]);
        if mean > 0.0 {
            value / mean
        } else {
            0.0
        }
    }

    /// A direction drawn from the map's distribution by `(a, b)`, with the radiance the
    /// map sends along it (toward the receiver) and its solid-angle density.
    #[inline]
    pub fn sample_li(&self, map: &EnvironmentMap, a: f32, b: f32) -> Option<LightSample> {
        let ((u, v), p_cell) = self.cells.sample(a, b);
        // Where (a, b) fell inside the chosen cell is uniform there: warp it to the
        // bilinear density (rows first, then the column within the row).
        let ((lu, lv), c) = self.cell(u, v);
        let y = sample_linear(lv, c[0] + c[1], c[2] + c[3]);
        let x = sample_linear(lu, (1.0 - y) * c[0] + y * c[2], (1.0 - y) * c[1] + y * c[3]);
        let (i, j) = (
            (u * self.width as f32 - lu).round(),
            (v * self.height as f32 - lv).round(),
        );
        let (u, v) = ((i + x) / self.width as f32, (j + y) / self.height as f32);
        let p_uv = p_cell * Self::within((x, y), c);
        let (sin_t, cos_t) = (PI * v).sin_cos();
        let (sin_p, cos_p) = (2.0 * PI * (u - 0.5)).sin_cos();
        let wi = Vec3A::new(sin_t * sin_p, cos_t, -sin_t * cos_p);
        let pdf = p_uv / (2.0 * PI * PI * sin_t);
        (pdf > 0.0 && pdf.is_finite()).then(|| LightSample {
            wi,
            distance: f32::INFINITY,
            radiance: map.radiance(wi),
            pdf,
            is_delta: false,
        })
    }

    /// The solid-angle density with which [`EnvironmentLight::sample_li`] draws `wi`.
    #[inline]
    pub fn pdf_li(&self, wi: Vec3A) -> f32 {
        let cos_t = wi.y.clamp(-1.0, 1.0);
        let sin_t = (1.0 - cos_t * cos_t).sqrt();
        if !(sin_t > 0.0) {
            return 0.0;
        }
        let u = (0.5 + wi.x.atan2(-wi.z) / (2.0 * PI)).clamp(0.0, 1.0);
        let v = (cos_t.acos() / PI).clamp(0.0, 1.0);
        let (local, c) = self.cell(u, v);
        self.cells.density(u, v) * Self::within(local, c) / (2.0 * PI * PI * sin_t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Color;
    use crate::sampling::chi2::chi2_test_edged;
    use crate::shading::texture::Image;

    fn map(w: u32, h: u32, f: impl Fn(u32, u32) -> f32) -> EnvironmentMap {
        let colors: Vec<Color> = (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .map(|(x, y)| Color::new(f(x, y), 0.5 * f(x, y), 0.25 * f(x, y)))
            .collect();
        EnvironmentMap {
            image: Image::from_colors(w, h, &colors),
            intensity: 1.5,
        }
    }

    #[test]
    fn environment_samples_follow_their_solid_angle_density() {
        // A map with a bright spot, a dark band and a gradient; and one lit only in a
        // corner, so that most of the sphere has density zero.
        let maps = [
            map(16, 8, |x, y| {
                if (x, y) == (5, 2) {
                    40.0
                } else if y == 6 {
                    0.0
                } else {
                    1.0 + x as f32 * 0.2
                }
            }),
            map(12, 6, |x, y| if x < 2 && y < 2 { 3.0 } else { 0.0 }),
        ];
        for (k, m) in maps.iter().enumerate() {
            let light = EnvironmentLight::new(m).unwrap();
            let r = chi2_test_edged(
                &format!("environment {k}"),
                |a, b| light.sample_li(m, a, b).map(|s| s.wi),
                |wi| light.pdf_li(wi),
            );
            assert!(r.dof > 20, "{r:?}");
            for (a, b) in [(0.1, 0.2), (0.7, 0.9), (0.5, 0.5), (0.99, 0.01)] {
                let s = light.sample_li(m, a, b).unwrap();
                let p = light.pdf_li(s.wi);
                assert!((s.pdf - p).abs() <= 1e-3 * p, "{} {}", s.pdf, p);
                assert_eq!(s.radiance, m.radiance(s.wi));
                assert!((s.wi.length() - 1.0).abs() < 1e-5);
            }
        }
    }

    #[test]
    fn every_direction_the_map_lights_can_be_drawn() {
        // One bright texel: bilinear filtering spreads it over its neighbours' cells,
        // and the density must be positive wherever the lookup is.
        let m = map(8, 4, |x, y| if (x, y) == (3, 1) { 1.0 } else { 0.0 });
        let light = EnvironmentLight::new(&m).unwrap();
        for i in 0..4000 {
            let (a, b) = crate::sampler::Sampler::new(1, i, 0, 0).uniform2();
            let (sin_t, cos_t) = (PI * b).sin_cos();
            let (sin_p, cos_p) = (2.0 * PI * (a - 0.5)).sin_cos();
            let wi = Vec3A::new(sin_t * sin_p, cos_t, -sin_t * cos_p);
            if m.radiance(wi) != Color::ZERO {
                assert!(light.pdf_li(wi) > 0.0, "{wi}");
            }
        }
        assert!(EnvironmentLight::new(&map(4, 2, |_, _| 0.0)).is_none());
    }
}
