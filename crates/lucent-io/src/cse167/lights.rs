//! Lights: `directional dx dy dz r g b`, `point x y z r g b` (with the current
//! `attenuation c0 c1 c2`) and `quadLight a ab ac r g b`, each under the current
//! transform. Lights cannot be part of an object.

use glam::DVec3;

use super::lexer::Command;
use super::parser::Parser;
use crate::desc::{LightDesc, LightKind};

impl Parser {
    pub(super) fn directional(&mut self, c: &Command) {
        if let Some(v) = self.nums::<6>(c) {
            let dir = DVec3::new(v[0], v[1], v[2]);
            if dir.length() == 0.0 {
                self.err_span(c, 0, 3, "directional: the direction is zero");
                return;
            }
            let color = self.color_at(c, 3, &v[3..6]);
            self.light(c, LightKind::Directional { dir, color });
        }
    }

    pub(super) fn point(&mut self, c: &Command) {
        if let Some(v) = self.nums::<6>(c) {
            let color = self.color_at(c, 3, &v[3..6]);
            let position = DVec3::new(v[0], v[1], v[2]);
            let attenuation = self.attenuation;
            self.light(
                c,
                LightKind::Point {
                    position,
                    color,
                    attenuation,
                },
            );
        }
    }

    /// `attenuation c0 c1 c2`: for the point lights that follow; not negative, not all 0.
    pub(super) fn attenuation(&mut self, c: &Command) {
        if let Some(a) = self.nums::<3>(c) {
            if let Some(k) = a.iter().position(|&x| x < 0.0) {
                self.err_arg(c, k, "attenuation: coefficients must not be negative");
            } else if a.iter().all(|&x| x == 0.0) {
                self.err_span(c, 0, 3, "attenuation: all three coefficients are zero (infinite light)");
            } else {
                self.attenuation = DVec3::from_array(a);
            }
        }
    }

    pub(super) fn quad_light(&mut self, c: &Command) {
        if let Some(v) = self.nums::<12>(c) {
            let a = DVec3::new(v[0], v[1], v[2]);
            let ab = DVec3::new(v[3], v[4], v[5]);
            let ac = DVec3::new(v[6], v[7], v[8]);
            if ab.cross(ac).length() == 0.0 {
                self.err_span(
                    c,
                    3,
                    6,
                    "quadLight: the edges ab and ac are parallel or zero (the light has no area)",
                );
                return;
            }
            let color = self.color_at(c, 9, &v[9..12]);
            self.light(c, LightKind::Quad { a, ab, ac, color });
        }
    }

    /// Records a light of command `c` under the current transform.
    fn light(&mut self, c: &Command, kind: LightKind) {
        if let Some((o, line)) = self.object {
            let name = &self.desc.objects[o as usize].name;
            self.err_cmd(
                c,
                format!(
                    "{}: lights cannot be part of an object (object '{name}' begun on line {line} is still open)",
                    c.name.text
                ),
            );
            return;
        }
        if !self.current.is_identity() {
            self.warn_cmd(c, format!("{}: the light is transformed by the current transform (the course's renderers ignore transforms on lights)", c.name.text));
        }
        let transform = self.transform_id();
        let loc = self.loc(c.line, &c.name);
        self.desc.lights.push(LightDesc { kind, transform, loc });
    }
}
