//! The extension commands that make the ray tracer sample: `glossy exponent samples`
//! (part of the material) and `lens aperture focusdistance` (global).

use super::{Command, Parser};
use crate::desc::Located;
use lucent_core::shading::material::Glossy;

/// More glossy rays than this per hit would only burn time.
const MAX_GLOSSY_SAMPLES: i64 = 4096;

impl Parser {
    /// `glossy exponent samples` or `glossy off`.
    pub(super) fn glossy(&mut self, c: &Command) {
        if c.args.len() == 1 && c.args[0].text == "off" {
            self.material.base.glossy = None;
            self.material_id = None;
            return;
        }
        if !self.expect_count(c, 2, "an exponent and a number of samples, or 'off'") {
            return;
        }
        let (Some(exponent), Some(samples)) = (self.number(c, &c.args[0]), self.integer(c, &c.args[1])) else {
            return;
        };
        if !(exponent >= 0.0 && exponent.is_finite()) {
            self.err_arg(
                c,
                0,
                format!("glossy: the exponent must not be negative, got {}", c.args[0].text),
            );
            return;
        }
        if !(1..=MAX_GLOSSY_SAMPLES).contains(&samples) {
            self.err_arg(
                c,
                1,
                format!("glossy: samples must be between 1 and {MAX_GLOSSY_SAMPLES}, got {samples}"),
            );
            return;
        }
        self.material.base.glossy = Some(Glossy {
            exponent: exponent as f32,
            samples: samples as u32,
        });
        self.material_id = None;
    }

    /// `lens aperture focusdistance`: aperture ≥ 0 (0 is the pinhole), focus > 0.
    pub(super) fn lens(&mut self, c: &Command) {
        let Some([aperture, focus]) = self.nums::<2>(c) else {
            return;
        };
        if aperture < 0.0 {
            self.err_arg(
                c,
                0,
                format!("lens: the aperture must not be negative, got {}", c.args[0].text),
            );
            return;
        }
        if !(focus > 0.0) {
            self.err_arg(
                c,
                1,
                format!("lens: the focus distance must be positive, got {}", c.args[1].text),
            );
            return;
        }
        let v = Located {
            value: (aperture, focus),
            loc: self.loc(c.line, &c.name),
        };
        self.set_global(c, |d| &mut d.lens, v);
    }
}
