//! Numbers as the scene format writes them (SCENE_FORMAT.md §1.7–1.8): C-style decimals
//! (`640`, `-1`, `+1`, `.5`, `1e-3`); no `inf`, `nan`, hexadecimal or anything else —
//! which Rust's own `parse::<f32>` would accept, hence this check.

/// Whether `s` is `[+-]? (digits [. digits?] | . digits) ([eE] [+-]? digits)?`.
pub fn is_decimal(s: &str) -> bool {
    let b = s.as_bytes();
    let mut i = 0;
    if i < b.len() && (b[i] == b'+' || b[i] == b'-') {
        i += 1;
    }
    let int_start = i;
    while i < b.len() && b[i].is_ascii_digit() {
        i += 1;
    }
    let mut digits = i - int_start;
    if i < b.len() && b[i] == b'.' {
        i += 1;
        let frac_start = i;
        while i < b.len() && b[i].is_ascii_digit() {
            i += 1;
        }
        digits += i - frac_start;
    }
    if digits == 0 {
        return false;
    }
    if i < b.len() && (b[i] == b'e' || b[i] == b'E') {
        i += 1;
        if i < b.len() && (b[i] == b'+' || b[i] == b'-') {
            i += 1;
        }
        let exp_start = i;
        while i < b.len() && b[i].is_ascii_digit() {
            i += 1;
        }
        if i == exp_start {
            return false;
        }
    }
    i == b.len()
}

/// Whether `s` is `[+-]? digits`.
pub fn is_integer(s: &str) -> bool {
    let d = s.strip_prefix(['+', '-']).unwrap_or(s);
    !d.is_empty() && d.bytes().all(|c| c.is_ascii_digit())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn accepts_the_forms_official_files_use() {
        for s in [
            "640", "-1", "+1", ".5", "-.25", "0.0001", "1.", "1e5", "2.5E-3", "+.5e+2",
        ] {
            assert!(is_decimal(s), "{s}");
        }
    }

    #[test]
    fn rejects_everything_else() {
        for s in [
            "", "+", "-", ".", "e5", "1e", "1e+", "inf", "-inf", "nan", "NaN", "infinity", "0x10", "1,5", "1.2.3",
            "1e5.5", "--1", "1f", " 1",
        ] {
            assert!(!is_decimal(s), "{s}");
        }
    }

    #[test]
    fn integers() {
        assert!(is_integer("12") && is_integer("-1") && is_integer("+3"));
        assert!(!is_integer("1.0") && !is_integer("") && !is_integer("-") && !is_integer("1e3"));
    }
}
