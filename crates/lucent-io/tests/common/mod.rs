//! What the integration tests share: a temporary folder for scenes and the files they
//! name.

#![allow(dead_code)] // each test file uses its own part of this

use std::path::PathBuf;

/// A folder of its own for each test, removed when the test ends.
pub struct TempDir(pub PathBuf);

impl TempDir {
    pub fn new(name: &str) -> TempDir {
        let dir = std::env::temp_dir().join(format!("lucent-test-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        TempDir(dir)
    }

    pub fn write(&self, name: &str, text: &str) {
        std::fs::write(self.0.join(name), text).unwrap();
    }

    /// The name of a scene file in the folder (file names in it resolve here).
    pub fn scene(&self) -> String {
        self.0.join("s.test").display().to_string()
    }

    pub fn path(&self, name: &str) -> String {
        self.0.join(name).display().to_string()
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Parses, builds and renders `text` (as the scene file `scene`, for relative file
/// names) with `threads` worker threads; panics with the diagnostics on any error.
/// Returns the film and the scene's `gamma`.
pub fn render_scene(
    scene: &str,
    text: &str,
    accel: lucent_core::accel::AccelKind,
    threads: usize,
) -> (lucent_core::film::Film, f32) {
    use lucent_io::build::{build, BuildOptions};
    use lucent_io::cse167::{parse_bytes, ParseOptions};
    let (desc, mut diags) = parse_bytes(scene, text.as_bytes(), ParseOptions::default());
    let built =
        build(&desc, &BuildOptions { accel }, &mut diags).unwrap_or_else(|| panic!("{}", diags.render(&desc.sources)));
    assert!(!diags.has_errors(), "{}", diags.render(&desc.sources));
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    let cancel = std::sync::atomic::AtomicBool::new(false);
    let control = lucent_core::render::RenderControl {
        progress: &|_| {},
        cancel: &cancel,
    };
    let (film, _) = pool
        .install(|| lucent_core::render::render(&built.scene, built.integrator.as_ref(), &control))
        .unwrap();
    (film, built.gamma)
}

/// [`render_scene`] as 8-bit RGB.
pub fn render_rgb8(scene: &str, text: &str, accel: lucent_core::accel::AccelKind, threads: usize) -> Vec<u8> {
    let (film, gamma) = render_scene(scene, text, accel, threads);
    film.to_rgb8(gamma)
}

/// `line:col: message` of every error the parser reports (the build is not run).
pub fn parse_errors(scene: &str, text: &str) -> Vec<String> {
    use lucent_io::cse167::{parse_bytes, ParseOptions};
    let (_, diags) = parse_bytes(scene, text.as_bytes(), ParseOptions::default());
    diags
        .items
        .iter()
        .filter(|d| d.severity == lucent_io::diag::Severity::Error)
        .map(|d| format!("{}:{}: {}", d.loc.line, d.loc.col, d.message))
        .collect()
}

/// `line:col: severity: message` of every error and warning of parse and build, in
/// order (notes left out).
pub fn diagnostics(scene: &str, text: &str, strict: bool) -> Vec<String> {
    use lucent_io::build::{build, BuildOptions};
    use lucent_io::cse167::{parse_bytes, ParseOptions};
    let (desc, mut diags) = parse_bytes(scene, text.as_bytes(), ParseOptions { strict });
    if !diags.has_errors() {
        build(&desc, &BuildOptions::default(), &mut diags);
    }
    diags
        .items
        .iter()
        .filter(|d| d.severity != lucent_io::diag::Severity::Note)
        .map(|d| format!("{}:{}: {}: {}", d.loc.line, d.loc.col, d.severity, d.message))
        .collect()
}
