//! Render state files (`--state OUT.lstate`): the exact per-pixel sample sums and counts
//! of a render of some pixels and some sample indices, with what they belong to, so that
//! renders can be merged (`lucent merge`) and continued (`--resume`) into the very bytes
//! of a render made in one go.
//!
//! The format (docs/long-renders.md): a text header of `key value` lines —
//!
//! ```text
//! lucent-state 2
//! scene 9f3a…            (a 64-bit hash of the scene's text, every file of it)
//! name scene.test        (the scene file's name, for people: not compared)
//! resolution 640 480
//! pixels 0 640 0 240     (x0 x1 y0 y1, ends exclusive)
//! spp 256
//! samples 0 64           (first, end exclusive)
//! seed 0
//! sampler sobol
//! pixelsampling uniform  (where samples go in a pixel: uniform or stratified)
//! gamma 3f800000         (the f32 bits of the output encoding's gamma)
//! aovs yes               (whether the auxiliary passes are kept: yes or no)
//! noisethreshold none    (adaptive sampling's threshold, f32 bits, or none)
//! data
//! ```
//!
//! — then, for every pixel of the rectangle row by row, its three sums (i128, little
//! endian: fixed point with 64 fractional bits, [`ExactSum`]) and its sample count (u32);
//! with `aovs yes` the sums of its albedo (3 × i128), normal (3 × i128) and depth (i128)
//! and the number of samples that hit a surface (u32); with a noise threshold adaptive
//! sampling's sums of luminance and its square (2 × f64) and whether the pixel has
//! stopped (one byte, 0 or 1). Last comes a 64-bit FNV-1a checksum of those bytes. Files are written whole or not at
//! all (a temporary file renamed), and a file whose checksum does not match is refused.

use std::ops::Range;
use std::path::Path;

use lucent_core::film::{AovSum, ExactSum, Film, PixelNoise};
use lucent_core::render::job::PixelRect;
use lucent_core::sampler::SamplerKind;

use crate::cse167::MAX_PIXELS;
use crate::fnv::{fnv1a, START as FNV_START};
use crate::resources::{io_reason, read_input, Budget, Inputs};

mod merge;
pub use merge::merge;

/// What a render state holds.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderState {
    pub header: StateHeader,
    /// The sums and counts of `header.pixels`.
    pub film: Film,
}

/// Everything a state file says besides its pixels: what must agree for two states to
/// merge.
#[derive(Clone, Debug, PartialEq)]
pub struct StateHeader {
    pub scene_hash: u64,
    /// The scene file's name (without its folder), for people; merging ignores it.
    pub scene_name: String,
    pub resolution: (u32, u32),
    pub pixels: PixelRect,
    pub spp: u32,
    pub samples: Range<u32>,
    pub seed: u64,
    pub sampler: String,
    /// `uniform` (the Monte Carlo integrators: sample i is the same for any spp) or
    /// `stratified` (the ray tracer: sample positions depend on spp).
    pub pixel_sampling: String,
    pub gamma: f32,
    /// Whether the auxiliary passes are kept (`--aov`, `--denoise`).
    pub aovs: bool,
    /// Adaptive sampling's threshold, if the render samples adaptively.
    pub noise_threshold: Option<f32>,
}

const MAGIC: &str = "lucent-state 2";
const BEAUTY_BYTES: usize = 3 * 16 + 4;
const AOV_BYTES: usize = 7 * 16 + 4;
const NOISE_BYTES: usize = 2 * 8 + 1;

impl StateHeader {
    /// The bytes of one pixel's data.
    fn pixel_bytes(&self) -> usize {
        BEAUTY_BYTES
            + if self.aovs { AOV_BYTES } else { 0 }
            + if self.noise_threshold.is_some() { NOISE_BYTES } else { 0 }
    }
}

impl RenderState {
    pub fn encode(&self) -> Vec<u8> {
        let h = &self.header;
        let p = h.pixels;
        let mut out = format!(
            "{MAGIC}\nscene {:016x}\nname {}\nresolution {} {}\npixels {} {} {} {}\nspp {}\nsamples {} {}\nseed {}\nsampler {}\npixelsampling {}\ngamma {:08x}\naovs {}\nnoisethreshold {}\ndata\n",
            h.scene_hash,
            // (One line, and no CR at its end for a reader to take for a CR LF.)
            h.scene_name.replace(['\n', '\r'], " "),
            h.resolution.0,
            h.resolution.1,
            p.x0,
            p.x1,
            p.y0,
            p.y1,
            h.spp,
            h.samples.start,
            h.samples.end,
            h.seed,
            h.sampler,
            h.pixel_sampling,
            h.gamma.to_bits(),
            if h.aovs { "yes" } else { "no" },
            h.noise_threshold.map_or("none".to_string(), |t| format!("{:08x}", t.to_bits()))
        )
        .into_bytes();
        let start = out.len();
        let f = &self.film;
        assert_eq!(
            f.aovs.is_some(),
            h.aovs,
            "a film whose passes its header does not describe"
        );
        assert_eq!(
            f.noise.is_some(),
            h.noise_threshold.is_some(),
            "a film whose sampling its header does not describe"
        );
        out.reserve(f.counts.len() * h.pixel_bytes() + 8);
        for k in 0..f.counts.len() {
            for v in f.sum(k).0 {
                out.extend(v.to_le_bytes());
            }
            out.extend(f.counts[k].to_le_bytes());
            if let Some(aovs) = &f.aovs {
                let a = &aovs[k];
                for v in a.albedo.0.iter().chain(&a.normal.0).chain([&a.depth]) {
                    out.extend(v.to_le_bytes());
                }
                out.extend(a.hits.to_le_bytes());
            }
            if let Some(noise) = &f.noise {
                let p = &noise[k];
                out.extend(p.sum.to_bits().to_le_bytes());
                out.extend(p.sum_sq.to_bits().to_le_bytes());
                out.push(p.stopped as u8);
            }
        }
        let sum = fnv1a(&out[start..], FNV_START);
        out.extend(sum.to_le_bytes());
        out
    }

    /// Reads a state file's bytes; the error says what is wrong with them.
    pub fn decode(bytes: &[u8]) -> Result<RenderState, String> {
        let mut pos = 0;
        let mut line = || -> Result<&str, String> {
            let rest = &bytes[pos..];
            let end = rest
                .iter()
                .take(200)
                .position(|&b| b == b'\n')
                .ok_or("not a lucent state file (its header is cut short)")?;
            pos += end + 1;
            // (A header whose lines end in CR LF, converted by some tool: read, so that
            // its converted data is named as damaged rather than its version unknown.)
            let text = rest[..end].strip_suffix(b"\r").unwrap_or(&rest[..end]);
            std::str::from_utf8(text).map_err(|_| "not a lucent state file (its header is not text)".to_string())
        };
        let not_state = || format!("not a lucent state file (it does not start with '{MAGIC}')");
        // (Checked first, so that any other file is named for what it is not, not for a
        // header it never had.)
        let kind = "lucent-state ".as_bytes();
        if bytes.is_empty() || !bytes.starts_with(&kind[..bytes.len().min(kind.len())]) {
            return Err(not_state());
        }
        match line()? {
            MAGIC => {}
            l if l.starts_with("lucent-state ") => {
                return Err(format!(
                    "a state file of another version of lucent ('{l}'; this one reads '{MAGIC}')"
                ))
            }
            _ => return Err(not_state()),
        }
        // `count` values after the key; `usize::MAX`: the rest of the line as one value.
        let mut field = |key: &str, count: usize| -> Result<Vec<String>, String> {
            let l = line()?;
            if count == usize::MAX {
                let rest = l.strip_prefix(key).and_then(|r| r.strip_prefix(' '));
                return rest
                    .map(|r| vec![r.to_string()])
                    .ok_or_else(|| format!("the header has '{l}' where '{key}' belongs"));
            }
            let mut words = l.split(' ');
            if words.next() != Some(key) {
                return Err(format!("the header has '{l}' where '{key}' belongs"));
            }
            let values: Vec<String> = words.map(str::to_string).collect();
            if values.len() != count {
                return Err(format!("the header's '{key}' has {} values, not {count}", values.len()));
            }
            Ok(values)
        };
        let num = |s: &str, what: &str| {
            s.parse::<u64>()
                .map_err(|_| format!("the header's {what} '{s}' is not a number"))
        };
        let small = |s: &str, what: &str| {
            s.parse::<u32>()
                .map_err(|_| format!("the header's {what} '{s}' is not a number"))
        };
        let scene = field("scene", 1)?;
        let scene_hash =
            u64::from_str_radix(&scene[0], 16).map_err(|_| "the header's scene hash is not hexadecimal")?;
        let scene_name = field("name", usize::MAX)?.remove(0);
        let r = field("resolution", 2)?;
        let resolution = (small(&r[0], "width")?, small(&r[1], "height")?);
        let p = field("pixels", 4)?;
        let pixels = PixelRect {
            x0: small(&p[0], "x0")?,
            x1: small(&p[1], "x1")?,
            y0: small(&p[2], "y0")?,
            y1: small(&p[3], "y1")?,
        };
        let spp = small(&field("spp", 1)?[0], "spp")?;
        let s = field("samples", 2)?;
        let samples = small(&s[0], "first sample")?..small(&s[1], "sample end")?;
        let seed = num(&field("seed", 1)?[0], "seed")?;
        let sampler = field("sampler", 1)?.remove(0);
        if !SamplerKind::ALL.iter().any(|(name, _)| *name == sampler) {
            return Err(format!("the header's sampler '{sampler}' is not one lucent has"));
        }
        let pixel_sampling = field("pixelsampling", 1)?.remove(0);
        if !["uniform", "stratified"].contains(&pixel_sampling.as_str()) {
            return Err(format!(
                "the header's pixelsampling '{pixel_sampling}' is not uniform or stratified"
            ));
        }
        let g = field("gamma", 1)?;
        let gamma =
            f32::from_bits(u32::from_str_radix(&g[0], 16).map_err(|_| "the header's gamma is not hexadecimal")?);
        let aovs = match field("aovs", 1)?[0].as_str() {
            "yes" => true,
            "no" => false,
            other => return Err(format!("the header's aovs '{other}' is not yes or no")),
        };
        let noise_threshold = match field("noisethreshold", 1)?.remove(0) {
            t if t == "none" => None,
            t => Some(f32::from_bits(
                u32::from_str_radix(&t, 16).map_err(|_| "the header's noise threshold is not hexadecimal")?,
            )),
        };
        field("data", 0)?;
        if !(pixels.x0 < pixels.x1 && pixels.y0 < pixels.y1 && pixels.x1 <= resolution.0 && pixels.y1 <= resolution.1) {
            return Err("the header's pixels are not a rectangle inside its resolution".into());
        }
        if !(samples.start < samples.end && samples.end <= spp) {
            return Err("the header's samples are not a range within its spp".into());
        }
        // (As the scene and the command line take them.)
        if resolution.0 as u64 * resolution.1 as u64 > MAX_PIXELS {
            return Err(format!(
                "the header's resolution {} x {} is more than lucent renders",
                resolution.0, resolution.1
            ));
        }
        // (As the scene's `gamma` command: no subnormal value, which no scene gives.)
        if !(gamma > 0.0 && gamma.is_normal()) {
            return Err(format!("the header's gamma {gamma} is not a number > 0"));
        }
        if let Some(t) = noise_threshold.filter(|t| !(*t >= 0.0 && t.is_finite())) {
            return Err(format!("the header's noise threshold {t} is not a number >= 0"));
        }
        let header = StateHeader {
            scene_hash,
            scene_name,
            resolution,
            pixels,
            spp,
            samples,
            seed,
            sampler,
            pixel_sampling,
            gamma,
            aovs,
            noise_threshold,
        };
        let n = pixels.pixels() as usize;
        let size = header.pixel_bytes();
        let data = &bytes[pos..];
        let needed = n.checked_mul(size).and_then(|b| b.checked_add(8));
        if needed != Some(data.len()) {
            return Err(format!(
                "{} bytes of pixel data where {} pixels need {} (a file cut short?)",
                data.len(),
                n,
                needed.map_or("more than any file holds".to_string(), |b| b.to_string())
            ));
        }
        let (body, check) = data.split_at(n * size);
        if fnv1a(body, FNV_START).to_le_bytes() != check {
            return Err("its pixel data does not match its checksum (a damaged file)".into());
        }
        let mut film = Film::with_aovs(pixels.width(), pixels.height(), aovs);
        if noise_threshold.is_some() {
            film.noise = Some(vec![PixelNoise::default(); n]);
        }
        let damaged = || "its pixel data is not what a state file holds (a damaged file)".to_string();
        for (k, px) in body.chunks_exact(size).enumerate() {
            let i = |j: usize| i128::from_le_bytes(px[16 * j..16 * j + 16].try_into().unwrap());
            let u = |at: usize| u32::from_le_bytes(px[at..at + 4].try_into().unwrap());
            let (sum, count) = (ExactSum([i(0), i(1), i(2)]), u(48));
            // What no render makes: other than every sample of the file's range (fewer
            // only where adaptive sampling stopped the pixel), or a sum beyond what its
            // samples can add up to (each is clamped: ExactSum).
            let all = header.samples.len() as u32;
            let adaptive = header.noise_threshold.is_some();
            if count > all || (count < all && !adaptive) || !sum.within(count) {
                return Err(damaged());
            }
            film.sums_mut()[k] = sum;
            film.counts[k] = count;
            let mut at = BEAUTY_BYTES;
            if let Some(aovs) = &mut film.aovs {
                let a = &px[at..];
                let i = |j: usize| i128::from_le_bytes(a[16 * j..16 * j + 16].try_into().unwrap());
                aovs[k] = AovSum {
                    albedo: ExactSum([i(0), i(1), i(2)]),
                    normal: ExactSum([i(3), i(4), i(5)]),
                    depth: i(6),
                    hits: u(at + 112),
                };
                let a = &aovs[k];
                if a.hits > count
                    || !a.albedo.within(count)
                    || !a.normal.within(count)
                    || !ExactSum([a.depth, 0, 0]).within(a.hits)
                {
                    return Err(damaged());
                }
                at += AOV_BYTES;
            }
            if let Some(noise) = &mut film.noise {
                let f = |at: usize| f64::from_bits(u64::from_le_bytes(px[at..at + 8].try_into().unwrap()));
                noise[k] = PixelNoise {
                    sum: f(at),
                    sum_sq: f(at + 8),
                    stopped: match px[at + 16] {
                        0 => false,
                        1 => true,
                        _ => return Err(damaged()),
                    },
                };
                if !(noise[k].sum.is_finite() && noise[k].sum_sq >= 0.0 && noise[k].sum_sq.is_finite()) {
                    return Err(damaged());
                }
            }
        }
        Ok(RenderState { header, film })
    }
}

/// Reads the state file at `path` (a regular file, as [`read_input`] takes it) and takes
/// its memory from `budget`: the file's bytes while they are decoded, and the film they
/// become, which stays taken ([`RenderState::film_bytes`] gives it back). A film takes at
/// most 1.5 times its bytes in the file (a pixel's noise estimate, 17 bytes there, is 24
/// in memory; everything else about the same), so that much is taken before reading.
pub fn read_state(path: &Path, budget: &mut Budget, inputs: &mut Inputs) -> Result<RenderState, String> {
    let size = std::fs::metadata(path).map_err(|e| io_reason(&e))?.len();
    let taken = size.saturating_add(size / 2 * 3 + 2);
    budget.take(taken, "the state file and its film")?;
    // (Held to the size just looked at: a file that grew since is refused.)
    let state = read_input(path, size, inputs).and_then(|bytes| RenderState::decode(&bytes));
    let kept = state.as_ref().map_or(0, |s| s.film_bytes().min(taken));
    budget.give_back(taken - kept);
    state
}

impl RenderState {
    /// The memory its film takes (what [`read_state`] keeps taken).
    pub fn film_bytes(&self) -> u64 {
        let f = &self.film;
        Film::bytes(f.counts.len() as u64, false, f.aovs.is_some(), f.noise.is_some())
    }
}

/// What an image made from this state says about itself (PNG text): the scene (its name
/// and hash) and everything that decides its pixels — the same for a render made in one
/// go and one merged from parts, and it records where a region belongs.
pub fn describe_render(h: &StateHeader) -> String {
    let p = h.pixels;
    format!(
        "scene {} (hash {:016x}), {} x {} image, pixels {}..{} x {}..{}, samples {}..{} of {} per pixel, seed {}, sampler {}, gamma {}",
        h.scene_name,
        h.scene_hash,
        h.resolution.0,
        h.resolution.1,
        p.x0,
        p.x1,
        p.y0,
        p.y1,
        h.samples.start,
        h.samples.end.saturating_sub(1),
        h.spp,
        h.seed,
        h.sampler,
        h.gamma
    )
}

impl StateHeader {
    /// What differs between the renders two headers describe, apart from their pixels
    /// and sample ranges (and their spp unless `same_spp`): `None` when they are parts
    /// of one render.
    pub fn difference(&self, other: &StateHeader, same_spp: bool) -> Option<&'static str> {
        let differs = [
            (self.scene_hash != other.scene_hash, "scene"),
            (self.resolution != other.resolution, "resolution"),
            (same_spp && self.spp != other.spp, "samples per pixel"),
            (self.seed != other.seed, "seed"),
            (self.sampler != other.sampler, "sampler"),
            (
                self.pixel_sampling != other.pixel_sampling,
                "integrator's pixel sampling",
            ),
            (self.gamma.to_bits() != other.gamma.to_bits(), "gamma"),
            (self.aovs != other.aovs, "set of passes (AOVs)"),
            (
                self.noise_threshold.map(f32::to_bits) != other.noise_threshold.map(f32::to_bits),
                "noise threshold",
            ),
        ];
        differs.iter().find(|(d, _)| *d).map(|(_, what)| *what)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use lucent_core::math::Color;

    pub(super) fn state(pixels: PixelRect, samples: Range<u32>) -> RenderState {
        let mut film = Film::new(pixels.width(), pixels.height());
        for (k, s) in film.sums_mut().iter_mut().enumerate() {
            for i in samples.clone() {
                s.add_sample(Color::splat((k as f32 + 1.0) * 0.1 + i as f32 * 0.01));
            }
        }
        film.counts.iter_mut().for_each(|c| *c = samples.len() as u32);
        RenderState {
            header: StateHeader {
                scene_hash: 0xabc,
                scene_name: "a scene.test".into(),
                resolution: (8, 4),
                pixels,
                spp: 16,
                samples,
                seed: 3,
                sampler: "sobol".into(),
                pixel_sampling: "uniform".into(),
                gamma: 2.2,
                aovs: false,
                noise_threshold: None,
            },
            film,
        }
    }

    pub(super) fn rect(x0: u32, x1: u32, y0: u32, y1: u32) -> PixelRect {
        PixelRect { x0, x1, y0, y1 }
    }

    #[test]
    fn states_survive_a_round_trip_and_refuse_damage() {
        let s = state(rect(1, 5, 0, 3), 2..9);
        let bytes = s.encode();
        assert_eq!(RenderState::decode(&bytes).unwrap(), s);
        let mut bad = bytes.clone();
        let n = bad.len();
        bad[n - 20] ^= 1;
        assert!(RenderState::decode(&bad).unwrap_err().contains("checksum"));
        assert!(RenderState::decode(&bytes[..n - 1]).unwrap_err().contains("cut short"));
        assert!(RenderState::decode(b"P6\n")
            .unwrap_err()
            .contains("not a lucent state file"));
        assert!(RenderState::decode(b"lucent-state 1\n")
            .unwrap_err()
            .contains("another version"));
        // Any other file is named for what it is not, whatever its length or lines.
        for other in [&[0u8; 4096][..], b"", b"lucent.state", &[b'x'; 300][..]] {
            let e = RenderState::decode(other).unwrap_err();
            assert!(e.contains("does not start with"), "{e}");
        }
        // A state file's first bytes alone are one cut short.
        assert!(RenderState::decode(b"lucent-sta").unwrap_err().contains("cut short"));
    }

    #[test]
    fn states_no_render_makes_are_refused() {
        // Checksums are right: these are what a tool, not a damaged disk, would write.
        let mut s = state(rect(0, 2, 0, 2), 4..8);
        s.film.counts[1] = 5;
        let e = RenderState::decode(&s.encode()).unwrap_err();
        assert!(e.contains("not what a state file holds"), "{e}");
        // Fewer samples than the range, where no adaptive sampling stopped the pixel.
        let mut s = state(rect(0, 2, 0, 2), 4..8);
        s.film.counts[2] = 3;
        let e = RenderState::decode(&s.encode()).unwrap_err();
        assert!(e.contains("not what a state file holds"), "{e}");
        let mut s = state(rect(0, 2, 0, 2), 4..8);
        s.header.resolution = (u32::MAX, u32::MAX);
        let e = RenderState::decode(&s.encode()).unwrap_err();
        assert!(e.contains("more than lucent renders"), "{e}");
        let mut s = state(rect(0, 2, 0, 2), 4..8);
        s.film.sums_mut()[3].0[2] = i128::MAX;
        let e = RenderState::decode(&s.encode()).unwrap_err();
        assert!(e.contains("not what a state file holds"), "{e}");
        for gamma in [0.0, -1.0, f32::NAN, f32::INFINITY, 1e-40] {
            let mut s = state(rect(0, 2, 0, 2), 4..8);
            s.header.gamma = gamma;
            let e = RenderState::decode(&s.encode()).unwrap_err();
            assert!(e.contains("gamma"), "{e}");
        }
        let mut s = state(rect(0, 2, 0, 2), 4..8);
        s.header.noise_threshold = Some(f32::NAN);
        s.film.noise = Some(vec![PixelNoise::default(); 4]);
        assert!(RenderState::decode(&s.encode())
            .unwrap_err()
            .contains("noise threshold"));
        s.header.noise_threshold = Some(0.1);
        s.film.noise.as_mut().unwrap()[2].sum = f64::NAN;
        assert!(RenderState::decode(&s.encode())
            .unwrap_err()
            .contains("not what a state file holds"));
        let mut s = state(rect(0, 2, 0, 2), 4..8);
        s.header.sampler = "s%bol".into();
        assert!(RenderState::decode(&s.encode()).unwrap_err().contains("sampler"));
        let mut s = state(rect(0, 2, 0, 2), 4..8);
        s.header.pixel_sampling = "unifrom".into();
        assert!(RenderState::decode(&s.encode()).unwrap_err().contains("pixelsampling"));
        // At the clamp in every sample: still a state.
        let mut s = state(rect(0, 2, 0, 2), 4..8);
        s.film.sums_mut()[0] = ExactSum([4 * (1i128 << 104), -4 * (1i128 << 104), 0]);
        assert_eq!(RenderState::decode(&s.encode()).unwrap(), s);
    }

    #[test]
    fn auxiliary_passes_and_adaptive_estimates_survive_a_round_trip() {
        let mut s = state(rect(0, 3, 1, 3), 0..16);
        s.header.aovs = true;
        s.header.noise_threshold = Some(0.05);
        let n = s.film.counts.len();
        s.film.aovs = Some(
            (0..n)
                .map(|k| {
                    let mut a = AovSum::default();
                    a.add_sample(&lucent_core::film::AovSample {
                        albedo: Color::splat(0.1 * k as f32),
                        normal: lucent_core::math::Vec3A::new(0.0, -1.0, 0.0),
                        depth: (k % 2 == 0).then_some(2.5 + k as f32),
                    });
                    a
                })
                .collect(),
        );
        s.film.noise = Some(
            (0..n)
                .map(|k| PixelNoise {
                    sum: k as f64 / 3.0,
                    sum_sq: k as f64 / 7.0,
                    stopped: k % 3 == 0,
                })
                .collect(),
        );
        let back = RenderState::decode(&s.encode()).unwrap();
        assert_eq!(back, s);
        // Parts of an adaptive render that share pixels do not merge.
        let mut a = state(rect(0, 4, 0, 4), 0..8);
        let mut b = state(rect(0, 4, 0, 4), 8..16);
        for p in [&mut a, &mut b] {
            p.header.noise_threshold = Some(0.05);
            p.film.noise = Some(vec![PixelNoise::default(); 16]);
        }
        let names = ["a".to_string(), "b".to_string()];
        assert!(merge(&[a, b], &names).unwrap_err().contains("--resume"));
    }
}
