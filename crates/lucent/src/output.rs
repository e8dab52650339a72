//! Where the image goes, in which format, and how diagnostics are printed.

use std::path::{Path, PathBuf};

use lucent_io::desc::SceneDesc;
use lucent_io::diag::{Diagnostics, Loc, Severity, SourceMap};
use lucent_io::image::{encode_exr, encode_hdr, encode_jpeg, encode_png, ImageInfo};
use lucent_io::resources::{write_together, OutputTarget};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Png,
    Jpeg,
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
/// course's encoding), `.jpg`/`.jpeg` (8-bit, the same encoding), `.exr` (linear 32-bit
/// floats) or `.hdr` (Radiance RGBE); any other extension of a file is an error (never
/// PNG bytes under another name); standard output (`-`) and devices such as `/dev/null`
/// get PNG. An output that cannot be written is an error now, before any work is done.
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
        Some("jpg" | "jpeg") => Format::Jpeg,
        _ if !matches!(target, OutputTarget::File(_)) => Format::Png,
        _ => {
            let msg = format!(
                "'{}' does not end in .png, .jpg, .exr or .hdr: lucent cannot tell which format to write",
                name.display()
            );
            if let Some(loc) = loc {
                diags.error(loc, format!("output: {msg}"));
            }
            return Err(msg);
        }
    };
    Ok(Output { name, format, target })
}

/// An output's bytes, made before anything is written ([`write_all`]).
pub struct Encoded {
    pub name: PathBuf,
    pub target: OutputTarget,
    pub bytes: Vec<u8>,
}

/// The image in the output's format; PNG and EXR files carry `info`'s text (and an EXR
/// its place in the whole picture).
pub fn encode_image(out: &Output, film: &lucent_core::image::Image, info: &ImageInfo) -> Result<Encoded, String> {
    let (w, h) = (film.width, film.height);
    let gamma = info.gamma;
    let bytes = match out.format {
        Format::Exr => encode_exr(w, h, &film.to_rgb_f32(), info),
        Format::Hdr => encode_hdr(w, h, &film.to_rgb_f32()),
        Format::Jpeg => encode_jpeg(w, h, &film.to_rgb8(gamma)),
        Format::Png => encode_png(w, h, &film.to_rgb8(gamma), info),
    };
    let bytes = bytes.map_err(|e| format!("cannot write {}: {e}", out.name.display()))?;
    Ok(Encoded {
        name: out.name.clone(),
        target: out.target.clone(),
        bytes,
    })
}

/// Writes a run's outputs together ([`write_together`]): where one fails, no file is
/// replaced.
pub fn write_all(files: &[Encoded]) -> Result<(), String> {
    let list: Vec<(&OutputTarget, &[u8])> = files.iter().map(|f| (&f.target, &f.bytes[..])).collect();
    write_together(&list).map_err(|(i, e)| format!("cannot write {}: {e}", files[i].name.display()))
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
        err!("{text}");
    }
}

/// The text an image carries about itself: lucent and its version, the scene's name, and
/// what decides the pixels ([`lucent_io::state::describe_render`]) — not the command
/// line, so that renders of the same pixels carry the same bytes however they were made.
pub fn image_info(header: &lucent_io::state::StateHeader) -> ImageInfo {
    ImageInfo {
        gamma: header.gamma,
        text: vec![
            ("Software".into(), format!("lucent {}", env!("CARGO_PKG_VERSION"))),
            ("Source".into(), header.scene_name.clone()),
            ("Comment".into(), lucent_io::state::describe_render(header)),
        ],
        origin: (header.pixels.x0, header.pixels.y0),
        full: header.resolution,
    }
}
