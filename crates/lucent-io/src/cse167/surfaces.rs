//! Surfaces made of triangles, recorded as recipes the build follows: `mesh file` (an
//! OBJ with its MTL materials, or a PLY file), `subdivmesh loop|catmullclark levels
//! file` and `bezierpatches file [divisions]`. Files are named relative to the scene's
//! folder; the build reads them and reports their problems at these commands.

use super::lexer::Command;
use super::parser::Parser;
use crate::desc::{Located, SubdivisionScheme, SurfaceRecipe};

/// Subdivision levels `subdivmesh` accepts: every level multiplies the faces by four.
const MAX_SUBDIVISION_LEVEL: i64 = 8;
/// `bezierpatches` divisions per patch side.
const MAX_PATCH_DIVISIONS: i64 = 256;

impl Parser {
    /// `mesh file`.
    pub(super) fn mesh(&mut self, c: &Command) {
        if !self.expect_count(c, 1, "a file name (.obj or .ply)") {
            return;
        }
        let file = self.file_arg(c, 0);
        self.surface(c, SurfaceRecipe::MeshFile { file });
    }

    /// `subdivmesh loop|catmullclark levels file`.
    pub(super) fn subdiv_mesh(&mut self, c: &Command) {
        if !self.expect_count(
            c,
            3,
            "a scheme (loop or catmullclark), a number of levels and a file name",
        ) {
            return;
        }
        let schemes = [
            ("loop", SubdivisionScheme::Loop),
            ("catmullclark", SubdivisionScheme::CatmullClark),
        ];
        let Some(scheme) = self.keyword_at(c, 0, &schemes) else {
            return;
        };
        let Some(levels) = self.integer(c, &c.args[1]) else {
            return;
        };
        if !self.in_range(c, 1, levels, 0..=MAX_SUBDIVISION_LEVEL, "levels") {
            return;
        }
        let levels = Located {
            value: levels as u32,
            loc: self.loc(c.line, &c.args[1]),
        };
        let file = self.file_arg(c, 2);
        self.surface(c, SurfaceRecipe::Subdivision { scheme, levels, file });
    }

    /// `bezierpatches file [divisions]`: each patch becomes `divisions × divisions` quads.
    pub(super) fn bezier_patches(&mut self, c: &Command) {
        if !self.one_or_two(c, "a file name and optionally a number of divisions") {
            return;
        }
        let Some(divisions) = self.optional_second(c, 16, |p, c| {
            let d = p.integer(c, &c.args[1])?;
            p.in_range(c, 1, d, 1..=MAX_PATCH_DIVISIONS, "divisions")
                .then_some(d as u32)
        }) else {
            return;
        };
        let file = self.file_arg(c, 0);
        self.surface(c, SurfaceRecipe::BezierPatches { file, divisions });
    }
}
