//! NURBS surfaces: `nurbs du dv nu nv`, followed at once by one `knotsu` line (nu + du + 1
//! non-decreasing values), one `knotsv` line and nu × nv `cpoint x y z w` lines (u
//! varying fastest, weight w > 0). Any other command before the surface is complete is
//! an error; the build tessellates it.

use glam::DVec4;

use super::lexer::Command;
use super::parser::Parser;
use crate::desc::{NurbsDesc, NurbsDirection, SurfaceRecipe};
use crate::diag::Loc;

/// Degrees `nurbs` accepts.
const MAX_DEGREE: i64 = 16;
/// Control points one surface may have.
const MAX_CONTROL_POINTS: i64 = 1 << 20;

/// A `nurbs` command waiting for its `knotsu`, `knotsv` and `cpoint` lines.
pub(super) struct PendingNurbs {
    /// The `nurbs` command.
    at: Loc,
    surface: NurbsDesc,
}

impl Parser {
    /// `nurbs du dv nu nv`: degrees and control point counts; the knots and control
    /// points follow on their own lines.
    pub(super) fn nurbs_header(&mut self, c: &Command) {
        let Some([du, dv, nu, nv]) = self.ints::<4>(c) else {
            return;
        };
        for (k, d) in [(0, du), (1, dv)] {
            if !self.in_range(c, k, d, 1..=MAX_DEGREE, "degree") {
                return;
            }
        }
        for (k, n, d) in [(2, nu, du), (3, nv, dv)] {
            if n < d + 1 {
                self.err_arg(
                    c,
                    k,
                    format!("nurbs: degree {d} needs at least {} control points, got {n}", d + 1),
                );
                return;
            }
        }
        if nu * nv > MAX_CONTROL_POINTS {
            self.err_span(c, 2, 2, format!("nurbs: {nu} × {nv} control points is too many"));
            return;
        }
        self.nurbs = Some(PendingNurbs {
            at: self.loc(c.line, &c.name),
            surface: NurbsDesc {
                u: NurbsDirection {
                    degree: du as usize,
                    count: nu as usize,
                    knots: Vec::new(),
                },
                v: NurbsDirection {
                    degree: dv as usize,
                    count: nv as usize,
                    knots: Vec::new(),
                },
                points: Vec::new(),
            },
        });
    }

    /// What the pending surface needs next.
    fn nurbs_expects(s: &NurbsDesc) -> String {
        if s.u.knots.is_empty() {
            "knotsu".into()
        } else if s.v.knots.is_empty() {
            "knotsv".into()
        } else {
            format!("{} more cpoint lines", s.u.count * s.v.count - s.points.len())
        }
    }

    /// Any command but the surface's own lines ends a pending surface with an error.
    pub(super) fn interrupt_nurbs(&mut self, c: &Command) {
        if self.nurbs.is_some() && !matches!(c.name.text, "knotsu" | "knotsv" | "cpoint") {
            let p = self.nurbs.take().expect("checked");
            let wanted = Self::nurbs_expects(&p.surface);
            self.err_cmd(
                c,
                format!(
                    "'{}' inside the nurbs surface of line {} (expected {wanted})",
                    c.name.text, p.at.line
                ),
            );
        }
    }

    /// At the end of the file: a surface still pending is an error at its `nurbs`.
    pub(super) fn unfinished_nurbs(&mut self) {
        if let Some(p) = self.nurbs.take() {
            let wanted = Self::nurbs_expects(&p.surface);
            self.diags.error(
                p.at,
                format!("nurbs: the file ends before the surface is complete (expected {wanted})"),
            );
        }
    }

    /// `knotsu …`, `knotsv …` and `cpoint x y z w`.
    pub(super) fn nurbs_part(&mut self, c: &Command) {
        let name = c.name.text;
        let Some(mut p) = self.nurbs.take() else {
            self.err_cmd(c, format!("{name}: only allowed right after a 'nurbs' command"));
            return;
        };
        let expected = Self::nurbs_expects(&p.surface);
        let fits = match name {
            "knotsu" => p.surface.u.knots.is_empty(),
            "knotsv" => !p.surface.u.knots.is_empty() && p.surface.v.knots.is_empty(),
            _ => !p.surface.v.knots.is_empty(),
        };
        if !fits {
            self.err_cmd(
                c,
                format!(
                    "{name}: out of order in the nurbs surface of line {} (expected {expected})",
                    p.at.line
                ),
            );
            return;
        }
        let s = &mut p.surface;
        if name == "cpoint" {
            let Some([x, y, z, w]) = self.nums::<4>(c) else { return };
            if !(w > 0.0) {
                self.err_arg(c, 3, format!("cpoint: weight must be positive, got {}", c.args[3].text));
                return;
            }
            s.points.push(DVec4::new(x, y, z, w));
        } else {
            let direction = if name == "knotsu" { &mut s.u } else { &mut s.v };
            let Some(knots) = self.knots(c, direction) else { return };
            direction.knots = knots;
        }
        if s.points.len() == s.u.count * s.v.count {
            self.surface_at(p.at, SurfaceRecipe::Nurbs(p.surface));
        } else {
            self.nurbs = Some(p);
        }
    }

    /// The knot vector of a `knotsu` or `knotsv` line: count + degree + 1 values that
    /// never decrease and leave a parameter range.
    fn knots(&mut self, c: &Command, direction: &NurbsDirection) -> Option<Vec<f64>> {
        let name = c.name.text;
        let (degree, count) = (direction.degree, direction.count);
        let want = count + degree + 1;
        if c.args.len() != want {
            self.err_cmd(
                c,
                format!(
                    "{name}: expected {want} knots ({count} control points of degree {degree}), got {}",
                    c.args.len()
                ),
            );
            return None;
        }
        let mut knots: Vec<f64> = Vec::with_capacity(want);
        for (k, tok) in c.args.iter().enumerate() {
            let x = self.number(c, tok)?;
            if let Some(&prev) = knots.last() {
                if x < prev {
                    self.err_arg(
                        c,
                        k,
                        format!("{name}: knots must not decrease ({} after {prev})", tok.text),
                    );
                    return None;
                }
            }
            knots.push(x);
        }
        if !(knots[degree] < knots[count]) {
            self.err_cmd(
                c,
                format!("{name}: the knots leave no parameter range (knot {degree} equals knot {count})"),
            );
            return None;
        }
        Some(knots)
    }
}
