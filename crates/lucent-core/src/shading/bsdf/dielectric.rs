//! The smooth dielectric of `transparent Kt` with `ior n` in the Monte Carlo integrators
//! (EXTENSIONS.md, "In the Monte Carlo integrators"): an interface between the outside
//! (index 1) and the inside (index n) that reflects with probability F, the unpolarised
//! Fresnel reflectance, and otherwise refracts by Snell's law. Both lobes are deltas: the
//! reflected ray has weight 1, the refracted one `Kt` (no η² scaling of radiance); total
//! internal reflection always reflects.

use super::DeltaSample;
use crate::math::{Color, Vec3A};
use crate::shading::optics::{fresnel_dielectric, lift_above, reflect_above, refract, side_of};

#[derive(Clone, Copy, Debug)]
pub struct Dielectric {
    /// The shading normal, pointing outside.
    pub n: Vec3A,
    /// The true surface's normal, on the side of `n`.
    pub ng: Vec3A,
    /// Index of refraction of the inside.
    pub ior: f32,
    /// The weight of the refracted ray.
    pub kt: Color,
}

impl Dielectric {
    /// Reflection when `pick < F`, refraction otherwise.
    pub fn sample(&self, wo: Vec3A, pick: f32) -> Option<DeltaSample> {
        let cos_o = wo.dot(self.n);
        // Arriving from outside when the viewer is on the side the normal points to.
        let (facing, n_i, n_t) = if cos_o > 0.0 {
            (self.n, 1.0, self.ior)
        } else {
            (-self.n, self.ior, 1.0)
        };
        let f = fresnel_dielectric(cos_o.abs(), n_i, n_t);
        // The viewer's side of the true surface: reflected rays leave on it, refracted
        // rays on the other, whatever the shading normal says.
        let viewer = side_of(wo, self.ng);
        if pick < f {
            return Some(DeltaSample {
                wi: reflect_above(wo, facing, viewer),
                weight: Color::ONE,
                transmitted: false,
            });
        }
        let wi = refract(-wo, facing, n_i / n_t)?;
        Some(DeltaSample {
            wi: lift_above(wi, -viewer, 0.01),
            weight: self.kt,
            transmitted: true,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn glass() -> Dielectric {
        Dielectric {
            n: Vec3A::Z,
            ng: Vec3A::Z,
            ior: 1.5,
            kt: Color::new(1.0, 0.5, 0.25),
        }
    }

    #[test]
    fn reflects_with_the_fresnel_probability_and_refracts_otherwise() {
        let g = glass();
        let wo = Vec3A::new(0.6, 0.0, 0.8);
        let f = fresnel_dielectric(0.8, 1.0, 1.5);
        let below = g.sample(wo, f * 0.999).unwrap();
        assert!(!below.transmitted && below.weight == Color::ONE);
        assert!((below.wi - Vec3A::new(-0.6, 0.0, 0.8)).length() < 1e-6);
        let above = g.sample(wo, f * 1.001 + 1e-6).unwrap();
        assert!(above.transmitted && above.weight == g.kt);
        // Snell: sin θt = sin θi / 1.5, on the other side.
        assert!((above.wi.x + 0.6 / 1.5).abs() < 1e-6 && above.wi.z < 0.0);
    }

    #[test]
    fn leaving_the_inside_past_the_critical_angle_always_reflects() {
        let g = glass();
        // From inside (below the outward normal), 60° off the normal: sin 60° · 1.5 > 1.
        let wo = Vec3A::new(0.866, 0.0, -0.5);
        for pick in [0.0, 0.5, 0.999] {
            let s = g.sample(wo, pick).unwrap();
            assert!(!s.transmitted && s.wi.z < 0.0, "{s:?}");
        }
        // Near the normal it leaves the glass, bent away from the normal.
        let s = g.sample(Vec3A::new(0.3, 0.0, -0.954).normalize(), 0.999).unwrap();
        assert!(s.transmitted && s.wi.z > 0.0 && s.wi.x.abs() > 0.3);
    }
}
