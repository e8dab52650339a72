//! The CSE167/CSE168 scene format and lucent's extensions to it (docs/scene-format.md
//! lists every command with its arguments, defaults and errors), read into a
//! [`SceneDesc`].
//!
//! The file is a program that changes a parser state (transform stack, current material,
//! attenuation, vertex piles); commands that create objects capture a snapshot of it.
//! The parser checks each command where it stands — argument count, number syntax,
//! ranges, indices, names — and records what it says with its location. It reads no
//! other file but the scene text that `include` names, and builds nothing: the build
//! step ([`crate::build`]) does.
//!
//! The rooms: [`lexer`] (lines and tokens), `args` (reading arguments), `parser` (the
//! state and how objects capture it), `commands` (the command table that dispatches every
//! line), and one file per family of commands: `settings`, `camera`, `transforms`,
//! `lights`, `materials`, `textures`, `geometry`, `surfaces`, `nurbs`, `objects`, and
//! `include` (the one command that reads another file: more scene text).

mod args;
mod camera;
mod commands;
mod geometry;
mod include;
mod lexer;
mod lights;
mod materials;
mod nurbs;
mod objects;
mod parser;
mod settings;
mod surfaces;
mod textures;
mod transforms;

use std::path::Path;

pub use commands::command_names;

use crate::desc::SceneDesc;
use crate::diag::{Diagnostics, Loc};
use crate::resources::input::{bytes as bytes_text, MAX_SCENE_BYTES};
use crate::resources::{read_input, Resources};
use parser::Parser;

/// Images larger than this many pixels are refused.
pub const MAX_PIXELS: u64 = 1 << 26;

#[derive(Clone, Copy, Debug, Default)]
pub struct ParseOptions {
    /// Unknown commands are errors instead of warnings.
    pub strict: bool,
}

/// Reads and parses a scene file (a regular file of at most [`MAX_SCENE_BYTES`]),
/// recorded in `res`. A file that cannot be read is an error at `path:1:1`.
pub fn parse_file(path: &Path, options: ParseOptions, res: &mut Resources) -> (SceneDesc, Diagnostics) {
    parse_file_with(path, options, res, &[])
}

/// [`parse_file`] with command-line overrides ([`parse_bytes_with`]).
pub fn parse_file_with(
    path: &Path,
    options: ParseOptions,
    res: &mut Resources,
    overrides: &[String],
) -> (SceneDesc, Diagnostics) {
    // The text, and then its description at about eight bytes for each byte of text,
    // are taken from the budget before the file is read.
    let size = std::fs::metadata(path).map_or(0, |m| m.len());
    let what = format!("the scene file of {}", bytes_text(size));
    let read = res
        .budget
        .take(size.saturating_mul(9), &what)
        .and_then(|_| read_input(path, MAX_SCENE_BYTES, &mut res.inputs));
    match read {
        Ok(bytes) => parse_bytes_with(&path.display().to_string(), &bytes, options, overrides),
        Err(e) => {
            let mut desc = SceneDesc::default();
            let file = desc.sources.add(path.display().to_string(), Vec::new());
            let mut diags = Diagnostics::default();
            diags.error(
                Loc {
                    file,
                    line: 1,
                    col: 1,
                    len: 0,
                },
                format!("cannot read scene file: {e}"),
            );
            (desc, diags)
        }
    }
}

/// Parses scene text; `name` is what diagnostics call the file, and files the scene
/// names are resolved against its folder.
pub fn parse_bytes(name: &str, bytes: &[u8], options: ParseOptions) -> (SceneDesc, Diagnostics) {
    parse_bytes_with(name, bytes, options, &[])
}

/// The scene settings a command line may override (`-D name=value`, `--size`, …).
pub const SETTINGS: [&str; 13] = [
    "size",
    "output",
    "maxdepth",
    "gamma",
    "integrator",
    "spp",
    "lightsamples",
    "lightstratify",
    "nexteventestimation",
    "russianroulette",
    "importancesampling",
    "sampler",
    "noisethreshold",
];

/// [`parse_bytes`], then `overrides`: lines of scene settings (`spp 64`) read as if they
/// ended the file, each replacing what the file said without a warning. Their
/// diagnostics point into a source called "command line"; a line that is not a setting
/// is an error there.
pub fn parse_bytes_with(
    name: &str,
    bytes: &[u8],
    options: ParseOptions,
    overrides: &[String],
) -> (SceneDesc, Diagnostics) {
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let raw_lines = lexer::split_lines(bytes);
    let shown: Vec<String> = raw_lines
        .iter()
        .map(|l| String::from_utf8_lossy(l).into_owned())
        .collect();
    let mut p = Parser::new(options);
    p.base_dir = Path::new(name).parent().map(Path::to_path_buf).unwrap_or_default();
    p.file = p.desc.sources.add(name.to_string(), shown);
    if let Ok(canonical) = std::fs::canonicalize(name) {
        p.include_stack.push(canonical);
    }
    for (i, raw) in raw_lines.iter().enumerate() {
        if p.diags.too_many_errors() {
            break;
        }
        p.line(i as u32 + 1, raw);
    }
    if !overrides.is_empty() {
        let file = p.file;
        p.file = p
            .desc
            .sources
            .add_command_line("command line".into(), overrides.to_vec());
        p.overriding = true;
        for (i, line) in overrides.iter().enumerate() {
            let name = line.split_whitespace().next().unwrap_or("");
            if SETTINGS.contains(&name) {
                p.line(i as u32 + 1, line.as_bytes());
            } else {
                let loc = Loc {
                    file: p.file,
                    line: i as u32 + 1,
                    col: 1,
                    len: name.len().max(1) as u32,
                };
                p.diags.error(
                    loc,
                    format!("-D: '{name}' is not a scene setting (one of {})", SETTINGS.join(", ")),
                );
            }
        }
        p.overriding = false;
        p.file = file;
    }
    p.finish(raw_lines.len() as u32);
    (p.desc, p.diags)
}
