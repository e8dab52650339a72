//! lucent-core: everything that runs while a picture is made — geometry, acceleration
//! structures, the camera, shading, the integrator and the tiled render loop.
//!
//! This crate does no file I/O and knows no scene format: `lucent-io` parses files into
//! a description and builds a [`scene::Scene`] from it; this crate renders that scene.
//! The path of one pixel can be read top-down in [`render`].
//!
//! The modules stand on floors, and each imports only from its own floor and the floors
//! below it (`tests/layering.rs` in the `lucent` crate checks every `use`):
//!
//! | floor | modules |
//! |---|---|
//! | 0 base | [`math`], [`pow`], [`huge_pages`], [`transform`], [`ray`], [`aabb`], [`hit`], [`spawn`], [`sampler`], [`sampling`] (and `test_rng` for the tests) |
//! | 1 shapes | [`shape`]: intersection routines, texture coordinates, tangents |
//! | 2 acceleration | [`accel`]: structures over any [`accel::PrimitiveSet`] |
//! | 3 geometry | [`geometry`]: primitives, meshes, instances, the primitive set |
//! | 4 tessellation | [`tessellate`]: Bézier, NURBS, subdivision, displacement |
//! | 5 shading and lights | [`shading`], [`light`], [`camera`] |
//! | 6 scene | [`scene`] |
//! | 7 integrators | [`integrator`] |
//! | 8 render loop and film | [`render`], [`film`], [`image`] |

// `!(x > 0.0)` is used on purpose: unlike `x <= 0.0` it also rejects NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod aabb;
pub mod hit;
pub mod huge_pages;
pub mod math;
pub mod pow;
pub mod ray;
pub mod sampler;
pub mod sampling;
pub mod spawn;
#[cfg(test)]
pub(crate) mod test_rng;
pub mod transform;

pub mod shape;

pub mod accel;

pub mod geometry;

pub mod tessellate;

pub mod camera;
pub mod light;
pub mod shading;

pub mod scene;

pub mod integrator;

pub mod film;
pub mod image;
pub mod render;
