//! The χ² goodness-of-fit test of a sampling routine against its own density (as pbrt-v4
//! and Mitsuba 3 test theirs): draw a million directions, count them in 32 × 64 bins of
//! the sphere (θ, φ), integrate the claimed density over every bin for the expected
//! counts, pool the bins expected to get fewer than 5, and reject when Pearson's χ² has a
//! p-value below [`SIGNIFICANCE`] (or when a sample falls where the density claims
//! nothing). The random numbers are fixed, so the outcome never changes. The level is
//! pbrt's: 1% for the whole family of about 40 tested routines (Šidák:
//! 1 − 0.99^(1/40) ≈ 2.5 · 10⁻⁴ each), so that a correct routine's seed is rejected with
//! a chance of one in a hundred for all of them together; a density 2% wrong in half
//! the hemisphere is still rejected ([`tests::a_wrong_density_is_rejected`]).

use std::f64::consts::PI;

use crate::math::Vec3A;
use crate::sampler::Sampler;

const THETA_BINS: usize = 32;
const PHI_BINS: usize = 64;
/// Sub-intervals per bin for the expected counts, along θ and φ.
const THETA_SUBDIVISIONS: usize = 16;
const PHI_SUBDIVISIONS: usize = 4;
pub const SAMPLES: usize = 1_000_000;
pub const SIGNIFICANCE: f64 = 2.5e-4;

fn bin_of(w: Vec3A) -> usize {
    let w = w.normalize();
    let theta = (w.z as f64).clamp(-1.0, 1.0).acos();
    let mut phi = (w.y as f64).atan2(w.x as f64);
    if phi < 0.0 {
        phi += 2.0 * PI;
    }
    // Bins are (a, b] in θ: a direction exactly on the horizon (cos θ = 0, which the
    // hemisphere warps draw at u = 0) belongs to the upper hemisphere's last row.
    let t = ((theta / PI * THETA_BINS as f64).ceil() as usize).clamp(1, THETA_BINS) - 1;
    let p = ((phi / (2.0 * PI) * PHI_BINS as f64) as usize).min(PHI_BINS - 1);
    t * PHI_BINS + p
}

/// The outcome: the statistic, its degrees of freedom and the p-value.
#[derive(Debug)]
pub struct Chi2 {
    pub statistic: f64,
    pub dof: usize,
    pub p_value: f64,
}

/// Runs the test on `sample` (two uniform numbers to a direction, `None` when the routine
/// draws nothing) against `pdf` (solid-angle density of a direction); panics with the
/// routine's `name` when it fails, and returns the figures otherwise.
pub fn chi2_test(name: &str, sample: impl FnMut(f32, f32) -> Option<Vec3A>, pdf: impl Fn(Vec3A) -> f32) -> Chi2 {
    chi2_test_at(name, (THETA_SUBDIVISIONS, PHI_SUBDIVISIONS), sample, pdf)
}

/// [`chi2_test`] for a density with edges inside the bins (an area light's outline):
/// the expected counts on a grid of 64 × 64 sub-intervals per bin, where a cut bin's
/// integration error is a small part of its noise.
pub fn chi2_test_edged(name: &str, sample: impl FnMut(f32, f32) -> Option<Vec3A>, pdf: impl Fn(Vec3A) -> f32) -> Chi2 {
    chi2_test_at(name, (64, 64), sample, pdf)
}

fn chi2_test_at(
    name: &str,
    subdivisions: (usize, usize),
    mut sample: impl FnMut(f32, f32) -> Option<Vec3A>,
    pdf: impl Fn(Vec3A) -> f32,
) -> Chi2 {
    let mut observed = vec![0f64; THETA_BINS * PHI_BINS];
    for i in 0..SAMPLES {
        let (u, v) = Sampler::new(0x5eed, i as u32, 0, 0).uniform2();
        if let Some(w) = sample(u, v) {
            assert!(w.is_finite(), "{name}: sample {i} is {w}");
            observed[bin_of(w)] += 1.0;
        }
    }
    let expected = expected_counts(&pdf, subdivisions);
    let result = pearson(&observed, &expected).unwrap_or_else(|e| panic!("{name}: {e}"));
    eprintln!(
        "chi2 {name}: statistic {:.1}, {} degrees of freedom, p = {:.3}",
        result.statistic, result.dof, result.p_value
    );
    assert!(
        result.p_value >= SIGNIFICANCE,
        "{name}: the samples do not follow the density (chi2 {:.1}, dof {}, p = {:.2e})",
        result.statistic,
        result.dof,
        result.p_value
    );
    result
}

/// `SAMPLES` × the integral of `pdf` over every bin: two-point Gauss–Legendre on a
/// 16 × 4 grid of sub-intervals in (θ, φ) — interior points only, so that a density that
/// jumps at a bin edge (the horizon) is not read on the wrong side of it.
fn expected_counts(pdf: &impl Fn(Vec3A) -> f32, (theta_sub, phi_sub): (usize, usize)) -> Vec<f64> {
    let (dt, dp) = (PI / THETA_BINS as f64, 2.0 * PI / PHI_BINS as f64);
    let nodes = |sub: usize| -> Vec<f64> {
        let h = 1.0 / sub as f64;
        let off = h * 0.5 / 3f64.sqrt();
        (0..sub)
            .flat_map(|k| {
                let mid = (k as f64 + 0.5) * h;
                [mid - off, mid + off]
            })
            .collect()
    };
    let (theta_nodes, phi_nodes) = (nodes(theta_sub), nodes(phi_sub));
    let cell = dt * dp / (theta_nodes.len() * phi_nodes.len()) as f64;
    let mut out = vec![0.0; THETA_BINS * PHI_BINS];
    for t in 0..THETA_BINS {
        for p in 0..PHI_BINS {
            let mut sum = 0.0;
            for &i in &theta_nodes {
                let (st, ct) = ((t as f64 + i) * dt).sin_cos();
                for &j in &phi_nodes {
                    let phi = (p as f64 + j) * dp;
                    let w = Vec3A::new((st * phi.cos()) as f32, (st * phi.sin()) as f32, ct as f32);
                    sum += pdf(w) as f64 * st;
                }
            }
            out[t * PHI_BINS + p] = sum * cell * SAMPLES as f64;
        }
    }
    out
}

/// Pearson's test with the bins expected to get fewer than 5 pooled into one.
pub fn pearson(observed: &[f64], expected: &[f64]) -> Result<Chi2, String> {
    let mut order: Vec<usize> = (0..observed.len()).collect();
    order.sort_by(|&a, &b| expected[a].total_cmp(&expected[b]));
    let (mut pooled_o, mut pooled_e, mut pooled_n) = (0.0, 0.0, 0);
    let (mut statistic, mut dof) = (0.0, 0usize);
    for &i in &order {
        let (o, e) = (observed[i], expected[i]);
        if e <= 0.0 && o > 0.0 {
            return Err(format!("{o} samples in bin {i}, where the density is 0"));
        }
        if e < 5.0 {
            pooled_o += o;
            pooled_e += e;
            pooled_n += 1;
        } else {
            statistic += (o - e) * (o - e) / e;
            dof += 1;
        }
    }
    if pooled_n > 0 && pooled_e > 0.0 {
        statistic += (pooled_o - pooled_e) * (pooled_o - pooled_e) / pooled_e;
        dof += 1;
    } else if pooled_o > 0.0 && pooled_e <= 0.0 {
        return Err(format!("{pooled_o} samples where the density is 0"));
    }
    if dof < 2 {
        return Err(format!("only {dof} bins with enough expected samples"));
    }
    let dof = dof - 1;
    Ok(Chi2 {
        statistic,
        dof,
        p_value: upper_incomplete_gamma(dof as f64 / 2.0, statistic / 2.0),
    })
}

/// The regularised upper incomplete gamma function Q(a, x) = Γ(a, x)/Γ(a): the
/// probability that a χ² variable of 2a degrees of freedom exceeds 2x. A power series
/// below x = a + 1, Lentz's continued fraction above.
pub fn upper_incomplete_gamma(a: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 1.0;
    }
    let log_prefix = a * x.ln() - x - ln_gamma(a);
    if x < a + 1.0 {
        let (mut term, mut sum, mut k) = (1.0 / a, 1.0 / a, a);
        while term.abs() > sum.abs() * 1e-15 {
            k += 1.0;
            term *= x / k;
            sum += term;
        }
        1.0 - sum * log_prefix.exp()
    } else {
        let tiny = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..10_000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < tiny {
                d = tiny;
            }
            c = b + an / c;
            if c.abs() < tiny {
                c = tiny;
            }
            d = 1.0 / d;
            let step = d * c;
            h *= step;
            if (step - 1.0).abs() < 1e-15 {
                break;
            }
        }
        h * log_prefix.exp()
    }
}

/// ln Γ(x) for x > 0 (Lanczos, g = 7, nine terms: 15 digits).
fn ln_gamma(x: f64) -> f64 {
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        // Reflection: Γ(x) Γ(1 − x) = π / sin(πx).
        return (PI / (PI * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut a = C[0];
    let t = x + 7.5;
    for (i, c) in C.iter().enumerate().skip(1) {
        a += c / (x + i as f64);
    }
    0.5 * (2.0 * PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

#[cfg(test)]
mod tests {
    use super::super::warp::{cosine_hemisphere, uniform_hemisphere_pdf};
    use super::*;

    #[test]
    fn the_chi2_distribution_is_right() {
        // Known quantiles: P(χ²₁ > 3.841) = 0.05, P(χ²₁₀ > 23.209) = 0.01,
        // P(χ²₁₀₀ > 124.342) = 0.05; and Q(1, x) = e^(−x).
        assert!((upper_incomplete_gamma(0.5, 3.841 / 2.0) - 0.05).abs() < 1e-4);
        assert!((upper_incomplete_gamma(5.0, 23.209 / 2.0) - 0.01).abs() < 1e-5);
        assert!((upper_incomplete_gamma(50.0, 124.342 / 2.0) - 0.05).abs() < 1e-4);
        for x in [0.1, 1.0, 2.0, 5.0, 30.0] {
            assert!((upper_incomplete_gamma(1.0, x) - (-x as f64).exp()).abs() < 1e-12);
        }
        assert!((ln_gamma(5.0) - 24f64.ln()).abs() < 1e-12);
    }

    #[test]
    fn a_wrong_density_is_rejected() {
        // Cosine-weighted samples against the uniform hemisphere's density.
        let r = std::panic::catch_unwind(|| {
            chi2_test(
                "cosine vs uniform",
                |u, v| Some(cosine_hemisphere(u, v)),
                |w| uniform_hemisphere_pdf(w.z),
            )
        });
        assert!(r.is_err());
        // A density 2% too large in one half of the hemisphere (and 2% too small in the other).
        let r = std::panic::catch_unwind(|| {
            chi2_test(
                "cosine, skewed",
                |u, v| Some(cosine_hemisphere(u, v)),
                |w| super::super::warp::cosine_hemisphere_pdf(w.z) * if w.x > 0.0 { 1.02 } else { 0.98 },
            )
        });
        assert!(r.is_err());
    }
}
