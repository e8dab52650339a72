//! Lines and tokens (docs/scene-format.md, "Lexical rules"): one command per line, tokens
//! separated by spaces or tabs, `#` starting a comment, `\n` or `\r\n` line ends, text
//! only.

/// A token and its 1-based column (in characters).
#[derive(Clone, Copy)]
pub(super) struct Token<'a> {
    pub text: &'a str,
    pub col: u32,
}

/// One command: its name, its arguments and where it stands.
pub(super) struct Command<'a> {
    pub name: Token<'a>,
    pub args: Vec<Token<'a>>,
    pub line: u32,
    /// Column just past the end of the line, comment included (where a missing argument
    /// is reported).
    pub end_col: u32,
}

/// Why a line cannot be read: the column of the first bad character and the message.
pub(super) struct LineError {
    pub col: u32,
    pub message: String,
}

/// More tokens than any command takes (a knot vector has at most 2²⁰ + 17): a line with
/// more is refused without being split further.
pub const MAX_TOKENS: usize = (1 << 20) + 32;

/// The lines of a file, without their terminators (a final line end adds no line).
pub(super) fn split_lines(bytes: &[u8]) -> Vec<&[u8]> {
    if bytes.is_empty() {
        return Vec::new();
    }
    let body = bytes.strip_suffix(b"\n").unwrap_or(bytes);
    body.split(|&b| b == b'\n')
        .map(|l| l.strip_suffix(b"\r").unwrap_or(l))
        .collect()
}

/// The command on line `line` (1-based), `None` for a blank or comment line.
pub(super) fn command<'a>(line: u32, raw: &'a [u8]) -> Result<Option<Command<'a>>, LineError> {
    let text = match std::str::from_utf8(raw) {
        Ok(t) => t,
        Err(e) => {
            let col = String::from_utf8_lossy(&raw[..e.valid_up_to()]).chars().count() as u32 + 1;
            let byte = raw[e.valid_up_to()];
            return Err(LineError {
                col,
                message: format!("invalid UTF-8 (byte 0x{byte:02X}): scene files are text"),
            });
        }
    };
    if let Some((i, c)) = text.chars().enumerate().find(|(_, c)| c.is_control() && *c != '\t') {
        return Err(LineError {
            col: i as u32 + 1,
            message: format!("unexpected control character U+{:04X}: scene files are text", c as u32),
        });
    }
    let mut name: Option<Token> = None;
    let mut args = Vec::new();
    let mut col = 0u32;
    let mut start: Option<(usize, u32)> = None;
    // Returns whether the line ends here (a comment).
    let mut push = |tok: Token<'a>| -> Result<bool, LineError> {
        // A token starting with '#' begins a comment to the end of the line.
        if tok.text.starts_with('#') {
            return Ok(true);
        }
        if name.is_none() {
            name = Some(tok);
        } else if args.len() < MAX_TOKENS {
            args.push(tok);
        } else {
            return Err(LineError {
                col: tok.col,
                message: format!("too many arguments on one line (no command takes more than {MAX_TOKENS})"),
            });
        }
        Ok(false)
    };
    let mut comment = false;
    for (i, c) in text.char_indices() {
        col += 1;
        let blank = c == ' ' || c == '\t';
        match (blank, start) {
            (false, None) => start = Some((i, col)),
            (true, Some((s, sc))) => {
                start = None;
                if push(Token {
                    text: &text[s..i],
                    col: sc,
                })? {
                    comment = true;
                    break;
                }
            }
            _ => {}
        }
    }
    if let (Some((s, sc)), false) = (start, comment) {
        push(Token {
            text: &text[s..],
            col: sc,
        })?;
    }
    let Some(name) = name else {
        return Ok(None);
    };
    Ok(Some(Command {
        name,
        args,
        line,
        // Past the end of the line, comment included.
        end_col: if comment {
            text.chars().count() as u32 + 1
        } else {
            col + 1
        },
    }))
}
