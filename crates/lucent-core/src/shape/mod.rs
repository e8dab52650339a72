//! Floor 1 — ray–shape intersection routines, one file per shape, and what a surface
//! point's texture coordinates and tangents are on each. Each works on plain geometry in
//! the shape's own space and is tested against analytic answers; `crate::geometry` wraps
//! them as the primitives a scene holds. Imports only the base floor (math, ray, bounds).

pub mod cone;
pub mod cuboid;
pub mod cylinder;
pub mod disk;
pub mod plane;
pub mod quadratic;
pub mod quadric;
pub mod sphere;
pub mod tangents;
pub mod texcoord;
pub mod triangle;
