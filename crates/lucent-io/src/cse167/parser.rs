//! The parser's state — the transform stack, the current material and attenuation, the
//! vertex piles, the object being recorded — and how a command that creates something
//! captures it. The commands themselves are in the files of their family, dispatched by
//! [`super::commands`].

use std::path::PathBuf;

use glam::DVec3;
use lucent_core::transform::Transform;

use super::lexer::{self, Command, Token};
use super::nurbs::PendingNurbs;
use super::ParseOptions;
use crate::desc::*;
use crate::diag::{Diagnostics, Loc};

pub(super) struct Parser {
    pub desc: SceneDesc,
    pub diags: Diagnostics,
    pub options: ParseOptions,
    /// The file being read (index in the description's sources).
    pub file: u32,
    /// Where files named by the scene are looked for: the scene file's directory.
    pub base_dir: PathBuf,
    pub stack: Vec<Transform>,
    pub current: Transform,
    /// Index in `desc.transforms` of `current`, once a shape or light has captured it.
    pub current_id: Option<u32>,
    pub material: MaterialDesc,
    pub material_id: Option<u32>,
    pub attenuation: DVec3,
    /// `maxverts`/`maxvertnorms` hints: (count, line), and whether the excess was reported.
    pub max_verts: Option<(u64, u32)>,
    pub max_vert_norms: Option<(u64, u32)>,
    pub warned_verts: bool,
    pub warned_vert_norms: bool,
    pub seen_command: bool,
    /// Reading command-line overrides: a setting given again replaces the file's
    /// silently.
    pub overriding: bool,
    /// The files being read, outermost first (canonical paths): `include` refuses
    /// cycles by them.
    pub include_stack: Vec<PathBuf>,
    /// Bytes read by `include` so far (bounded like one scene file).
    pub included_bytes: u64,
    /// Lines of the `pushTransform`s not popped yet.
    pub push_lines: Vec<u32>,
    /// The object being recorded (`objectbegin` without its `objectend` yet), with the
    /// line of its `objectbegin`.
    pub object: Option<(u32, u32)>,
    /// `displacementmap`: what displaces the surfaces that follow.
    pub displacement: Option<DisplacementDesc>,
    /// The `nurbs` command being read, if any.
    pub nurbs: Option<PendingNurbs>,
}

impl Parser {
    pub fn new(options: ParseOptions) -> Parser {
        Parser {
            desc: SceneDesc::default(),
            diags: Diagnostics::default(),
            options,
            file: 0,
            base_dir: PathBuf::new(),
            stack: Vec::new(),
            current: Transform::IDENTITY,
            current_id: None,
            material: MaterialDesc::default(),
            material_id: None,
            attenuation: DVec3::new(1.0, 0.0, 0.0),
            max_verts: None,
            max_vert_norms: None,
            warned_verts: false,
            warned_vert_norms: false,
            seen_command: false,
            overriding: false,
            include_stack: Vec::new(),
            included_bytes: 0,
            push_lines: Vec::new(),
            object: None,
            displacement: None,
            nurbs: None,
        }
    }

    pub fn loc(&self, line: u32, tok: &Token) -> Loc {
        Loc {
            file: self.file,
            line,
            col: tok.col,
            len: tok.text.chars().count() as u32,
        }
    }

    /// Reads line `line` (1-based) and runs its command.
    pub fn line(&mut self, line: u32, raw: &[u8]) {
        match lexer::command(line, raw) {
            Err(e) => {
                let loc = Loc {
                    file: self.file,
                    line,
                    col: e.col,
                    len: 1,
                };
                self.diags.error(loc, e.message);
            }
            Ok(None) => {}
            Ok(Some(c)) => {
                self.run(&c);
                self.seen_command = true;
            }
        }
    }

    /// The file named by argument `k`, resolved against the scene's folder, with the
    /// argument's place.
    pub fn file_arg(&self, c: &Command, k: usize) -> Located<PathBuf> {
        Located {
            value: self.base_dir.join(c.args[k].text),
            loc: self.loc(c.line, &c.args[k]),
        }
    }

    // ---- state capture ----

    pub fn apply(&mut self, t: Transform) {
        self.current = self.current.then_apply(&t);
        self.current_id = None;
    }

    pub fn transform_id(&mut self) -> u32 {
        *self.current_id.get_or_insert_with(|| {
            self.desc.transforms.push(self.current);
            (self.desc.transforms.len() - 1) as u32
        })
    }

    /// The current material's index in `desc.materials`, added there on first use.
    pub fn material_id(&mut self) -> u32 {
        *self.material_id.get_or_insert_with(|| {
            self.desc.materials.push(self.material);
            (self.desc.materials.len() - 1) as u32
        })
    }

    /// Changes the current material (objects created from now on capture the change).
    pub fn set_material(&mut self, change: impl FnOnce(&mut MaterialDesc)) {
        change(&mut self.material);
        self.material_id = None;
    }

    /// Records a shape of command `c` with the current transform and material.
    pub fn shape(&mut self, c: &Command, kind: ShapeKind) {
        let loc = self.loc(c.line, &c.name);
        self.shape_at(loc, kind);
    }

    /// Records a shape of the command at `loc` with the current transform and material.
    pub fn shape_at(&mut self, loc: Loc, kind: ShapeKind) {
        let transform = self.transform_id();
        let material = self.material_id();
        self.desc.shapes.push(ShapeDesc {
            kind,
            transform,
            material,
            object: self.object.map(|(o, _)| o),
            loc,
        });
    }

    /// Records a surface the build will make into triangles, with the current
    /// displacement, as a shape of command `c`.
    pub fn surface(&mut self, c: &Command, recipe: SurfaceRecipe) {
        let loc = self.loc(c.line, &c.name);
        self.surface_at(loc, recipe);
    }

    /// [`Parser::surface`] for the command at `loc`.
    pub fn surface_at(&mut self, loc: Loc, recipe: SurfaceRecipe) {
        let index = self.desc.surfaces.len() as u32;
        self.desc.surfaces.push(SurfaceDesc {
            recipe,
            displacement: self.displacement,
        });
        self.shape_at(loc, ShapeKind::Surface { index });
    }

    /// Sets a global setting; given again, the last one wins, with a warning.
    pub fn set_global<T>(
        &mut self,
        c: &Command,
        field: impl Fn(&mut SceneDesc) -> &mut Option<Located<T>>,
        value: Located<T>,
    ) {
        if let (Some(prev), false) = (field(&mut self.desc), self.overriding) {
            let line = prev.loc.line;
            self.warn_cmd(
                c,
                format!(
                    "{}: given again (previously on line {line}); the last one wins",
                    c.name.text
                ),
            );
        }
        *field(&mut self.desc) = Some(value);
    }

    /// What the end of the file still has to say: an object or a NURBS surface left
    /// open, the required commands, transforms pushed and never popped.
    pub fn finish(&mut self, lines: u32) {
        self.unclosed_object();
        self.unfinished_nurbs();
        let end = Loc {
            file: self.file,
            line: lines.max(1),
            col: 1,
            len: 0,
        };
        self.desc.end = end;
        if self.desc.size.is_none() {
            self.diags
                .error(end, "the scene has no 'size' command (required: size width height)");
        }
        if self.desc.camera.is_none() {
            self.diags.error(
                end,
                "the scene has no 'camera' command (required: camera from at up fovy)",
            );
        }
        if let Some(&line) = self.push_lines.first() {
            let n = self.push_lines.len();
            self.diags.note(
                Loc {
                    file: self.file,
                    line,
                    col: 1,
                    len: 13,
                },
                format!("{n} pushTransform without popTransform at the end of the file (harmless)"),
            );
        }
    }

    // ---- diagnostics at a command ----

    pub fn err_cmd(&mut self, c: &Command, msg: impl Into<String>) {
        let loc = self.loc(c.line, &c.name);
        self.diags.error(loc, msg);
    }

    pub fn warn_cmd(&mut self, c: &Command, msg: impl Into<String>) {
        let loc = self.loc(c.line, &c.name);
        self.diags.warning(loc, msg);
    }

    pub fn err_arg(&mut self, c: &Command, k: usize, msg: impl Into<String>) {
        let loc = self.loc(c.line, &c.args[k]);
        self.diags.error(loc, msg);
    }

    /// The span of arguments `first .. first + n`.
    pub fn span(&self, c: &Command, first: usize, n: usize) -> Loc {
        let a = &c.args[first];
        let b = &c.args[first + n - 1];
        Loc {
            file: self.file,
            line: c.line,
            col: a.col,
            len: b.col + b.text.chars().count() as u32 - a.col,
        }
    }

    /// An error underlining arguments `first .. first + n`.
    pub fn err_span(&mut self, c: &Command, first: usize, n: usize, msg: impl Into<String>) {
        let loc = self.span(c, first, n);
        self.diags.error(loc, msg);
    }
}
