//! Images out and in: the encoders of the output formats (8-bit PNG, OpenEXR with 32-bit
//! float channels, Radiance RGBE) — the bytes are written by
//! [`crate::resources::OutputTarget`] — and the reader `lucent diff` compares images with.

use std::path::Path;

use image::ImageEncoder;

use crate::resources::{input::MAX_IMAGE_BYTES, read_input, Inputs};

/// Encodes 8-bit RGB (interleaved, top row first) as PNG.
pub fn encode_png(width: u32, height: u32, rgb: &[u8]) -> Result<Vec<u8>, String> {
    let mut png = Vec::new();
    image::codecs::png::PngEncoder::new(&mut png)
        .write_image(rgb, width, height, image::ExtendedColorType::Rgb8)
        .map_err(|e| e.to_string())?;
    Ok(png)
}

/// Encodes linear RGB floats (interleaved, top row first) as an OpenEXR file (32-bit float
/// channels): the render's values before clamping and encoding.
pub fn encode_exr(width: u32, height: u32, rgb: &[f32]) -> Result<Vec<u8>, String> {
    let mut out = std::io::Cursor::new(Vec::new());
    let bytes: Vec<u8> = rgb.iter().flat_map(|v| v.to_le_bytes()).collect();
    image::codecs::openexr::OpenExrEncoder::new(&mut out)
        .write_image(&bytes, width, height, image::ExtendedColorType::Rgb32F)
        .map_err(|e| e.to_string())?;
    Ok(out.into_inner())
}

/// Encodes linear RGB floats as a Radiance RGBE (`.hdr`) file.
pub fn encode_hdr(width: u32, height: u32, rgb: &[f32]) -> Result<Vec<u8>, String> {
    let mut out = Vec::new();
    let pixels: Vec<image::Rgb<f32>> = rgb
        .chunks_exact(3)
        .map(|c| image::Rgb([c[0].max(0.0), c[1].max(0.0), c[2].max(0.0)]))
        .collect();
    image::codecs::hdr::HdrEncoder::new(&mut out)
        .encode(&pixels, width as usize, height as usize)
        .map_err(|e| e.to_string())?;
    Ok(out)
}

/// An 8-bit RGB image read from disk (PNG or JPEG).
pub struct Rgb8Image {
    pub width: u32,
    pub height: u32,
    pub data: Vec<u8>,
}

/// Reads a PNG or JPEG file (a regular file) as 8-bit RGB; the error says why not.
pub fn read_rgb8(path: &Path) -> Result<Rgb8Image, String> {
    let bytes = read_input(path, MAX_IMAGE_BYTES, &mut Inputs::default())?;
    let reader = image::ImageReader::new(std::io::Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| e.to_string())?;
    let img = reader.decode().map_err(|e| e.to_string())?.to_rgb8();
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
