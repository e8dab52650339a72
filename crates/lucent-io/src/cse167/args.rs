//! Reading a command's arguments: counts, numbers (C-style decimals within the `f32`
//! range), integers, keywords and colours, each bad one reported at its place.

use std::ops::RangeInclusive;

use glam::DVec3;

use super::lexer::{Command, Token};
use super::parser::Parser;
use crate::diag::Loc;
use crate::number::{is_decimal, is_integer};

impl Parser {
    /// Whether `c` has exactly `n` arguments; if not, an error at the first extra one or
    /// where the missing one would go.
    pub fn expect_count(&mut self, c: &Command, n: usize, what: &str) -> bool {
        if c.args.len() == n {
            return true;
        }
        let got = c.args.len();
        let loc = if got > n {
            let extra = &c.args[n];
            let last = &c.args[got - 1];
            Loc {
                file: self.file,
                line: c.line,
                col: extra.col,
                len: last.col + last.text.chars().count() as u32 - extra.col,
            }
        } else {
            Loc {
                file: self.file,
                line: c.line,
                col: c.end_col,
                len: 1,
            }
        };
        self.diags.error(
            loc,
            format!(
                "{}: expected {what}, got {got} argument{}",
                c.name.text,
                if got == 1 { "" } else { "s" }
            ),
        );
        false
    }

    pub fn nums<const N: usize>(&mut self, c: &Command) -> Option<[f64; N]> {
        self.args(c, "number", Self::number)
    }

    pub fn ints<const N: usize>(&mut self, c: &Command) -> Option<[i64; N]> {
        self.args(c, "integer", Self::integer)
    }

    /// Exactly `N` arguments, each read by `parse`; every bad one is reported.
    fn args<T: Copy + Default, const N: usize>(
        &mut self,
        c: &Command,
        noun: &str,
        parse: fn(&mut Self, &Command, &Token) -> Option<T>,
    ) -> Option<[T; N]> {
        let what = if N == 1 {
            format!("1 {noun}")
        } else {
            format!("{N} {noun}s")
        };
        if !self.expect_count(c, N, &what) {
            return None;
        }
        let mut out = [T::default(); N];
        let mut ok = true;
        for (k, tok) in c.args.iter().enumerate() {
            match parse(self, c, tok) {
                Some(x) => out[k] = x,
                None => ok = false,
            }
        }
        ok.then_some(out)
    }

    /// The numbers after a leading name argument (`checker name …`).
    pub fn nums_after_name<const N: usize>(&mut self, c: &Command) -> Option<[f64; N]> {
        if !self.expect_count(c, N + 1, &format!("a name and {N} numbers")) {
            return None;
        }
        let mut out = [0.0; N];
        for (k, slot) in out.iter_mut().enumerate() {
            *slot = self.number(c, &c.args[k + 1])?;
        }
        Some(out)
    }

    pub fn number(&mut self, c: &Command, tok: &Token) -> Option<f64> {
        let loc = self.loc(c.line, tok);
        if !is_decimal(tok.text) {
            self.diags
                .error(loc, format!("{}: '{}' is not a number", c.name.text, tok.text));
            return None;
        }
        match tok.text.parse::<f64>() {
            Ok(x) if x.is_finite() && x.abs() <= f32::MAX as f64 && !underflows(x) => Some(x),
            Ok(x) if underflows(x) => {
                let msg = format!(
                    "{}: {} is too small for single precision (nonzero numbers start at 1.2e-38)",
                    c.name.text, tok.text
                );
                self.diags.error(loc, msg);
                None
            }
            _ => {
                self.diags
                    .error(loc, format!("{}: {} is out of range", c.name.text, tok.text));
                None
            }
        }
    }

    pub fn integer(&mut self, c: &Command, tok: &Token) -> Option<i64> {
        let loc = self.loc(c.line, tok);
        if !is_integer(tok.text) {
            let what = if is_decimal(tok.text) {
                "is not an integer"
            } else {
                "is not a number"
            };
            self.diags.error(loc, format!("{}: '{}' {what}", c.name.text, tok.text));
            return None;
        }
        match tok.text.parse::<i64>() {
            Ok(v) => Some(v),
            Err(_) => {
                self.diags
                    .error(loc, format!("{}: {} is out of range", c.name.text, tok.text));
                None
            }
        }
    }

    /// The single argument of `c`, which must be a number > 0.
    pub fn positive(&mut self, c: &Command) -> Option<f64> {
        let [x] = self.nums::<1>(c)?;
        if x > 0.0 {
            return Some(x);
        }
        self.err_arg(
            c,
            0,
            format!("{}: must be positive, got {}", c.name.text, c.args[0].text),
        );
        None
    }

    /// The single argument of `c`, one of the names in `options`.
    pub fn keyword<T: Copy>(&mut self, c: &Command, options: &[(&str, T)]) -> Option<T> {
        if !self.expect_count(c, 1, &format!("one of {}", alternatives(options))) {
            return None;
        }
        self.keyword_at(c, 0, options)
    }

    /// Argument `k` as one of the names in `options`.
    pub fn keyword_at<T: Copy>(&mut self, c: &Command, k: usize, options: &[(&str, T)]) -> Option<T> {
        let tok = &c.args[k];
        let found = options.iter().find(|(n, _)| *n == tok.text).map(|(_, v)| *v);
        if found.is_none() {
            let loc = self.loc(c.line, tok);
            let list = alternatives(options);
            self.diags.error(
                loc,
                format!("{}: unknown value '{}' (expected {list})", c.name.text, tok.text),
            );
        }
        found
    }

    /// A colour from three parsed numbers starting at argument `first`; negative
    /// components are allowed but warned about.
    pub fn color_at(&mut self, c: &Command, first: usize, v: &[f64]) -> DVec3 {
        if let Some(k) = v.iter().position(|&x| x < 0.0) {
            let loc = self.loc(c.line, &c.args[first + k]);
            self.diags.warning(
                loc,
                format!("{}: negative colour component {}", c.name.text, c.args[first + k].text),
            );
        }
        DVec3::new(v[0], v[1], v[2])
    }

    /// Whether integer argument `k` (whose value is `x`) lies in `range`; an error if not.
    pub fn in_range(&mut self, c: &Command, k: usize, x: i64, range: RangeInclusive<i64>, what: &str) -> bool {
        if range.contains(&x) {
            return true;
        }
        let msg = format!(
            "{}: {what} must be between {} and {}, got {x}",
            c.name.text,
            range.start(),
            range.end()
        );
        self.err_arg(c, k, msg);
        false
    }

    /// Whether `c` has one or two arguments (`what` says which); an error if not.
    pub fn one_or_two(&mut self, c: &Command, what: &str) -> bool {
        let n = c.args.len();
        if (1..=2).contains(&n) {
            return true;
        }
        self.err_cmd(c, format!("{}: expected {what}, got {n} arguments", c.name.text));
        false
    }

    /// The optional second argument read by `read` (which reports what is wrong with it),
    /// or `default` when there is none.
    pub fn optional_second<T>(
        &mut self,
        c: &Command,
        default: T,
        read: impl FnOnce(&mut Self, &Command) -> Option<T>,
    ) -> Option<T> {
        if c.args.len() < 2 {
            Some(default)
        } else {
            read(self, c)
        }
    }

    /// Whether the arguments are the single word `off` (`glossy off`, `bumpmap off`, …).
    pub fn is_off(c: &Command) -> bool {
        c.args.len() == 1 && c.args[0].text == "off"
    }
}

/// Whether `x` is not zero but smaller than the smallest normal single-precision number:
/// the renderer would see 0 (a radius of 1e-50 is no sphere) or lose its precision.
fn underflows(x: f64) -> bool {
    x != 0.0 && x.abs() < f32::MIN_POSITIVE as f64
}

/// "a, b or c".
fn alternatives<T>(options: &[(&str, T)]) -> String {
    let names: Vec<&str> = options.iter().map(|(n, _)| *n).collect();
    match names.as_slice() {
        [a, b] => format!("{a} or {b}"),
        [init @ .., last] => format!("{} or {last}", init.join(", ")),
        [] => String::new(),
    }
}
