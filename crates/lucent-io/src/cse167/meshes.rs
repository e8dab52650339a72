//! The commands that make triangle meshes: `mesh` (OBJ or PLY files), `subdivmesh`
//! (subdivision surfaces) and `bezierpatches` (bicubic patches). Files are read here,
//! relative to the scene's folder, so that their errors point at the command.

use glam::Vec3;
use lucent_core::geometry::mesh::TriangleMesh;
use lucent_core::tessellate::grid::grid_mesh;
use lucent_core::tessellate::subdivision::{self, Scheme};

use std::path::Path;

use lucent_core::shading::texture::Texture;

use super::{io_reason, Command, Parser};
use crate::desc::{MaterialDesc, ShapeKind, TextureDesc};
use crate::mesh_file::{load_mesh, load_polygons, LoadedMesh, NO_MATERIAL};
use crate::texture_file::load_image;

/// Subdivision levels `subdivmesh` accepts: every level multiplies the faces by four.
const MAX_SUBDIVISION_LEVEL: i64 = 8;
/// The largest mesh subdivision may make.
const MAX_SUBDIVIDED_TRIANGLES: u64 = 1 << 25;

impl Parser {
    /// `mesh file`: a triangle mesh from an OBJ (with its MTL materials) or PLY file.
    pub(super) fn mesh(&mut self, c: &Command) {
        if !self.expect_count(c, 1, "a file name (.obj or .ply)") {
            return;
        }
        let path = self.base_dir.join(c.args[0].text);
        let loaded = match load_mesh(&path) {
            Ok(m) => m,
            Err(e) => {
                self.err_arg(c, 0, format!("mesh: {}: {e}", path.display()));
                return;
            }
        };
        for w in &loaded.warnings {
            let loc = self.loc(c.line, &c.args[0]);
            self.diags.warning(loc, format!("mesh: {}: {w}", path.display()));
        }
        let mesh_dir = path.parent().unwrap_or(Path::new(".")).to_path_buf();
        let Some(mesh) = self.with_scene_materials(c, loaded, &mesh_dir) else {
            return;
        };
        self.add_mesh(c, mesh);
    }

    /// The mesh with its MTL materials turned into scene materials: each is the current
    /// material with what the MTL sets replaced (`map_Kd` becomes a diffuse map); faces
    /// without one take the current one.
    fn with_scene_materials(&mut self, c: &Command, loaded: LoadedMesh, mesh_dir: &Path) -> Option<TriangleMesh> {
        let LoadedMesh { mut mesh, library, .. } = loaded;
        if mesh.materials.is_empty() {
            return Some(mesh);
        }
        let current = self.material_id();
        let mut ids = Vec::with_capacity(library.len());
        for m in &library {
            let mut d: MaterialDesc = self.material;
            let rgb = |v: [f32; 3]| glam::Vec3A::from_array(v);
            if let Some(v) = m.diffuse {
                d.base.diffuse = rgb(v);
            }
            if let Some(v) = m.specular {
                d.base.specular = rgb(v);
            }
            if let Some(v) = m.emission {
                d.base.emission = rgb(v);
            }
            if let Some(v) = m.shininess {
                d.base.shininess = v;
            }
            if let Some(file) = &m.diffuse_texture {
                // map_Kd: relative to the OBJ file, loaded once per scene.
                let path = mesh_dir.join(file);
                let name = format!("map_Kd:{}", path.display());
                let index = match self.desc.textures.iter().position(|t| t.name == name) {
                    Some(i) => i,
                    None => match load_image(&path) {
                        Ok(img) => {
                            let loc = self.loc(c.line, &c.args[0]);
                            self.desc.textures.push(TextureDesc {
                                name,
                                texture: Texture::Image(img),
                                loc,
                            });
                            self.desc.textures.len() - 1
                        }
                        Err(e) => {
                            let msg = format!("mesh: material '{}': map_Kd {}: {e}", m.name, path.display());
                            self.err_arg(c, 0, msg);
                            return None;
                        }
                    },
                };
                d.base.diffuse_map = Some(index as u32);
            }
            self.desc.materials.push(d);
            ids.push(self.desc.materials.len() as u32 - 1);
        }
        for m in &mut mesh.materials {
            *m = if *m == NO_MATERIAL { current } else { ids[*m as usize] };
        }
        Some(mesh)
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
        let Some(scheme) = self.keyword_at(c, 0, &[("loop", Scheme::Loop), ("catmullclark", Scheme::CatmullClark)])
        else {
            return;
        };
        let Some(levels) = self.integer(c, &c.args[1]) else {
            return;
        };
        if !(0..=MAX_SUBDIVISION_LEVEL).contains(&levels) {
            self.err_arg(
                c,
                1,
                format!("subdivmesh: levels must be between 0 and {MAX_SUBDIVISION_LEVEL}, got {levels}"),
            );
            return;
        }
        let path = self.base_dir.join(c.args[2].text);
        let control = match load_polygons(&path) {
            Ok(m) => m,
            Err(e) => {
                self.err_arg(c, 2, format!("subdivmesh: {}: {e}", path.display()));
                return;
            }
        };
        // Loop refines the fan triangulation, four triangles for one per level;
        // Catmull-Clark makes n quads of an n-gon, then four of each quad per level.
        let corners: u64 = control.faces.iter().map(|f| f.len() as u64).sum();
        let fan = corners - 2 * control.faces.len() as u64;
        let total = match (scheme, levels as u32) {
            (_, 0) => fan,
            (Scheme::Loop, l) => fan.saturating_mul(4u64.pow(l)),
            (Scheme::CatmullClark, l) => (2 * corners).saturating_mul(4u64.pow(l - 1)),
        };
        if total > MAX_SUBDIVIDED_TRIANGLES {
            self.err_arg(
                c,
                1,
                format!(
                    "subdivmesh: {levels} levels would make {total} triangles (at most {MAX_SUBDIVIDED_TRIANGLES})"
                ),
            );
            return;
        }
        match subdivision::subdivide(&control, scheme, levels as u32) {
            Ok(mesh) => self.add_mesh(c, mesh),
            Err(e) => self.err_arg(c, 2, format!("subdivmesh: {}: {e}", path.display())),
        }
    }

    /// `bezierpatches file [divisions]`: the patches of `file`, each tessellated into
    /// `divisions × divisions` quads (two triangles each) with normals from the exact
    /// derivatives, under the current transform and material.
    pub(super) fn bezier_patches(&mut self, c: &Command) {
        if c.args.is_empty() || c.args.len() > 2 {
            let n = c.args.len();
            self.err_cmd(
                c,
                format!("bezierpatches: expected a file name and optionally a number of divisions, got {n} arguments"),
            );
            return;
        }
        let divisions = match c.args.get(1) {
            None => 16,
            Some(tok) => match self.integer(c, tok) {
                Some(d) if (1..=256).contains(&d) => d as u32,
                Some(d) => {
                    self.err_arg(
                        c,
                        1,
                        format!("bezierpatches: divisions must be between 1 and 256, got {d}"),
                    );
                    return;
                }
                None => return,
            },
        };
        let name = c.args[0].text.to_string();
        let path = self.base_dir.join(&name);
        let text = match std::fs::read(&path) {
            Ok(bytes) => String::from_utf8_lossy(&bytes).into_owned(),
            Err(e) => {
                self.err_arg(
                    c,
                    0,
                    format!("bezierpatches: cannot read '{}': {}", path.display(), io_reason(&e)),
                );
                return;
            }
        };
        let patches = match crate::patches::parse_patches(&text) {
            Ok(p) => p,
            Err(e) => {
                let at = if e.line > 0 {
                    format!(":{}", e.line)
                } else {
                    String::new()
                };
                self.err_arg(c, 0, format!("bezierpatches: {}{at}: {}", path.display(), e.message));
                return;
            }
        };
        let d = divisions as usize;
        let mut mesh = TriangleMesh::default();
        for patch in &patches.patches {
            let grid: Vec<(Vec3, Vec3)> = lucent_core::tessellate::bezier::tessellate(patch, divisions)
                .into_iter()
                .map(|(p, n)| (p.as_vec3(), n.as_vec3()))
                .collect();
            mesh.append(grid_mesh(&grid, d, d));
        }
        self.add_mesh(c, mesh);
    }

    /// Adds a mesh in object space under the current transform and material, displaced
    /// by the current `displacementmap`, without its degenerate triangles.
    fn add_mesh(&mut self, c: &Command, mut mesh: TriangleMesh) {
        if let Some((texture, scale)) = self.displacement {
            let tex = &self.desc.textures[texture as usize].texture;
            match lucent_core::tessellate::displacement::displace(
                &mesh,
                &lucent_core::shading::texture::Displacement { texture: tex, scale },
            ) {
                Ok(m) => mesh = m,
                Err(e) => {
                    self.err_cmd(c, format!("{}: displacementmap: {e}", c.name.text));
                    return;
                }
            }
        }
        let removed = mesh.remove_degenerate();
        if removed > 0 && c.name.text == "mesh" {
            self.warn_cmd(c, format!("mesh: {removed} degenerate triangles (zero area) skipped"));
        }
        if mesh.indices.is_empty() {
            self.warn_cmd(c, format!("{}: the surface has no triangles", c.name.text));
            return;
        }
        let index = self.desc.meshes.len() as u32;
        self.desc.meshes.push(mesh);
        self.shape(c, ShapeKind::Mesh { index });
    }
}
