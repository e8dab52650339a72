//! `brdf mirror` in the Monte Carlo integrators: perfect specular reflection with
//! reflectance `specular` (a delta lobe; EXTENSIONS.md, "In the Monte Carlo integrators").

use super::DeltaSample;
use crate::math::{Color, Vec3A};
use crate::shading::optics::{reflect_above, side_of};

#[derive(Clone, Copy, Debug)]
pub struct Mirror {
    /// The shading normal.
    pub n: Vec3A,
    /// The true surface's normal, on the side of `n`.
    pub ng: Vec3A,
    /// `specular`: the reflectance.
    pub ks: Color,
}

impl Mirror {
    /// The mirror direction, kept on the viewer's side of the true surface.
    pub fn sample(&self, wo: Vec3A) -> Option<DeltaSample> {
        (self.ks != Color::ZERO).then(|| DeltaSample {
            wi: reflect_above(wo, self.n, side_of(wo, self.ng)),
            weight: self.ks,
            transmitted: false,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reflects_about_the_normal_with_the_specular_colour() {
        let m = Mirror {
            n: Vec3A::Y,
            ng: Vec3A::Y,
            ks: Color::new(0.9, 0.8, 0.7),
        };
        let s = m.sample(Vec3A::new(0.6, 0.8, 0.0)).unwrap();
        assert!((s.wi - Vec3A::new(-0.6, 0.8, 0.0)).length() < 1e-6);
        assert_eq!(s.weight, m.ks);
        assert!(Mirror { ks: Color::ZERO, ..m }.sample(Vec3A::Y).is_none());
    }
}
