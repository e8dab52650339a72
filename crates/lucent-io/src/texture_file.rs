//! Texture and environment images from files: PNG and JPEG (8 or 16 bits, decoded from
//! sRGB to linear), Radiance HDR and OpenEXR (linear already).

use std::path::Path;

use lucent_core::math::Color;
use lucent_core::shading::texture::{srgb_to_linear, srgb_value_to_linear, Image};

/// The largest image accepted, in texels (a 16k × 16k picture).
const MAX_TEXELS: u64 = 1 << 28;

pub fn load_image(path: &Path) -> Result<Image, String> {
    let reader = image::ImageReader::open(path)
        .map_err(|e| format!("cannot open: {}", crate::files::io_reason(&e)))?
        .with_guessed_format()
        .map_err(|e| format!("cannot read: {e}"))?;
    let img = reader.decode().map_err(|e| format!("cannot decode the image: {e}"))?;
    let (width, height) = (img.width(), img.height());
    if width == 0 || height == 0 || width as u64 * height as u64 > MAX_TEXELS {
        return Err(format!("unusable image size {width} x {height}"));
    }
    use image::DynamicImage as D;
    let texels: Vec<Color> = match &img {
        D::ImageRgb32F(_) | D::ImageRgba32F(_) => {
            img.to_rgb32f().pixels().map(|p| Color::new(p[0], p[1], p[2])).collect()
        }
        D::ImageLuma16(_) | D::ImageLumaA16(_) | D::ImageRgb16(_) | D::ImageRgba16(_) => img
            .to_rgb16()
            .pixels()
            .map(|p| Color::from_array(p.0.map(|c| srgb_value_to_linear(c as f32 / 65535.0))))
            .collect(),
        _ => img
            .to_rgb8()
            .pixels()
            .map(|p| Color::from_array(p.0.map(srgb_to_linear)))
            .collect(),
    };
    if texels.iter().any(|c| !c.is_finite()) {
        return Err("the image holds values that are not finite numbers".into());
    }
    Ok(Image { width, height, texels })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eight_bit_images_are_decoded_from_srgb_and_float_images_kept() {
        let dir = std::env::temp_dir().join(format!("lucent-tex-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let png = dir.join("t.png");
        image::RgbImage::from_raw(2, 1, vec![255, 188, 0, 0, 0, 255])
            .unwrap()
            .save(&png)
            .unwrap();
        let img = load_image(&png).unwrap();
        assert_eq!((img.width, img.height), (2, 1));
        assert!((img.texels[0].x - 1.0).abs() < 1e-6 && (img.texels[0].y - 0.5).abs() < 0.01);
        let exr = dir.join("t.exr");
        image::Rgb32FImage::from_raw(1, 1, vec![2.5, 0.25, 0.0])
            .unwrap()
            .save(&exr)
            .unwrap();
        assert_eq!(load_image(&exr).unwrap().texels[0], Color::new(2.5, 0.25, 0.0));
        std::fs::write(dir.join("bad.png"), b"not a png").unwrap();
        assert!(load_image(&dir.join("bad.png")).is_err());
        assert!(load_image(&dir.join("missing.png")).is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
