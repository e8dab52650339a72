//! Floor 5 — what a surface does with light: materials, textures and the environment
//! map, the optics of reflection and refraction, bump mapping, what a material makes of
//! a surface point ([`surface`]) and the BSDFs of the Monte Carlo integrators.

pub mod bsdf;
pub mod bump;
pub mod material;
pub mod optics;
pub mod surface;
pub mod texture;
