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
            self.apply_checked(c, Transform::translate(DVec3::from_array(t)));
        }
    }

    /// `rotate x y z angle`: counter-clockwise, in degrees, about a non-zero axis.
    pub(super) fn rotate(&mut self, c: &Command) {
        if let Some(r) = self.nums::<4>(c) {
            match Transform::rotate(DVec3::new(r[0], r[1], r[2]), r[3]) {
                Some(t) => self.apply_checked(c, t),
                None => self.err_span(c, 0, 3, "rotate: the rotation axis is zero"),
            }
        }
    }

    /// `scale x y z`: no zero factor.
    pub(super) fn scale(&mut self, c: &Command) {
        if let Some(s) = self.nums::<3>(c) {
            match Transform::scale(DVec3::from_array(s)) {
                Some(t) => self.apply_checked(c, t),
                None => {
                    let k = s.iter().position(|&x| x == 0.0).unwrap_or(0);
                    self.err_arg(c, k, "scale: a zero factor makes the transform singular");
                }
            }
        }
    }

    /// Applies `t` unless the result leaves single precision — entries of the matrix or
    /// its inverse beyond ±3.4e38 (`scale 1e30 1e30 1e30` twice), where objects would
    /// vanish — which is an error at this command.
    fn apply_checked(&mut self, c: &Command, t: Transform) {
        let next = self.current.then_apply(&t);
        let fits = |m: &glam::DAffine3| m.to_cols_array().iter().all(|x| x.abs() <= f32::MAX as f64);
        if !(fits(&next.m) && fits(&next.inv)) {
            let msg = format!(
                "{}: the transform would leave single precision (entries of it or of its inverse beyond 3.4e38)",
                c.name.text
            );
            self.err_cmd(c, msg);
            return;
        }
        self.apply(t);
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
