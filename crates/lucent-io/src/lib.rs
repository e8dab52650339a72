//! lucent-io: scene formats in, images out.
//!
//! The flow is parse → description → build: [`cse167::parse_file`] records what a scene
//! file says, with the `file:line:col` of every command, into a plain [`desc::SceneDesc`];
//! [`build::build`] reads the files it names and turns it into a renderable
//! [`lucent_core::scene::Scene`]. [`session`] runs that sequence and renders. Problems
//! found on the way are [`diag::Diagnostic`]s that point at the offending token.
//!
//! Floors (checked by `tests/layering.rs` in the `lucent` crate): `diag`, `number`,
//! `files` → `desc` → `cse167` (the parser: records, reads no other file) → the file
//! formats (`obj`, `ply`, `mesh_file`, `patches`, `texture_file`, `image`), render
//! state files (`state`) and the denoiser (`denoise`) → `build` → `session`.

// `!(x > 0.0)` is used on purpose: unlike `x <= 0.0` it also rejects NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod diag;
pub mod fnv;
mod number;
pub mod resources;

pub mod desc;

pub mod cse167;

pub mod denoise;
pub mod image;
pub mod mesh_file;
pub mod obj;
pub mod patches;
pub mod ply;
pub mod state;
pub mod texture_file;

pub mod build;

pub mod session;

/// A fresh folder for one unit test, removed when it is dropped.
#[cfg(test)]
pub(crate) struct TestDir(pub std::path::PathBuf);

#[cfg(test)]
impl TestDir {
    pub fn new(name: &str) -> TestDir {
        let dir = std::env::temp_dir().join(format!("lucent-unit-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        TestDir(dir)
    }

    pub fn join(&self, name: &str) -> std::path::PathBuf {
        self.0.join(name)
    }
}

#[cfg(test)]
impl Drop for TestDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}
