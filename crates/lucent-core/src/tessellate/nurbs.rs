//! NURBS surfaces (scene command `nurbs`): evaluation with first derivatives (Piegl &
//! Tiller, The NURBS Book, A2.1–A2.3 and the quotient rule for the rational surface),
//! and tessellation fine enough for a given chord tolerance.

use glam::{DVec3, DVec4};

#[derive(Clone, Debug, PartialEq)]
pub struct NurbsSurface {
    pub degree_u: usize,
    pub degree_v: usize,
    pub count_u: usize,
    pub count_v: usize,
    /// `count_u + degree_u + 1` non-decreasing values.
    pub knots_u: Vec<f64>,
    pub knots_v: Vec<f64>,
    /// Control points `(w·x, w·y, w·z, w)`, `u` varying fastest.
    pub points: Vec<DVec4>,
}

/// The span `k` with `knots[k] <= t < knots[k + 1]` (the last non-empty span at the end).
fn find_span(knots: &[f64], degree: usize, count: usize, t: f64) -> usize {
    if t >= knots[count] {
        let mut k = count - 1;
        while k > degree && knots[k] == knots[count] {
            k -= 1;
        }
        return k;
    }
    let (mut lo, mut hi) = (degree, count);
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if t < knots[mid] {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    lo
}

/// The `degree + 1` non-zero basis functions at `t` in `span`, and their derivatives.
fn basis(knots: &[f64], degree: usize, span: usize, t: f64) -> (Vec<f64>, Vec<f64>) {
    // Triangular table of the basis functions of degrees 0..=degree (The NURBS Book A2.3).
    let p = degree;
    let mut ndu = vec![vec![0.0; p + 1]; p + 1];
    let (mut left, mut right) = (vec![0.0; p + 1], vec![0.0; p + 1]);
    ndu[0][0] = 1.0;
    for j in 1..=p {
        left[j] = t - knots[span + 1 - j];
        right[j] = knots[span + j] - t;
        let mut saved = 0.0;
        for r in 0..j {
            ndu[j][r] = right[r + 1] + left[j - r];
            let temp = if ndu[j][r] == 0.0 {
                0.0
            } else {
                ndu[r][j - 1] / ndu[j][r]
            };
            ndu[r][j] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        ndu[j][j] = saved;
    }
    let values: Vec<f64> = (0..=p).map(|j| ndu[j][p]).collect();
    // First derivatives: N'ᵢ,ₚ = p·(Nᵢ,ₚ₋₁ / (u_{i+p} − uᵢ) − Nᵢ₊₁,ₚ₋₁ / (u_{i+p+1} − u_{i+1})).
    let mut ders = vec![0.0; p + 1];
    if p > 0 {
        for (r, d) in ders.iter_mut().enumerate() {
            let mut v = 0.0;
            if r >= 1 {
                let denom = ndu[p][r - 1];
                if denom != 0.0 {
                    v += ndu[r - 1][p - 1] / denom;
                }
            }
            if r < p {
                let denom = ndu[p][r];
                if denom != 0.0 {
                    v -= ndu[r][p - 1] / denom;
                }
            }
            *d = v * p as f64;
        }
    }
    (values, ders)
}

impl NurbsSurface {
    /// The parameter rectangle `[u0, u1] × [v0, v1]`.
    pub fn domain(&self) -> ((f64, f64), (f64, f64)) {
        (
            (self.knots_u[self.degree_u], self.knots_u[self.count_u]),
            (self.knots_v[self.degree_v], self.knots_v[self.count_v]),
        )
    }

    /// `S(u, v)`, `∂S/∂u` and `∂S/∂v`.
    pub fn evaluate(&self, u: f64, v: f64) -> (DVec3, DVec3, DVec3) {
        let su = find_span(&self.knots_u, self.degree_u, self.count_u, u);
        let sv = find_span(&self.knots_v, self.degree_v, self.count_v, v);
        let (nu, du) = basis(&self.knots_u, self.degree_u, su, u);
        let (nv, dv) = basis(&self.knots_v, self.degree_v, sv, v);
        let (mut a, mut au, mut av) = (DVec4::ZERO, DVec4::ZERO, DVec4::ZERO);
        for (l, (&bv, &dbv)) in nv.iter().zip(&dv).enumerate() {
            let row = (sv - self.degree_v + l) * self.count_u;
            for (k, (&bu, &dbu)) in nu.iter().zip(&du).enumerate() {
                let pw = self.points[row + su - self.degree_u + k];
                a += pw * (bu * bv);
                au += pw * (dbu * bv);
                av += pw * (bu * dbv);
            }
        }
        let s = a.truncate() / a.w;
        // Quotient rule: S_u = (A_u − w_u·S) / w.
        let s_u = (au.truncate() - s * au.w) / a.w;
        let s_v = (av.truncate() - s * av.w) / a.w;
        (s, s_u, s_v)
    }

    /// The unit normal `S_u × S_v`, taken a little way inside where it vanishes (poles).
    pub fn normal(&self, u: f64, v: f64) -> Option<DVec3> {
        let ((u0, u1), (v0, v1)) = self.domain();
        let derivatives = |u, v| {
            let (_, su, sv) = self.evaluate(u, v);
            (su, sv)
        };
        super::grid::normal(derivatives, (u, v), ((u0 + u1) / 2.0, (v0 + v1) / 2.0))
    }

    /// Segments along u and v so that no chord strays more than `tolerance` from the
    /// surface: a chord over a parameter step `h` deviates by at most `h²·M/8`, where `M`
    /// bounds the second derivative, estimated here by second differences on a fine grid
    /// (with a safety factor of 2).
    pub fn segments_for(&self, tolerance: f64) -> (usize, usize) {
        let ((u0, u1), (v0, v1)) = self.domain();
        let spans_u = self.count_u - self.degree_u;
        let spans_v = self.count_v - self.degree_v;
        let probe = |along_u: bool| {
            let (n, m) = if along_u {
                (16 * spans_u, 8 * spans_v)
            } else {
                (16 * spans_v, 8 * spans_u)
            };
            // 16 samples per span along the direction, 8 across, within a fixed budget.
            let (n, m) = (n.min(512), m.min(64));
            let (a0, a1, b0, b1) = if along_u { (u0, u1, v0, v1) } else { (v0, v1, u0, u1) };
            let h = (a1 - a0) / n as f64;
            let mut worst: f64 = 0.0;
            for j in 0..=m {
                let b = b0 + (b1 - b0) * j as f64 / m as f64;
                let at = |a: f64| {
                    if along_u {
                        self.evaluate(a, b).0
                    } else {
                        self.evaluate(b, a).0
                    }
                };
                for i in 1..n {
                    let a = a0 + h * i as f64;
                    let second = (at(a - h) - at(a) * 2.0 + at(a + h)) / (h * h);
                    worst = worst.max(second.length());
                }
            }
            let step = (8.0 * tolerance / (2.0 * worst.max(1e-300))).sqrt();
            let min = 2 * if along_u { spans_u } else { spans_v };
            (((a1 - a0) / step).ceil() as usize).clamp(min.max(2), 2048)
        };
        (probe(true), probe(false))
    }

    /// Points and unit normals on a `(segments_u + 1) × (segments_v + 1)` grid, row by
    /// row in v. A normal that cannot be found is zero.
    pub fn tessellate(&self, segments_u: usize, segments_v: usize) -> Vec<(DVec3, DVec3)> {
        let ((u0, u1), (v0, v1)) = self.domain();
        let mut grid = Vec::with_capacity((segments_u + 1) * (segments_v + 1));
        for i in 0..=segments_v {
            let v = v0 + (v1 - v0) * i as f64 / segments_v as f64;
            for j in 0..=segments_u {
                let u = u0 + (u1 - u0) * j as f64 / segments_u as f64;
                grid.push((self.evaluate(u, v).0, self.normal(u, v).unwrap_or(DVec3::ZERO)));
            }
        }
        grid
    }
}

/// The rational quadratic sphere of radius `r` at the origin (9 × 5 control points), the
/// textbook example; used by the tests and the gallery.
pub fn sphere(r: f64) -> NurbsSurface {
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let circle = [
        (1.0, 0.0, 1.0),
        (1.0, 1.0, h),
        (0.0, 1.0, 1.0),
        (-1.0, 1.0, h),
        (-1.0, 0.0, 1.0),
        (-1.0, -1.0, h),
        (0.0, -1.0, 1.0),
        (1.0, -1.0, h),
        (1.0, 0.0, 1.0),
    ];
    let arc = [
        (0.0, -1.0, 1.0),
        (1.0, -1.0, h),
        (1.0, 0.0, 1.0),
        (1.0, 1.0, h),
        (0.0, 1.0, 1.0),
    ];
    let mut points = Vec::new();
    for &(rho, z, wv) in &arc {
        for &(x, y, wu) in &circle {
            let w = wu * wv;
            points.push(DVec4::new(x * rho * r * w, y * rho * r * w, z * r * w, w));
        }
    }
    NurbsSurface {
        degree_u: 2,
        degree_v: 2,
        count_u: 9,
        count_v: 5,
        knots_u: vec![0.0, 0.0, 0.0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1.0, 1.0, 1.0],
        knots_v: vec![0.0, 0.0, 0.0, 0.5, 0.5, 1.0, 1.0, 1.0],
        points,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_rational_sphere_is_exactly_round() {
        let s = sphere(2.0);
        for i in 0..=20 {
            for j in 0..=20 {
                let (u, v) = (i as f64 / 20.0, j as f64 / 20.0);
                let (p, _, _) = s.evaluate(u, v);
                assert!((p.length() - 2.0).abs() < 1e-12, "({u}, {v}): {p}");
                // The normal points out, along the radius.
                let n = s.normal(u, v).unwrap();
                assert!((n - p / 2.0).length() < 1e-4, "({u}, {v}): {n} vs {p}");
            }
        }
    }

    #[test]
    fn derivatives_match_finite_differences() {
        let s = sphere(1.0);
        let h = 1e-6;
        for (u, v) in [(0.1, 0.3), (0.6, 0.7), (0.3, 0.55)] {
            let (_, su, sv) = s.evaluate(u, v);
            let fu = (s.evaluate(u + h, v).0 - s.evaluate(u - h, v).0) / (2.0 * h);
            let fv = (s.evaluate(u, v + h).0 - s.evaluate(u, v - h).0) / (2.0 * h);
            assert!(
                (su - fu).length() < 1e-5 && (sv - fv).length() < 1e-5,
                "{su} {fu} {sv} {fv}"
            );
        }
    }

    #[test]
    fn tessellation_keeps_within_the_tolerance() {
        let s = sphere(1.0);
        let (nu, nv) = s.segments_for(1e-3);
        let grid = s.tessellate(nu, nv);
        // The midpoint of every grid edge along u lies within the tolerance of the sphere.
        for i in 0..=nv {
            for j in 0..nu {
                let (a, b) = (grid[i * (nu + 1) + j].0, grid[i * (nu + 1) + j + 1].0);
                let mid = (a + b) / 2.0;
                assert!(1.0 - mid.length() <= 1e-3, "{}", 1.0 - mid.length());
            }
        }
        assert!(nu >= 8 && nv >= 4 && nu < 2048);
    }
}
