//! What a render (or a merge) writes of its film: the colour in the output's format —
//! denoised with `--denoise` — and the auxiliary passes of `--aov`: layers of the same
//! file when the output is an EXR (`albedo.R/G/B`, `normal.X/Y/Z`, `depth.Z`, alpha as
//! `A`, and with `--denoise` the colour before denoising as `noisy.R/G/B`), else an EXR
//! beside it, `OUT.aovs.exr`, with the colour and those layers.

use std::path::Path;

use lucent_core::film::{AovImages, Film};
use lucent_core::image::Image;
use lucent_core::render::job::RenderJob;
use lucent_io::denoise::{DenoiseInput, Denoiser};
use lucent_io::desc::SceneDesc;
use lucent_io::diag::Diagnostics;
use lucent_io::image::encode_exr_channels;
use lucent_io::resources::{Budget, OutputTarget};
use lucent_io::state::StateHeader;

use crate::aov_args::AovSelection;
use crate::output::{choose_output, encode_image, image_info, Encoded, Format, Output};

/// What is written besides the plain colour.
#[derive(Clone, Copy)]
pub struct Extras<'a> {
    pub aovs: AovSelection,
    /// The denoiser, with `--denoise`.
    pub denoiser: Option<&'a Denoiser>,
    /// The threads the denoiser may use.
    pub threads: usize,
}

impl Extras<'_> {
    /// Whether the film must keep the auxiliary passes.
    pub fn need_aovs(&self) -> bool {
        self.aovs.any() || self.denoiser.is_some()
    }
}

/// The memory a render of `job` takes for its picture, about and rather more than less
/// (the scene's own is the build's): its films — a one-sample pass's, then the film of
/// sums and the pass under way, or the resumed one (`resumed`) — the image written, the
/// auxiliary passes' images, and the denoiser's buffers. Measured peaks (resident memory
/// per pixel, 2048 × 2048): one sample 33 (PNG) to 45 bytes (EXR), 2 samples 82, 2
/// samples with every auxiliary pass 338, adaptive sampling 130; `--denoise` adds about
/// 510.
pub fn picture_bytes(job: &RenderJob, resumed: bool, extras: &Extras) -> u64 {
    let pixels = job.pixels.pixels();
    let (aovs, noise) = (job.aovs, job.noise_threshold.is_some());
    let films = if job.samples.len() == 1 && !resumed {
        Film::bytes(pixels, true, aovs, noise)
    } else {
        Film::bytes(pixels, true, aovs, noise) + 2 * Film::bytes(pixels, false, aovs, noise)
    };
    films + image_bytes(pixels, aovs, extras)
}

/// What [`encode_picture`] makes of a film of `pixels` pixels: the colour as floats and as
/// written, each auxiliary pass as floats (up to four, where the film keeps them:
/// `aovs`), and the denoiser's buffers.
pub fn image_bytes(pixels: u64, aovs: bool, extras: &Extras) -> u64 {
    let images = pixels * (32 + if aovs { 64 } else { 0 });
    let denoiser = if extras.denoiser.is_some() { pixels * 512 } else { 0 };
    images + denoiser
}

/// Takes the picture's memory ([`picture_bytes`]) from the run's `budget`; where it does
/// not fit, an error at the scene's `size` (or the `--size` that replaced it) and `false`.
pub fn take_picture_memory(
    budget: &mut Budget,
    diags: &mut Diagnostics,
    desc: &SceneDesc,
    job: &RenderJob,
    need: u64,
) -> bool {
    let (width, height) = (job.pixels.width(), job.pixels.height());
    let samples = match job.samples.len() {
        1 => "1 sample".to_string(),
        n => format!("{n} samples"),
    };
    let what = format!("the picture ({width} x {height} pixels, {samples} each)");
    match budget.take(need, &what) {
        Ok(()) => true,
        Err(e) => {
            let loc = desc.size.as_ref().map_or(desc.end, |s| s.loc);
            diags.error(loc, format!("size: {e}"));
            false
        }
    }
}

/// The EXR that holds the passes of a non-EXR output: `OUT.aovs.exr` beside it; `None`
/// when the output is an EXR itself, `/dev/null`, or no pass is asked for. An error when
/// the output is standard output or another device (there is no "beside").
pub fn aov_file(out: &Output, aovs: AovSelection) -> Result<Option<Output>, String> {
    if !aovs.any() || out.format == Format::Exr {
        return Ok(None);
    }
    // `-o /dev/null` keeps no picture, and no passes either: a task whose state is what
    // counts (the state keeps the passes' sums for the merge).
    if let OutputTarget::Device(p) = &out.target {
        if std::fs::canonicalize(p).is_ok_and(|c| c == Path::new("/dev/null")) {
            return Ok(None);
        }
    }
    if !matches!(out.target, OutputTarget::File(_)) {
        return Err("--aov writes its passes to a file: name an .exr output with -o (or a file beside which OUT.aovs.exr can go)".into());
    }
    let stem = out
        .name
        .file_stem()
        .map_or("render".into(), |s| s.to_string_lossy().into_owned());
    let name = out.name.with_file_name(format!("{stem}.aovs.exr"));
    choose_output(
        Some(Path::new(&name)),
        &SceneDesc::default(),
        &mut Diagnostics::default(),
    )
    .map(Some)
}

/// The files of the picture of `film` (described by `header`) at `out`, with `extras`:
/// the image, and the passes' EXR beside it.
pub fn encode_picture(
    out: &Output,
    film: &Film,
    header: &StateHeader,
    extras: &Extras,
) -> Result<Vec<Encoded>, String> {
    let info = image_info(header);
    let noisy = film.resolve();
    let aovs = film.resolve_aovs();
    let denoised = match extras.denoiser {
        Some(d) => {
            let a = aovs.as_ref().expect("a film rendered for denoising keeps its passes");
            Some(denoise(d, &noisy, a, extras.threads)?)
        }
        None => None,
    };
    let colour = denoised.as_ref().unwrap_or(&noisy);
    let layered = |at: &Output| {
        let noisy = denoised.is_some().then_some(&noisy);
        let bytes = encode_exr_channels(
            film.width,
            film.height,
            channels(colour, noisy, aovs.as_ref(), extras.aovs),
            &info,
        )
        .map_err(|e| format!("cannot write {}: {e}", at.name.display()))?;
        Ok::<_, String>(Encoded {
            name: at.name.clone(),
            target: at.target.clone(),
            bytes,
        })
    };
    if out.format == Format::Exr {
        return Ok(vec![layered(out)?]);
    }
    let mut files = vec![encode_image(out, colour, &info)?];
    if let Some(side) = aov_file(out, extras.aovs)? {
        files.push(layered(&side)?);
    }
    Ok(files)
}

/// The colour through Open Image Denoise, guided by the albedo and normal passes.
fn denoise(d: &Denoiser, noisy: &Image, aovs: &AovImages, threads: usize) -> Result<Image, String> {
    let input = DenoiseInput {
        width: noisy.width,
        height: noisy.height,
        color: &noisy.to_rgb_f32(),
        albedo: &aovs.albedo.to_rgb_f32(),
        normal: &aovs.normal.to_rgb_f32(),
    };
    let out = d.denoise(&input, threads)?;
    Ok(Image {
        width: noisy.width,
        height: noisy.height,
        pixels: out
            .chunks_exact(3)
            .map(|c| lucent_core::math::Color::new(c[0], c[1], c[2]))
            .collect(),
    })
}

/// The EXR channels: the colour, then the passes chosen, and the colour before denoising.
fn channels(
    colour: &Image,
    noisy: Option<&Image>,
    aovs: Option<&AovImages>,
    sel: AovSelection,
) -> Vec<(String, Vec<f32>)> {
    let plane = |img: &Image, k: usize| img.pixels.iter().map(|p| p[k]).collect::<Vec<f32>>();
    let mut out = Vec::new();
    let mut rgb = |prefix: &str, img: &Image, names: [&str; 3]| {
        for (k, n) in names.iter().enumerate() {
            out.push((format!("{prefix}{n}"), plane(img, k)));
        }
    };
    rgb("", colour, ["R", "G", "B"]);
    if let Some(n) = noisy {
        rgb("noisy.", n, ["R", "G", "B"]);
    }
    if let Some(a) = aovs {
        if sel.albedo {
            rgb("albedo.", &a.albedo, ["R", "G", "B"]);
        }
        if sel.normal {
            rgb("normal.", &a.normal, ["X", "Y", "Z"]);
        }
        if sel.depth {
            out.push(("depth.Z".into(), a.depth.clone()));
        }
        if sel.alpha {
            out.push(("A".into(), a.alpha.clone()));
        }
    }
    out
}
