//! The options of `lucent render` (and of `lucent plan`, which plans that render), their
//! parsers, and the command that continues a render from its partial state with the
//! same options.

use std::path::{Path, PathBuf};

use clap::Args;
use lucent_core::accel::AccelKind;
use lucent_core::render::plan::Cut;

use crate::aov_args::{parse_aovs, AovSelection, AOV_NAMES};
use crate::job_args::parse_samples;

#[derive(Args)]
pub struct RenderArgs {
    /// The scene files (CSE167/CSE168 format), rendered one after the other; `-` reads
    /// a scene from standard input (its file names are relative to the current folder).
    #[arg(required = true, value_name = "SCENE")]
    pub scenes: Vec<PathBuf>,
    /// Output image (`-` for standard output); default: the scene's `output` command,
    /// else raytrace.png (with several scenes: SCENE.png beside each).
    #[arg(short, long, value_name = "OUT.png")]
    pub output: Option<PathBuf>,
    /// Threads for the build and the render (default: all cores; with 1, one core: the
    /// build runs on the main thread, the render on one worker). The image is the same
    /// for any count.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub threads: Option<u32>,
    /// Samples per pixel, instead of the scene's `spp` (as pbrt's --spp).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..))]
    pub spp: Option<u32>,
    /// The source of random numbers, instead of the scene's `sampler` (default: sobol
    /// for the Monte Carlo integrators, independent for the others).
    #[arg(long, value_parser = clap::builder::PossibleValuesParser::new(["independent", "sobol"]))]
    pub sampler: Option<String>,
    /// Adaptive sampling: stop a pixel once the estimated relative error of its mean
    /// (luminance) is below T, after at least 16 samples; the scene's `spp` (or `--spp`)
    /// stays the cap. Instead of the scene's `noisethreshold`; 0 turns it off.
    #[arg(long, value_name = "T", value_parser = parse_threshold)]
    pub noise_threshold: Option<f32>,
    /// Also write the number of samples each pixel took: EXR/HDR with the counts,
    /// PNG with count / spp.
    #[arg(long, value_name = "FILE")]
    pub spp_map: Option<PathBuf>,
    /// Render only this part of the image, as fractions of its width and height (pbrt's
    /// cropwindow; pixel edges are the fractions times the size, rounded up). The output
    /// holds the region alone.
    #[arg(long, num_args = 4, value_names = ["X0", "X1", "Y0", "Y1"], conflicts_with = "pixel_bounds")]
    pub crop: Option<Vec<f64>>,
    /// Render only these pixels: columns X0..X1 and rows Y0..Y1, ends exclusive (row 0 at
    /// the top).
    #[arg(long, num_args = 4, value_names = ["X0", "X1", "Y0", "Y1"])]
    pub pixel_bounds: Option<Vec<u32>>,
    /// Take only these sample indices in every pixel, both ends included (0..63: the
    /// first 64); renders of several ranges merge into the whole (`lucent merge`).
    #[arg(long, value_name = "FIRST..LAST", value_parser = parse_samples)]
    pub samples: Option<std::ops::Range<u32>>,
    /// Another set of random numbers (the same seed gives the same bytes); default 0.
    #[arg(long, value_name = "N")]
    pub seed: Option<u64>,
    /// Also write the render's state (exact sample sums and counts, with the scene's
    /// hash and the options) for `lucent merge` and `--resume`.
    #[arg(long, value_name = "OUT.lstate")]
    pub state: Option<PathBuf>,
    /// Render task I (from 0) of the N that `lucent plan --tasks N` (with the same --by
    /// and options) cuts the render into, into the state file of --state; `lucent
    /// merge` puts the N states together.
    #[arg(long, value_name = "I/N", value_parser = crate::plan::parse_task, conflicts_with_all = ["crop", "pixel_bounds", "samples", "resume"], requires = "state")]
    pub task: Option<(u32, u32)>,
    /// The plan `lucent plan --json` wrote, for --task: its task I is rendered (the
    /// plan must be of this render: its size and spp).
    #[arg(long, value_name = "PLAN.json", requires = "task")]
    pub plan: Option<PathBuf>,
    /// How --task (and `lucent plan`) cut the render: bands of rows (tiles), sample
    /// ranges, or auto (sample ranges for the Monte Carlo integrators, else tiles).
    #[arg(long, default_value = "auto", value_parser = clap::builder::PossibleValuesParser::new(Cut::NAMES))]
    pub by: String,
    /// Continue the render a state file holds, up to `--spp` (or the scene's spp)
    /// samples per pixel: the same pixels, the sample indices after its last.
    #[arg(long, value_name = "STATE", conflicts_with_all = ["crop", "pixel_bounds", "samples"])]
    pub resume: Option<PathBuf>,
    /// Every SECS seconds, write the image of the samples done so far and a state to
    /// resume from (OUT.partial.png and OUT.partial.lstate, or --state), each whole or
    /// not at all; they are removed when the render completes.
    #[arg(long, value_name = "SECS", value_parser = parse_seconds)]
    pub checkpoint: Option<f64>,
    /// Also write these auxiliary passes of the first surface each sample sees: as layers
    /// of the EXR output (albedo.R/G/B, normal.X/Y/Z, depth.Z, alpha as A), or beside a
    /// PNG/JPEG/HDR output in OUT.aovs.exr.
    #[arg(long, value_name = "albedo,normal,depth,alpha", value_parser = parse_aovs)]
    pub aov: Option<AovSelection>,
    /// Denoise the colour with Intel Open Image Denoise, guided by the albedo and normal
    /// passes (the library is loaded at run time: scripts/install_oidn.sh installs it, or
    /// set OIDN_LIB). An EXR output keeps the colour before denoising as noisy.R/G/B.
    #[arg(long)]
    pub denoise: bool,
    /// Override a scene setting, as Mitsuba's -D: `-D spp=64`, `-D integrator=pathtracer`,
    /// `-D size=320,240` (commas or spaces between values); repeatable, the last wins.
    #[arg(short = 'D', value_name = "NAME=VALUE", action = clap::ArgAction::Append)]
    pub define: Vec<String>,
    /// The image size, instead of the scene's `size` (the camera's view is the same).
    #[arg(long, num_args = 2, value_names = ["W", "H"])]
    pub size: Option<Vec<String>>,
    /// The scene's `maxdepth` (-1: unbounded, with Russian roulette).
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub maxdepth: Option<String>,
    /// A quick preview: half the size, at most 4 samples per pixel and 3 bounces.
    #[arg(long)]
    pub quick: bool,
    /// Acceleration structure.
    #[arg(long, default_value = "bvh", value_parser = clap::builder::PossibleValuesParser::new(AccelKind::NAMES))]
    pub accel: String,
    /// Treat unknown commands as errors.
    #[arg(long)]
    pub strict: bool,
    /// The memory the scene may take (e.g. 4G, 512M); default: 3/4 of the machine's.
    #[arg(long, value_name = "SIZE", value_parser = parse_size)]
    pub memory_limit: Option<u64>,
    /// No progress bar and no summary line (warnings and errors are still printed).
    #[arg(short, long)]
    pub quiet: bool,
    /// Print the time of each phase (parse, build, render, write).
    #[arg(long)]
    pub stats: bool,
}

/// `--noise-threshold`: a finite number ≥ 0.
fn parse_threshold(s: &str) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(t) if t >= 0.0 && t.is_finite() => Ok(t),
        _ => Err(format!("'{s}' is not a number >= 0")),
    }
}

/// `--checkpoint`: seconds, a number > 0 and at most 10⁹ (some 30 years).
fn parse_seconds(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v > 0.0 && v <= 1e9 => Ok(v),
        _ => Err(format!("'{s}' is not a number of seconds > 0 (and at most 1e9)")),
    }
}

/// `--memory-limit`: a size as people write it (`4G`, `512MiB`, bytes).
pub fn parse_size(s: &str) -> Result<u64, String> {
    lucent_io::resources::budget::parse_size(s)
}

/// The command that continues this render from `state`: the scene and every option
/// that decides its samples and outputs, as given, then `--resume`.
pub fn resume_command(args: &RenderArgs, scene: &Path, state: &str) -> String {
    // Quoted for a POSIX shell where a word needs it.
    let quote = |w: &str| {
        let plain = !w.is_empty() && w.chars().all(|c| c.is_ascii_alphanumeric() || "-_./,=:+@%".contains(c));
        if plain {
            w.to_string()
        } else {
            format!("'{}'", w.replace('\'', "'\\''"))
        }
    };
    let mut words = vec!["lucent".to_string(), "render".into(), quote(&scene.to_string_lossy())];
    let mut add = |option: &str, values: &[String]| {
        words.push(option.to_string());
        words.extend(values.iter().map(|v| quote(v)));
    };
    let path = |p: &PathBuf| vec![p.to_string_lossy().into_owned()];
    if let Some(o) = &args.output {
        add("-o", &path(o));
    }
    for d in &args.define {
        add("-D", std::slice::from_ref(d));
    }
    if let Some(size) = &args.size {
        add("--size", size);
    }
    if let Some(d) = &args.maxdepth {
        add("--maxdepth", std::slice::from_ref(d));
    }
    if args.quick {
        add("--quick", &[]);
    }
    if let Some(n) = args.spp {
        add("--spp", &[n.to_string()]);
    }
    if let Some(name) = &args.sampler {
        add("--sampler", std::slice::from_ref(name));
    }
    if let Some(t) = args.noise_threshold {
        add("--noise-threshold", &[t.to_string()]);
    }
    if let Some(seed) = args.seed {
        add("--seed", &[seed.to_string()]);
    }
    if let Some(a) = args.aov {
        let on = [a.albedo, a.normal, a.depth, a.alpha];
        let names: Vec<&str> = AOV_NAMES
            .iter()
            .zip(on)
            .filter(|(_, on)| *on)
            .map(|(n, _)| *n)
            .collect();
        add("--aov", &[names.join(",")]);
    }
    if args.denoise {
        add("--denoise", &[]);
    }
    if let Some(m) = &args.spp_map {
        add("--spp-map", &path(m));
    }
    if let Some(s) = &args.state {
        add("--state", &path(s));
    }
    if let Some(c) = args.checkpoint {
        add("--checkpoint", &[c.to_string()]);
    }
    add("--resume", &[state.to_string()]);
    words.join(" ")
}
