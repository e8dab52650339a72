//! Scene commands: `ambient`, `diffuse`, `specular`, `emission`, `shininess` — the
//! material every object captures when it is created (SCENE_FORMAT.md §3.6) — and the
//! extensions `transparent`, `ior` and `glossy`, and the CSE168 `brdf phong|ggx` and
//! `roughness` that choose the BSDF of the Monte Carlo integrators ([`super::bsdf`]). In
//! the Whitted ray tracer `specular` is also the mirror reflectance.

use super::bsdf::{Bsdf, Dielectric, Ggx, Mirror, Phong};
use crate::math::{Color, Vec3A};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    pub ambient: Color,
    pub diffuse: Color,
    pub specular: Color,
    pub emission: Color,
    pub shininess: f32,
    /// `transparent`: the weight of the refracted ray (0: opaque).
    pub transparent: Color,
    /// `ior`: index of refraction of the inside.
    pub ior: f32,
    /// `glossy exponent samples`: the mirror ray becomes rays from a Phong lobe.
    pub glossy: Option<Glossy>,
    /// `diffusemap`: index of the texture that multiplies `diffuse`.
    pub diffuse_map: Option<u32>,
    /// `bumpmap`: the texture whose luminance, times `strength`, is a height field.
    pub bump_map: Option<BumpMap>,
    /// `brdf`: the model of the Monte Carlo integrators.
    pub brdf: BrdfModel,
    /// `roughness`: GGX's α.
    pub roughness: f32,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BrdfModel {
    Phong,
    Ggx,
    /// `brdf mirror`: perfect reflection with reflectance `specular`.
    Mirror,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BumpMap {
    pub texture: u32,
    pub strength: f32,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Glossy {
    pub exponent: f32,
    pub samples: u32,
}

impl Default for Material {
    /// The format's initial state: ambient 0.2, everything else 0, shininess 1, the
    /// Phong BRDF, roughness 1.
    fn default() -> Self {
        Material {
            ambient: Color::splat(0.2),
            diffuse: Color::ZERO,
            specular: Color::ZERO,
            emission: Color::ZERO,
            shininess: 1.0,
            transparent: Color::ZERO,
            ior: 1.0,
            glossy: None,
            diffuse_map: None,
            bump_map: None,
            brdf: BrdfModel::Phong,
            roughness: 1.0,
        }
    }
}

impl Material {
    /// Whether the material scatters as a plain Lambertian surface, the same everywhere:
    /// `brdf phong` with `specular 0`, no texture or bump map, no glass, no emission.
    pub fn is_lambertian(&self) -> bool {
        self.brdf == BrdfModel::Phong
            && self.specular == Color::ZERO
            && self.transparent == Color::ZERO
            && self.emission == Color::ZERO
            && self.diffuse_map.is_none()
            && self.bump_map.is_none()
    }

    /// Whether its BSDF scatters into single directions only (a `brdf mirror`, glass):
    /// [`Bsdf::is_delta`] wherever it is hit.
    pub fn is_delta(&self) -> bool {
        self.transparent != Color::ZERO || self.brdf == BrdfModel::Mirror
    }

    /// The BSDF at a point with unit shading normal `normal`, the true surface's normal
    /// `geometric` (on the side of `normal`) and (textured) diffuse colour `diffuse`. A
    /// `transparent` material is a smooth dielectric, whatever its `brdf`.
    pub fn bsdf(&self, normal: Vec3A, geometric: Vec3A, diffuse: Color) -> Bsdf {
        if self.transparent != Color::ZERO {
            return Bsdf::Dielectric(Dielectric {
                n: normal,
                ng: geometric,
                ior: self.ior,
                kt: self.transparent,
            });
        }
        match self.brdf {
            BrdfModel::Phong => Bsdf::Phong(Phong {
                n: normal,
                kd: diffuse,
                ks: self.specular,
                shininess: self.shininess,
            }),
            BrdfModel::Ggx => Bsdf::Ggx(Ggx {
                n: normal,
                kd: diffuse,
                ks: self.specular,
                alpha: self.roughness,
            }),
            BrdfModel::Mirror => Bsdf::Mirror(Mirror {
                n: normal,
                ng: geometric,
                ks: self.specular,
            }),
        }
    }
}
