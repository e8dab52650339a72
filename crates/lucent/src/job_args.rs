//! The part of a render the command line picks: `--crop x0 x1 y0 y1` (fractions of the
//! image, pbrt's cropwindow), `--pixel-bounds x0 x1 y0 y1` (pixels, ends exclusive),
//! `--samples FIRST..LAST` (inclusive, like Blender's frame ranges), `--seed N`, and
//! `--resume STATE` (what an earlier render left to do).

use lucent_core::render::job::{PixelRect, RenderJob};
use lucent_io::resources::{Budget, Inputs};
use lucent_io::state::{read_state, RenderState, StateHeader};

/// `--samples FIRST..LAST`: the inclusive range as `FIRST..LAST+1`.
pub fn parse_samples(s: &str) -> Result<std::ops::Range<u32>, String> {
    let (a, b) = s
        .split_once("..")
        .ok_or_else(|| format!("'{s}' is not a range FIRST..LAST (e.g. 0..63: the first 64 samples)"))?;
    let num = |v: &str| {
        v.trim()
            .parse::<u32>()
            .map_err(|_| format!("'{v}' in '{s}' is not a sample index (a whole number ≥ 0)"))
    };
    let (a, b) = (num(a)?, num(b)?);
    if b < a {
        return Err(format!("'{s}' ends before it starts"));
    }
    b.checked_add(1)
        .map(|end| a..end)
        .ok_or_else(|| format!("'{s}' goes past the largest sample index"))
}

/// The pixels of `--crop` (pbrt's rule: the fractions times the resolution, rounded up)
/// or `--pixel-bounds` within a `width × height` image.
pub fn pixel_rect(
    crop: Option<&[f64]>,
    bounds: Option<&[u32]>,
    width: u32,
    height: u32,
) -> Result<Option<PixelRect>, String> {
    let rect = match (crop, bounds) {
        (Some(c), _) => {
            if let Some(v) = c.iter().find(|v| !(0.0..=1.0).contains(*v)) {
                return Err(format!("--crop: {v} is not a fraction between 0 and 1"));
            }
            let at = |f: f64, n: u32| (f * n as f64).ceil() as u32;
            PixelRect {
                x0: at(c[0], width),
                x1: at(c[1], width),
                y0: at(c[2], height),
                y1: at(c[3], height),
            }
        }
        (None, Some(b)) => PixelRect {
            x0: b[0],
            x1: b[1],
            y0: b[2],
            y1: b[3],
        },
        (None, None) => return Ok(None),
    };
    let what = if crop.is_some() { "--crop" } else { "--pixel-bounds" };
    if !(rect.x0 < rect.x1 && rect.y0 < rect.y1 && rect.x1 <= width && rect.y1 <= height) {
        return Err(format!(
            "{what}: pixels {}..{} x {}..{} are not a non-empty rectangle inside the {width} x {height} image",
            rect.x0, rect.x1, rect.y0, rect.y1
        ));
    }
    Ok(Some(rect))
}

/// Applies `--samples` to the job: the range must lie within `0..spp`.
pub fn apply_samples(job: &mut RenderJob, samples: &std::ops::Range<u32>) -> Result<(), String> {
    if samples.end > job.spp {
        return Err(format!(
            "--samples {}..{}: the render has {} samples per pixel (indices 0..{})",
            samples.start,
            samples.end - 1,
            job.spp,
            job.spp - 1
        ));
    }
    job.samples = samples.clone();
    Ok(())
}

/// Reads the state to continue and points `job` at what is left: its pixels, the sample
/// indices from its end to `job.spp`. The state must be of this scene and these options,
/// from an integrator whose samples do not depend on the total (the Monte Carlo ones).
/// The state's film is taken from `budget` (and stays taken).
pub fn resume(
    path: &std::path::Path,
    job: &mut RenderJob,
    now: &StateHeader,
    budget: &mut Budget,
) -> Result<RenderState, String> {
    let state = read_state(path, budget, &mut Inputs::default())?;
    let h = &state.header;
    // The passes the state keeps are continued whether or not they are asked for again.
    if job.aovs && !h.aovs {
        return Err("it keeps no auxiliary passes, which --aov and --denoise need (render it with --aov or --denoise to keep them)".into());
    }
    job.aovs = h.aovs;
    let now = StateHeader {
        aovs: h.aovs,
        ..now.clone()
    };
    if let Some(what) = h.difference(&now, false) {
        let why = match what {
            "scene" => "the scene's text (or its -D, --size or --maxdepth overrides) has changed".to_string(),
            _ => format!("the {what} differs"),
        };
        return Err(format!("it is not a render of this scene with these options: {why}"));
    }
    if h.pixel_sampling != "uniform" || h.spp < 2 || now.pixel_sampling != "uniform" {
        return Err("only renders of the Monte Carlo integrators (direct, pathtracer) with spp 2 or more can be continued: the ray tracer places its samples on a grid that depends on spp, and spp 1 is the pixel centre".into());
    }
    if h.samples.end == u32::MAX {
        return Err(format!(
            "it already holds samples {}..{}, the most a pixel can have",
            h.samples.start,
            h.samples.end - 1
        ));
    }
    if job.spp <= h.samples.end {
        return Err(format!(
            "it already holds samples {}..{}; ask for more with --spp (above {})",
            h.samples.start,
            h.samples.end - 1,
            h.samples.end
        ));
    }
    job.pixels = h.pixels;
    job.samples = h.samples.end..job.spp;
    Ok(state)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sample_ranges_are_inclusive_and_checked() {
        assert_eq!(parse_samples("0..63"), Ok(0..64));
        assert_eq!(parse_samples("64..64"), Ok(64..65));
        assert!(parse_samples("5..2").unwrap_err().contains("ends before"));
        assert!(parse_samples("a..2").unwrap_err().contains("not a sample index"));
        assert!(parse_samples("7").unwrap_err().contains("not a range"));
    }

    #[test]
    fn crops_round_up_as_pbrt_does() {
        let r = pixel_rect(Some(&[0.0, 0.5, 0.25, 1.0]), None, 101, 10)
            .unwrap()
            .unwrap();
        assert_eq!((r.x0, r.x1, r.y0, r.y1), (0, 51, 3, 10));
        assert!(pixel_rect(Some(&[0.5, 0.5, 0.0, 1.0]), None, 10, 10).is_err());
        assert!(pixel_rect(None, Some(&[0, 11, 0, 1]), 10, 10).is_err());
        assert_eq!(pixel_rect(None, None, 10, 10), Ok(None));
    }
}
