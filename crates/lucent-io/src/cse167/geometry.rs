//! Shapes given by their parameters: `sphere`, and the extensions `plane`, `box`,
//! `cylinder`, `disk`, `cone`, `quadric`; triangles from the vertex piles: `maxverts`,
//! `maxvertnorms` (hints), `vertex`, `vertexnormal`, `tri`, `trinormal`. Each shape
//! captures the current transform and material.

use glam::DVec3;

use super::lexer::Command;
use super::parser::Parser;
use crate::desc::ShapeKind;

impl Parser {
    /// `sphere x y z radius`, radius > 0.
    pub(super) fn sphere(&mut self, c: &Command) {
        let Some(v) = self.nums::<4>(c) else { return };
        if v[3] <= 0.0 {
            self.err_arg(c, 3, format!("sphere: radius must be positive, got {}", c.args[3].text));
            return;
        }
        let kind = ShapeKind::Sphere {
            center: DVec3::new(v[0], v[1], v[2]),
            radius: v[3],
        };
        self.shape(c, kind);
    }

    /// The shapes of the geometry extensions: `plane`, `box`, `cylinder`, `disk`,
    /// `cone`, `quadric`.
    pub(super) fn analytic(&mut self, c: &Command) {
        let kind = match c.name.text {
            "plane" => {
                let Some(v) = self.nums::<6>(c) else { return };
                let normal = DVec3::new(v[3], v[4], v[5]);
                if normal == DVec3::ZERO {
                    self.err_span(c, 3, 3, "plane: the normal must not be zero");
                    return;
                }
                ShapeKind::Plane {
                    point: DVec3::new(v[0], v[1], v[2]),
                    normal,
                }
            }
            "box" => {
                let Some(v) = self.nums::<6>(c) else { return };
                let (a, b) = (DVec3::new(v[0], v[1], v[2]), DVec3::new(v[3], v[4], v[5]));
                if let Some(axis) = (0..3).find(|&k| a[k] == b[k]) {
                    let msg = format!(
                        "box: the corners have the same {} (the box would be flat)",
                        ["x", "y", "z"][axis]
                    );
                    self.err_arg(c, 3 + axis, msg);
                    return;
                }
                ShapeKind::Box {
                    lo: a.min(b),
                    hi: a.max(b),
                }
            }
            "cylinder" => {
                let Some([radius, zmin, zmax]) = self.nums::<3>(c) else {
                    return;
                };
                if !self.positive_arg(c, 0, radius, "radius") {
                    return;
                }
                if !(zmax > zmin) {
                    let msg = format!(
                        "cylinder: zmax ({}) must be greater than zmin ({})",
                        c.args[2].text, c.args[1].text
                    );
                    self.err_arg(c, 2, msg);
                    return;
                }
                ShapeKind::Cylinder { radius, zmin, zmax }
            }
            "disk" => {
                let Some([radius]) = self.nums::<1>(c) else { return };
                if !self.positive_arg(c, 0, radius, "radius") {
                    return;
                }
                ShapeKind::Disk { radius }
            }
            "cone" => {
                let Some([radius, height]) = self.nums::<2>(c) else {
                    return;
                };
                if !self.positive_arg(c, 0, radius, "radius") {
                    return;
                }
                if height == 0.0 {
                    self.err_arg(c, 1, "cone: height must not be zero");
                    return;
                }
                ShapeKind::Cone { radius, height }
            }
            _ => {
                let Some(v) = self.nums::<16>(c) else { return };
                let mut coefficients = [0.0; 10];
                coefficients.copy_from_slice(&v[..10]);
                if coefficients.iter().all(|&x| x == 0.0) {
                    self.err_span(c, 0, 10, "quadric: all ten coefficients are zero (no surface)");
                    return;
                }
                let (lo, hi) = (DVec3::new(v[10], v[11], v[12]), DVec3::new(v[13], v[14], v[15]));
                if let Some(axis) = (0..3).find(|&k| !(hi[k] > lo[k])) {
                    let xyz = ["x", "y", "z"][axis];
                    let msg = format!(
                        "quadric: the clip box needs {xyz}1 > {xyz}0, got {} and {}",
                        c.args[13 + axis].text,
                        c.args[10 + axis].text
                    );
                    self.err_arg(c, 13 + axis, msg);
                    return;
                }
                ShapeKind::Quadric { coefficients, lo, hi }
            }
        };
        self.shape(c, kind);
    }

    /// Whether argument `k` (whose value is `x`) is positive; an error if not.
    fn positive_arg(&mut self, c: &Command, k: usize, x: f64, what: &str) -> bool {
        if x > 0.0 {
            return true;
        }
        let msg = format!("{}: {what} must be positive, got {}", c.name.text, c.args[k].text);
        self.err_arg(c, k, msg);
        false
    }

    /// `maxverts n` and `maxvertnorms n`: hints; more vertices are a warning.
    pub(super) fn max_verts(&mut self, c: &Command) {
        if let Some([n]) = self.ints::<1>(c) {
            if n < 0 {
                self.err_arg(c, 0, format!("{}: count must not be negative, got {n}", c.name.text));
            } else if c.name.text == "maxverts" {
                self.max_verts = Some((n as u64, c.line));
            } else {
                self.max_vert_norms = Some((n as u64, c.line));
            }
        }
    }

    /// `vertex x y z`.
    pub(super) fn vertex(&mut self, c: &Command) {
        if let Some(v) = self.nums::<3>(c) {
            self.desc.vertices.push(DVec3::from_array(v));
            if let Some((max, line)) = self.max_verts {
                if self.desc.vertices.len() as u64 > max && !self.warned_verts {
                    self.warned_verts = true;
                    let n = self.desc.vertices.len() - 1;
                    self.warn_cmd(
                        c,
                        format!("vertex: vertex #{n} exceeds 'maxverts {max}' (line {line}); continuing (hint only)"),
                    );
                }
            }
        }
    }

    /// `vertexnormal x y z nx ny nz`, the normal not zero.
    pub(super) fn vertex_normal(&mut self, c: &Command) {
        if let Some(v) = self.nums::<6>(c) {
            let n = DVec3::new(v[3], v[4], v[5]);
            if n.length() == 0.0 {
                self.err_arg(c, 3, "vertexnormal: the normal has zero length");
                return;
            }
            self.desc.vertex_normals.push((DVec3::new(v[0], v[1], v[2]), n));
            if let Some((max, line)) = self.max_vert_norms {
                if self.desc.vertex_normals.len() as u64 > max && !self.warned_vert_norms {
                    self.warned_vert_norms = true;
                    let n = self.desc.vertex_normals.len() - 1;
                    self.warn_cmd(c, format!("vertexnormal: vertex #{n} exceeds 'maxvertnorms {max}' (line {line}); continuing (hint only)"));
                }
            }
        }
    }

    /// `tri a b c` and `trinormal a b c`: indices into the `vertex` or `vertexnormal`
    /// pile as it stands at this line.
    pub(super) fn triangle(&mut self, c: &Command) {
        let Some(idx) = self.ints::<3>(c) else { return };
        let normals = c.name.text == "trinormal";
        let pile = if normals {
            self.desc.vertex_normals.len()
        } else {
            self.desc.vertices.len()
        };
        let (one, many) = if normals {
            ("vertexnormal", "vertexnormals")
        } else {
            ("vertex", "vertices")
        };
        let mut v = [0u32; 3];
        for (k, &i) in idx.iter().enumerate() {
            if i < 0 || i as u64 >= pile as u64 {
                let defined = match pile {
                    0 => format!("no {one} defined yet"),
                    1 => format!("1 {one} defined, valid 0..0"),
                    _ => format!("{pile} {many} defined, valid 0..{}", pile - 1),
                };
                self.err_arg(
                    c,
                    k,
                    format!("{}: vertex index {i} out of range ({defined})", c.name.text),
                );
                return;
            }
            v[k] = i as u32;
        }
        let kind = if normals {
            ShapeKind::TriNormal { v }
        } else {
            ShapeKind::Triangle { v }
        };
        self.shape(c, kind);
    }
}
