//! `lucent diff A B`: how two images differ — pixels differing by more than a threshold in
//! any channel, and the mean absolute error on the 0–255 scale. With `--max-pixels` or
//! `--max-mae` it exits with 1 when the difference is larger (for scripts).
//!
//! `lucent diff --noise A.exr B.exr`: whether two Monte Carlo renders of one scene agree
//! within their noise in linear radiance (regions of 8 × 6, z-scores of the mean
//! difference; exit 1 beyond `--max-z`, default 5).

use std::path::PathBuf;

use clap::Args;
use lucent_io::image::{agreement, diff, read_rgb8, read_rgb_f32};

use crate::EXIT_BAD_INPUT;

#[derive(Args)]
pub struct DiffArgs {
    pub a: PathBuf,
    pub b: PathBuf,
    /// A pixel differs when a channel differs by more than this (0–255).
    #[arg(long, default_value_t = 2)]
    pub threshold: u8,
    /// Fail when more pixels than this differ.
    #[arg(long)]
    pub max_pixels: Option<usize>,
    /// Fail when the mean absolute error is this or more (a number ≥ 0).
    #[arg(long, value_parser = non_negative)]
    pub max_mae: Option<f64>,
    /// Compare two Monte Carlo renders (EXR or HDR) statistically, in linear radiance.
    #[arg(long)]
    pub noise: bool,
    /// With --noise: fail when a region's mean difference is more than this many of its
    /// standard errors (48 regions × 3 channels: at 5, a false alarm about once in
    /// 10,000 comparisons of agreeing renders).
    #[arg(long, default_value_t = 5.0, value_parser = non_negative)]
    pub max_z: f64,
}

/// A finite number ≥ 0: `nan` would let every pair of images pass.
fn non_negative(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(x) if x.is_finite() && x >= 0.0 => Ok(x),
        _ => Err(format!("'{s}' is not a number ≥ 0")),
    }
}

pub fn run(args: &DiffArgs) -> u8 {
    if args.noise {
        return run_noise(args);
    }
    let read = |p: &std::path::Path| read_rgb8(p).map_err(|e| format!("cannot read {}: {e}", p.display()));
    let (a, b) = match (read(&args.a), read(&args.b)) {
        (Ok(a), Ok(b)) => (a, b),
        (Err(e), _) | (_, Err(e)) => {
            errln!("lucent: error: {e}");
            return EXIT_BAD_INPUT;
        }
    };
    let Some(d) = diff(&a, &b, args.threshold) else {
        errln!(
            "lucent: error: the images differ in size: {}x{} and {}x{}",
            a.width,
            a.height,
            b.width,
            b.height
        );
        return EXIT_BAD_INPUT;
    };
    outln!(
        "pixels_over={} pixels={} threshold={} mae={:.4} max={}",
        d.pixels_over,
        d.pixels,
        args.threshold,
        d.mean_abs_error,
        d.max_abs_error
    );
    let too_many = args.max_pixels.is_some_and(|m| d.pixels_over > m);
    let too_far = args.max_mae.is_some_and(|m| d.mean_abs_error >= m);
    if too_many || too_far {
        1
    } else {
        0
    }
}

fn run_noise(args: &DiffArgs) -> u8 {
    let read = |p: &std::path::Path| read_rgb_f32(p).map_err(|e| format!("cannot read {}: {e}", p.display()));
    let (a, b) = match (read(&args.a), read(&args.b)) {
        (Ok(a), Ok(b)) => (a, b),
        (Err(e), _) | (_, Err(e)) => {
            errln!("lucent: error: {e}");
            return EXIT_BAD_INPUT;
        }
    };
    let Some(g) = agreement(&a, &b, 8, 6) else {
        errln!(
            "lucent: error: the images differ in size or are too small: {}x{} and {}x{}",
            a.width,
            a.height,
            b.width,
            b.height
        );
        return EXIT_BAD_INPUT;
    };
    let (x, y, c) = g.worst_at;
    outln!(
        "mean_ratio={:.4} whole_z={:+.2} worst_region_z={:+.2} at col {x} row {y} channel {}",
        g.mean_ratio,
        g.whole_z,
        g.worst_z,
        ["R", "G", "B"][c]
    );
    if g.worst_z.abs() > args.max_z || g.whole_z.abs() > args.max_z || g.worst_z.is_nan() {
        1
    } else {
        0
    }
}
