//! Textures (`texture`, `checker`) and the environment map (`envmap`).
//!
//! Image textures hold linear RGB (8-bit files keep their sRGB bytes, decoded by a table
//! on lookup: 3 bytes a texel instead of 12) and are filtered bilinearly with wrapping; texture coordinates run from (0, 0) at the bottom
//! left of the image to (1, 1) at the top right, as in OBJ files. The checker is a solid
//! texture of the world-space hit point.

use crate::math::{Color, Vec3A};
use crate::tessellate::displacement::{Detail, HeightField};
use glam::Vec2;

/// An image of linear RGB values, row 0 at the top.
#[derive(Clone, Debug)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    texels: Texels,
}

/// The texels, row by row, three values each, kept as compact as the file allows.
#[derive(Clone, Debug)]
enum Texels {
    /// 8-bit sRGB values (3 bytes a texel), decoded on lookup by a table of the 256
    /// linear values — the very values decoding at load would give.
    Srgb8(Vec<u8>, &'static [f32; 256]),
    /// Linear floats (12 bytes a texel): 16-bit and floating-point files.
    Linear(Vec<f32>),
}

/// The linear value of each 8-bit sRGB value.
fn srgb_table() -> &'static [f32; 256] {
    static TABLE: std::sync::OnceLock<[f32; 256]> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| std::array::from_fn(|b| srgb_to_linear(b as u8)))
}

impl Image {
    /// An image of 8-bit sRGB values, `3 · width · height` of them.
    pub fn srgb8(width: u32, height: u32, rgb: Vec<u8>) -> Image {
        assert_eq!(rgb.len(), 3 * width as usize * height as usize);
        Image {
            width,
            height,
            texels: Texels::Srgb8(rgb, srgb_table()),
        }
    }

    /// An image of linear values, `3 · width · height` of them.
    pub fn linear(width: u32, height: u32, rgb: Vec<f32>) -> Image {
        assert_eq!(rgb.len(), 3 * width as usize * height as usize);
        Image {
            width,
            height,
            texels: Texels::Linear(rgb),
        }
    }

    /// An image of linear colours, row by row.
    pub fn from_colors(width: u32, height: u32, colors: &[Color]) -> Image {
        Image::linear(width, height, colors.iter().flat_map(|c| c.to_array()).collect())
    }

    /// Bytes the texels take: what a texture costs in memory.
    pub fn memory_bytes(&self) -> usize {
        match &self.texels {
            Texels::Srgb8(v, _) => v.len(),
            Texels::Linear(v) => v.len() * 4,
        }
    }

    /// Texel `i` (row by row) as linear RGB.
    #[inline]
    pub fn texel_at(&self, i: usize) -> Color {
        match &self.texels {
            Texels::Srgb8(v, table) => {
                let t = &v[3 * i..3 * i + 3];
                Color::new(table[t[0] as usize], table[t[1] as usize], table[t[2] as usize])
            }
            Texels::Linear(v) => Color::new(v[3 * i], v[3 * i + 1], v[3 * i + 2]),
        }
    }

    #[inline]
    fn texel(&self, x: i64, y: i64) -> Color {
        let (w, h) = (self.width as i64, self.height as i64);
        self.texel_at((y.rem_euclid(h) * w + x.rem_euclid(w)) as usize)
    }

    /// Bilinear filtering at image coordinates (`x`, `y`) in texels (texel centres at
    /// half-integers), wrapping around every edge.
    pub fn bilinear(&self, x: f32, y: f32) -> Color {
        let (x, y) = (x - 0.5, y - 0.5);
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let top = self.texel(x0, y0) * (1.0 - fx) + self.texel(x0 + 1, y0) * fx;
        let bottom = self.texel(x0, y0 + 1) * (1.0 - fx) + self.texel(x0 + 1, y0 + 1) * fx;
        top * (1.0 - fy) + bottom * fy
    }

    /// The largest channel value of any texel (in absolute value).
    pub fn max_channel(&self) -> f32 {
        match &self.texels {
            Texels::Srgb8(v, table) => v.iter().map(|&b| table[b as usize]).fold(0.0, f32::max),
            Texels::Linear(v) => v.iter().map(|x| x.abs()).fold(0.0, f32::max),
        }
    }

    /// The image at texture coordinates `uv` ((0, 0) bottom left, wrapping).
    pub fn at_uv(&self, uv: Vec2) -> Color {
        let (u, v) = (uv.x - uv.x.floor(), uv.y - uv.y.floor());
        if !(u.is_finite() && v.is_finite()) {
            return Color::ZERO;
        }
        self.bilinear(u * self.width as f32, (1.0 - v) * self.height as f32)
    }
}

#[derive(Clone, Debug)]
pub enum Texture {
    Image(Image),
    /// Alternating cubes of side `scale` in world space: `a` where the cell indices sum
    /// to an even number, `b` elsewhere. Cell boundaries sit 10⁻⁴ of a cell below the
    /// multiples of `scale`, so surfaces on those planes are in one cell.
    Checker {
        a: Color,
        b: Color,
        scale: f32,
    },
}

impl Texture {
    /// The texture's colour at a hit with texture coordinates `uv` and world position `p`.
    pub fn eval(&self, uv: Vec2, p: Vec3A) -> Color {
        match self {
            Texture::Image(img) => img.at_uv(uv),
            Texture::Checker { a, b, scale } => {
                // Nudged by 10⁻⁴ of a cell: a floor lying exactly on a cell boundary
                // (y = 0 is one) would otherwise flip between cells with rounding noise.
                let c = (p / *scale + Vec3A::splat(1e-4)).floor();
                let parity = (c.x as i64 + c.y as i64 + c.z as i64).rem_euclid(2);
                if parity == 0 {
                    *a
                } else {
                    *b
                }
            }
        }
    }
}

/// `displacementmap name scale`: the texture's luminance times `scale` as a height field.
/// An image's finest detail is a texel; a checker's, a quarter of a cell.
pub struct Displacement<'a> {
    pub texture: &'a Texture,
    pub scale: f32,
}

impl HeightField for Displacement<'_> {
    fn height(&self, uv: Vec2, p: Vec3A) -> f32 {
        self.scale * luminance(self.texture.eval(uv, p))
    }

    fn detail(&self) -> Detail {
        match self.texture {
            Texture::Image(img) => Detail::Texel(1.0 / img.width.max(img.height) as f32),
            Texture::Checker { scale, .. } => Detail::Solid(0.25 * scale),
        }
    }
}

/// An equirectangular (latitude–longitude) image around the scene, seen by every ray that
/// hits nothing: +y is up (the top row), and the centre of the image looks along −z.
#[derive(Clone, Debug)]
pub struct EnvironmentMap {
    pub image: Image,
    pub intensity: f32,
}

impl EnvironmentMap {
    /// The radiance arriving along direction `-d` (what a ray travelling along `d` sees).
    pub fn radiance(&self, d: Vec3A) -> Color {
        let d = d.normalize();
        let u = 0.5 + d.x.atan2(-d.z) / (2.0 * std::f32::consts::PI);
        let v = d.y.clamp(-1.0, 1.0).acos() / std::f32::consts::PI;
        let img = &self.image;
        // Longitude wraps; latitude is clamped to the rows at the poles.
        let y = (v * img.height as f32).clamp(0.5, img.height as f32 - 0.5);
        img.bilinear(u * img.width as f32, y) * self.intensity
    }
}

/// The 8-bit sRGB transfer function undone: a byte to linear light.
pub fn srgb_to_linear(byte: u8) -> f32 {
    srgb_value_to_linear(byte as f32 / 255.0)
}

/// The sRGB transfer function undone for an encoded value in [0, 1].
pub fn srgb_value_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Relative luminance of linear RGB (Rec. 709 weights): what bump maps differentiate.
pub fn luminance(c: Color) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(w: u32, h: u32, f: impl Fn(u32, u32) -> Color) -> Image {
        let colors: Vec<Color> = (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .map(|(x, y)| f(x, y))
            .collect();
        Image::from_colors(w, h, &colors)
    }

    #[test]
    fn bilinear_filtering_interpolates_between_texel_centres_and_wraps() {
        let img = image(2, 1, |x, _| Color::splat(x as f32));
        assert_eq!(img.bilinear(0.5, 0.5), Color::ZERO);
        assert_eq!(img.bilinear(1.5, 0.5), Color::ONE);
        assert_eq!(img.bilinear(1.0, 0.5), Color::splat(0.5));
        // Past the right edge it wraps back towards texel 0.
        assert_eq!(img.bilinear(2.0, 0.5), Color::splat(0.5));
        // uv (0, 0) is the bottom left; v = 1 the top.
        let tall = image(1, 2, |_, y| Color::splat(y as f32));
        assert_eq!(tall.at_uv(Vec2::new(0.5, 0.25)), Color::ONE, "bottom row");
        assert_eq!(tall.at_uv(Vec2::new(0.5, 0.75)), Color::ZERO, "top row");
        assert_eq!(tall.at_uv(Vec2::new(1.5, 1.75)), Color::ZERO, "wrapped");
    }

    #[test]
    fn checker_alternates_in_three_dimensions() {
        let t = Texture::Checker {
            a: Color::ONE,
            b: Color::ZERO,
            scale: 2.0,
        };
        let at = |x: f32, y: f32, z: f32| t.eval(Vec2::ZERO, Vec3A::new(x, y, z)).x;
        assert_eq!(at(0.5, 0.5, 0.5), 1.0);
        assert_eq!(at(2.5, 0.5, 0.5), 0.0);
        assert_eq!(at(2.5, 2.5, 0.5), 1.0);
        assert_eq!(at(-0.5, 0.5, 0.5), 0.0);
        // A floor at y = 0 with rounding noise stays in one cell.
        assert_eq!(at(0.5, -1e-7, 0.5), at(0.5, 1e-7, 0.5));
    }

    #[test]
    fn the_environment_centre_looks_along_minus_z_and_up_is_the_top_row() {
        // 4 × 2 image: top row red, bottom row blue; columns tell longitude.
        let img = image(4, 2, |x, y| {
            Color::new(x as f32, (y == 0) as u8 as f32, (y == 1) as u8 as f32)
        });
        let env = EnvironmentMap {
            image: img,
            intensity: 2.0,
        };
        let up = env.radiance(Vec3A::Y);
        assert_eq!((up.y, up.z), (2.0, 0.0));
        let down = env.radiance(-Vec3A::Y);
        assert_eq!((down.y, down.z), (0.0, 2.0));
        // −z is the image centre (u = 0.5: between columns 1 and 2).
        assert!((env.radiance(-Vec3A::Z).x - 3.0).abs() < 1e-5);
    }

    #[test]
    fn eight_bit_texels_read_as_their_decoded_values() {
        let img = Image::srgb8(2, 1, vec![0, 128, 255, 188, 1, 2]);
        assert_eq!(img.texel_at(0), Color::new(0.0, srgb_to_linear(128), 1.0));
        assert_eq!(
            img.texel_at(1),
            Color::new(srgb_to_linear(188), srgb_to_linear(1), srgb_to_linear(2))
        );
        assert_eq!(img.memory_bytes(), 6);
        assert_eq!(img.max_channel(), 1.0);
    }

    #[test]
    fn srgb_decoding() {
        assert_eq!(srgb_to_linear(0), 0.0);
        assert!((srgb_to_linear(255) - 1.0).abs() < 1e-6);
        assert!((srgb_to_linear(188) - 0.5).abs() < 0.01);
    }
}
