//! Materials as the file sets them (`ambient`, `diffuse`, `specular`, `emission`,
//! `shininess`, `transparent`, `ior`, `glossy`, `brdf`, `roughness`, `diffusemap`,
//! `bumpmap`), textures by the file or pattern that makes them (`texture`, `checker`)
//! and the environment map (`envmap`).

use std::path::PathBuf;

use glam::DVec3;

use super::Located;
use crate::diag::Loc;

/// The current material as objects capture it: every parameter the file can set.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MaterialDesc {
    pub ambient: DVec3,
    pub diffuse: DVec3,
    pub specular: DVec3,
    pub emission: DVec3,
    pub shininess: f64,
    /// `transparent`: the weight of the refracted ray (0: opaque).
    pub transparent: DVec3,
    /// `ior`: index of refraction of the inside.
    pub ior: f64,
    /// `glossy exponent samples`, or `None` for the mirror (`glossy off`).
    pub glossy: Option<GlossyDesc>,
    /// `diffusemap name`: index into the description's textures.
    pub diffuse_map: Option<u32>,
    /// `bumpmap name strength`.
    pub bump_map: Option<BumpDesc>,
    /// `brdf` and `roughness` (CSE168).
    pub brdf: Brdf,
    pub roughness: f64,
}

impl Default for MaterialDesc {
    /// The format's initial state: ambient 0.2, everything else 0, shininess 1, index of
    /// refraction 1, the Phong BRDF with roughness 1.
    fn default() -> Self {
        MaterialDesc {
            ambient: DVec3::splat(0.2),
            diffuse: DVec3::ZERO,
            specular: DVec3::ZERO,
            emission: DVec3::ZERO,
            shininess: 1.0,
            transparent: DVec3::ZERO,
            ior: 1.0,
            glossy: None,
            diffuse_map: None,
            bump_map: None,
            brdf: Brdf::Phong,
            roughness: 1.0,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Brdf {
    Phong,
    Ggx,
    Mirror,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GlossyDesc {
    pub exponent: f64,
    pub samples: u32,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BumpDesc {
    /// Index into the description's textures.
    pub texture: u32,
    pub strength: f64,
}

/// A named texture.
#[derive(Clone, Debug, PartialEq)]
pub struct TextureDesc {
    pub name: String,
    pub source: TextureSource,
    /// The name's place in the file.
    pub loc: Loc,
}

#[derive(Clone, Debug, PartialEq)]
pub enum TextureSource {
    /// `texture name file`: an image file (resolved against the scene's folder), with
    /// the place of its name in the scene.
    Image(Located<PathBuf>),
    /// `checker name r1 g1 b1 r2 g2 b2 scale`.
    Checker { a: DVec3, b: DVec3, scale: f64 },
}

/// `envmap file [intensity]`.
#[derive(Clone, Debug, PartialEq)]
pub struct EnvironmentDesc {
    pub file: Located<PathBuf>,
    pub intensity: f64,
}
