//! lucent-io: scene formats in, images out.
//!
//! The flow is parse → description → build: [`cse167::parse_file`] records what a scene
//! file says, with the `file:line:col` of every command, into a plain [`desc::SceneDesc`];
//! [`build::build`] turns that into a renderable [`lucent_core::scene::Scene`]. Problems
//! found on the way are [`diag::Diagnostic`]s that point at the offending token.

// `!(x > 0.0)` is used on purpose: unlike `x <= 0.0` it also rejects NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod build;
pub mod cse167;
pub mod desc;
pub mod diag;
pub mod image;
pub mod mesh_file;
mod number;
pub mod obj;
pub mod patches;
pub mod ply;
pub mod texture_file;
