//! Diagnostics: errors, warnings and notes that point at a place in a source file, printed
//! as `file:line:col: error: message` followed by the offending line and a caret.

use std::fmt::{self, Write as _};

/// A place in a source file of the [`SourceMap`]: 1-based line and column (in
/// characters), and the length of the span the caret underlines.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Loc {
    pub file: u32,
    pub line: u32,
    pub col: u32,
    pub len: u32,
}

/// The files a scene was read from, kept so that diagnostics can quote their lines.
#[derive(Clone, Debug, Default)]
pub struct SourceMap {
    files: Vec<SourceFile>,
}

#[derive(Clone, Debug)]
struct SourceFile {
    name: String,
    /// Lines as text (invalid UTF-8 replaced), without their terminators.
    lines: Vec<String>,
    /// The command line's settings (`-D`, `--size`, `--maxdepth`), not a file.
    command_line: bool,
}

impl SourceMap {
    /// Registers a file; returns its id for [`Loc::file`].
    pub fn add(&mut self, name: String, lines: Vec<String>) -> u32 {
        self.files.push(SourceFile {
            name,
            lines,
            command_line: false,
        });
        (self.files.len() - 1) as u32
    }

    /// Registers the command line's settings, one per line, under `name`.
    pub fn add_command_line(&mut self, name: String, lines: Vec<String>) -> u32 {
        let id = self.add(name, lines);
        self.files[id as usize].command_line = true;
        id
    }

    pub fn name(&self, file: u32) -> &str {
        self.files.get(file as usize).map_or("<unknown>", |f| &f.name)
    }

    pub fn line(&self, loc: Loc) -> Option<&str> {
        let f = self.files.get(loc.file as usize)?;
        f.lines.get((loc.line as usize).checked_sub(1)?).map(|s| s.as_str())
    }

    /// A 64-bit FNV-1a hash of every line of every file, in order: what render state
    /// files record as "the scene" (the files a scene reads besides its own text, meshes
    /// and images, are not part of it; nor is an `spp` given on the command line).
    pub fn digest(&self) -> u64 {
        let mut h = crate::fnv::START;
        for f in &self.files {
            // `-D spp=N` is not part of the scene, as `--spp N` is not: a render may be
            // continued (`--resume`) with more samples given either way. (A command line
            // of nothing else adds nothing: the scene's hash without it.)
            let spp = |line: &String| f.command_line && line.split_whitespace().next() == Some("spp");
            if f.command_line && f.lines.iter().all(spp) {
                continue;
            }
            for line in f.lines.iter().filter(|l| !spp(l)) {
                h = crate::fnv::fnv1a(b"\n", crate::fnv::fnv1a(line.as_bytes(), h));
            }
            h = crate::fnv::fnv1a(&[0xff], h);
        }
        h
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Severity {
    Note,
    Warning,
    Error,
}

impl fmt::Display for Severity {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str(match self {
            Severity::Note => "note",
            Severity::Warning => "warning",
            Severity::Error => "error",
        })
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Diagnostic {
    pub severity: Severity,
    pub loc: Loc,
    pub message: String,
}

/// Stop reporting after this many errors: a binary file would otherwise print one per line.
pub const MAX_ERRORS: usize = 50;
/// And after this many warnings (or notes): 200,000 lines of a misspelt command say the
/// same thing 200,000 times.
pub const MAX_WARNINGS: usize = 100;
/// A message longer than this (it quotes a ten-megabyte token, say) is cut.
pub const MAX_MESSAGE: usize = 1000;

/// The diagnostics of one parse and build. Counting them costs nothing, whatever their
/// number.
#[derive(Clone, Debug, Default)]
pub struct Diagnostics {
    pub items: Vec<Diagnostic>,
    /// Errors not recorded because `MAX_ERRORS` was reached.
    pub suppressed_errors: usize,
    /// Warnings not recorded because `MAX_WARNINGS` were.
    pub suppressed_warnings: usize,
    /// Notes not recorded because `MAX_WARNINGS` were.
    pub suppressed_notes: usize,
    /// How many of `items` are errors, warnings and notes (by [`Severity`]).
    counts: [usize; 3],
}

impl Diagnostics {
    pub fn push(&mut self, severity: Severity, loc: Loc, message: impl Into<String>) {
        let recorded = self.count(severity);
        if severity == Severity::Error && recorded >= MAX_ERRORS {
            self.suppressed_errors += 1;
            return;
        }
        if severity != Severity::Error && recorded >= MAX_WARNINGS {
            match severity {
                Severity::Note => self.suppressed_notes += 1,
                _ => self.suppressed_warnings += 1,
            }
            return;
        }
        let mut message = message.into();
        if message.len() > MAX_MESSAGE {
            let mut cut = MAX_MESSAGE;
            while !message.is_char_boundary(cut) {
                cut -= 1;
            }
            message.truncate(cut);
            message.push('…');
        }
        self.counts[severity as usize] += 1;
        self.items.push(Diagnostic { severity, loc, message });
    }

    pub fn error(&mut self, loc: Loc, message: impl Into<String>) {
        self.push(Severity::Error, loc, message)
    }

    pub fn warning(&mut self, loc: Loc, message: impl Into<String>) {
        self.push(Severity::Warning, loc, message)
    }

    pub fn note(&mut self, loc: Loc, message: impl Into<String>) {
        self.push(Severity::Note, loc, message)
    }

    /// Whether a diagnostic of this severity would be recorded now (rather than only
    /// counted): what it costs to word one need not be paid otherwise.
    pub fn will_record(&self, severity: Severity) -> bool {
        let cap = if severity == Severity::Error {
            MAX_ERRORS
        } else {
            MAX_WARNINGS
        };
        self.count(severity) < cap
    }

    pub fn count(&self, severity: Severity) -> usize {
        self.counts[severity as usize]
    }

    pub fn has_errors(&self) -> bool {
        self.count(Severity::Error) > 0 || self.suppressed_errors > 0
    }

    pub fn too_many_errors(&self) -> bool {
        self.suppressed_errors > 0 || self.count(Severity::Error) >= MAX_ERRORS
    }

    /// All diagnostics, each with its source line and caret, in the order found.
    pub fn render(&self, sources: &SourceMap) -> String {
        let mut out = String::new();
        for d in &self.items {
            out.push_str(&render_one(d, sources));
        }
        if self.suppressed_errors > 0 {
            let _ = writeln!(out, "error: {} more errors not shown", self.suppressed_errors);
        }
        if self.suppressed_warnings > 0 {
            let _ = writeln!(out, "warning: {} more warnings not shown", self.suppressed_warnings);
        }
        out
    }
}

/// How much of a line a diagnostic shows: up to this many characters.
const SHOWN_CHARS: usize = 120;

/// The first character and the number of characters of a line to show so that the span
/// starting at `col` (0-based) of `len` characters is in view.
fn window(col: usize, len: usize) -> (usize, usize) {
    if col + len.min(SHOWN_CHARS / 2) <= SHOWN_CHARS {
        (0, SHOWN_CHARS)
    } else {
        (col - SHOWN_CHARS / 4, SHOWN_CHARS)
    }
}

/// `file:line:col: severity: message`, then the line and a caret under the span.
pub fn render_one(d: &Diagnostic, sources: &SourceMap) -> String {
    let mut out = format!(
        "{}:{}:{}: {}: {}\n",
        sources.name(d.loc.file),
        d.loc.line,
        d.loc.col,
        d.severity,
        d.message
    );
    if let Some(text) = sources.line(d.loc) {
        let num = d.loc.line.to_string();
        let pad = " ".repeat(num.len());
        // A long line is shown in a window around the span (the column stays the line's).
        let col = d.loc.col.saturating_sub(1) as usize;
        let (first, shown_chars) = window(col, d.loc.len.max(1) as usize);
        let cut_before = first > 0;
        let chars: Vec<char> = text.chars().skip(first).take(shown_chars + 1).collect();
        let cut_after = chars.len() > shown_chars;
        let visible = &chars[..chars.len().min(shown_chars)];
        // Keep tabs so the caret lines up with the text above it.
        let lead: String = visible
            .iter()
            .take(col - first)
            .map(|&c| if c == '\t' { '\t' } else { ' ' })
            .collect();
        let body: String = visible
            .iter()
            .map(|&c| if c.is_control() && c != '\t' { '\u{fffd}' } else { c })
            .collect();
        let (open, close, shift) = (
            if cut_before { "…" } else { "" },
            if cut_after { "…" } else { "" },
            if cut_before { " " } else { "" },
        );
        let underline = (d.loc.len as usize).min(shown_chars.saturating_sub(col - first)).max(1);
        let _ = writeln!(
            out,
            "{pad} |\n{num} | {open}{body}{close}\n{pad} | {shift}{lead}^{}",
            "~".repeat(underline - 1)
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn renders_location_line_and_caret() {
        let mut sources = SourceMap::default();
        let f = sources.add("a.test".into(), vec!["size 10 10".into(), "sphere 0 0 0 -1".into()]);
        let mut d = Diagnostics::default();
        d.error(
            Loc {
                file: f,
                line: 2,
                col: 14,
                len: 2,
            },
            "sphere: radius must be positive, got -1",
        );
        assert_eq!(
            d.render(&sources),
            "a.test:2:14: error: sphere: radius must be positive, got -1\n  |\n2 | sphere 0 0 0 -1\n  |              ^~\n"
        );
        assert!(d.has_errors());
    }

    #[test]
    fn long_lines_and_messages_are_shown_in_part() {
        let mut sources = SourceMap::default();
        let line = format!("size 1 1 {}", "9".repeat(1_000_000));
        let f = sources.add("a.test".into(), vec![line]);
        let mut d = Diagnostics::default();
        let token = Loc {
            file: f,
            line: 1,
            col: 10,
            len: 1_000_000,
        };
        d.error(token, format!("size: '{}' is out of range", "9".repeat(1_000_000)));
        let text = d.render(&sources);
        assert!(text.len() < 2 * MAX_MESSAGE + 400, "{} bytes", text.len());
        assert!(text.starts_with("a.test:1:10: error: size: '999"), "{text}");
        assert!(text.contains("| size 1 1 999") && text.contains("…\n"), "{text}");
        // A span far along a long line is shown in a window around it.
        let far = Loc {
            file: f,
            line: 1,
            col: 500_000,
            len: 3,
        };
        let mut d = Diagnostics::default();
        d.error(far, "here");
        let text = d.render(&sources);
        let lines: Vec<&str> = text.lines().collect();
        assert!(lines[2].starts_with("1 | …9") && lines[3].contains("^~~"), "{text}");
        // The caret stands under the span: "1 | …" then the quarter window before it.
        let caret = lines[3].chars().position(|c| c == '^');
        assert_eq!(caret, Some("1 | …".chars().count() + SHOWN_CHARS / 4), "{text}");
    }

    #[test]
    fn warnings_are_capped_and_counted_in_constant_time() {
        let mut d = Diagnostics::default();
        for _ in 0..200_000 {
            d.warning(Loc::default(), "unknown command 'x' ignored");
        }
        assert_eq!(d.count(Severity::Warning), MAX_WARNINGS);
        assert_eq!(d.suppressed_warnings, 200_000 - MAX_WARNINGS);
        assert!(!d.has_errors());
        assert!(d
            .render(&SourceMap::default())
            .ends_with("warning: 199900 more warnings not shown\n"));
    }

    #[test]
    fn caps_the_number_of_errors() {
        let mut d = Diagnostics::default();
        for _ in 0..MAX_ERRORS + 7 {
            d.error(Loc::default(), "x");
        }
        assert_eq!(d.count(Severity::Error), MAX_ERRORS);
        assert_eq!(d.suppressed_errors, 7);
    }

    #[test]
    fn the_scene_hash_leaves_out_only_an_spp_given_on_the_command_line() {
        let mut file = SourceMap::default();
        file.add("s.test".into(), vec!["size 4 4".into()]);
        let with = |lines: &[&str]| {
            let mut m = file.clone();
            m.add_command_line("command line".into(), lines.iter().map(|l| l.to_string()).collect());
            m.digest()
        };
        let alone = file.digest();
        assert_eq!(with(&["spp 64"]), alone);
        assert_eq!(with(&["spp 64", "maxdepth 3"]), with(&["maxdepth 3"]));
        assert_ne!(with(&["maxdepth 3"]), alone);
        // The file's own spp is its text.
        let mut own = SourceMap::default();
        own.add("s.test".into(), vec!["size 4 4".into(), "spp 64".into()]);
        assert_ne!(own.digest(), alone);
    }
}
