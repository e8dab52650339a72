//! Scene command `envmap file [s]` as a light of the Monte Carlo integrators
//! (EXTENSIONS.md): an infinitely distant sphere of radiance s × texel around the scene,
//! seen by every ray that escapes, and sampled by next-event estimation in proportion to
//! luminance × sin θ.
//!
//! The map is looked up with bilinear filtering, so the radiance inside a texel's cell of
//! the (u, v) square depends on its 3 × 3 neighbours. Each cell's weight is the integral
//! of that filtered luminance over the cell (weights 1/8, 3/4, 1/8 along each axis), times
//! sin θ at the row's centre: wherever the map shows any light the density is positive, so
//! light sampling alone (`nexteventestimation on`) misses none of it.
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
}

impl EnvironmentLight {
    /// `None` for a map that is black everywhere (it lights nothing).
    pub fn new(map: &EnvironmentMap) -> Option<EnvironmentLight> {
        let img = &map.image;
        let (w, h) = (img.width as i64, img.height as i64);
        let lum: Vec<f32> = (0..(w * h) as usize).map(|i| luminance(img.texel_at(i)).max(0.0)).collect();
        // Longitude wraps; latitude repeats the edge rows (the lookup clamps there).
        let at = |x: i64, y: i64| lum[(y.clamp(0, h - 1) * w + x.rem_euclid(w)) as usize];
        const K: [f32; 3] = [0.125, 0.75, 0.125];
        let mut weights = Vec::with_capacity((w * h) as usize);
        for y in 0..h {
            let sin_theta = (PI * (y as f32 + 0.5) / h as f32).sin();
            for x in 0..w {
                let mut filtered = 0.0;
                for (dy, ky) in (-1..=1).zip(K) {
                    for (dx, kx) in (-1..=1).zip(K) {
                        filtered += kx * ky * at(x + dx, y + dy);
                    }
                }
                weights.push(filtered * sin_theta);
            }
        }
        let cells = Distribution2D::new(w as usize, h as usize, &weights)?;
        (map.intensity > 0.0).then_some(EnvironmentLight { cells })
    }

    /// A direction drawn from the map's distribution by `(a, b)`, with the radiance the
    /// map sends along it (toward the receiver) and its solid-angle density.
    #[inline]
    pub fn sample_li(&self, map: &EnvironmentMap, a: f32, b: f32) -> Option<LightSample> {
        let ((u, v), p_uv) = self.cells.sample(a, b);
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
        let u = 0.5 + wi.x.atan2(-wi.z) / (2.0 * PI);
        let v = cos_t.acos() / PI;
        self.cells.density(u.clamp(0.0, 1.0), v.clamp(0.0, 1.0)) / (2.0 * PI * PI * sin_t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::chi2::chi2_test_edged;
    use crate::math::Color;
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
            map(16, 8, |x, y| if (x, y) == (5, 2) { 40.0 } else if y == 6 { 0.0 } else { 1.0 + x as f32 * 0.2 }),
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
