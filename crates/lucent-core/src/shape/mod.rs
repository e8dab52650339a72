//! Ray–shape intersection routines, one file per shape. Each works on plain geometry
//! and is tested against analytic answers; [`crate::primitive`] wraps them as the
//! primitives a scene holds.

pub mod bezier;
pub mod cone;
pub mod cuboid;
pub mod cylinder;
pub mod disk;
pub mod displacement;
pub mod nurbs;
pub mod parametric;
pub mod plane;
pub mod quadratic;
pub mod quadric;
pub mod sphere;
pub mod subdivision;
pub mod texcoord;
pub mod triangle;
