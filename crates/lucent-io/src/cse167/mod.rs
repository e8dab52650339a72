//! The CSE167/CSE168 scene format (`../shared/SCENE_FORMAT.md`), read into a
//! [`SceneDesc`].
//!
//! The file is a program that changes a parser state (transform stack, current material,
//! attenuation, vertex piles); commands that create objects capture a snapshot of it.
//! This module checks each command where it stands — argument count, number syntax,
//! ranges, indices — and records it with its location. It does not build geometry.
//! docs/scene-format.md lists every command with its arguments, defaults and errors.

mod meshes;
mod objects;
mod sampling;
mod textures;

use std::path::Path;

use glam::DVec3;
use lucent_core::camera::{Camera, CameraError, Projection};
use lucent_core::transform::Transform;

use crate::desc::*;
use crate::diag::{Diagnostics, Loc};
use crate::number::{is_decimal, is_integer};

/// Images larger than this many pixels are refused (SCENE_FORMAT.md §5.4).
pub const MAX_PIXELS: u64 = 1 << 26;

#[derive(Clone, Copy, Debug, Default)]
pub struct ParseOptions {
    /// Unknown commands are errors instead of warnings.
    pub strict: bool,
}

/// Every command of the course format, with its argument count, for dispatch and for
/// suggestions when a name is misspelt.
const COMMANDS: &[&str] = &[
    "size",
    "maxdepth",
    "output",
    "camera",
    "sphere",
    "plane",
    "box",
    "cylinder",
    "disk",
    "cone",
    "quadric",
    "bezierpatches",
    "mesh",
    "subdivmesh",
    "nurbs",
    "knotsu",
    "knotsv",
    "cpoint",
    "objectbegin",
    "objectend",
    "instance",
    "transparent",
    "ior",
    "glossy",
    "orthocamera",
    "lens",
    "texture",
    "checker",
    "diffusemap",
    "bumpmap",
    "envmap",
    "displacementmap",
    "maxverts",
    "maxvertnorms",
    "vertex",
    "vertexnormal",
    "tri",
    "trinormal",
    "translate",
    "rotate",
    "scale",
    "pushTransform",
    "popTransform",
    "directional",
    "point",
    "attenuation",
    "ambient",
    "diffuse",
    "specular",
    "shininess",
    "emission",
    "integrator",
    "quadLight",
    "lightsamples",
    "lightstratify",
    "spp",
    "nexteventestimation",
    "russianroulette",
    "importancesampling",
    "brdf",
    "roughness",
    "gamma",
];

/// Reads and parses a scene file. A file that cannot be read is an error at `path:1:1`.
pub fn parse_file(path: &Path, options: ParseOptions) -> (SceneDesc, Diagnostics) {
    match std::fs::read(path) {
        Ok(bytes) => parse_bytes(&path.display().to_string(), &bytes, options),
        Err(e) => {
            let mut desc = SceneDesc::default();
            let file = desc.sources.add(path.display().to_string(), Vec::new());
            let mut diags = Diagnostics::default();
            diags.error(
                Loc {
                    file,
                    line: 1,
                    col: 1,
                    len: 0,
                },
                format!("cannot read scene file: {}", io_reason(&e)),
            );
            (desc, diags)
        }
    }
}

pub(crate) fn io_reason(e: &std::io::Error) -> String {
    match e.kind() {
        std::io::ErrorKind::NotFound => "no such file".into(),
        std::io::ErrorKind::PermissionDenied => "permission denied".into(),
        _ => {
            let s = e.to_string();
            s.split(" (os error").next().unwrap_or(&s).to_lowercase()
        }
    }
}

/// Parses scene text; `name` is what diagnostics call the file.
pub fn parse_bytes(name: &str, bytes: &[u8], options: ParseOptions) -> (SceneDesc, Diagnostics) {
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let raw_lines: Vec<&[u8]> = split_lines(bytes);
    let shown: Vec<String> = raw_lines
        .iter()
        .map(|l| String::from_utf8_lossy(l).into_owned())
        .collect();
    let mut p = Parser::new(options);
    p.base_dir = Path::new(name).parent().map(Path::to_path_buf).unwrap_or_default();
    p.file = p.desc.sources.add(name.to_string(), shown);
    for (i, raw) in raw_lines.iter().enumerate() {
        if p.diags.too_many_errors() {
            break;
        }
        p.line(i as u32 + 1, raw);
    }
    p.finish(raw_lines.len() as u32);
    (p.desc, p.diags)
}

fn split_lines(bytes: &[u8]) -> Vec<&[u8]> {
    if bytes.is_empty() {
        return Vec::new();
    }
    let body = bytes.strip_suffix(b"\n").unwrap_or(bytes);
    body.split(|&b| b == b'\n')
        .map(|l| l.strip_suffix(b"\r").unwrap_or(l))
        .collect()
}

/// A token and its 1-based column (in characters).
#[derive(Clone, Copy)]
struct Token<'a> {
    text: &'a str,
    col: u32,
}

struct Command<'a> {
    name: Token<'a>,
    args: Vec<Token<'a>>,
    line: u32,
    /// Column just past the last token (where a missing argument would go).
    end_col: u32,
}

/// A `nurbs` command waiting for its `knotsu`, `knotsv` and `cpoint` lines.
struct PendingNurbs {
    at: Loc,
    line: u32,
    transform: u32,
    material: u32,
    surface: lucent_core::tessellate::nurbs::NurbsSurface,
}

struct Parser {
    /// The `nurbs` command being read, if any.
    nurbs: Option<PendingNurbs>,
    /// Where files named by the scene are looked for: the scene file's directory.
    base_dir: std::path::PathBuf,
    desc: SceneDesc,
    diags: Diagnostics,
    options: ParseOptions,
    file: u32,
    stack: Vec<Transform>,
    current: Transform,
    /// Index in `desc.transforms` of `current`, once a shape or light has captured it.
    current_id: Option<u32>,
    material: MaterialDesc,
    material_id: Option<u32>,
    attenuation: DVec3,
    /// `maxverts`/`maxvertnorms` hints: (count, line), and whether the excess was reported.
    max_verts: Option<(u64, u32)>,
    max_vert_norms: Option<(u64, u32)>,
    warned_verts: bool,
    warned_vert_norms: bool,
    seen_command: bool,
    push_lines: Vec<u32>,
    /// The object being recorded (`objectbegin` without its `objectend` yet), with the
    /// line of its `objectbegin`.
    object: Option<(u32, u32)>,
    /// `displacementmap`: texture index and scale for the surfaces tessellated next.
    displacement: Option<(u32, f32)>,
}

impl Parser {
    fn new(options: ParseOptions) -> Parser {
        Parser {
            nurbs: None,
            base_dir: std::path::PathBuf::new(),
            desc: SceneDesc::default(),
            diags: Diagnostics::default(),
            options,
            file: 0,
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
            push_lines: Vec::new(),
            object: None,
            displacement: None,
        }
    }

    fn loc(&self, line: u32, tok: &Token) -> Loc {
        Loc {
            file: self.file,
            line,
            col: tok.col,
            len: tok.text.chars().count() as u32,
        }
    }

    fn line(&mut self, line: u32, raw: &[u8]) {
        let text = match std::str::from_utf8(raw) {
            Ok(t) => t,
            Err(e) => {
                let col = String::from_utf8_lossy(&raw[..e.valid_up_to()]).chars().count() as u32 + 1;
                let byte = raw[e.valid_up_to()];
                self.diags.error(
                    Loc {
                        file: self.file,
                        line,
                        col,
                        len: 1,
                    },
                    format!("invalid UTF-8 (byte 0x{byte:02X}): scene files are text"),
                );
                return;
            }
        };
        if let Some((i, c)) = text.chars().enumerate().find(|(_, c)| c.is_control() && *c != '\t') {
            self.diags.error(
                Loc {
                    file: self.file,
                    line,
                    col: i as u32 + 1,
                    len: 1,
                },
                format!("unexpected control character U+{:04X}: scene files are text", c as u32),
            );
            return;
        }
        let mut tokens = Vec::new();
        let mut col = 0u32;
        let mut start: Option<(usize, u32)> = None;
        for (i, c) in text.char_indices() {
            col += 1;
            let blank = c == ' ' || c == '\t';
            match (blank, start) {
                (false, None) => start = Some((i, col)),
                (true, Some((s, sc))) => {
                    tokens.push(Token {
                        text: &text[s..i],
                        col: sc,
                    });
                    start = None;
                }
                _ => {}
            }
        }
        if let Some((s, sc)) = start {
            tokens.push(Token {
                text: &text[s..],
                col: sc,
            });
        }
        // A token starting with '#' begins a comment to the end of the line.
        if let Some(k) = tokens.iter().position(|t| t.text.starts_with('#')) {
            tokens.truncate(k);
        }
        let Some((&name, args)) = tokens.split_first() else {
            return;
        };
        let end_col = col + 1;
        let cmd = Command {
            name,
            args: args.to_vec(),
            line,
            end_col,
        };
        self.command(&cmd);
        self.seen_command = true;
    }

    fn command(&mut self, c: &Command) {
        if self.nurbs.is_some() && !matches!(c.name.text, "knotsu" | "knotsv" | "cpoint") {
            let p = self.nurbs.take().expect("checked");
            let wanted = Self::nurbs_expects(&p.surface);
            self.err_cmd(
                c,
                format!(
                    "'{}' inside the nurbs surface of line {} (expected {wanted})",
                    c.name.text, p.line
                ),
            );
        }
        match c.name.text {
            "nurbs" => self.nurbs_header(c),
            "mesh" => self.mesh(c),
            "subdivmesh" => self.subdiv_mesh(c),
            "objectbegin" => self.object_begin(c),
            "objectend" => self.object_end(c),
            "instance" => self.instance(c),
            "knotsu" | "knotsv" | "cpoint" => self.nurbs_part(c),
            "size" => self.size(c),
            "maxdepth" => {
                if let Some([d]) = self.ints::<1>(c) {
                    if d < -1 || d > i32::MAX as i64 {
                        self.err_arg(
                            c,
                            0,
                            format!(
                                "maxdepth: depth must be -1 (unbounded) or between 0 and {}, got {d}",
                                i32::MAX
                            ),
                        );
                    } else {
                        let v = Located {
                            value: d as i32,
                            loc: self.loc(c.line, &c.name),
                        };
                        self.set_global(c, |d| &mut d.max_depth, v);
                    }
                }
            }
            "output" => {
                if self.expect_count(c, 1, "a file name") {
                    let v = Located {
                        value: c.args[0].text.to_string(),
                        loc: self.loc(c.line, &c.args[0]),
                    };
                    self.set_global(c, |d| &mut d.output, v);
                }
            }
            "camera" | "orthocamera" => self.camera(c),
            "lens" => self.lens(c),
            "transparent" => {
                if let Some(v) = self.nums::<3>(c) {
                    self.material.base.transparent = self.color_at(c, 0, &v).as_vec3a();
                    self.material_id = None;
                }
            }
            "ior" => {
                if let Some([n]) = self.nums::<1>(c) {
                    if n > 0.0 {
                        self.material.base.ior = n as f32;
                        self.material_id = None;
                    } else {
                        self.err_arg(c, 0, format!("ior: must be positive, got {}", c.args[0].text));
                    }
                }
            }
            "glossy" => self.glossy(c),
            "texture" | "checker" => self.texture(c),
            "diffusemap" => self.diffuse_map(c),
            "bumpmap" => self.bump_map(c),
            "displacementmap" => self.displacement_map(c),
            "envmap" => self.environment(c),
            "sphere" => self.sphere(c),
            "plane" | "box" | "cylinder" | "disk" | "cone" | "quadric" => self.analytic(c),
            "bezierpatches" => self.bezier_patches(c),
            "maxverts" | "maxvertnorms" => {
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
            "vertex" => {
                if let Some(v) = self.nums::<3>(c) {
                    self.desc.vertices.push(DVec3::from_array(v));
                    if let Some((max, line)) = self.max_verts {
                        if self.desc.vertices.len() as u64 > max && !self.warned_verts {
                            self.warned_verts = true;
                            let n = self.desc.vertices.len() - 1;
                            self.warn_cmd(c, format!("vertex: vertex #{n} exceeds 'maxverts {max}' (line {line}); continuing (hint only)"));
                        }
                    }
                }
            }
            "vertexnormal" => {
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
            "tri" | "trinormal" => self.triangle(c),
            "translate" => {
                if let Some(t) = self.nums::<3>(c) {
                    self.apply(Transform::translate(DVec3::from_array(t)));
                }
            }
            "rotate" => {
                if let Some(r) = self.nums::<4>(c) {
                    match Transform::rotate(DVec3::new(r[0], r[1], r[2]), r[3]) {
                        Some(t) => self.apply(t),
                        None => self.err_span(c, 0, 3, "rotate: the rotation axis is zero"),
                    }
                }
            }
            "scale" => {
                if let Some(s) = self.nums::<3>(c) {
                    match Transform::scale(DVec3::from_array(s)) {
                        Some(t) => self.apply(t),
                        None => {
                            let k = s.iter().position(|&x| x == 0.0).unwrap_or(0);
                            self.err_arg(c, k, "scale: a zero factor makes the transform singular");
                        }
                    }
                }
            }
            "pushTransform" => {
                if self.expect_count(c, 0, "no arguments") {
                    self.stack.push(self.current);
                    self.push_lines.push(c.line);
                }
            }
            "popTransform" => {
                if self.expect_count(c, 0, "no arguments") {
                    match self.stack.pop() {
                        Some(t) => {
                            self.current = t;
                            self.current_id = None;
                            self.push_lines.pop();
                        }
                        None => self.err_cmd(c, "popTransform: transform stack is empty"),
                    }
                }
            }
            "directional" => {
                if let Some(v) = self.nums::<6>(c) {
                    let dir = DVec3::new(v[0], v[1], v[2]);
                    if dir.length() == 0.0 {
                        self.err_span(c, 0, 3, "directional: the direction is zero");
                        return;
                    }
                    let color = self.color_at(c, 3, &v[3..6]);
                    self.light(c, LightKind::Directional { dir, color });
                }
            }
            "point" => {
                if let Some(v) = self.nums::<6>(c) {
                    let color = self.color_at(c, 3, &v[3..6]);
                    self.light(
                        c,
                        LightKind::Point {
                            position: DVec3::new(v[0], v[1], v[2]),
                            color,
                            attenuation: self.attenuation,
                        },
                    );
                }
            }
            "attenuation" => {
                if let Some(a) = self.nums::<3>(c) {
                    if let Some(k) = a.iter().position(|&x| x < 0.0) {
                        self.err_arg(c, k, "attenuation: coefficients must not be negative");
                    } else if a.iter().all(|&x| x == 0.0) {
                        self.err_span(c, 0, 3, "attenuation: all three coefficients are zero (infinite light)");
                    } else {
                        self.attenuation = DVec3::from_array(a);
                    }
                }
            }
            "ambient" | "diffuse" | "specular" | "emission" => {
                if let Some(v) = self.nums::<3>(c) {
                    let col = self.color_at(c, 0, &v).as_vec3a();
                    let m = &mut self.material.base;
                    match c.name.text {
                        "ambient" => m.ambient = col,
                        "diffuse" => m.diffuse = col,
                        "specular" => m.specular = col,
                        _ => m.emission = col,
                    }
                    self.material_id = None;
                }
            }
            "shininess" => {
                if let Some([s]) = self.nums::<1>(c) {
                    if s < 0.0 {
                        self.err_arg(c, 0, format!("shininess: must not be negative, got {}", c.args[0].text));
                    } else {
                        self.material.base.shininess = s as f32;
                        self.material_id = None;
                    }
                }
            }
            "integrator" => {
                if let Some(k) = self.keyword(c, &IntegratorKind::ALL) {
                    let v = Located {
                        value: k,
                        loc: self.loc(c.line, &c.args[0]),
                    };
                    self.set_global(c, |d| &mut d.integrator, v);
                }
            }
            "quadLight" => {
                if let Some(v) = self.nums::<12>(c) {
                    let a = DVec3::new(v[0], v[1], v[2]);
                    let ab = DVec3::new(v[3], v[4], v[5]);
                    let ac = DVec3::new(v[6], v[7], v[8]);
                    if ab.cross(ac).length() == 0.0 {
                        self.err_span(
                            c,
                            3,
                            6,
                            "quadLight: the edges ab and ac are parallel or zero (the light has no area)",
                        );
                        return;
                    }
                    let color = self.color_at(c, 9, &v[9..12]);
                    self.light(c, LightKind::Quad { a, ab, ac, color });
                }
            }
            "lightsamples" | "spp" => {
                if let Some([n]) = self.ints::<1>(c) {
                    if n < 1 {
                        self.err_arg(c, 0, format!("{}: must be at least 1, got {n}", c.name.text));
                    } else if n > u32::MAX as i64 {
                        self.err_arg(c, 0, format!("{}: {n} is too large", c.name.text));
                    } else {
                        let v = Located {
                            value: n as u32,
                            loc: self.loc(c.line, &c.args[0]),
                        };
                        if c.name.text == "spp" {
                            self.set_global(c, |d| &mut d.spp, v);
                        } else {
                            self.set_global(c, |d| &mut d.light_samples, v);
                        }
                    }
                }
            }
            "lightstratify" | "russianroulette" => {
                if let Some(on) = self.keyword(c, &[("on", true), ("off", false)]) {
                    let v = Located {
                        value: on,
                        loc: self.loc(c.line, &c.args[0]),
                    };
                    if c.name.text == "lightstratify" {
                        self.set_global(c, |d| &mut d.light_stratify, v);
                    } else {
                        self.set_global(c, |d| &mut d.russian_roulette, v);
                    }
                }
            }
            "nexteventestimation" => {
                if let Some(m) = self.keyword(c, &[("on", NeeMode::On), ("off", NeeMode::Off), ("mis", NeeMode::Mis)]) {
                    let v = Located {
                        value: m,
                        loc: self.loc(c.line, &c.args[0]),
                    };
                    self.set_global(c, |d| &mut d.next_event_estimation, v);
                }
            }
            "importancesampling" => {
                let kinds = [
                    ("hemisphere", DirectionSampling::Hemisphere),
                    ("cosine", DirectionSampling::Cosine),
                    ("brdf", DirectionSampling::Brdf),
                ];
                if let Some(m) = self.keyword(c, &kinds) {
                    let v = Located {
                        value: m,
                        loc: self.loc(c.line, &c.args[0]),
                    };
                    self.set_global(c, |d| &mut d.importance_sampling, v);
                }
            }
            "brdf" => {
                if let Some(b) = self.keyword(c, &[("phong", Brdf::Phong), ("ggx", Brdf::Ggx)]) {
                    self.material.brdf = b;
                    self.material_id = None;
                }
            }
            "roughness" => {
                if let Some(a) = self.positive(c) {
                    self.material.roughness = a;
                    self.material_id = None;
                }
            }
            "gamma" => {
                if let Some(g) = self.positive(c) {
                    let v = Located {
                        value: g,
                        loc: self.loc(c.line, &c.name),
                    };
                    self.set_global(c, |d| &mut d.gamma, v);
                }
            }
            name => {
                let hint = suggestion(name).map_or(String::new(), |s| format!("; did you mean '{s}'?"));
                let loc = self.loc(c.line, &c.name);
                if self.options.strict {
                    self.diags.error(loc, format!("unknown command '{name}'{hint}"));
                } else {
                    self.diags
                        .warning(loc, format!("unknown command '{name}' ignored{hint}"));
                }
            }
        }
    }

    // ---- commands with more to check ----

    fn size(&mut self, c: &Command) {
        let Some([w, h]) = self.ints::<2>(c) else {
            return;
        };
        for (k, v) in [w, h].into_iter().enumerate() {
            if v < 1 {
                self.err_arg(c, k, format!("size: width and height must be at least 1, got {v}"));
                return;
            }
        }
        let pixels = (w as i128) * (h as i128);
        if pixels > MAX_PIXELS as i128 || w > u32::MAX as i64 || h > u32::MAX as i64 {
            self.err_span(
                c,
                0,
                2,
                format!("size: {w} x {h} is too large (at most {MAX_PIXELS} pixels)"),
            );
            return;
        }
        if self.seen_command && self.desc.size.is_none() {
            self.warn_cmd(c, "size: should be the first command of the file");
        }
        let v = Located {
            value: (w as u32, h as u32),
            loc: self.loc(c.line, &c.name),
        };
        self.set_global(c, |d| &mut d.size, v);
    }

    /// `camera … fovy` and `orthocamera … height`: either is the scene's camera (the
    /// last one given wins).
    fn camera(&mut self, c: &Command) {
        let Some(v) = self.nums::<10>(c) else { return };
        let projection = if c.name.text == "orthocamera" {
            Projection::Orthographic { height: v[9] }
        } else {
            Projection::Perspective { fovy: v[9] }
        };
        let cam = CameraDesc {
            eye: DVec3::new(v[0], v[1], v[2]),
            center: DVec3::new(v[3], v[4], v[5]),
            up: DVec3::new(v[6], v[7], v[8]),
            projection,
        };
        match Camera::new(cam.eye, cam.center, cam.up, cam.projection, 1, 1) {
            Ok(_) => {
                let v = Located {
                    value: cam,
                    loc: self.loc(c.line, &c.name),
                };
                self.set_global(c, |d| &mut d.camera, v);
            }
            Err(CameraError::FovOutOfRange) => self.err_arg(
                c,
                9,
                format!(
                    "camera: field of view must be between 0 and 180 degrees, got {}",
                    c.args[9].text
                ),
            ),
            Err(CameraError::HeightNotPositive) => self.err_arg(
                c,
                9,
                format!("orthocamera: the view height must be positive, got {}", c.args[9].text),
            ),
            Err(CameraError::EyeAtTarget) => {
                let msg = format!("{}: the eye and the look-at point are the same", c.name.text);
                self.err_span(c, 0, 6, msg)
            }
            Err(CameraError::UpParallelToView) => {
                let msg = format!("{}: the up vector is parallel to the viewing direction", c.name.text);
                self.err_span(c, 6, 3, msg)
            }
        }
    }

    fn sphere(&mut self, c: &Command) {
        let Some(v) = self.nums::<4>(c) else { return };
        if v[3] <= 0.0 {
            self.err_arg(c, 3, format!("sphere: radius must be positive, got {}", c.args[3].text));
            return;
        }
        let object = Transform::translate(DVec3::new(v[0], v[1], v[2]))
            .then_apply(&Transform::scale(DVec3::splat(v[3])).expect("radius > 0"));
        if Transform::new(self.current.m * object.m).is_none() {
            self.err_cmd(c, "sphere: the current transform is singular");
            return;
        }
        let kind = ShapeKind::Sphere {
            center: DVec3::new(v[0], v[1], v[2]),
            radius: v[3],
        };
        self.shape(c, kind);
    }

    /// The shapes of the geometry extensions (EXTENSIONS.md): `plane`, `box`, `cylinder`,
    /// `disk`, `cone`, `quadric`.
    fn analytic(&mut self, c: &Command) {
        let name = c.name.text.to_string();
        let kind = match name.as_str() {
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
                if !(radius > 0.0) {
                    self.err_arg(
                        c,
                        0,
                        format!("cylinder: radius must be positive, got {}", c.args[0].text),
                    );
                    return;
                }
                if !(zmax > zmin) {
                    self.err_arg(
                        c,
                        2,
                        format!(
                            "cylinder: zmax ({}) must be greater than zmin ({})",
                            c.args[2].text, c.args[1].text
                        ),
                    );
                    return;
                }
                ShapeKind::Cylinder { radius, zmin, zmax }
            }
            "disk" => {
                let Some([radius]) = self.nums::<1>(c) else { return };
                if !(radius > 0.0) {
                    self.err_arg(c, 0, format!("disk: radius must be positive, got {}", c.args[0].text));
                    return;
                }
                ShapeKind::Disk { radius }
            }
            "cone" => {
                let Some([radius, height]) = self.nums::<2>(c) else {
                    return;
                };
                if !(radius > 0.0) {
                    self.err_arg(c, 0, format!("cone: radius must be positive, got {}", c.args[0].text));
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
        if Transform::new(self.current.m).is_none() {
            self.err_cmd(c, format!("{name}: the current transform is singular"));
            return;
        }
        self.shape(c, kind);
    }

    /// `nurbs du dv nu nv`: degrees and control point counts; the knots and control
    /// points follow on their own lines.
    fn nurbs_header(&mut self, c: &Command) {
        let Some([du, dv, nu, nv]) = self.ints::<4>(c) else {
            return;
        };
        for (k, d) in [(0, du), (1, dv)] {
            if !(1..=16).contains(&d) {
                self.err_arg(c, k, format!("nurbs: degree must be between 1 and 16, got {d}"));
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
        if nu * nv > 1 << 20 {
            self.err_span(c, 2, 2, format!("nurbs: {nu} × {nv} control points is too many"));
            return;
        }
        let transform = self.transform_id();
        let material = self.material_id();
        self.nurbs = Some(PendingNurbs {
            at: self.loc(c.line, &c.name),
            line: c.line,
            transform,
            material,
            surface: lucent_core::tessellate::nurbs::NurbsSurface {
                degree_u: du as usize,
                degree_v: dv as usize,
                count_u: nu as usize,
                count_v: nv as usize,
                knots_u: Vec::new(),
                knots_v: Vec::new(),
                points: Vec::new(),
            },
        });
    }

    /// What the pending surface needs next.
    fn nurbs_expects(s: &lucent_core::tessellate::nurbs::NurbsSurface) -> String {
        if s.knots_u.is_empty() {
            "knotsu".into()
        } else if s.knots_v.is_empty() {
            "knotsv".into()
        } else {
            format!("{} more cpoint lines", s.count_u * s.count_v - s.points.len())
        }
    }

    fn nurbs_part(&mut self, c: &Command) {
        let name = c.name.text;
        let Some(mut p) = self.nurbs.take() else {
            self.err_cmd(c, format!("{name}: only allowed right after a 'nurbs' command"));
            return;
        };
        let expected = Self::nurbs_expects(&p.surface);
        let fits = match name {
            "knotsu" => p.surface.knots_u.is_empty(),
            "knotsv" => !p.surface.knots_u.is_empty() && p.surface.knots_v.is_empty(),
            _ => !p.surface.knots_v.is_empty(),
        };
        if !fits {
            self.err_cmd(
                c,
                format!(
                    "{name}: out of order in the nurbs surface of line {} (expected {expected})",
                    p.line
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
            s.points.push(glam::DVec4::new(x * w, y * w, z * w, w));
        } else {
            let (degree, count) = if name == "knotsu" {
                (s.degree_u, s.count_u)
            } else {
                (s.degree_v, s.count_v)
            };
            let want = count + degree + 1;
            if c.args.len() != want {
                self.err_cmd(
                    c,
                    format!(
                        "{name}: expected {want} knots ({count} control points of degree {degree}), got {}",
                        c.args.len()
                    ),
                );
                return;
            }
            let mut knots = Vec::with_capacity(want);
            for (k, tok) in c.args.iter().enumerate() {
                let Some(x) = self.number(c, tok) else { return };
                if let Some(&prev) = knots.last() {
                    if x < prev {
                        self.err_arg(
                            c,
                            k,
                            format!("{name}: knots must not decrease ({} after {prev})", tok.text),
                        );
                        return;
                    }
                }
                knots.push(x);
            }
            if !(knots[degree] < knots[count]) {
                self.err_cmd(
                    c,
                    format!("{name}: the knots leave no parameter range (knot {degree} equals knot {count})"),
                );
                return;
            }
            if name == "knotsu" {
                s.knots_u = knots;
            } else {
                s.knots_v = knots;
            }
        }
        if s.points.len() == s.count_u * s.count_v {
            let index = self.desc.nurbs.len() as u32;
            self.desc.nurbs.push(p.surface);
            self.desc.shapes.push(ShapeDesc {
                kind: ShapeKind::Nurbs {
                    index,
                    displacement: self.displacement,
                },
                transform: p.transform,
                material: p.material,
                object: self.object.map(|(o, _)| o),
                loc: p.at,
            });
        } else {
            self.nurbs = Some(p);
        }
    }

    fn triangle(&mut self, c: &Command) {
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

    // ---- state capture ----

    fn apply(&mut self, t: Transform) {
        self.current = self.current.then_apply(&t);
        self.current_id = None;
    }

    fn transform_id(&mut self) -> u32 {
        *self.current_id.get_or_insert_with(|| {
            self.desc.transforms.push(self.current);
            (self.desc.transforms.len() - 1) as u32
        })
    }

    fn shape(&mut self, c: &Command, kind: ShapeKind) {
        let transform = self.transform_id();
        let material = self.material_id();
        let loc = self.loc(c.line, &c.name);
        self.desc.shapes.push(ShapeDesc {
            kind,
            transform,
            material,
            object: self.object.map(|(o, _)| o),
            loc,
        });
    }

    /// The current material's index in `desc.materials`, added there on first use.
    fn material_id(&mut self) -> u32 {
        *self.material_id.get_or_insert_with(|| {
            self.desc.materials.push(self.material);
            (self.desc.materials.len() - 1) as u32
        })
    }

    fn light(&mut self, c: &Command, kind: LightKind) {
        if let Some((o, line)) = self.object {
            let name = &self.desc.objects[o as usize].name;
            self.err_cmd(
                c,
                format!(
                    "{}: lights cannot be part of an object (object '{name}' begun on line {line} is still open)",
                    c.name.text
                ),
            );
            return;
        }
        if !self.current.is_identity() {
            self.warn_cmd(c, format!("{}: the light is transformed by the current transform (the course's renderers ignore transforms on lights)", c.name.text));
        }
        let transform = self.transform_id();
        let loc = self.loc(c.line, &c.name);
        self.desc.lights.push(LightDesc { kind, transform, loc });
    }

    fn set_global<T>(
        &mut self,
        c: &Command,
        field: impl Fn(&mut SceneDesc) -> &mut Option<Located<T>>,
        value: Located<T>,
    ) {
        if let Some(prev) = field(&mut self.desc) {
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

    fn finish(&mut self, lines: u32) {
        self.unclosed_object();
        if let Some(p) = self.nurbs.take() {
            let wanted = Self::nurbs_expects(&p.surface);
            self.diags.error(
                p.at,
                format!("nurbs: the file ends before the surface is complete (expected {wanted})"),
            );
        }
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
        if let Some(s) = &self.desc.light_stratify {
            if s.value {
                let n = self.desc.light_samples.as_ref().map_or(1, |l| l.value);
                let root = (n as f64).sqrt().round() as u64;
                if root * root != n as u64 {
                    let loc = self.desc.light_samples.as_ref().map_or(s.loc, |l| l.loc);
                    self.diags.error(
                        loc,
                        format!("lightsamples: 'lightstratify on' needs a perfect square, got {n}"),
                    );
                }
            }
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

    // ---- arguments ----

    fn expect_count(&mut self, c: &Command, n: usize, what: &str) -> bool {
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

    fn nums<const N: usize>(&mut self, c: &Command) -> Option<[f64; N]> {
        self.args(c, "number", Self::number)
    }

    fn ints<const N: usize>(&mut self, c: &Command) -> Option<[i64; N]> {
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

    fn number(&mut self, c: &Command, tok: &Token) -> Option<f64> {
        let loc = self.loc(c.line, tok);
        if !is_decimal(tok.text) {
            self.diags
                .error(loc, format!("{}: '{}' is not a number", c.name.text, tok.text));
            return None;
        }
        match tok.text.parse::<f64>() {
            Ok(x) if x.is_finite() && x.abs() <= f32::MAX as f64 => Some(x),
            _ => {
                self.diags
                    .error(loc, format!("{}: {} is out of range", c.name.text, tok.text));
                None
            }
        }
    }

    fn integer(&mut self, c: &Command, tok: &Token) -> Option<i64> {
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
    fn positive(&mut self, c: &Command) -> Option<f64> {
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

    fn keyword<T: Copy>(&mut self, c: &Command, options: &[(&str, T)]) -> Option<T> {
        if !self.expect_count(c, 1, &format!("one of {}", Self::alternatives(options))) {
            return None;
        }
        self.keyword_at(c, 0, options)
    }

    /// Argument `k` as one of the names in `options`.
    fn keyword_at<T: Copy>(&mut self, c: &Command, k: usize, options: &[(&str, T)]) -> Option<T> {
        let tok = &c.args[k];
        let found = options.iter().find(|(n, _)| *n == tok.text).map(|(_, v)| *v);
        if found.is_none() {
            let loc = self.loc(c.line, tok);
            let list = Self::alternatives(options);
            self.diags.error(
                loc,
                format!("{}: unknown value '{}' (expected {list})", c.name.text, tok.text),
            );
        }
        found
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

    /// A colour from three parsed numbers starting at argument `first`; negative
    /// components are allowed but warned about.
    fn color_at(&mut self, c: &Command, first: usize, v: &[f64]) -> DVec3 {
        if let Some(k) = v.iter().position(|&x| x < 0.0) {
            let loc = self.loc(c.line, &c.args[first + k]);
            self.diags.warning(
                loc,
                format!("{}: negative colour component {}", c.name.text, c.args[first + k].text),
            );
        }
        DVec3::new(v[0], v[1], v[2])
    }

    // ---- diagnostics at a command ----

    fn err_cmd(&mut self, c: &Command, msg: impl Into<String>) {
        let loc = self.loc(c.line, &c.name);
        self.diags.error(loc, msg);
    }

    fn warn_cmd(&mut self, c: &Command, msg: impl Into<String>) {
        let loc = self.loc(c.line, &c.name);
        self.diags.warning(loc, msg);
    }

    fn err_arg(&mut self, c: &Command, k: usize, msg: impl Into<String>) {
        let loc = self.loc(c.line, &c.args[k]);
        self.diags.error(loc, msg);
    }

    /// An error underlining arguments `first .. first + n`.
    fn err_span(&mut self, c: &Command, first: usize, n: usize, msg: impl Into<String>) {
        let a = &c.args[first];
        let b = &c.args[first + n - 1];
        let loc = Loc {
            file: self.file,
            line: c.line,
            col: a.col,
            len: b.col + b.text.chars().count() as u32 - a.col,
        };
        self.diags.error(loc, msg);
    }
}

/// The known command closest to a misspelt one: same letters ignoring case, or at most
/// two edits away.
fn suggestion(name: &str) -> Option<&'static str> {
    let lower = name.to_lowercase();
    if let Some(c) = COMMANDS.iter().find(|c| c.to_lowercase() == lower) {
        return Some(c);
    }
    COMMANDS
        .iter()
        .map(|c| (edit_distance(&lower, &c.to_lowercase()), *c))
        .filter(|(d, _)| *d <= 2)
        .min_by_key(|(d, _)| *d)
        .map(|(_, c)| c)
}

fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut cur = vec![i + 1; b.len() + 1];
        for (j, &cb) in b.iter().enumerate() {
            cur[j + 1] = (prev[j] + (ca != cb) as usize).min(prev[j + 1] + 1).min(cur[j] + 1);
        }
        prev = cur;
    }
    prev[b.len()]
}
