//! Textures and what uses them: `texture name file`, `checker name r1 g1 b1 r2 g2 b2
//! scale`, `diffusemap name|off`, `bumpmap name strength|off` (part of the material) and
//! `envmap file [intensity]` (global). Image files are read here, relative to the scene
//! file's folder, so that their errors point at the command.

use super::{Command, Parser};
use crate::desc::{Located, TextureDesc};
use crate::texture_file::load_image;
use lucent_core::shading::material::BumpMap;
use lucent_core::shading::texture::{EnvironmentMap, Texture};

impl Parser {
    /// `texture name file` and `checker name r1 g1 b1 r2 g2 b2 scale`.
    pub(super) fn texture(&mut self, c: &Command) {
        let texture = if c.name.text == "checker" {
            let Some(v) = self.nums_after_name::<7>(c) else { return };
            if !(v[6] > 0.0) {
                self.err_arg(
                    c,
                    7,
                    format!("checker: the cell size must be positive, got {}", c.args[7].text),
                );
                return;
            }
            let a = self.color_at(c, 1, &v[0..3]).as_vec3a();
            let b = self.color_at(c, 4, &v[3..6]).as_vec3a();
            Texture::Checker {
                a,
                b,
                scale: v[6] as f32,
            }
        } else {
            if !self.expect_count(c, 2, "a texture name and an image file") {
                return;
            }
            let path = self.base_dir.join(c.args[1].text);
            match load_image(&path) {
                Ok(img) => Texture::Image(img),
                Err(e) => {
                    self.err_arg(c, 1, format!("texture: {}: {e}", path.display()));
                    return;
                }
            }
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
            texture,
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
        self.material.base.diffuse_map = map;
        self.material_id = None;
    }

    /// `bumpmap name strength` or `bumpmap off`.
    pub(super) fn bump_map(&mut self, c: &Command) {
        if c.args.len() == 1 && c.args[0].text == "off" {
            self.material.base.bump_map = None;
            self.material_id = None;
            return;
        }
        if !self.expect_count(c, 2, "a texture name and a strength, or 'off'") {
            return;
        }
        let Some(strength) = self.number(c, &c.args[1]) else {
            return;
        };
        let Some(texture) = self.texture_named(c, 0) else {
            return;
        };
        self.material.base.bump_map = Some(BumpMap {
            texture,
            strength: strength as f32,
        });
        self.material_id = None;
    }

    /// `displacementmap name scale` or `displacementmap off`: parser state, not part of
    /// the material; it applies to the meshes, subdivision surfaces, patches and NURBS
    /// that follow.
    pub(super) fn displacement_map(&mut self, c: &Command) {
        if c.args.len() == 1 && c.args[0].text == "off" {
            self.displacement = None;
            return;
        }
        if !self.expect_count(c, 2, "a texture name and a scale, or 'off'") {
            return;
        }
        let Some(scale) = self.number(c, &c.args[1]) else {
            return;
        };
        let Some(texture) = self.texture_named(c, 0) else {
            return;
        };
        self.displacement = Some((texture, scale as f32));
    }

    /// `envmap file [intensity]`.
    pub(super) fn environment(&mut self, c: &Command) {
        if c.args.is_empty() || c.args.len() > 2 {
            let n = c.args.len();
            self.err_cmd(
                c,
                format!("envmap: expected an image file and optionally an intensity, got {n} arguments"),
            );
            return;
        }
        let intensity = match c.args.get(1) {
            None => 1.0,
            Some(tok) => match self.number(c, tok) {
                Some(i) if i >= 0.0 => i,
                Some(_) => {
                    self.err_arg(
                        c,
                        1,
                        format!("envmap: the intensity must not be negative, got {}", tok.text),
                    );
                    return;
                }
                None => return,
            },
        };
        let path = self.base_dir.join(c.args[0].text);
        let image = match load_image(&path) {
            Ok(img) => img,
            Err(e) => {
                self.err_arg(c, 0, format!("envmap: {}: {e}", path.display()));
                return;
            }
        };
        let v = Located {
            value: EnvironmentMap {
                image,
                intensity: intensity as f32,
            },
            loc: self.loc(c.line, &c.name),
        };
        self.set_global(c, |d| &mut d.environment, v);
    }

    /// The numbers after a leading name argument (`checker name …`).
    fn nums_after_name<const N: usize>(&mut self, c: &Command) -> Option<[f64; N]> {
        if !self.expect_count(c, N + 1, &format!("a name and {N} numbers")) {
            return None;
        }
        let mut out = [0.0; N];
        for (k, slot) in out.iter_mut().enumerate() {
            *slot = self.number(c, &c.args[k + 1])?;
        }
        Some(out)
    }
}
