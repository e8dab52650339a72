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
/// Returns the resolved image and the scene's `gamma`.
pub fn render_scene(
    scene: &str,
    text: &str,
    accel: lucent_core::accel::AccelKind,
    threads: usize,
) -> (lucent_core::image::Image, f32) {
    use lucent_io::session::{Renderer, Session, SessionOptions};
    let mut session = Session::parse_text(
        scene,
        text.as_bytes(),
        SessionOptions {
            accel,
            ..SessionOptions::default()
        },
    );
    session.build();
    let built = session
        .built
        .as_ref()
        .unwrap_or_else(|| panic!("{}", session.diags.render(&session.desc.sources)));
    assert!(
        !session.diags.has_errors(),
        "{}",
        session.diags.render(&session.desc.sources)
    );
    let renderer = Renderer::new(Some(threads)).unwrap();
    let cancel = std::sync::atomic::AtomicBool::new(false);
    let (film, _) = renderer.render(built, &built.job(), &|_| {}, &cancel).unwrap();
    (film.resolve(), built.settings.gamma)
}

/// Renders the job the scene asks for, changed by `edit` (a crop, a sample range, a
/// seed), with two worker threads; panics with the diagnostics on any error.
pub fn render_job(
    scene: &str,
    text: &str,
    edit: impl FnOnce(&mut lucent_core::render::job::RenderJob),
) -> lucent_core::image::Image {
    render_film(scene, text, 2, edit).0.resolve()
}

/// The film and statistics of the job the scene asks for, changed by `edit`, with
/// `threads` worker threads; panics with the diagnostics on any error.
pub fn render_film(
    scene: &str,
    text: &str,
    threads: usize,
    edit: impl FnOnce(&mut lucent_core::render::job::RenderJob),
) -> (lucent_core::film::Film, lucent_core::render::RenderStats) {
    use lucent_io::session::{Renderer, Session, SessionOptions};
    let mut session = Session::parse_text(scene, text.as_bytes(), SessionOptions::default());
    session.build();
    let built = session
        .built
        .as_ref()
        .unwrap_or_else(|| panic!("{}", session.diags.render(&session.desc.sources)));
    let mut job = built.job();
    edit(&mut job);
    let cancel = std::sync::atomic::AtomicBool::new(false);
    let renderer = Renderer::new(Some(threads)).unwrap();
    renderer.render(built, &job, &|_| {}, &cancel).unwrap()
}

/// [`render_scene`] as 8-bit RGB.
pub fn render_rgb8(scene: &str, text: &str, accel: lucent_core::accel::AccelKind, threads: usize) -> Vec<u8> {
    let (film, gamma) = render_scene(scene, text, accel, threads);
    film.to_rgb8(gamma)
}

/// `line:col: message` of every error the parser and the build report.
pub fn errors(scene: &str, text: &str) -> Vec<String> {
    diagnostics(scene, text, false)
        .into_iter()
        .filter_map(|d| {
            let (place, rest) = d.split_once(": error: ")?;
            Some(format!("{place}: {rest}"))
        })
        .collect()
}

/// `line:col: severity: message` of every error and warning of parse and build, in
/// order (notes left out).
pub fn diagnostics(scene: &str, text: &str, strict: bool) -> Vec<String> {
    use lucent_io::session::{Session, SessionOptions};
    let options = SessionOptions {
        strict,
        ..SessionOptions::default()
    };
    let mut session = Session::parse_text(scene, text.as_bytes(), options);
    session.build();
    session
        .diags
        .items
        .iter()
        .filter(|d| d.severity != lucent_io::diag::Severity::Note)
        .map(|d| format!("{}:{}: {}: {}", d.loc.line, d.loc.col, d.severity, d.message))
        .collect()
}
