//! A finished picture: linear RGB floats, row 0 at the top (what the film resolves to),
//! and its 8-bit encoding (SCENE_FORMAT.md §4.1): clamp to [0, 1], apply `gamma`, then
//! **truncate** `floor(255 c)`.

use crate::math::Color;

#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    /// Row-major, top row first.
    pub pixels: Vec<Color>,
}

impl Image {
    pub fn new(width: u32, height: u32) -> Image {
        Image {
            width,
            height,
            pixels: vec![Color::ZERO; width as usize * height as usize],
        }
    }

    /// Interleaved linear RGB floats, top row first (for EXR and HDR files); samples
    /// that were not finite are already 0.
    pub fn to_rgb_f32(&self) -> Vec<f32> {
        self.pixels.iter().flat_map(|p| p.to_array()).collect()
    }

    /// Interleaved 8-bit RGB, top row first.
    pub fn to_rgb8(&self, gamma: f32) -> Vec<u8> {
        let mut out = Vec::with_capacity(self.pixels.len() * 3);
        for p in &self.pixels {
            for c in p.to_array() {
                out.push(encode_channel(c, gamma));
            }
        }
        out
    }
}

/// One channel of linear colour to a byte; NaN becomes 0.
#[inline]
pub fn encode_channel(c: f32, gamma: f32) -> u8 {
    let c = if c.is_nan() { 0.0 } else { c.clamp(0.0, 1.0) };
    let c = if gamma == 1.0 { c } else { c.powf(1.0 / gamma) };
    // Truncation: `floor` for the non-negative values here, without its library call
    // (x86-64 without SSE4.1 has no rounding instruction).
    (255.0 * c) as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn truncates_clamps_and_applies_gamma() {
        assert_eq!(encode_channel(0.25, 1.0), 63); // 63.75 truncated
        assert_eq!(encode_channel(1.0, 1.0), 255);
        assert_eq!(encode_channel(7.0, 1.0), 255);
        assert_eq!(encode_channel(-1.0, 1.0), 0);
        assert_eq!(encode_channel(f32::NAN, 1.0), 0);
        assert_eq!(encode_channel(0.25, 2.0), 127); // sqrt(0.25) = 0.5 → 127.5
    }
}
