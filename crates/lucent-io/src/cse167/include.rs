//! Scene command `include file`: the commands of another scene file, read where the
//! command stands, as if they were written there (the transform stack, the material and
//! everything else carry on through it). The name is relative to the folder of the file
//! that includes it; diagnostics point into the included file. A file that includes
//! itself, directly or through others, is refused with the chain of files; so are more
//! than 32 levels, more than 10,000 inclusions in all (31 files that each include the
//! next twice would include 2³¹), and more included text than one scene file may hold.

use std::path::PathBuf;

use super::lexer::{self, Command};
use super::parser::Parser;
use crate::resources::input::{read_input, Inputs, MAX_SCENE_BYTES};

/// Files open inside one another at most.
const MAX_DEPTH: usize = 32;
/// Inclusions in all, at most (each keeps its file's lines for diagnostics).
pub const MAX_INCLUDES: usize = 10_000;

impl Parser {
    /// `include file`.
    pub(super) fn include(&mut self, c: &Command) {
        if !self.expect_count(c, 1, "a scene file") {
            return;
        }
        if self.desc.included.len() >= MAX_INCLUDES {
            self.err_arg(c, 0, format!("include: more than {MAX_INCLUDES} inclusions in all"));
            return;
        }
        let file = self.file_arg(c, 0);
        let path = file.value.clone();
        let left = MAX_SCENE_BYTES.saturating_sub(self.included_bytes);
        let bytes = match read_input(&path, left, &mut Inputs::default()) {
            Ok(b) => b,
            Err(e) => {
                self.err_arg(c, 0, format!("include: {}: {e}", path.display()));
                return;
            }
        };
        let canonical = std::fs::canonicalize(&path).unwrap_or_else(|_| path.clone());
        if let Some(at) = self.include_stack.iter().position(|p| *p == canonical) {
            let chain: Vec<String> = self.include_stack[at..]
                .iter()
                .chain(std::iter::once(&canonical))
                .map(|p| {
                    p.file_name()
                        .map_or_else(|| p.display().to_string(), |n| n.to_string_lossy().into_owned())
                })
                .collect();
            self.err_arg(c, 0, format!("include: a cycle: {}", chain.join(" includes ")));
            return;
        }
        if self.include_stack.len() >= MAX_DEPTH {
            self.err_arg(c, 0, format!("include: more than {MAX_DEPTH} files inside one another"));
            return;
        }
        self.included_bytes += bytes.len() as u64;
        let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(&bytes);
        let lines = lexer::split_lines(bytes);
        let shown: Vec<String> = lines.iter().map(|l| String::from_utf8_lossy(l).into_owned()).collect();
        let saved = (self.file, std::mem::replace(&mut self.base_dir, PathBuf::new()));
        self.base_dir = path.parent().map(|p| p.to_path_buf()).unwrap_or_default();
        self.file = self.desc.sources.add(path.display().to_string(), shown);
        self.desc.included.push(path);
        self.include_stack.push(canonical);
        for (i, raw) in lines.iter().enumerate() {
            if self.diags.too_many_errors() {
                break;
            }
            self.line(i as u32 + 1, raw);
        }
        self.include_stack.pop();
        (self.file, self.base_dir) = saved;
    }
}
