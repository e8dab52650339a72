//! Bicubic Bézier patches (scene command `bezierpatches`): evaluation with exact partial
//! derivatives, and tessellation into a grid of points with normals.
//!
//! A patch has 16 control points, row by row: `P[4·i + j]`, `u` running along a row (j)
//! and `v` across rows (i). `S(u, v) = Σᵢ Σⱼ Bᵢ(v) Bⱼ(u) P[4i + j]` with the cubic
//! Bernstein polynomials `B`, and the normal is `∂S/∂u × ∂S/∂v`. Where that vanishes — at
//! the poles of the teapot's lid and bottom, whose patches collapse a whole row of
//! control points into one — the normal is taken a little way into the patch.

use glam::DVec3;

fn bernstein(t: f64) -> [f64; 4] {
    let s = 1.0 - t;
    [s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t]
}

fn bernstein_derivative(t: f64) -> [f64; 4] {
    let s = 1.0 - t;
    [
        -3.0 * s * s,
        3.0 * s * s - 6.0 * t * s,
        6.0 * t * s - 3.0 * t * t,
        3.0 * t * t,
    ]
}

/// The point `S(u, v)` and the partial derivatives `∂S/∂u`, `∂S/∂v`.
pub fn evaluate(p: &[DVec3; 16], u: f64, v: f64) -> (DVec3, DVec3, DVec3) {
    let (bu, bv) = (bernstein(u), bernstein(v));
    let (du, dv) = (bernstein_derivative(u), bernstein_derivative(v));
    let (mut s, mut su, mut sv) = (DVec3::ZERO, DVec3::ZERO, DVec3::ZERO);
    for i in 0..4 {
        for j in 0..4 {
            let q = p[4 * i + j];
            s += q * (bv[i] * bu[j]);
            su += q * (bv[i] * du[j]);
            sv += q * (dv[i] * bu[j]);
        }
    }
    (s, su, sv)
}

/// The unit normal `∂S/∂u × ∂S/∂v` at `(u, v)`, or where it vanishes, the normal a
/// little way towards the middle of the patch; `None` if the whole patch is degenerate.
pub fn normal(p: &[DVec3; 16], u: f64, v: f64) -> Option<DVec3> {
    let derivatives = |u, v| {
        let (_, su, sv) = evaluate(p, u, v);
        (su, sv)
    };
    super::grid::normal(derivatives, (u, v), (0.5, 0.5))
}

/// `(divisions + 1)²` points and normals on a regular `(u, v)` grid, row by row in `v`.
/// A normal that cannot be found (a fully degenerate patch) is zero.
pub fn tessellate(p: &[DVec3; 16], divisions: u32) -> Vec<(DVec3, DVec3)> {
    let n = divisions as usize;
    let mut grid = Vec::with_capacity((n + 1) * (n + 1));
    for i in 0..=n {
        let v = i as f64 / n as f64;
        for j in 0..=n {
            let u = j as f64 / n as f64;
            let (s, _, _) = evaluate(p, u, v);
            grid.push((s, normal(p, u, v).unwrap_or(DVec3::ZERO)));
        }
    }
    grid
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A wavy patch over the unit square: P[4i + j] = (j/3, i/3, h(i, j)).
    fn wavy() -> [DVec3; 16] {
        std::array::from_fn(|k| {
            let (i, j) = ((k / 4) as f64, (k % 4) as f64);
            DVec3::new(j / 3.0, i / 3.0, ((i * 1.7 + j * 0.9).sin()) * 0.3)
        })
    }

    #[test]
    fn passes_through_its_four_corner_control_points() {
        let p = wavy();
        for (u, v, k) in [(0.0, 0.0, 0), (1.0, 0.0, 3), (0.0, 1.0, 12), (1.0, 1.0, 15)] {
            let (s, _, _) = evaluate(&p, u, v);
            assert!((s - p[k]).length() < 1e-12, "corner {k}: {s}");
        }
    }

    #[test]
    fn derivatives_match_finite_differences() {
        let p = wavy();
        let h = 1e-6;
        for (u, v) in [(0.3, 0.6), (0.0, 0.5), (0.9, 0.1)] {
            let (_, su, sv) = evaluate(&p, u, v);
            let fu = (evaluate(&p, u + h, v).0 - evaluate(&p, u - h, v).0) / (2.0 * h);
            let fv = (evaluate(&p, u, v + h).0 - evaluate(&p, u, v - h).0) / (2.0 * h);
            assert!((su - fu).length() < 1e-6 && (sv - fv).length() < 1e-6);
        }
    }

    #[test]
    fn flat_patch_normal_and_a_collapsed_row() {
        // A flat patch in z = 0: the normal is +z everywhere (u along x, v along y).
        let flat: [DVec3; 16] = std::array::from_fn(|k| DVec3::new((k % 4) as f64, (k / 4) as f64, 0.0));
        assert!((normal(&flat, 0.2, 0.7).unwrap() - DVec3::Z).length() < 1e-12);
        // Collapse the first row into one point (a pole): ∂S/∂u vanishes at v = 0, but a
        // normal is still found, close to the one just inside.
        let mut pole = flat;
        pole[..4].fill(DVec3::new(1.5, 0.0, 0.0));
        let n = normal(&pole, 0.5, 0.0).unwrap();
        assert!((n - DVec3::Z).length() < 1e-6, "{n}");
        let grid = tessellate(&pole, 4);
        assert_eq!(grid.len(), 25);
        assert!(grid.iter().all(|(_, n)| (n.length() - 1.0).abs() < 1e-9));
    }
}
