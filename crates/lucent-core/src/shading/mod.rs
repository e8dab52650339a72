//! Floor 5 — what a surface does with light: materials, textures and the environment
//! map, the optics of reflection and refraction, and bump mapping.

pub mod bump;
pub mod material;
pub mod optics;
pub mod texture;
