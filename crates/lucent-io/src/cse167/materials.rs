//! The current material, which every object captures when it is created:
//! `ambient`, `diffuse`, `specular`, `emission`, `transparent` (colours), `shininess`,
//! `ior`, `glossy exponent samples|off`, and the CSE168 `brdf phong|ggx` and
//! `roughness`. Materials are not on the transform stack: nothing restores them.

use super::lexer::Command;
use super::parser::Parser;
use crate::desc::{Brdf, GlossyDesc};

/// More glossy rays than this per hit would only burn time.
const MAX_GLOSSY_SAMPLES: i64 = 4096;

impl Parser {
    /// `ambient`, `diffuse`, `specular`, `emission`, `transparent`: `r g b`.
    pub(super) fn material_color(&mut self, c: &Command) {
        if let Some(v) = self.nums::<3>(c) {
            let col = self.color_at(c, 0, &v);
            let name = c.name.text;
            self.set_material(|m| match name {
                "ambient" => m.ambient = col,
                "diffuse" => m.diffuse = col,
                "specular" => m.specular = col,
                "emission" => m.emission = col,
                _ => m.transparent = col,
            });
        }
    }

    /// `shininess s`, s ≥ 0.
    pub(super) fn shininess(&mut self, c: &Command) {
        if let Some([s]) = self.nums::<1>(c) {
            if s < 0.0 {
                self.err_arg(c, 0, format!("shininess: must not be negative, got {}", c.args[0].text));
            } else {
                self.set_material(|m| m.shininess = s);
            }
        }
    }

    /// `ior n`, n > 0: the index of refraction of the inside.
    pub(super) fn ior(&mut self, c: &Command) {
        if let Some([n]) = self.nums::<1>(c) {
            if n > 0.0 {
                self.set_material(|m| m.ior = n);
            } else {
                self.err_arg(c, 0, format!("ior: must be positive, got {}", c.args[0].text));
            }
        }
    }

    /// `glossy exponent samples` or `glossy off`.
    pub(super) fn glossy(&mut self, c: &Command) {
        if Self::is_off(c) {
            self.set_material(|m| m.glossy = None);
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
        if !self.in_range(c, 1, samples, 1..=MAX_GLOSSY_SAMPLES, "samples") {
            return;
        }
        let glossy = GlossyDesc {
            exponent,
            samples: samples as u32,
        };
        self.set_material(|m| m.glossy = Some(glossy));
    }

    /// `brdf phong|ggx|mirror`.
    pub(super) fn brdf(&mut self, c: &Command) {
        let models = [("phong", Brdf::Phong), ("ggx", Brdf::Ggx), ("mirror", Brdf::Mirror)];
        if let Some(b) = self.keyword(c, &models) {
            self.set_material(|m| m.brdf = b);
        }
    }

    /// `roughness alpha`, alpha > 0.
    pub(super) fn roughness(&mut self, c: &Command) {
        if let Some(a) = self.positive(c) {
            self.set_material(|m| m.roughness = a);
        }
    }
}
