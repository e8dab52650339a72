//! The transform stack (docs/scene-format.md, "Transforms"): `translate`, `rotate`, `scale` right-multiply
//! the current transform; `pushTransform` and `popTransform` save and restore it.

use glam::DVec3;
use lucent_core::transform::Transform;

use super::lexer::Command;
use super::parser::Parser;

impl Parser {
    /// `translate x y z`.
    pub(super) fn translate(&mut self, c: &Command) {
        if let Some(t) = self.nums::<3>(c) {
            self.apply(Transform::translate(DVec3::from_array(t)));
        }
    }

    /// `rotate x y z angle`: counter-clockwise, in degrees, about a non-zero axis.
    pub(super) fn rotate(&mut self, c: &Command) {
        if let Some(r) = self.nums::<4>(c) {
            match Transform::rotate(DVec3::new(r[0], r[1], r[2]), r[3]) {
                Some(t) => self.apply(t),
                None => self.err_span(c, 0, 3, "rotate: the rotation axis is zero"),
            }
        }
    }

    /// `scale x y z`: no zero factor.
    pub(super) fn scale(&mut self, c: &Command) {
        if let Some(s) = self.nums::<3>(c) {
            match Transform::scale(DVec3::from_array(s)) {
                Some(t) => self.apply(t),
                None => {
                    let k = s.iter().position(|&x| x == 0.0).unwrap_or(0);
                    self.err_arg(c, k, "scale: a zero factor makes the transform singular");
                }
            }
        }
    }

    pub(super) fn push_transform(&mut self, c: &Command) {
        if self.expect_count(c, 0, "no arguments") {
            self.stack.push(self.current);
            self.push_lines.push(c.line);
        }
    }

    pub(super) fn pop_transform(&mut self, c: &Command) {
        if self.expect_count(c, 0, "no arguments") {
            match self.stack.pop() {
                Some(t) => {
                    self.current = t;
                    self.current_id = None;
                    self.push_lines.pop();
                }
                None => self.err_cmd(c, "popTransform: transform stack is empty"),
            }
        }
    }
}
