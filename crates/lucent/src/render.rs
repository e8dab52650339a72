//! `lucent render SCENE [-o OUT.png] [--spp N] [--sampler independent|sobol] [--noise-threshold T] [--spp-map FILE] [--threads N] [--accel bvh|list] [--strict] [--quiet] [--stats]`

use std::path::PathBuf;
use std::sync::atomic::Ordering;
use std::time::Instant;

use clap::Args;
use lucent_core::accel::AccelKind;
use lucent_core::integrator::whitted::MAX_PENDING;
use lucent_core::math::Color;
use lucent_core::sampler::SamplerKind;
use lucent_io::resources::input::FileId;
use lucent_io::resources::Budget;
use lucent_io::session::{Renderer, Session, SessionOptions};

use crate::output::{choose_output, report};
use crate::progress::Progress;
use crate::signals;
use crate::EXIT_BAD_INPUT;

#[derive(Args)]
pub struct RenderArgs {
    /// The scene file (CSE167/CSE168 format).
    pub scene: PathBuf,
    /// Output image (`-` for standard output); default: the scene's `output` command,
    /// else raytrace.png.
    #[arg(short, long, value_name = "OUT.png")]
    pub output: Option<PathBuf>,
    /// Worker threads (default: all cores). The image is the same for any count.
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

/// `--memory-limit`: a size as people write it (`4G`, `512MiB`, bytes).
pub fn parse_size(s: &str) -> Result<u64, String> {
    lucent_io::resources::budget::parse_size(s)
}

pub fn run(args: &RenderArgs) -> u8 {
    let accel: AccelKind = args.accel.parse().expect("clap checked the value");
    let t_start = Instant::now();
    signals::install();
    let options = SessionOptions {
        strict: args.strict,
        accel,
        memory_limit: args.memory_limit.unwrap_or_else(Budget::machine_default),
    };
    let mut session = Session::parse_file(&args.scene, options);
    if session.diags.has_errors() {
        report(&session.diags, &session.desc.sources, false);
        return EXIT_BAD_INPUT;
    }
    // The output is checked before the build, which may take long: that it can be
    // written, and that it is none of the files the scene names.
    let out = match choose_output(args.output.as_deref(), &session.desc, &mut session.diags) {
        Ok(out) => out,
        Err(msg) => {
            report(&session.diags, &session.desc.sources, false);
            eprintln!("lucent: error: {msg}");
            return EXIT_BAD_INPUT;
        }
    };
    let spp_map = match &args.spp_map {
        Some(p) => match choose_output(Some(p), &session.desc, &mut session.diags) {
            Ok(m) => Some(m),
            Err(msg) => {
                report(&session.diags, &session.desc.sources, false);
                eprintln!("lucent: error: --spp-map: {msg}");
                return EXIT_BAD_INPUT;
            }
        },
        None => None,
    };
    let mut named = session.res.inputs.clone();
    for p in session.desc.named_files() {
        if let Ok(meta) = std::fs::metadata(p) {
            named.record(FileId::of(&meta), p);
        }
    }
    for o in std::iter::once(&out).chain(&spp_map) {
        if let Err(e) = o.target.check_not_input(&named) {
            report(&session.diags, &session.desc.sources, false);
            eprintln!("lucent: error: cannot write {}: {e}", o.name.display());
            return EXIT_BAD_INPUT;
        }
    }
    session.build();
    report(&session.diags, &session.desc.sources, false);
    let Some(built) = &session.built else {
        return EXIT_BAD_INPUT;
    };

    let renderer = match start_renderer(args.threads) {
        Ok(r) => r,
        Err(code) => return code,
    };
    let mut job = built.job();
    if let Some(spp) = args.spp {
        job.spp = spp;
        job.samples = 0..spp;
    }
    if let Some(t) = args.noise_threshold {
        job.noise_threshold = (t > 0.0).then_some(t);
    }
    if let Some(name) = &args.sampler {
        job.sampler = SamplerKind::ALL
            .iter()
            .find(|(n, _)| n == name)
            .expect("clap checked the value")
            .1;
    }
    let progress = Progress::new(job.pixels.pixels() * job.samples.len() as u64, args.quiet);
    let cancel = signals::cancel_flag();
    let t_render = Instant::now();
    let rendered = renderer.render(built, &job, &|n| progress.advance(n), cancel);
    let t_rendered = Instant::now();
    progress.finish();
    let Some((film, stats)) = rendered.filter(|_| !cancel.load(Ordering::Relaxed)) else {
        eprintln!("lucent: interrupted; nothing written");
        return signals::exit_code();
    };

    if stats.bad_samples > 0 {
        eprintln!(
            "lucent: warning: {} samples were NaN or infinite and were replaced by black",
            stats.bad_samples
        );
    }
    if stats.cut_branches > 0 {
        eprintln!(
            "lucent: warning: {} ray branches were not traced: too many were waiting at once (mirrors and glass that reflect everything, and a maxdepth above {})",
            stats.cut_branches,
            MAX_PENDING / 2
        );
    }
    // Everything the build read (MTL libraries and their images too) is an input.
    if let Err(e) = out.target.check_not_input(&session.res.inputs) {
        eprintln!("lucent: error: cannot write {}: {e}", out.name.display());
        return EXIT_BAD_INPUT;
    }
    if let Err(e) = crate::output::write_image(&out, &film.resolve(), built.settings.gamma) {
        eprintln!("lucent: error: {e}");
        return EXIT_BAD_INPUT;
    }
    if let Some(map) = &spp_map {
        // PNG holds fractions of the cap; the float formats hold the counts themselves.
        let scale = if map.format == crate::output::Format::Png {
            1.0 / job.samples.len() as f32
        } else {
            1.0
        };
        let counts = lucent_core::image::Image {
            width: film.width,
            height: film.height,
            pixels: film.counts.iter().map(|&n| Color::splat(n as f32 * scale)).collect(),
        };
        if let Err(e) = crate::output::write_image(map, &counts, 1.0) {
            eprintln!("lucent: error: {e}");
            return EXIT_BAD_INPUT;
        }
    }
    let t_written = Instant::now();

    let scene = &built.scene;
    let render_s = (t_rendered - t_render).as_secs_f64();
    if !args.quiet {
        eprintln!(
            "{}x{}, {} primitives, {} rays, {:.3} s, {:.2} Mrays/s -> {}",
            film.width,
            film.height,
            scene.geometry.shown_primitive_count(),
            stats.rays,
            render_s,
            stats.rays as f64 / render_s.max(1e-9) / 1e6,
            out.name.display()
        );
    }
    if job.noise_threshold.is_some() && !args.quiet {
        eprintln!(
            "adaptive sampling: {:.1} samples per pixel on average (min {}, max {}, cap {})",
            stats.samples as f64 / film.counts.len().max(1) as f64,
            stats.min_pixel_samples,
            stats.max_pixel_samples,
            job.samples.len()
        );
    }
    if args.stats {
        eprintln!(
            "parse {:.3} s, build {:.3} s ({} {:.1} MB), render {:.3} s on {} threads, write {:.3} s, total {:.3} s",
            session.parse_seconds,
            session.build_seconds,
            scene.accel_kind().name(),
            scene.accel_memory_bytes() as f64 / 1e6,
            render_s,
            renderer.threads(),
            (t_written - t_rendered).as_secs_f64(),
            (t_written - t_start).as_secs_f64(),
        );
    }
    0
}

/// Worker threads for `--threads N` (all cores without it), or the exit code after
/// saying why they could not start.
pub fn start_renderer(threads: Option<u32>) -> Result<Renderer, u8> {
    Renderer::new(threads.map(|n| n as usize)).map_err(|e| {
        eprintln!("lucent: error: {e}");
        1
    })
}
