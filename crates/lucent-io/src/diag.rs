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
}

impl SourceMap {
    /// Registers a file; returns its id for [`Loc::file`].
    pub fn add(&mut self, name: String, lines: Vec<String>) -> u32 {
        self.files.push(SourceFile { name, lines });
        (self.files.len() - 1) as u32
    }

    pub fn name(&self, file: u32) -> &str {
        self.files.get(file as usize).map_or("<unknown>", |f| &f.name)
    }

    pub fn line(&self, loc: Loc) -> Option<&str> {
        let f = self.files.get(loc.file as usize)?;
        f.lines.get((loc.line as usize).checked_sub(1)?).map(|s| s.as_str())
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

/// The diagnostics of one parse and build.
#[derive(Clone, Debug, Default)]
pub struct Diagnostics {
    pub items: Vec<Diagnostic>,
    /// Errors not recorded because `MAX_ERRORS` was reached.
    pub suppressed_errors: usize,
}

impl Diagnostics {
    pub fn push(&mut self, severity: Severity, loc: Loc, message: impl Into<String>) {
        if severity == Severity::Error && self.count(Severity::Error) >= MAX_ERRORS {
            self.suppressed_errors += 1;
            return;
        }
        self.items.push(Diagnostic {
            severity,
            loc,
            message: message.into(),
        });
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

    pub fn count(&self, severity: Severity) -> usize {
        self.items.iter().filter(|d| d.severity == severity).count()
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
        out
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
        // Keep tabs so the caret lines up with the text above it.
        let lead: String = text
            .chars()
            .take(d.loc.col.saturating_sub(1) as usize)
            .map(|c| if c == '\t' { '\t' } else { ' ' })
            .collect();
        let shown: String = text
            .chars()
            .map(|c| if c.is_control() && c != '\t' { '\u{fffd}' } else { c })
            .collect();
        let _ = writeln!(
            out,
            "{pad} |\n{num} | {shown}\n{pad} | {lead}^{}",
            "~".repeat(d.loc.len.saturating_sub(1) as usize)
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
    fn caps_the_number_of_errors() {
        let mut d = Diagnostics::default();
        for _ in 0..MAX_ERRORS + 7 {
            d.error(Loc::default(), "x");
        }
        assert_eq!(d.count(Severity::Error), MAX_ERRORS);
        assert_eq!(d.suppressed_errors, 7);
    }
}
