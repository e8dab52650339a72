//! The Bézier patch file of `bezierpatches` (EXTENSIONS.md): a line with the patch count,
//! one line of 16 control-point indices per patch (1-based, the 4 × 4 grid row by row),
//! a line with the point count, then one `x y z` line per point. Numbers may also be
//! separated by commas; blank lines and `#` comments are skipped.

use glam::DVec3;

#[derive(Debug, PartialEq)]
pub struct Patches {
    /// Control points of each patch, row by row.
    pub patches: Vec<[DVec3; 16]>,
}

/// A problem in the file: its 1-based line number (0 for the file as a whole).
#[derive(Debug, PartialEq)]
pub struct PatchError {
    pub line: usize,
    pub message: String,
}

fn err(line: usize, message: impl Into<String>) -> PatchError {
    PatchError {
        line,
        message: message.into(),
    }
}

pub fn parse_patches(text: &str) -> Result<Patches, PatchError> {
    // The non-blank lines as (line number, fields).
    let rows: Vec<(usize, Vec<&str>)> = text
        .lines()
        .enumerate()
        .map(|(i, l)| {
            let l = l.split('#').next().unwrap_or("");
            (
                i + 1,
                l.split([' ', '\t', ',']).filter(|t| !t.is_empty()).collect::<Vec<_>>(),
            )
        })
        .filter(|(_, t)| !t.is_empty())
        .collect();
    let last_line = text.lines().count();
    let mut rows = rows.into_iter();
    let mut next_row = |what: &str| {
        rows.next()
            .ok_or_else(|| err(last_line, format!("the file ends where {what} should be")))
    };
    let count = |(n, t): (usize, Vec<&str>), what: &str| match t.as_slice() {
        [c] => c
            .parse::<usize>()
            .map_err(|_| err(n, format!("expected {what}, got '{c}'"))),
        _ => Err(err(n, format!("expected {what} alone on its line"))),
    };
    let what = "the number of patches";
    let patch_count = count(next_row(what)?, what)?;
    if patch_count == 0 || patch_count > 1 << 20 {
        return Err(err(0, format!("{patch_count} patches: expected between 1 and 1048576")));
    }
    let mut indices = Vec::with_capacity(patch_count);
    for k in 0..patch_count {
        let (n, t) = next_row(&format!("the indices of patch {}", k + 1))?;
        if t.len() != 16 {
            return Err(err(n, format!("patch {}: expected 16 indices, got {}", k + 1, t.len())));
        }
        let mut idx = [0usize; 16];
        for (slot, tok) in idx.iter_mut().zip(&t) {
            *slot = tok
                .parse::<usize>()
                .ok()
                .filter(|&i| i >= 1)
                .ok_or_else(|| err(n, format!("patch {}: '{tok}' is not an index (1, 2, …)", k + 1)))?;
        }
        indices.push((n, idx));
    }
    let what = "the number of points";
    let point_count = count(next_row(what)?, what)?;
    if point_count > 1 << 24 {
        return Err(err(0, format!("{point_count} points: too many")));
    }
    let mut points = Vec::with_capacity(point_count);
    for k in 0..point_count {
        let (n, t) = next_row(&format!("point {}", k + 1))?;
        let xyz: Vec<f64> = t
            .iter()
            .filter_map(|s| s.parse::<f64>().ok())
            .filter(|x| x.is_finite())
            .collect();
        if t.len() != 3 || xyz.len() != 3 {
            return Err(err(n, format!("point {}: expected three numbers x y z", k + 1)));
        }
        points.push(DVec3::new(xyz[0], xyz[1], xyz[2]));
    }
    let mut patches = Vec::with_capacity(patch_count);
    for (k, (n, idx)) in indices.into_iter().enumerate() {
        if let Some(&bad) = idx.iter().find(|&&i| i > point_count) {
            return Err(err(
                n,
                format!("patch {}: point {bad} does not exist ({point_count} points)", k + 1),
            ));
        }
        patches.push(idx.map(|i| points[i - 1]));
    }
    Ok(Patches { patches })
}

#[cfg(test)]
mod tests {
    use super::*;

    const ONE: &str = "1\n1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16\n16\n0 0 0\n1 0 0\n2 0 0\n3 0 0\n0 1 0\n1 1 1\n2 1 1\n3 1 0\n0,2,0\n1,2,1\n2,2,1\n3,2,0\n# comment\n\n0 3 0\n1 3 0\n2 3 0\n3 3 0\n";

    #[test]
    fn reads_a_patch() {
        let p = parse_patches(ONE).unwrap();
        assert_eq!(p.patches.len(), 1);
        assert_eq!(p.patches[0][5], DVec3::new(1.0, 1.0, 1.0));
        assert_eq!(p.patches[0][15], DVec3::new(3.0, 3.0, 0.0));
    }

    #[test]
    fn malformed_files_say_where() {
        let cases = [
            ("", 0, "the file ends where the number of patches should be"),
            ("x\n", 1, "expected the number of patches, got 'x'"),
            ("1\n1 2 3\n", 2, "patch 1: expected 16 indices, got 3"),
            (
                "1\n0 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16\n",
                2,
                "patch 1: '0' is not an index (1, 2, …)",
            ),
            (
                "1\n1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16\n",
                2,
                "the file ends where the number of points should be",
            ),
            (
                "1\n1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16\n1\n0 0\n",
                4,
                "point 1: expected three numbers x y z",
            ),
            (
                "1\n1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 17\n1\n0 0 0\n",
                2,
                "patch 1: point 2 does not exist (1 points)",
            ),
        ];
        for (text, line, message) in cases {
            assert_eq!(parse_patches(text), Err(err(line, message)), "{text:?}");
        }
    }

    #[test]
    fn the_shipped_teapot() {
        let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/teapot.bpt")).unwrap();
        let p = parse_patches(&text).unwrap();
        assert_eq!(p.patches.len(), 32);
    }
}
