//! What a material makes of a surface point: the shading normal (bent by `bumpmap`) and
//! the diffuse colour (multiplied by `diffusemap`), from which the Whitted integrator
//! shades and [`Material::bsdf`] builds the BSDF of the Monte Carlo integrators.

use super::bump;
use super::material::Material;
use super::texture::Texture;
use crate::hit::SurfacePoint;
use crate::math::{Color, Vec3A};

#[derive(Clone, Copy, Debug)]
pub struct Shaded {
    /// Unit shading normal.
    pub normal: Vec3A,
    /// `diffuse`, times the diffuse map's texel at the point.
    pub diffuse: Color,
}

/// The shading normal and diffuse colour of material `m` at `sp`; `tangents` gives
/// `∂p/∂u`, `∂p/∂v` when a bump map needs them.
#[inline]
pub fn shade(
    m: &Material,
    textures: &[Texture],
    sp: &SurfacePoint,
    tangents: impl FnOnce() -> (Vec3A, Vec3A),
) -> Shaded {
    let normal = match m.bump_map {
        Some(b) => {
            let (dpdu, dpdv) = tangents();
            bump::bumped_normal(&textures[b.texture as usize], b, sp, dpdu, dpdv)
        }
        None => sp.normal,
    };
    let diffuse = match m.diffuse_map {
        Some(t) => m.diffuse * textures[t as usize].eval(sp.uv, sp.point),
        None => m.diffuse,
    };
    Shaded { normal, diffuse }
}
