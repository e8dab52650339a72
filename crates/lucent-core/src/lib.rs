//! lucent-core: everything that runs while a picture is made — geometry, acceleration
//! structures, the camera, shading, the integrator and the tiled render loop.
//!
//! This crate does no file I/O and knows no scene format: `lucent-io` parses files into
//! a description and builds a [`scene::Scene`] from it; this crate renders that scene.
//! The path of one pixel can be read top-down in [`render`].

// `!(x > 0.0)` is used on purpose: unlike `x <= 0.0` it also rejects NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod aabb;
pub mod accel;
pub mod camera;
pub mod film;
pub mod geometry;
pub mod hit;
pub mod instance;
pub mod integrator;
pub mod light;
pub mod material;
pub mod math;
pub mod mesh;
pub mod optics;
pub mod primitive;
pub mod ray;
pub mod render;
pub mod sampler;
pub mod scene;
pub mod shape;
pub mod texture;
pub mod transform;
