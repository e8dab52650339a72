//! Where the image goes, in which format, and how diagnostics are printed.

use std::path::{Path, PathBuf};

use lucent_io::desc::SceneDesc;
use lucent_io::diag::{Diagnostics, Loc, Severity, SourceMap};
use lucent_io::image::{encode_exr, encode_hdr, encode_png};
use lucent_io::resources::OutputTarget;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Png,
    Exr,
    Hdr,
}

/// The image's destination: the name as given, the format it picks, and how the bytes
/// get there ([`OutputTarget`]).
pub struct Output {
    pub name: PathBuf,
    pub format: Format,
    pub target: OutputTarget,
}

/// The output: `-o`, else the scene's `output` command (relative to the current
/// directory), else `raytrace.png`. The extension picks the format: `.png` (8-bit, the
/// course's encoding), `.exr` (linear 32-bit floats) or `.hdr` (Radiance RGBE); another
/// name gets PNG, with a warning for a file (`-` for standard output and devices such as
/// `/dev/null` get PNG silently). An output that cannot be written is an error now,
/// before any work is done.
pub fn choose_output(cli: Option<&Path>, desc: &SceneDesc, diags: &mut Diagnostics) -> Result<Output, String> {
    let (name, loc): (PathBuf, Option<Loc>) = match (cli, &desc.output) {
        (Some(p), _) => (p.to_path_buf(), None),
        (None, Some(o)) => (PathBuf::from(&o.value), Some(o.loc)),
        (None, None) => (PathBuf::from("raytrace.png"), None),
    };
    let target = OutputTarget::resolve(&name).map_err(|e| format!("cannot write {}: {e}", name.display()))?;
    if target.is_terminal() {
        return Err("standard output is a terminal: redirect it to a file or a pipe, or name a file with -o".into());
    }
    let ext = name.extension().map(|e| e.to_string_lossy().to_lowercase());
    let format = match ext.as_deref() {
        Some("exr") => Format::Exr,
        Some("hdr") => Format::Hdr,
        Some("png") => Format::Png,
        _ => {
            if matches!(target, OutputTarget::File(_)) {
                let msg = format!(
                    "output: '{}' does not end in .png, .exr or .hdr; writing PNG anyway",
                    name.display()
                );
                match loc {
                    Some(loc) => diags.warning(loc, msg),
                    None => eprintln!("lucent: warning: {msg}"),
                }
            }
            Format::Png
        }
    };
    Ok(Output { name, format, target })
}

/// Encodes the film in the output's format and writes it (atomically for a file).
pub fn write_image(out: &Output, film: &lucent_core::image::Image, gamma: f32) -> Result<(), String> {
    let (w, h) = (film.width, film.height);
    let bytes = match out.format {
        Format::Exr => encode_exr(w, h, &film.to_rgb_f32()),
        Format::Hdr => encode_hdr(w, h, &film.to_rgb_f32()),
        Format::Png => encode_png(w, h, &film.to_rgb8(gamma)),
    };
    bytes
        .and_then(|b| out.target.write(&b))
        .map_err(|e| format!("cannot write {}: {e}", out.name.display()))
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
