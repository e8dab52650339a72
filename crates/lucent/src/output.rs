//! Where the image goes, and how diagnostics are printed.

use std::path::{Path, PathBuf};

use lucent_io::desc::SceneDesc;
use lucent_io::diag::{Diagnostics, Loc, Severity, SourceMap};
use lucent_io::image::{write_exr, write_hdr, write_png, ImageError};

/// Writes the film to `path` in the format its extension names (see [`choose_output`]).
pub fn write_image(path: &Path, film: &lucent_core::film::Film, gamma: f32) -> Result<(), ImageError> {
    let ext = path.extension().map(|e| e.to_string_lossy().to_lowercase());
    match ext.as_deref() {
        Some("exr") => write_exr(path, film.width, film.height, &film.to_rgb_f32()),
        Some("hdr") => write_hdr(path, film.width, film.height, &film.to_rgb_f32()),
        _ => write_png(path, film.width, film.height, &film.to_rgb8(gamma)),
    }
}

/// The output file: `-o`, else the scene's `output` command (relative to the current
/// directory, SCENE_FORMAT.md §3.1), else `raytrace.png`. The extension picks the format:
/// `.png` (8-bit, the course's encoding), `.exr` (linear 32-bit floats) or `.hdr`
/// (Radiance RGBE); any other name gets PNG and a warning.
pub fn choose_output(cli: Option<&Path>, desc: &SceneDesc, diags: &mut Diagnostics) -> Result<PathBuf, String> {
    let (path, loc): (PathBuf, Option<Loc>) = match (cli, &desc.output) {
        (Some(p), _) => (p.to_path_buf(), None),
        (None, Some(o)) => (PathBuf::from(&o.value), Some(o.loc)),
        (None, None) => (PathBuf::from("raytrace.png"), None),
    };
    let ext = path.extension().map(|e| e.to_string_lossy().to_lowercase());
    match ext.as_deref() {
        Some("png" | "exr" | "hdr") => Ok(path),
        _ => {
            let msg = format!(
                "output: '{}' does not end in .png, .exr or .hdr; writing PNG anyway",
                path.display()
            );
            match loc {
                Some(loc) => diags.warning(loc, msg),
                None => eprintln!("lucent: warning: {msg}"),
            }
            Ok(path)
        }
    }
}

/// Prints errors and warnings to stderr, and notes too when `notes` is set (`check`
/// shows them; `render` keeps quiet about what is harmless).
pub fn report(diags: &Diagnostics, sources: &SourceMap, notes: bool) {
    let mut shown = diags.clone();
    if !notes {
        shown.items.retain(|d| d.severity != Severity::Note);
    }
    let text = shown.render(sources);
    if !text.is_empty() {
        eprint!("{text}");
    }
}
