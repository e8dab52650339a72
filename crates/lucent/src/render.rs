//! `lucent render SCENE [-o OUT.png] [--spp N] [--sampler independent|sobol] [--noise-threshold T] [--spp-map FILE] [--crop X0 X1 Y0 Y1 | --pixel-bounds X0 X1 Y0 Y1] [--samples FIRST..LAST] [--seed N] [--state OUT.lstate] [--resume STATE] [--threads N] [--accel bvh|list] [--strict] [--quiet] [--stats]
//!
//! A render of part of the image (a region), of some sample indices or continued from a
//! state file gives exactly the pixels of the one-go render: merged (`lucent merge`) the
//! parts are its bytes.`

use std::path::PathBuf;
use std::sync::atomic::Ordering;
use std::time::Instant;

use clap::Args;
use lucent_core::accel::AccelKind;
use lucent_core::integrator::whitted::MAX_PENDING;
use lucent_core::math::Color;
use lucent_core::film::Film;
use lucent_core::integrator::PixelSampling;
use lucent_core::render::job::RenderJob;
use lucent_core::sampler::SamplerKind;
use lucent_io::resources::input::FileId;
use lucent_io::resources::{Budget, OutputTarget};
use lucent_io::session::{Renderer, Session, SessionOptions};
use lucent_io::state::{RenderState, StateHeader};

use crate::output::{choose_output, report};
use crate::progress::Progress;
use crate::job_args::{apply_samples, parse_samples, pixel_rect};
use crate::output::Output;
use crate::passes::{render_in_passes, Outcome};
use crate::signals;
use crate::EXIT_BAD_INPUT;

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
    /// Continue the render a state file holds, up to `--spp` (or the scene's spp)
    /// samples per pixel: the same pixels, the sample indices after its last.
    #[arg(long, value_name = "STATE", conflicts_with_all = ["crop", "pixel_bounds", "samples"])]
    pub resume: Option<PathBuf>,
    /// Every SECS seconds, write the image of the samples done so far and a state to
    /// resume from (OUT.partial.png and OUT.partial.lstate, or --state), each whole or
    /// not at all; they are removed when the render completes.
    #[arg(long, value_name = "SECS", value_parser = parse_seconds)]
    pub checkpoint: Option<f64>,
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

/// The settings the command line overrides, as scene lines: `--size`, `--maxdepth`, then
/// every `-D name=value` in order (the last wins).
fn overrides(args: &RenderArgs) -> Vec<String> {
    let mut lines = Vec::new();
    if let Some(s) = &args.size {
        lines.push(format!("size {}", s.join(" ")));
    }
    if let Some(d) = &args.maxdepth {
        lines.push(format!("maxdepth {d}"));
    }
    for d in &args.define {
        let (name, value) = d.split_once('=').unwrap_or((d, ""));
        lines.push(format!("{} {}", name.trim(), value.replace(',', " ").trim()));
    }
    lines
}

/// `--quick`: half the image size, at most 4 samples per pixel and 3 scattering events
/// (or mirror bounces).
fn quick(desc: &mut lucent_io::desc::SceneDesc) {
    if let Some(size) = &mut desc.size {
        size.value = ((size.value.0 / 2).max(1), (size.value.1 / 2).max(1));
    }
    if let Some(spp) = &mut desc.spp {
        spp.value = spp.value.min(4);
    }
    match &mut desc.max_depth {
        Some(d) if d.value < 0 || d.value > 3 => d.value = 3,
        Some(_) => {}
        None => {
            desc.max_depth = Some(lucent_io::desc::Located {
                value: 3,
                loc: desc.end,
            })
        }
    }
}

/// `--checkpoint`: seconds, a finite number > 0.
fn parse_seconds(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v > 0.0 && v.is_finite() => Ok(v),
        _ => Err(format!("'{s}' is not a number of seconds > 0")),
    }
}

/// `--memory-limit`: a size as people write it (`4G`, `512MiB`, bytes).
pub fn parse_size(s: &str) -> Result<u64, String> {
    lucent_io::resources::budget::parse_size(s)
}

/// Renders every scene named, one after the other; the exit code is the worst of them (a
/// signal stops the run at once).
pub fn run(args: &RenderArgs) -> u8 {
    signals::install();
    let several = args.scenes.len() > 1;
    if several {
        let single = [
            (args.output.is_some(), "-o"),
            (args.state.is_some(), "--state"),
            (args.resume.is_some(), "--resume"),
            (args.spp_map.is_some(), "--spp-map"),
        ];
        if let Some((_, flag)) = single.iter().find(|(given, _)| *given) {
            eprintln!("lucent: error: {flag} names one file, and {} scenes were given: render them one at a time, or let each scene's output command (else SCENE.png beside it) name its image", args.scenes.len());
            return EXIT_BAD_INPUT;
        }
        if args.scenes.iter().filter(|s| s.as_os_str() == "-").count() > 1 {
            eprintln!("lucent: error: standard input (-) can hold one scene");
            return EXIT_BAD_INPUT;
        }
    }
    let mut worst = 0;
    for scene in &args.scenes {
        let code = run_one(args, scene, several);
        if code >= 128 {
            return code; // stopped by a signal
        }
        worst = worst.max(code);
    }
    worst
}

fn run_one(args: &RenderArgs, scene: &std::path::Path, several: bool) -> u8 {
    let accel: AccelKind = args.accel.parse().expect("clap checked the value");
    let t_start = Instant::now();
    let options = SessionOptions {
        strict: args.strict,
        accel,
        memory_limit: args.memory_limit.unwrap_or_else(Budget::machine_default),
    };
    let mut session = if scene.as_os_str() == "-" {
        let mut text = Vec::new();
        let read = std::io::Read::read_to_end(&mut std::io::Read::take(std::io::stdin(), 1 << 30), &mut text);
        if let Err(e) = read {
            eprintln!("lucent: error: cannot read the scene from standard input: {e}");
            return EXIT_BAD_INPUT;
        }
        Session::parse_text_with("-", &text, options, &overrides(args))
    } else {
        Session::parse_file_with(scene, options, &overrides(args))
    };
    if args.quick {
        quick(&mut session.desc);
    }
    if session.diags.has_errors() {
        report(&session.diags, &session.desc.sources, false);
        return EXIT_BAD_INPUT;
    }
    // The output is checked before the build, which may take long: that it can be
    // written, and that it is none of the files the scene names.
    // Several scenes, and this one names no output: SCENE.png beside it.
    let own = (several && session.desc.output.is_none()).then(|| {
        if scene.as_os_str() == "-" {
            PathBuf::from("stdin.png")
        } else {
            scene.with_extension("png")
        }
    });
    let out = match choose_output(args.output.as_deref().or(own.as_deref()), &session.desc, &mut session.diags) {
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
    let state_out = match &args.state {
        Some(p) => match OutputTarget::resolve(p) {
            Ok(t) => Some((p.clone(), t)),
            Err(e) => {
                eprintln!("lucent: error: --state: cannot write {}: {e}", p.display());
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
    if let Some(r) = &args.resume {
        if let Ok(meta) = std::fs::metadata(r) {
            named.record(FileId::of(&meta), r);
        }
    }
    let targets = std::iter::once((&out.name, &out.target))
        .chain(spp_map.iter().map(|m| (&m.name, &m.target)))
        .chain(state_out.iter().map(|(n, t)| (n, t)));
    for (name, target) in targets {
        if let Err(e) = target.check_not_input(&named) {
            report(&session.diags, &session.desc.sources, false);
            eprintln!("lucent: error: cannot write {}: {e}", name.display());
            return EXIT_BAD_INPUT;
        }
    }
    let building = Progress::phase("building", args.quiet);
    session.build();
    building.finish();
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
    if let Some(seed) = args.seed {
        job.seed = seed;
    }
    let pixel_sampling = match built.integrator.pixel_sampling() {
        PixelSampling::Uniform => "uniform",
        PixelSampling::Stratified => "stratified",
    };
    let header = |job: &RenderJob| StateHeader {
        scene_hash: session.desc.sources.digest(),
        scene_name: if scene.as_os_str() == "-" {
            "standard input".to_string()
        } else {
            scene.file_name().map_or(String::new(), |n| n.to_string_lossy().into_owned())
        },
        resolution: (job.resolution.width, job.resolution.height),
        pixels: job.pixels,
        spp: job.spp,
        samples: job.samples.clone(),
        seed: job.seed,
        sampler: SamplerKind::ALL
            .iter()
            .find(|(_, k)| *k == job.sampler)
            .map_or("independent", |(n, _)| n)
            .to_string(),
        pixel_sampling: pixel_sampling.to_string(),
        gamma: built.settings.gamma,
    };
    let (w, h) = (job.resolution.width, job.resolution.height);
    let part = pixel_rect(args.crop.as_deref(), args.pixel_bounds.as_deref(), w, h)
        .and_then(|rect| {
            if let Some(r) = rect {
                job.pixels = r;
            }
            args.samples.as_ref().map_or(Ok(()), |s| apply_samples(&mut job, s))
        })
        .and_then(|()| {
            let split = args.samples.is_some() || args.resume.is_some() || args.state.is_some();
            if job.noise_threshold.is_some() && split {
                return Err("adaptive sampling (--noise-threshold, noisethreshold) cannot be split into sample ranges, resumed or kept in a state file yet".into());
            }
            Ok(())
        });
    if let Err(e) = part {
        eprintln!("lucent: error: {e}");
        return EXIT_BAD_INPUT;
    }
    let now = header(&job);
    let resumed = match &args.resume {
        Some(path) => match resume(path, &mut job, &now) {
            Ok(s) => Some(s),
            Err(e) => {
                eprintln!("lucent: error: --resume {}: {e}", path.display());
                return EXIT_BAD_INPUT;
            }
        },
        None => None,
    };
    let progress = Progress::new(job.pixels.pixels() * job.samples.len() as u64, args.quiet);
    let cancel = signals::cancel_flag();
    let t_render = Instant::now();
    // Partial results (a checkpoint, or what an interrupt leaves) go beside the output,
    // never over it: OUT.partial.png and, without --state, OUT.partial.lstate.
    let partial = Partial::beside(&out, &args.state, &session.desc);
    let first = resumed.as_ref().map_or(job.samples.start, |s| s.header.samples.start);
    let mut wrote_partial = false;
    let mut save = |film: &Film, samples: &std::ops::Range<u32>| {
        let kept = StateHeader {
            samples: samples.clone(),
            ..header(&job)
        };
        match partial.write(film, kept) {
            Ok(()) => wrote_partial = true,
            Err(e) => eprintln!("lucent: warning: checkpoint not written: {e}"),
        }
    };
    let checkpoint = args.checkpoint.map(std::time::Duration::from_secs_f64);
    let outcome = render_in_passes(
        &renderer,
        built,
        &job,
        resumed.map(|s| s.film),
        first,
        &|n| progress.advance(n),
        cancel,
        checkpoint,
        &mut save,
    );
    let t_rendered = Instant::now();
    progress.finish();
    let (film, stats) = match outcome {
        Outcome::Done(film, stats) if !cancel.load(Ordering::Relaxed) => (film, stats),
        Outcome::Interrupted(Some((film, samples))) => {
            signals::saving(true);
            let kept = StateHeader {
                samples: samples.clone(),
                ..header(&job)
            };
            let how = if pixel_sampling == "uniform" {
                format!("continue with: lucent render {} --resume {}", scene.display(), partial.state_name())
            } else {
                format!(
                    "render the rest with --samples {}..{} --state REST.lstate and put them together with lucent merge",
                    samples.end,
                    job.spp - 1
                )
            };
            match partial.write(&film, kept) {
                Ok(()) => eprintln!(
                    "lucent: interrupted after samples {}..{} of every pixel: wrote {} and {}; {how}",
                    samples.start,
                    samples.end - 1,
                    partial.image_name(),
                    partial.state_name()
                ),
                Err(e) => eprintln!("lucent: interrupted; the partial render was not written: {e}"),
            }
            return signals::exit_code();
        }
        _ => {
            eprintln!("lucent: interrupted; nothing written");
            return signals::exit_code();
        }
    };
    let mut kept = header(&job);
    kept.samples = first..job.samples.end;

    let mut extra_warnings = 0;
    if stats.bad_samples > 0 {
        extra_warnings += 1;
        let at: Vec<String> = stats.bad_pixels.list().iter().map(|(x, y)| format!("({x}, {y})")).collect();
        let more = if stats.bad_samples > at.len() as u64 { ", …" } else { "" };
        eprintln!(
            "lucent: warning: {} samples were NaN or infinite and were replaced by black, first at pixels {}{more}",
            stats.bad_samples,
            at.join(", ")
        );
    }
    if stats.cut_branches > 0 {
        extra_warnings += 1;
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
    let writing = Progress::phase("writing", args.quiet);
    let _done_writing = Finish(&writing);
    let info = crate::output::image_info(&kept);
    if let Err(e) = crate::output::write_image(&out, &film.resolve(), &info) {
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
        let linear = lucent_io::image::ImageInfo { gamma: 1.0, ..info.clone() };
        if let Err(e) = crate::output::write_image(map, &counts, &linear) {
            eprintln!("lucent: error: {e}");
            return EXIT_BAD_INPUT;
        }
    }
    if let Some((name, target)) = &state_out {
        let state = RenderState { header: kept, film: film.clone() };
        if let Err(e) = target.write(&state.encode()) {
            eprintln!("lucent: error: cannot write {}: {e}", name.display());
            return EXIT_BAD_INPUT;
        }
    }
    if wrote_partial {
        partial.remove();
    }
    writing.finish();
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
    let warnings = session.diags.count(lucent_io::diag::Severity::Warning) + extra_warnings;
    if warnings > 0 && !args.quiet {
        let s = if warnings == 1 { "" } else { "s" };
        eprintln!("lucent: {warnings} warning{s} (see above)");
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
            "parse {:.3} s, build {:.3} s ({} {:.1} MB), render {:.3} s on {} threads ({:.3} Msamples/s, {:.2} rays per sample), write {:.3} s, total {:.3} s",
            session.parse_seconds,
            session.build_seconds,
            scene.accel_kind().name(),
            scene.accel_memory_bytes() as f64 / 1e6,
            render_s,
            renderer.threads(),
            stats.samples as f64 / render_s.max(1e-9) / 1e6,
            stats.rays as f64 / stats.samples.max(1) as f64,
            (t_written - t_rendered).as_secs_f64(),
            (t_written - t_start).as_secs_f64(),
        );
    }
    0
}

/// Reads the state to continue and points `job` at what is left: its pixels, the sample
/// indices from its end to `job.spp`. The state must be of this scene and these options,
/// from an integrator whose samples do not depend on the total (the Monte Carlo ones).
fn resume(path: &std::path::Path, job: &mut RenderJob, now: &StateHeader) -> Result<RenderState, String> {
    let bytes = std::fs::read(path).map_err(|e| e.to_string())?;
    let state = RenderState::decode(&bytes)?;
    let h = &state.header;
    let differs = [
        (h.scene_hash != now.scene_hash, "the scene's text has changed"),
        (h.resolution != now.resolution, "the image size differs"),
        (h.seed != now.seed, "the seed differs"),
        (h.sampler != now.sampler, "the sampler differs"),
        (h.gamma.to_bits() != now.gamma.to_bits(), "the gamma differs"),
    ];
    if let Some((_, why)) = differs.iter().find(|(d, _)| *d) {
        return Err(format!("it is not a render of this scene with these options: {why}"));
    }
    if h.pixel_sampling != "uniform" || h.spp < 2 || now.pixel_sampling != "uniform" {
        return Err("only renders of the Monte Carlo integrators (direct, pathtracer) with spp 2 or more can be continued: the ray tracer places its samples on a grid that depends on spp, and spp 1 is the pixel centre".into());
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

/// Worker threads for `--threads N` (all cores without it), or the exit code after
/// saying why they could not start.
pub fn start_renderer(threads: Option<u32>) -> Result<Renderer, u8> {
    Renderer::new(threads.map(|n| n as usize)).map_err(|e| {
        eprintln!("lucent: error: {e}");
        1
    })
}

/// Where a partial render goes: `OUT.partial.EXT` beside the output (nothing for standard
/// output or a device) and the state at `--state`, else `OUT.partial.lstate`.
struct Partial {
    image: Option<Output>,
    state: (PathBuf, bool),
}

impl Partial {
    fn beside(out: &Output, state: &Option<PathBuf>, desc: &lucent_io::desc::SceneDesc) -> Partial {
        let is_file = matches!(out.target, OutputTarget::File(_));
        // Beside a file; in the current folder for standard output or a device.
        let with = |ext: &str| match is_file {
            true => {
                let stem = out.name.file_stem().map_or("render".into(), |s| s.to_string_lossy().into_owned());
                out.name.with_file_name(format!("{stem}.partial.{ext}"))
            }
            false => PathBuf::from(format!("lucent.partial.{ext}")),
        };
        let ext = out.name.extension().map_or("png".into(), |e| e.to_string_lossy().into_owned());
        let mut quiet = lucent_io::diag::Diagnostics::default();
        let image = is_file
            .then(|| crate::output::choose_output(Some(&with(&ext)), desc, &mut quiet).ok())
            .flatten();
        let state = match state {
            Some(p) => (p.clone(), false),
            None => (with("lstate"), true),
        };
        Partial { image, state }
    }

    fn image_name(&self) -> String {
        self.image.as_ref().map_or("no image".into(), |o| o.name.display().to_string())
    }

    fn state_name(&self) -> String {
        self.state.0.display().to_string()
    }

    /// Writes the partial image and the state (each atomically).
    fn write(&self, film: &Film, header: StateHeader) -> Result<(), String> {
        if let Some(img) = &self.image {
            crate::output::write_image(img, &film.resolve(), &crate::output::image_info(&header))?;
        }
        let state = RenderState {
            header,
            film: film.clone(),
        };
        OutputTarget::resolve(&self.state.0)
            .and_then(|t| t.write(&state.encode()))
            .map_err(|e| format!("cannot write {}: {e}", self.state.0.display()))
    }

    /// Removes what checkpoints wrote, once the render is complete (the state at
    /// `--state` is the final one by then, and stays).
    fn remove(&self) {
        if let Some(img) = &self.image {
            let _ = std::fs::remove_file(&img.name);
        }
        if self.state.1 {
            let _ = std::fs::remove_file(&self.state.0);
        }
    }
}

/// Clears a phase's spinner when the phase ends, however it ends.
struct Finish<'a>(&'a Progress);

impl Drop for Finish<'_> {
    fn drop(&mut self) {
        self.0.finish();
    }
}
