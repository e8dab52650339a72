//! Materials and what they look up: the textures (`texture` image files are read here,
//! `checker`s made), the environment map (`envmap`), the materials objects captured, and
//! the materials of OBJ files' MTL libraries (each the captured material with what the
//! MTL sets replaced; `map_Kd` images are read relative to the OBJ file, once a scene).

use std::path::Path;

use lucent_core::shading::material::{BrdfModel, BumpMap, Glossy, Material};
use lucent_core::shading::texture::{EnvironmentMap, Texture};

use super::to_f32;
use crate::desc::{Brdf, MaterialDesc, SceneDesc, TextureSource};
use crate::diag::{Diagnostics, Loc};
use crate::mesh_file::MeshMaterial;
use crate::resources::Resources;
use crate::texture_file::load_image;

/// The scene's materials and textures, which meshes add to as they are built.
pub struct Materials {
    /// The description's materials first, in its order (shapes refer to them by index).
    pub materials: Vec<Material>,
    /// The description's textures first, in its order; then `map_Kd` images.
    pub textures: Vec<Texture>,
    /// The name of each texture: the scene's, or `map_Kd:PATH`.
    names: Vec<String>,
}

impl Materials {
    pub fn new(desc: &SceneDesc, res: &mut Resources, diags: &mut Diagnostics) -> Materials {
        let textures = desc
            .textures
            .iter()
            .map(|t| match &t.source {
                TextureSource::Image(file) => match load_image(&file.value, res) {
                    Ok(img) => Texture::Image(img),
                    Err(e) => {
                        diags.error(file.loc, format!("texture: {}: {e}", file.value.display()));
                        Texture::Checker {
                            a: lucent_core::math::Color::ZERO,
                            b: lucent_core::math::Color::ZERO,
                            scale: 1.0,
                        }
                    }
                },
                TextureSource::Checker { a, b, scale } => Texture::Checker {
                    a: to_f32(*a),
                    b: to_f32(*b),
                    scale: *scale as f32,
                },
            })
            .collect();
        Materials {
            materials: desc.materials.iter().map(material).collect(),
            textures,
            names: desc.textures.iter().map(|t| t.name.clone()).collect(),
        }
    }

    /// Adds the materials of a mesh's MTL library, each the material `base` with what
    /// the MTL sets replaced; returns their indices in library order, or `None` after an
    /// error (at `loc`, the mesh's file name).
    pub fn add_library(
        &mut self,
        base: &MaterialDesc,
        library: &[MeshMaterial],
        mesh_dir: &Path,
        loc: Loc,
        res: &mut Resources,
        diags: &mut Diagnostics,
    ) -> Option<Vec<u32>> {
        let mut ids = Vec::with_capacity(library.len());
        for m in library {
            let mut d = material(base);
            let rgb = |v: [f32; 3]| glam::Vec3A::from_array(v);
            if let Some(v) = m.diffuse {
                d.diffuse = rgb(v);
            }
            if let Some(v) = m.specular {
                d.specular = rgb(v);
            }
            if let Some(v) = m.emission {
                d.emission = rgb(v);
            }
            if let Some(v) = m.shininess {
                d.shininess = v;
            }
            if let Some(file) = &m.diffuse_texture {
                let path = mesh_dir.join(file);
                let name = format!("map_Kd:{}", path.display());
                let index = match self.names.iter().position(|n| *n == name) {
                    Some(i) => i,
                    None => match load_image(&path, res) {
                        Ok(img) => {
                            self.textures.push(Texture::Image(img));
                            self.names.push(name);
                            self.textures.len() - 1
                        }
                        Err(e) => {
                            let msg = format!("mesh: material '{}': map_Kd {}: {e}", m.name, path.display());
                            diags.error(loc, msg);
                            return None;
                        }
                    },
                };
                d.diffuse_map = Some(index as u32);
            }
            self.materials.push(d);
            ids.push(self.materials.len() as u32 - 1);
        }
        Some(ids)
    }

    /// The texture a description's texture index names.
    pub fn texture(&self, index: u32) -> &Texture {
        &self.textures[index as usize]
    }
}

/// A material of the description in the core's terms.
fn material(m: &MaterialDesc) -> Material {
    Material {
        ambient: to_f32(m.ambient),
        diffuse: to_f32(m.diffuse),
        specular: to_f32(m.specular),
        emission: to_f32(m.emission),
        shininess: m.shininess as f32,
        transparent: to_f32(m.transparent),
        ior: m.ior as f32,
        glossy: m.glossy.map(|g| Glossy {
            exponent: g.exponent as f32,
            samples: g.samples,
        }),
        diffuse_map: m.diffuse_map,
        bump_map: m.bump_map.map(|b| BumpMap {
            texture: b.texture,
            strength: b.strength as f32,
        }),
        brdf: match m.brdf {
            Brdf::Phong => BrdfModel::Phong,
            Brdf::Ggx => BrdfModel::Ggx,
            Brdf::Mirror => BrdfModel::Mirror,
        },
        roughness: m.roughness as f32,
    }
}

/// `envmap file [intensity]`, read.
pub fn environment(desc: &SceneDesc, res: &mut Resources, diags: &mut Diagnostics) -> Option<EnvironmentMap> {
    let env = &desc.environment.as_ref()?.value;
    match load_image(&env.file.value, res) {
        Ok(image) => Some(EnvironmentMap {
            image,
            intensity: env.intensity as f32,
        }),
        Err(e) => {
            diags.error(env.file.loc, format!("envmap: {}: {e}", env.file.value.display()));
            None
        }
    }
}
