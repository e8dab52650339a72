//! Bump mapping (`bumpmap name strength`): the shading normal of a surface displaced
//! along its normal by `strength × luminance` of a texture, without moving the surface.

use super::material::BumpMap;
use super::texture::{luminance, Texture};
use crate::hit::SurfacePoint;
use crate::math::Vec3A;

/// The shading normal of a bump-mapped surface (Blinn 1978): the surface displaced along
/// its normal by `strength × luminance` of the texture, differentiated along `∂p/∂u` and
/// `∂p/∂v` (the surface's tangents at the point) by central differences half a texel
/// wide.
pub fn bumped_normal(tex: &Texture, bump: BumpMap, sp: &SurfacePoint, dpdu: Vec3A, dpdv: Vec3A) -> Vec3A {
    let (du, dv) = match tex {
        Texture::Image(img) => (0.5 / img.width as f32, 0.5 / img.height as f32),
        Texture::Checker { .. } => (1e-3, 1e-3),
    };
    let height = |duv: glam::Vec2, dp: Vec3A| bump.strength * luminance(tex.eval(sp.uv + duv, sp.point + dp));
    let u = glam::Vec2::new(du, 0.0);
    let v = glam::Vec2::new(0.0, dv);
    let hu = (height(u, dpdu * du) - height(-u, -dpdu * du)) / (2.0 * du);
    let hv = (height(v, dpdv * dv) - height(-v, -dpdv * dv)) / (2.0 * dv);
    let n = sp.normal;
    let base = dpdu.cross(dpdv);
    let bumped = (dpdu + n * hu).cross(dpdv + n * hv);
    // The tangents' cross product may point to either side; the normal keeps its own.
    let bumped = if base.dot(n) < 0.0 { -bumped } else { bumped };
    let out = bumped.normalize();
    if out.is_finite() {
        out
    } else {
        n
    }
}
