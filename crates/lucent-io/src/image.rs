//! Images out (and in, for comparisons). Output is written atomically: to a temporary
//! file beside the target, then renamed over it, so a failed or interrupted run never
//! leaves a partial image and never destroys an existing one.

use std::fs::{self, File};
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use image::ImageEncoder;

#[derive(Debug, thiserror::Error)]
pub enum ImageError {
    #[error("cannot write {path}: {reason}")]
    Write { path: String, reason: String },
    #[error("cannot read {path}: {reason}")]
    Read { path: String, reason: String },
}

fn write_error(path: &Path, e: impl std::fmt::Display) -> ImageError {
    ImageError::Write {
        path: path.display().to_string(),
        reason: e.to_string(),
    }
}

fn io_write_error(path: &Path, e: &std::io::Error) -> ImageError {
    write_error(path, crate::files::io_reason(e))
}

fn temp_path(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    path.with_file_name(format!(".{name}.{}.lucent-tmp", std::process::id()))
}

/// Checks, before any work is done, that `path` can be written: its directory exists and
/// takes a new file, and `path` is not a directory.
pub fn check_writable(path: &Path) -> Result<(), ImageError> {
    if path.as_os_str().is_empty() || path.file_name().is_none() {
        return Err(write_error(path, "not a file name"));
    }
    if path.is_dir() {
        return Err(write_error(path, "it is a directory"));
    }
    let tmp = temp_path(path);
    File::create(&tmp).map_err(|e| io_write_error(path, &e))?;
    let _ = fs::remove_file(&tmp);
    Ok(())
}

/// Writes 8-bit RGB as PNG, atomically.
pub fn write_png(path: &Path, width: u32, height: u32, rgb: &[u8]) -> Result<(), ImageError> {
    let mut png = Vec::new();
    image::codecs::png::PngEncoder::new(&mut png)
        .write_image(rgb, width, height, image::ExtendedColorType::Rgb8)
        .map_err(|e| write_error(path, e))?;
    write_file_atomically(path, &png)
}

/// Writes linear RGB floats (interleaved, top row first) as an OpenEXR file (32-bit
/// float channels), atomically: the render's values before clamping and encoding.
pub fn write_exr(path: &Path, width: u32, height: u32, rgb: &[f32]) -> Result<(), ImageError> {
    let mut out = std::io::Cursor::new(Vec::new());
    let bytes: Vec<u8> = rgb.iter().flat_map(|v| v.to_le_bytes()).collect();
    image::codecs::openexr::OpenExrEncoder::new(&mut out)
        .write_image(&bytes, width, height, image::ExtendedColorType::Rgb32F)
        .map_err(|e| write_error(path, e))?;
    write_file_atomically(path, &out.into_inner())
}

/// Writes linear RGB floats as a Radiance RGBE (`.hdr`) file, atomically.
pub fn write_hdr(path: &Path, width: u32, height: u32, rgb: &[f32]) -> Result<(), ImageError> {
    let mut out = Vec::new();
    let pixels: Vec<image::Rgb<f32>> = rgb
        .chunks_exact(3)
        .map(|c| image::Rgb([c[0].max(0.0), c[1].max(0.0), c[2].max(0.0)]))
        .collect();
    image::codecs::hdr::HdrEncoder::new(&mut out)
        .encode(&pixels, width as usize, height as usize)
        .map_err(|e| write_error(path, e))?;
    write_file_atomically(path, &out)
}

/// Writes `bytes` to a temporary file beside `path`, syncs it and renames it over
/// `path`: readers see the old file or the whole new one, never a part.
pub fn write_file_atomically(path: &Path, bytes: &[u8]) -> Result<(), ImageError> {
    let tmp = temp_path(path);
    let result = (|| {
        let file = File::create(&tmp).map_err(|e| io_write_error(path, &e))?;
        let mut out = BufWriter::new(file);
        out.write_all(bytes).map_err(|e| io_write_error(path, &e))?;
        let file = out.into_inner().map_err(|e| io_write_error(path, e.error()))?;
        file.sync_all().map_err(|e| io_write_error(path, &e))?;
        fs::rename(&tmp, path).map_err(|e| io_write_error(path, &e))
    })();
    if result.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    result
}

/// An 8-bit RGB image read from disk (PNG or JPEG).
pub struct Rgb8Image {
    pub width: u32,
    pub height: u32,
    pub data: Vec<u8>,
}

pub fn read_rgb8(path: &Path) -> Result<Rgb8Image, ImageError> {
    let err = |e: &dyn std::fmt::Display| ImageError::Read {
        path: path.display().to_string(),
        reason: e.to_string(),
    };
    let reader = image::ImageReader::open(path).map_err(|e| err(&crate::files::io_reason(&e)))?;
    let reader = reader.with_guessed_format().map_err(|e| err(&e))?;
    let img = reader.decode().map_err(|e| err(&e))?.to_rgb8();
    Ok(Rgb8Image {
        width: img.width(),
        height: img.height(),
        data: img.into_raw(),
    })
}

/// How two images of the same size differ, on the 0–255 scale.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImageDiff {
    pub pixels: usize,
    /// Pixels with any channel differing by more than the threshold.
    pub pixels_over: usize,
    /// Mean absolute difference over all channels.
    pub mean_abs_error: f64,
    pub max_abs_error: u8,
}

pub fn diff(a: &Rgb8Image, b: &Rgb8Image, threshold: u8) -> Option<ImageDiff> {
    if (a.width, a.height) != (b.width, b.height) {
        return None;
    }
    let mut over = 0;
    let mut sum = 0u64;
    let mut max = 0u8;
    for (pa, pb) in a.data.chunks_exact(3).zip(b.data.chunks_exact(3)) {
        let d = [0, 1, 2].map(|k| pa[k].abs_diff(pb[k]));
        let m = *d.iter().max().unwrap();
        over += (m > threshold) as usize;
        max = max.max(m);
        sum += d.iter().map(|&x| x as u64).sum::<u64>();
    }
    let pixels = (a.width * a.height) as usize;
    Some(ImageDiff {
        pixels,
        pixels_over: over,
        mean_abs_error: sum as f64 / (pixels.max(1) * 3) as f64,
        max_abs_error: max,
    })
}
