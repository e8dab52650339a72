//! Images out and in: the encoders of the output formats (8-bit PNG, OpenEXR with 32-bit
//! float channels, Radiance RGBE) — the bytes are written by
//! [`crate::resources::OutputTarget`] — and the reader `lucent diff` compares images with.

use std::path::Path;

use image::ImageEncoder;

use crate::cse167::MAX_PIXELS;
use crate::resources::{input::MAX_IMAGE_BYTES, read_input, Inputs};
use crate::texture_file::decode_within;

/// Encodes 8-bit RGB (interleaved, top row first) as PNG.
pub fn encode_png(width: u32, height: u32, rgb: &[u8], info: &ImageInfo) -> Result<Vec<u8>, String> {
    let mut png = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut png, width, height);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        // What the bytes mean: the encoding exponent 1/g of SCENE_FORMAT.md §4.1 (1 for
        // linear values), with the sRGB / Rec. 709 primaries and white point.
        enc.set_source_gamma(png::ScaledFloat::from_scaled(
            (100_000.0 / info.gamma as f64).round() as u32
        ));
        enc.set_source_chromaticities(png::SourceChromaticities::new(
            (0.3127, 0.3290),
            (0.64, 0.33),
            (0.30, 0.60),
            (0.15, 0.06),
        ));
        for (k, v) in &info.text {
            // tEXt holds Latin-1 only; other text (a scene named in Chinese) goes in an
            // iTXt chunk, which holds UTF-8.
            let added = if v.chars().all(|c| (c as u32) < 256) {
                enc.add_text_chunk(k.clone(), v.clone())
            } else {
                enc.add_itxt_chunk(k.clone(), v.clone())
            };
            added.map_err(|e| e.to_string())?;
        }
        let mut w = enc.write_header().map_err(|e| e.to_string())?;
        w.write_image_data(rgb).map_err(|e| e.to_string())?;
        w.finish().map_err(|e| e.to_string())?;
    }
    Ok(png)
}

/// What an image file says about itself besides its pixels: the gamma its 8-bit values
/// are encoded with (1: linear), text (PNG tEXt chunks: `Software`, `Source`,
/// `Comment`…) and where it lies in the whole picture.
#[derive(Clone, Debug)]
pub struct ImageInfo {
    pub gamma: f32,
    pub text: Vec<(String, String)>,
    /// Where the image's top left pixel is in the whole picture, and the whole picture's
    /// size (an EXR's data and display windows).
    pub origin: (u32, u32),
    pub full: (u32, u32),
}

/// Encodes 8-bit RGB as a JPEG (quality 95).
pub fn encode_jpeg(width: u32, height: u32, rgb: &[u8]) -> Result<Vec<u8>, String> {
    let mut out = Vec::new();
    image::codecs::jpeg::JpegEncoder::new_with_quality(&mut out, 95)
        .write_image(rgb, width, height, image::ExtendedColorType::Rgb8)
        .map_err(|e| e.to_string())?;
    Ok(out)
}

/// Encodes linear RGB floats (interleaved, top row first) as an OpenEXR file (32-bit float
/// channels, ZIP-compressed): the render's values before clamping and encoding. See
/// [`encode_exr_channels`].
pub fn encode_exr(width: u32, height: u32, rgb: &[f32], info: &ImageInfo) -> Result<Vec<u8>, String> {
    let plane = |k: usize| rgb.iter().skip(k).step_by(3).copied().collect::<Vec<f32>>();
    let channels = vec![
        ("R".to_string(), plane(0)),
        ("G".to_string(), plane(1)),
        ("B".to_string(), plane(2)),
    ];
    encode_exr_channels(width, height, channels, info)
}

/// Encodes named channels of 32-bit floats (each a plane, top row first) as one
/// OpenEXR image, ZIP-compressed: `R`, `G`, `B` (and `A`) are the picture, names like
/// `albedo.R` or `normal.X` its layers, as Blender and Nuke name them. The data window is
/// the region at `info.origin` inside the display window `info.full` (the whole image: a
/// crop says where it belongs), and the header's `software` and `comments` carry
/// `info.text`'s `Software` and `Comment`.
pub fn encode_exr_channels(
    width: u32,
    height: u32,
    channels: Vec<(String, Vec<f32>)>,
    info: &ImageInfo,
) -> Result<Vec<u8>, String> {
    use exr::prelude::*;
    let list: SmallVec<[AnyChannel<FlatSamples>; 4]> = channels
        .into_iter()
        .map(|(name, plane)| AnyChannel::new(name.as_str(), FlatSamples::F32(plane)))
        .collect();
    let mut attributes = LayerAttributes::default();
    attributes.layer_position = Vec2(info.origin.0 as i32, info.origin.1 as i32);
    let text = |key: &str| {
        info.text
            .iter()
            .find(|(k, _)| k == key)
            // An EXR string is bytes (size-prefixed): UTF-8, as OpenEXR's own tools
            // read it. (`Text::from` panics on anything past Latin-1.)
            .map(|(_, v)| Text::from_slice_unchecked(v.as_bytes()))
    };
    attributes.software_name = text("Software");
    attributes.comments = text("Comment");
    let layer = Layer::new(
        (width as usize, height as usize),
        attributes,
        Encoding::FAST_LOSSLESS,
        AnyChannels::sort(list),
    );
    let mut image = Image::from_layer(layer);
    image.attributes.display_window = IntegerBounds::new((0, 0), (info.full.0 as usize, info.full.1 as usize));
    let mut out = std::io::Cursor::new(Vec::new());
    image
        .write()
        .non_parallel()
        .to_buffered(&mut out)
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

/// The image in `path` (a regular file), no larger than a picture lucent renders
/// ([`MAX_PIXELS`]: a 20000 × 20000 PNG of a few hundred kilobytes would otherwise take
/// gigabytes), the decoder held to its size.
fn decode_bounded(path: &Path) -> Result<image::DynamicImage, String> {
    use image::ImageDecoder;
    let bytes = read_input(path, MAX_IMAGE_BYTES, &mut Inputs::default())?;
    let decoder = image::ImageReader::new(std::io::Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| e.to_string())?
        .into_decoder()
        .map_err(|e| e.to_string())?;
    let (w, h) = decoder.dimensions();
    if w as u64 * h as u64 > MAX_PIXELS {
        return Err(format!(
            "the image is {w} x {h}, more than lucent compares (at most {MAX_PIXELS} pixels, as it renders)"
        ));
    }
    let bytes = decoder.total_bytes();
    decode_within(decoder, bytes)
}

/// Reads a PNG or JPEG file (a regular file) as 8-bit RGB; the error says why not.
pub fn read_rgb8(path: &Path) -> Result<Rgb8Image, String> {
    let img = decode_bounded(path)?.to_rgb8();
    Ok(Rgb8Image {
        width: img.width(),
        height: img.height(),
        data: img.into_raw(),
    })
}

/// A linear RGB image read from disk (EXR or Radiance HDR), interleaved.
pub struct RgbF32Image {
    pub width: u32,
    pub height: u32,
    pub data: Vec<f32>,
}

/// Reads an EXR or HDR file (a regular file) as linear RGB floats.
pub fn read_rgb_f32(path: &Path) -> Result<RgbF32Image, String> {
    let img = decode_bounded(path)?.to_rgb32f();
    Ok(RgbF32Image {
        width: img.width(),
        height: img.height(),
        data: img.into_raw(),
    })
}

/// Whether two Monte Carlo renders of the same scene agree within their noise, in linear
/// radiance: the image is cut into `cols × rows` regions, and in each the mean
/// difference of every channel is divided by its standard error, estimated from the
/// spread of the per-pixel differences in that region (the picture's own structure
/// cancels in a difference; what is left is the two renders' noise). The largest |z| of
/// the regions and of the whole image, and the ratio of the two images' means.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Agreement {
    pub worst_z: f64,
    /// (column, row, channel) of the worst region.
    pub worst_at: (u32, u32, usize),
    pub whole_z: f64,
    pub mean_ratio: f64,
}

pub fn agreement(a: &RgbF32Image, b: &RgbF32Image, cols: u32, rows: u32) -> Option<Agreement> {
    if (a.width, a.height) != (b.width, b.height) || a.width < cols || a.height < rows {
        return None;
    }
    let (w, h) = (a.width as usize, a.height as usize);
    // Per region and channel: n, Σd, Σd².
    let mut stats = vec![(0f64, 0f64, 0f64); (cols * rows) as usize * 3];
    let mut whole = [(0f64, 0f64, 0f64); 3];
    let (mut sum_a, mut sum_b) = (0f64, 0f64);
    for y in 0..h {
        let ry = (y * rows as usize / h) as u32;
        for x in 0..w {
            let rx = (x * cols as usize / w) as u32;
            for c in 0..3 {
                let i = (y * w + x) * 3 + c;
                let (va, vb) = (a.data[i] as f64, b.data[i] as f64);
                let va = if va.is_finite() { va } else { 0.0 };
                let vb = if vb.is_finite() { vb } else { 0.0 };
                sum_a += va;
                sum_b += vb;
                let d = va - vb;
                let s = &mut stats[((ry * cols + rx) as usize) * 3 + c];
                *s = (s.0 + 1.0, s.1 + d, s.2 + d * d);
                whole[c] = (whole[c].0 + 1.0, whole[c].1 + d, whole[c].2 + d * d);
            }
        }
    }
    let z = |(n, s, s2): (f64, f64, f64)| {
        let mean = s / n;
        let var = (s2 / n - mean * mean).max(0.0) * n / (n - 1.0);
        let se = (var / n).sqrt();
        if se > 0.0 {
            mean / se
        } else if mean == 0.0 {
            0.0
        } else {
            f64::INFINITY
        }
    };
    let mut worst = (0.0f64, (0, 0, 0));
    for (k, s) in stats.iter().enumerate() {
        let zk = z(*s);
        if zk.abs() > worst.0.abs() || worst.0.is_nan() {
            let region = (k / 3) as u32;
            worst = (zk, (region % cols, region / cols, k % 3));
        }
    }
    let whole_z = whole
        .iter()
        .map(|s| z(*s))
        .fold(0.0f64, |m, v| if v.abs() > m.abs() { v } else { m });
    Some(Agreement {
        worst_z: worst.0,
        worst_at: worst.1,
        whole_z,
        mean_ratio: if sum_b > 0.0 { sum_a / sum_b } else { f64::NAN },
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
