//! Warps: two uniform numbers `(u, v)` in [0, 1)² to a direction in the local frame
//! (z along the normal or lobe axis), and the density of that direction in solid angle.
//! SCENE_FORMAT.md §4.6–§4.7 give the formulas; all take φ = 2πv.

use std::f32::consts::{FRAC_1_PI, PI};

use crate::math::Vec3A;

/// The local direction with polar cosine `cos_t` and azimuth `2π v`.
#[inline]
fn spherical(cos_t: f32, v: f32) -> Vec3A {
    let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
    let (s, c) = (2.0 * PI * v).sin_cos();
    Vec3A::new(sin_t * c, sin_t * s, cos_t)
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
