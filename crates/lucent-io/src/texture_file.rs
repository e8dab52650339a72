//! Texture and environment images from files: PNG and JPEG (8 or 16 bits, sRGB), Radiance
//! HDR and OpenEXR (linear). The file must be a regular file; its size in texels is read
//! from its header first, and the memory its decoding takes is taken from the budget
//! before any of it is allocated (the decoder is held to the same bound).

use std::io::Cursor;
use std::path::Path;

use image::{DynamicImage, ImageDecoder, ImageReader};
use lucent_core::shading::texture::{srgb_value_to_linear, Image};

use crate::resources::input::MAX_IMAGE_BYTES;
use crate::resources::{read_input, Resources};

/// The largest image accepted, in texels (a 16k × 16k picture).
const MAX_TEXELS: u64 = 1 << 28;

/// Reads an image file as a texture, taking its memory from `res`'s budget.
pub fn load_image(path: &Path, res: &mut Resources) -> Result<Image, String> {
    // The file's bytes are held while it is decoded.
    let file_size = std::fs::metadata(path).map_or(0, |m| m.len());
    res.budget.take(file_size, "the image file")?;
    let image = decode(path, res);
    res.budget.give_back(file_size);
    image
}

/// [`load_image`] once the file's own memory is taken.
fn decode(path: &Path, res: &mut Resources) -> Result<Image, String> {
    let bytes = read_input(path, MAX_IMAGE_BYTES, &mut res.inputs).map_err(|e| format!("cannot open: {e}"))?;
    let decoder = ImageReader::new(Cursor::new(&bytes[..]))
        .with_guessed_format()
        .map_err(|e| format!("cannot read: {e}"))?
        .into_decoder()
        .map_err(|e| format!("cannot decode the image: {e}"))?;
    let (width, height) = decoder.dimensions();
    let texels = width as u64 * height as u64;
    if width == 0 || height == 0 || texels > MAX_TEXELS {
        return Err(format!("unusable image size {width} x {height}"));
    }
    // Decoding makes the file's own pixels, then ours: 3 bytes a texel for 8-bit files,
    // 12 for the others, which pass through a 6-byte copy on the way.
    let decoded = decoder.total_bytes();
    let eight_bit = decoder.color_type().bytes_per_pixel() / decoder.color_type().channel_count().max(1) == 1;
    let kept = texels * if eight_bit { 3 } else { 12 };
    let passing = if eight_bit { 0 } else { texels * 6 };
    let what = format!("the {width} x {height} image");
    res.budget.take(decoded + passing + kept, &what)?;
    let img = decode_within(decoder, decoded.max(kept));
    // The decoded pixels are gone once ours are made (or the decoding failed).
    res.budget.give_back(decoded + passing);
    let img = img.inspect_err(|_| res.budget.give_back(kept))?;
    use image::DynamicImage as D;
    let image = match img {
        D::ImageRgb32F(_) | D::ImageRgba32F(_) => Image::linear(width, height, img.into_rgb32f().into_raw()),
        D::ImageLuma16(_) | D::ImageLumaA16(_) | D::ImageRgb16(_) | D::ImageRgba16(_) => {
            let v = img.into_rgb16().into_raw();
            Image::linear(
                width,
                height,
                v.iter().map(|&c| srgb_value_to_linear(c as f32 / 65535.0)).collect(),
            )
        }
        _ => Image::srgb8(width, height, img.into_rgb8().into_raw()),
    };
    if !image.max_channel().is_finite() {
        res.budget.give_back(kept);
        return Err("the image holds values that are not finite numbers".into());
    }
    Ok(image)
}

/// The decoder's image, the decoder held to `bytes` (and a little) of memory.
pub(crate) fn decode_within(mut decoder: impl ImageDecoder, bytes: u64) -> Result<DynamicImage, String> {
    let mut limits = image::Limits::default();
    limits.max_alloc = Some(bytes + (1 << 20));
    decoder
        .set_limits(limits)
        .map_err(|e| format!("cannot decode the image: {e}"))?;
    DynamicImage::from_decoder(decoder).map_err(|e| format!("cannot decode the image: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use lucent_core::math::Color;

    #[test]
    fn eight_bit_images_are_decoded_from_srgb_and_float_images_kept() {
        let dir = crate::TestDir::new("tex");
        let mut res = Resources::new(u64::MAX);
        let png = dir.join("t.png");
        image::RgbImage::from_raw(2, 1, vec![255, 188, 0, 0, 0, 255])
            .unwrap()
            .save(&png)
            .unwrap();
        let img = load_image(&png, &mut res).unwrap();
        assert_eq!((img.width, img.height), (2, 1));
        let t = img.texel_at(0);
        assert!((t.x - 1.0).abs() < 1e-6 && (t.y - 0.5).abs() < 0.01);
        assert_eq!(img.memory_bytes(), 6, "3 bytes a texel");
        let exr = dir.join("t.exr");
        image::Rgb32FImage::from_raw(1, 1, vec![2.5, 0.25, 0.0])
            .unwrap()
            .save(&exr)
            .unwrap();
        assert_eq!(
            load_image(&exr, &mut res).unwrap().texel_at(0),
            Color::new(2.5, 0.25, 0.0)
        );
        std::fs::write(dir.join("bad.png"), b"not a png").unwrap();
        assert!(load_image(&dir.join("bad.png"), &mut res).is_err());
        assert!(load_image(&dir.join("missing.png"), &mut res).is_err());
        // The budget is taken before decoding: the file's bytes, then 2 texels need 6 + 6
        // bytes; all of it comes back when the image is refused.
        let file = std::fs::metadata(&png).unwrap().len();
        let mut small = Resources::new(file + 10);
        let e = load_image(&png, &mut small).unwrap_err();
        assert!(e.contains("the 2 x 1 image needs about 12 bytes"), "{e}");
        assert_eq!(small.budget.used(), 0);
        let mut enough = Resources::new(file + 12);
        load_image(&png, &mut enough).unwrap();
        assert_eq!(enough.budget.used(), 6, "what the texture keeps");
    }
}
