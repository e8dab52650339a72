//! Warps: two uniform numbers `(u, v)` in [0, 1)² to a direction in the local frame
//! (z along the normal or lobe axis), and the density of that direction in solid angle.
//! SCENE_FORMAT.md §4.6–§4.7 give the formulas; all take φ = 2πv.

use std::f32::consts::{FRAC_1_PI, PI};

use crate::math::Vec3A;

/// The local direction with polar cosine `cos_t` and azimuth `2π v`.
#[inline]
fn spherical(cos_t: f32, v: f32) -> Vec3A {
    let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
    let (s, c) = sin_cos_turns(v);
    Vec3A::new(sin_t * c, sin_t * s, cos_t)
}

/// Taylor coefficients of `sin 2πr` in odd powers of `r` (from r¹) and of `cos 2πr` in
/// even powers (from r²): on |r| ≤ 1/8 the first left out is below 2·10⁻⁹, under a
/// thirtieth of an `f32` ulp of the results there.
pub const SIN_TURN: [f32; 5] = [std::f32::consts::TAU, -41.341_7, 81.605_25, -76.705_86, 42.058_694];
pub const COS_TURN: [f32; 5] = [-19.739_208, 64.939_39, -85.456_82, 60.244_64, -26.426_257];

/// `(sin 2πv, cos 2πv)` for `v` in [0, 1], about as accurate as the C library's `sincosf`
/// (a few ulps) and without its call: the nearest quarter turn `q` is taken off exactly
/// (`r = v − q/4`, |r| ≤ 1/8), the polynomials give the sine and cosine of `2πr`, and the
/// quarter turns exchange and negate them. Plain multiplies and adds in a fixed order, so
/// that the path tracer's vector lanes (`integrator::path::lanes`) give the same bits.
#[inline]
pub fn sin_cos_turns(v: f32) -> (f32, f32) {
    let q = (4.0 * v + 0.5).floor();
    let r = v - q * 0.25;
    let z = r * r;
    let [s1, s3, s5, s7, s9] = SIN_TURN;
    let [c2, c4, c6, c8, c10] = COS_TURN;
    let s = r * (s1 + z * (s3 + z * (s5 + z * (s7 + z * s9))));
    let c = 1.0 + z * (c2 + z * (c4 + z * (c6 + z * (c8 + z * c10))));
    match q as i32 & 3 {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

/// Uniform on the hemisphere z ≥ 0 (`importancesampling hemisphere`): cos θ = u.
#[inline]
pub fn uniform_hemisphere(u: f32, v: f32) -> Vec3A {
    spherical(u, v)
}

/// 1/(2π) on the upper hemisphere, 0 below.
#[inline]
pub fn uniform_hemisphere_pdf(cos_t: f32) -> f32 {
    if cos_t > 0.0 {
        0.5 * FRAC_1_PI
    } else {
        0.0
    }
}

/// Cosine-weighted on the hemisphere z ≥ 0 (`importancesampling cosine`): cos θ = √u.
#[inline]
pub fn cosine_hemisphere(u: f32, v: f32) -> Vec3A {
    spherical(u.sqrt(), v)
}

/// cos θ / π above, 0 below.
#[inline]
pub fn cosine_hemisphere_pdf(cos_t: f32) -> f32 {
    cos_t.max(0.0) * FRAC_1_PI
}

/// A Phong lobe of exponent `s` around z: density ∝ cos^s θ, cos θ = u^(1/(s+1)).
#[inline]
pub fn phong_lobe(s: f32, u: f32, v: f32) -> Vec3A {
    spherical(u.powf(1.0 / (s + 1.0)), v)
}

/// (s+1)/(2π) · cos^s θ for cos θ > 0, 0 otherwise.
#[inline]
pub fn phong_lobe_pdf(s: f32, cos_t: f32) -> f32 {
    if cos_t > 0.0 {
        (s + 1.0) * 0.5 * FRAC_1_PI * cos_t.powf(s)
    } else {
        0.0
    }
}

/// A GGX half vector of roughness `alpha` around z: tan θ_h = α √u / √(1 − u), so that
/// its density is D(h) cos θ_h.
#[inline]
pub fn ggx_half_vector(alpha: f32, u: f32, v: f32) -> Vec3A {
    // cos θ = 1/√(1 + tan²θ), written without forming tan θ (u → 1 would overflow).
    let t2 = alpha * alpha * u;
    let cos_t = ((1.0 - u) / (1.0 - u + t2)).sqrt();
    spherical(cos_t, v)
}

/// The GGX distribution of normals `D(h) = α² / (π cos⁴θ (α² + tan²θ)²)` for a half
/// vector at polar cosine `cos_t` (0 below the surface).
#[inline]
pub fn ggx_d(alpha: f32, cos_t: f32) -> f32 {
    if !(cos_t > 0.0) {
        return 0.0;
    }
    let a2 = alpha * alpha;
    let c2 = cos_t * cos_t;
    // cos⁴θ (α² + tan²θ)² = (α² cos²θ + sin²θ)²
    let k = a2 * c2 + (1.0 - c2);
    a2 / (PI * k * k)
}

/// The density of [`ggx_half_vector`]: D(h) cos θ_h.
#[inline]
pub fn ggx_half_vector_pdf(alpha: f32, cos_t: f32) -> f32 {
    ggx_d(alpha, cos_t) * cos_t.max(0.0)
}

#[cfg(test)]
mod tests {
    use super::super::chi2::chi2_test;
    use super::*;

    #[test]
    fn the_turns_sine_and_cosine_are_within_two_ulps_of_the_true_ones() {
        // Every 2⁻²⁰ of a turn and the quarter turns' neighbours: against f64, at most
        // 1.2·10⁻⁷ off (two ulps of numbers near 1; the C library's `sincosf` of the
        // rounded 2πv is off by up to 4·10⁻⁷ near a whole turn).
        let mut worst = 0.0f64;
        let quarter_edges = [0.125f32, 0.375, 0.625, 0.875, 0.25, 0.5, 0.75, 1.0];
        let edges = quarter_edges
            .iter()
            .flat_map(|&e| [crate::spawn::next_down(e), e, crate::spawn::next_up(e)]);
        for v in (0..=1u32 << 20).map(|i| i as f32 / (1u32 << 20) as f32).chain(edges) {
            let (s, c) = sin_cos_turns(v);
            let t = std::f64::consts::TAU * v as f64;
            worst = worst.max((s as f64 - t.sin()).abs()).max((c as f64 - t.cos()).abs());
        }
        assert!(worst < 1.2e-7, "{worst}");
    }

    #[test]
    fn hemisphere_and_cosine_follow_their_densities() {
        chi2_test(
            "uniform hemisphere",
            |u, v| Some(uniform_hemisphere(u, v)),
            |w| uniform_hemisphere_pdf(w.z),
        );
        chi2_test(
            "cosine",
            |u, v| Some(cosine_hemisphere(u, v)),
            |w| cosine_hemisphere_pdf(w.z),
        );
    }

    #[test]
    fn phong_lobes_follow_their_density() {
        for s in [0.0f32, 1.0, 10.0, 100.0, 1000.0] {
            chi2_test(
                &format!("phong lobe {s}"),
                |u, v| Some(phong_lobe(s, u, v)),
                |w| phong_lobe_pdf(s, w.z),
            );
        }
    }

    #[test]
    fn ggx_half_vectors_follow_their_density() {
        for alpha in [0.02f32, 0.1, 0.3, 0.6, 1.0, 2.0] {
            chi2_test(
                &format!("ggx {alpha}"),
                |u, v| Some(ggx_half_vector(alpha, u, v)),
                |w| ggx_half_vector_pdf(alpha, w.z),
            );
        }
    }

    #[test]
    fn ggx_normals_project_to_unit_area() {
        // ∫ D(h) cos θ_h dω = 1 (the microfacets cover the macro surface exactly).
        for alpha in [0.05f32, 0.3, 1.0] {
            let n = 20000;
            let mut sum = 0.0f64;
            for i in 0..n {
                // Midpoint rule in cos θ, where the integrand is smooth for these α.
                let c = (i as f64 + 0.5) / n as f64;
                sum += ggx_d(alpha, c as f32) as f64 * c * 2.0 * std::f64::consts::PI / n as f64;
            }
            assert!((sum - 1.0).abs() < 2e-3, "{alpha}: {sum}");
        }
    }
}
