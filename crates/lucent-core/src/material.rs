//! Scene commands: `ambient`, `diffuse`, `specular`, `emission`, `shininess` — the
//! material every object captures when it is created (SCENE_FORMAT.md §3.6). In the
//! Whitted ray tracer `specular` is also the mirror reflectance.

use crate::math::Color;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    pub ambient: Color,
    pub diffuse: Color,
    pub specular: Color,
    pub emission: Color,
    pub shininess: f32,
}

impl Default for Material {
    /// The format's initial state: ambient 0.2, everything else 0, shininess 1.
    fn default() -> Self {
        Material {
            ambient: Color::splat(0.2),
            diffuse: Color::ZERO,
            specular: Color::ZERO,
            emission: Color::ZERO,
            shininess: 1.0,
        }
    }
}
