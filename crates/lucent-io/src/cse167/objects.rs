//! Named objects: `objectbegin name` … `objectend` records shapes as an object instead
//! of adding them to the scene, and `instance name` places the object with the current
//! transform (the geometry is shared, never copied).
//!
//! Objects do not nest, cannot hold instances (one level of instancing, as in pbrt) and
//! cannot hold lights; a name is defined once.

use super::lexer::Command;
use super::parser::Parser;
use crate::desc::{ObjectDesc, ShapeKind};

impl Parser {
    pub(super) fn object_begin(&mut self, c: &Command) {
        if !self.expect_count(c, 1, "an object name") {
            return;
        }
        let name = c.args[0].text;
        if self.refused_inside_object(c, "objects cannot be nested", "has no objectend yet") {
            return;
        }
        if let Some(o) = self.desc.objects.iter().find(|o| o.name == name) {
            let line = o.loc.line;
            self.err_arg(
                c,
                0,
                format!("objectbegin: an object named '{name}' is already defined on line {line}"),
            );
            return;
        }
        self.desc.objects.push(ObjectDesc {
            name: name.to_string(),
            loc: self.loc(c.line, &c.args[0]),
        });
        self.object = Some((self.desc.objects.len() as u32 - 1, c.line));
    }

    pub(super) fn object_end(&mut self, c: &Command) {
        if !self.expect_count(c, 0, "no arguments") {
            return;
        }
        match self.object.take() {
            None => self.err_cmd(c, "objectend without objectbegin"),
            Some((o, _)) => {
                if !self.desc.shapes.iter().any(|s| s.object == Some(o)) {
                    let name = &self.desc.objects[o as usize].name;
                    self.warn_cmd(c, format!("objectend: object '{name}' is empty"));
                }
            }
        }
    }

    pub(super) fn instance(&mut self, c: &Command) {
        if !self.expect_count(c, 1, "an object name") {
            return;
        }
        let name = c.args[0].text;
        if self.refused_inside_object(c, "objects cannot contain instances", "is still open") {
            return;
        }
        let Some(object) = self.desc.objects.iter().position(|o| o.name == name) else {
            let known: Vec<&str> = self.desc.objects.iter().map(|o| o.name.as_str()).collect();
            let defined = if known.is_empty() {
                "no object is defined yet".to_string()
            } else {
                format!("defined: {}", known.join(", "))
            };
            self.err_arg(c, 0, format!("instance: unknown object '{name}' ({defined})"));
            return;
        };
        self.shape(c, ShapeKind::Instance { object: object as u32 });
    }

    /// An error if an object is being recorded: `command: why (object 'a' begun on line
    /// N state)`.
    fn refused_inside_object(&mut self, c: &Command, why: &str, state: &str) -> bool {
        let Some((open, line)) = self.object else {
            return false;
        };
        let open = &self.desc.objects[open as usize].name;
        let msg = format!("{}: {why} (object '{open}' begun on line {line} {state})", c.name.text);
        self.err_cmd(c, msg);
        true
    }

    /// At the end of the file: an object still open is an error at its `objectbegin`.
    pub(super) fn unclosed_object(&mut self) {
        if let Some((o, _)) = self.object.take() {
            let object = &self.desc.objects[o as usize];
            let msg = format!("objectbegin: object '{}' has no objectend", object.name);
            self.diags.error(object.loc, msg);
        }
    }
}
