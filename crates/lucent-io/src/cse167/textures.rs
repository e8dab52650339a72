//! Textures and what uses them: `texture name file`, `checker name r1 g1 b1 r2 g2 b2
//! scale`, `diffusemap name|off`, `bumpmap name strength|off` (part of the material),
//! `displacementmap name scale|off` (for the surfaces that follow) and `envmap file
//! [intensity]` (global). Image files are only named here; the build reads them.

use super::lexer::Command;
use super::parser::Parser;
use crate::desc::{BumpDesc, DisplacementDesc, EnvironmentDesc, Located, TextureDesc, TextureSource};

impl Parser {
    /// `texture name file` and `checker name r1 g1 b1 r2 g2 b2 scale`.
    pub(super) fn texture(&mut self, c: &Command) {
        let source = if c.name.text == "checker" {
            let Some(v) = self.nums_after_name::<7>(c) else { return };
            if !(v[6] > 0.0) {
                self.err_arg(
                    c,
                    7,
                    format!("checker: the cell size must be positive, got {}", c.args[7].text),
                );
                return;
            }
            let a = self.color_at(c, 1, &v[0..3]);
            let b = self.color_at(c, 4, &v[3..6]);
            TextureSource::Checker { a, b, scale: v[6] }
        } else {
            if !self.expect_count(c, 2, "a texture name and an image file") {
                return;
            }
            TextureSource::Image(self.file_arg(c, 1))
        };
        let name = c.args[0].text;
        if let Some(t) = self.desc.textures.iter().find(|t| t.name == name) {
            let line = t.loc.line;
            self.err_arg(
                c,
                0,
                format!(
                    "{}: a texture named '{name}' is already defined on line {line}",
                    c.name.text
                ),
            );
            return;
        }
        self.desc.textures.push(TextureDesc {
            name: name.to_string(),
            source,
            loc: self.loc(c.line, &c.args[0]),
        });
    }

    /// The index of the texture named by argument `k`, or an error listing the names.
    fn texture_named(&mut self, c: &Command, k: usize) -> Option<u32> {
        let name = c.args[k].text;
        match self.desc.textures.iter().position(|t| t.name == name) {
            Some(i) => Some(i as u32),
            None => {
                let known: Vec<&str> = self.desc.textures.iter().map(|t| t.name.as_str()).collect();
                let defined = if known.is_empty() {
                    "no texture is defined yet".to_string()
                } else {
                    format!("defined: {}", known.join(", "))
                };
                self.err_arg(c, k, format!("{}: unknown texture '{name}' ({defined})", c.name.text));
                None
            }
        }
    }

    /// The texture and number of `command name number`; `None` after an error.
    fn texture_and_number(&mut self, c: &Command, what: &str) -> Option<(u32, f64)> {
        if !self.expect_count(c, 2, &format!("a texture name and {what}, or 'off'")) {
            return None;
        }
        let number = self.number(c, &c.args[1])?;
        let texture = self.texture_named(c, 0)?;
        Some((texture, number))
    }

    /// `diffusemap name` or `diffusemap off`.
    pub(super) fn diffuse_map(&mut self, c: &Command) {
        if !self.expect_count(c, 1, "a texture name or 'off'") {
            return;
        }
        let map = if c.args[0].text == "off" {
            None
        } else {
            let Some(t) = self.texture_named(c, 0) else { return };
            Some(t)
        };
        self.set_material(|m| m.diffuse_map = map);
    }

    /// `bumpmap name strength` or `bumpmap off`.
    pub(super) fn bump_map(&mut self, c: &Command) {
        let map = if Self::is_off(c) {
            None
        } else {
            let Some((texture, strength)) = self.texture_and_number(c, "a strength") else {
                return;
            };
            Some(BumpDesc { texture, strength })
        };
        self.set_material(|m| m.bump_map = map);
    }

    /// `displacementmap name scale` or `displacementmap off`: parser state, not part of
    /// the material; it applies to the meshes, subdivision surfaces, patches and NURBS
    /// that follow.
    pub(super) fn displacement_map(&mut self, c: &Command) {
        self.displacement = if Self::is_off(c) {
            None
        } else {
            let Some((texture, scale)) = self.texture_and_number(c, "a scale") else {
                return;
            };
            Some(DisplacementDesc { texture, scale })
        };
    }

    /// `envmap file [intensity]`.
    pub(super) fn environment(&mut self, c: &Command) {
        if !self.one_or_two(c, "an image file and optionally an intensity") {
            return;
        }
        let Some(intensity) = self.optional_second(c, 1.0, |p, c| {
            let i = p.number(c, &c.args[1])?;
            if i >= 0.0 {
                return Some(i);
            }
            let msg = format!("envmap: the intensity must not be negative, got {}", c.args[1].text);
            p.err_arg(c, 1, msg);
            None
        }) else {
            return;
        };
        let v = Located {
            value: EnvironmentDesc {
                file: self.file_arg(c, 0),
                intensity,
            },
            loc: self.loc(c.line, &c.name),
        };
        self.set_global(c, |d| &mut d.environment, v);
    }
}
