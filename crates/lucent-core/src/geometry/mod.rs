//! Floor 3 — the primitives a scene is made of, over the structures of floor 2: single
//! triangles, spheres and the analytic shapes placed by a transform ([`analytic`]),
//! triangle meshes with a structure of their own ([`mesh`]), instances of named objects
//! ([`instance`]), and the set of primitives with its structure that a scene or an object
//! is ([`Geometry`]).

pub mod analytic;
pub mod instance;
pub mod mesh;
pub mod primitive;
mod set;
#[cfg(test)]
mod structure_tests;
#[cfg(test)]
pub(crate) mod test_scenes;

pub use set::Geometry;
