//! `lucent render SCENE [-o OUT.png] [--spp N] [--sampler independent|sobol] [--noise-threshold T] [--spp-map FILE] [--crop X0 X1 Y0 Y1 | --pixel-bounds X0 X1 Y0 Y1] [--samples FIRST..LAST] [--seed N] [--state OUT.lstate] [--resume STATE] [--aov albedo,normal,depth,alpha] [--denoise] [--threads N] [--accel bvh|list] [--strict] [--quiet] [--stats]
//!
//! A render of part of the image (a region), of some sample indices or continued from a
//! state file gives exactly the pixels of the one-go render: merged (`lucent merge`) the
//! parts are its bytes.`

use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;
use std::time::Instant;

use lucent_core::accel::AccelKind;
use lucent_core::film::Film;
use lucent_core::integrator::whitted::{MAX_PENDING, MAX_TREE_RAYS};
use lucent_core::integrator::PixelSampling;
use lucent_core::math::Color;
use lucent_core::render::job::RenderJob;
use lucent_core::render::plan::Cut;
use lucent_core::sampler::SamplerKind;
use lucent_io::build::warn_if_absurd;
use lucent_io::diag::Diagnostics;
use lucent_io::resources::input::FileId;
use lucent_io::resources::{Budget, Inputs, OutputTarget};
use lucent_io::session::{Renderer, Session, SessionOptions};
use lucent_io::state::{RenderState, StateHeader};

use crate::job_args::{apply_samples, pixel_rect, resume};
use crate::output::{choose_output, encode_image, report, write_all, Encoded};
use crate::partial::Partial;
use crate::passes::{render_in_passes, Outcome};
use crate::picture::{aov_file, encode_picture, picture_bytes, take_picture_memory, Extras};
use crate::plan::{PlanRequest, Planned};
use crate::progress::{Finish, Progress};
use crate::render_args::{resume_command, RenderArgs};
use crate::settings_args::{overrides, quick};
use crate::signals;
use crate::targets::{check_targets, RunFiles};
use crate::EXIT_BAD_INPUT;

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
            errln!("lucent: error: {flag} names one file, and {} scenes were given: render them one at a time, or let each scene's output command (else SCENE.png beside it) name its image", args.scenes.len());
            return EXIT_BAD_INPUT;
        }
        if args.scenes.iter().filter(|s| s.as_os_str() == "-").count() > 1 {
            errln!("lucent: error: standard input (-) can hold one scene");
            return EXIT_BAD_INPUT;
        }
    }
    let mut worst = 0;
    let mut earlier = RunFiles::default();
    for scene in &args.scenes {
        let code = run_one(args, scene, several, &mut earlier, None);
        if code >= 128 {
            return code; // stopped by a signal
        }
        worst = worst.max(code);
    }
    worst
}

/// Renders one scene — or, with `planning`, prints (and writes) the plan of its render
/// instead of rendering it. `earlier`: what the run's earlier scenes read and write (this
/// scene may replace none of it); this scene's are added once it is built.
pub fn run_one(
    args: &RenderArgs,
    scene: &std::path::Path,
    several: bool,
    earlier: &mut RunFiles,
    planning: Option<&PlanRequest>,
) -> u8 {
    let accel: AccelKind = args.accel.parse().expect("clap checked the value");
    let t_start = Instant::now();
    let options = SessionOptions {
        strict: args.strict,
        accel,
        memory_limit: args.memory_limit.unwrap_or_else(Budget::machine_default),
    };
    let lines = overrides(args.size.as_deref(), args.maxdepth.as_deref(), &args.define);
    let parsing = Progress::phase("parsing", args.quiet);
    let mut session = if scene.as_os_str() == "-" {
        let mut text = Vec::new();
        let read = std::io::Read::read_to_end(&mut std::io::Read::take(std::io::stdin(), 1 << 30), &mut text);
        if let Err(e) = read {
            errln!("lucent: error: cannot read the scene from standard input: {e}");
            return EXIT_BAD_INPUT;
        }
        Session::parse_text_with("-", &text, options, &lines)
    } else {
        Session::parse_file_with(scene, options, &lines)
    };
    parsing.finish();
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
    let out = match choose_output(
        args.output.as_deref().or(own.as_deref()),
        &session.desc,
        &mut session.diags,
    ) {
        Ok(out) => out,
        Err(msg) => {
            report(&session.diags, &session.desc.sources, false);
            errln!("lucent: error: {msg}");
            return EXIT_BAD_INPUT;
        }
    };
    let spp_map = match &args.spp_map {
        Some(p) => match choose_output(Some(p), &session.desc, &mut session.diags) {
            Ok(m) => Some(m),
            Err(msg) => {
                report(&session.diags, &session.desc.sources, false);
                errln!("lucent: error: --spp-map: {msg}");
                return EXIT_BAD_INPUT;
            }
        },
        None => None,
    };
    let state_out = match &args.state {
        Some(p) => match OutputTarget::resolve(p) {
            Ok(t) => Some((p.clone(), t)),
            Err(e) => {
                errln!("lucent: error: --state: cannot write {}: {e}", p.display());
                return EXIT_BAD_INPUT;
            }
        },
        None => None,
    };
    let aov_side = match aov_file(&out, args.aov.unwrap_or_default()) {
        Ok(side) => side,
        Err(e) => {
            errln!("lucent: error: {e}");
            return EXIT_BAD_INPUT;
        }
    };
    // A missing denoiser is found now, not after hours of rendering.
    let denoiser = match args.denoise.then(lucent_io::denoise::Denoiser::load).transpose() {
        Ok(d) => d,
        Err(e) => {
            errln!("lucent: error: {e}");
            return EXIT_BAD_INPUT;
        }
    };
    // The run's inputs so far: what the scene read and names, and every scene of the
    // run (one scene's output must not replace the next one).
    let mut named = session.res.inputs.clone();
    for p in session
        .desc
        .named_files()
        .into_iter()
        .chain(args.scenes.iter().map(|s| s.as_path()))
    {
        if let Ok(meta) = std::fs::metadata(p) {
            named.record(FileId::of(&meta), p);
        }
    }
    // (`lucent plan --json`: its plan is an output too.)
    let plan_json = match planning.and_then(|p| p.json.as_ref()) {
        Some(p) => match OutputTarget::resolve(p) {
            Ok(t) => Some((p.clone(), t)),
            Err(e) => {
                errln!("lucent: error: --json: cannot write {}: {e}", p.display());
                return EXIT_BAD_INPUT;
            }
        },
        None => None,
    };
    // Partial results (a checkpoint, or what an interrupt leaves) go beside the outputs,
    // never over them: OUT.partial.png, and STATE.partial.lstate or OUT.partial.lstate.
    // They may replace the state resumed from (they hold its samples), no other input.
    let partial = Partial::beside(&out, &args.state, &session.desc);
    let partial_targets = partial.targets();
    let mut final_targets: Vec<(&Path, &OutputTarget)> = vec![(&out.name, &out.target)];
    final_targets.extend(spp_map.iter().map(|m| (m.name.as_path(), &m.target)));
    final_targets.extend(aov_side.iter().map(|m| (m.name.as_path(), &m.target)));
    final_targets.extend(state_out.iter().map(|(n, t)| (n.as_path(), t)));
    final_targets.extend(plan_json.iter().map(|(n, t)| (n.as_path(), t)));
    let partials: Vec<(&Path, &OutputTarget)> = partial_targets.iter().map(|(n, t)| (n.as_path(), t)).collect();
    let mut checked = check_targets(&partials, &named);
    for r in args.resume.iter().chain(&args.plan) {
        if let Ok(meta) = std::fs::metadata(r) {
            named.record(FileId::of(&meta), r);
        }
    }
    checked = checked.and_then(|()| check_targets(&final_targets, &named));
    // No partial result may be one of the final outputs either (`--spp-map x.partial.png`).
    let every: Vec<(&Path, &OutputTarget)> = final_targets.iter().chain(&partials).copied().collect();
    checked = checked.and_then(|()| check_targets(&every, &Inputs::default()));
    checked = checked.and_then(|()| earlier.check(&every));
    if let Err(e) = checked {
        report(&session.diags, &session.desc.sources, false);
        errln!("lucent: error: {e}");
        return EXIT_BAD_INPUT;
    }
    let renderer = match start_renderer(args.threads) {
        Ok(r) => r,
        Err(code) => return code,
    };
    // The build within the render's thread count: `--threads` bounds the whole run.
    let building = Progress::phase("building", args.quiet);
    renderer.build(|| session.build());
    building.finish();
    report(&session.diags, &session.desc.sources, false);
    let Some(built) = &session.built else {
        return EXIT_BAD_INPUT;
    };
    // Everything the build read (MTL libraries and their images too) is an input.
    named.extend(&session.res.inputs);
    let checked = check_targets(&partials, &session.res.inputs).and_then(|()| check_targets(&final_targets, &named));
    if let Err(e) = checked {
        errln!("lucent: error: {e}");
        return EXIT_BAD_INPUT;
    }
    // From here on the scene may write: the later scenes of the run must leave its inputs
    // and its outputs alone.
    earlier.add(&named, &every);
    let extras = Extras {
        aovs: args.aov.unwrap_or_default(),
        denoiser: denoiser.as_ref(),
        threads: renderer.threads(),
    };
    let mut job = built.job();
    job.aovs = extras.need_aovs();
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
            scene
                .file_name()
                .map_or(String::new(), |n| n.to_string_lossy().into_owned())
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
        aovs: job.aovs,
        noise_threshold: job.noise_threshold,
    };
    let cut = Cut::parse(&args.by).expect("clap checked the value");
    let planned = crate::plan::apply(
        &renderer,
        built,
        &mut job,
        args.task,
        args.plan.as_deref(),
        planning,
        cut,
        pixel_sampling == "uniform",
        &scene.display().to_string(),
    );
    match planned {
        Ok(Planned::Render) => {}
        Ok(Planned::Printed) => return 0,
        Err(e) => {
            errln!("lucent: error: {e}");
            return EXIT_BAD_INPUT;
        }
    }
    let (w, h) = (job.resolution.width, job.resolution.height);
    let part = pixel_rect(args.crop.as_deref(), args.pixel_bounds.as_deref(), w, h)
        .and_then(|rect| {
            if let Some(r) = rect {
                job.pixels = r;
            }
            args.samples.as_ref().map_or(Ok(()), |s| apply_samples(&mut job, s))
        })
        .and_then(|()| {
            if job.noise_threshold.is_some() && job.samples.start > 0 {
                return Err("with adaptive sampling (--noise-threshold, noisethreshold) a sample range must start at 0: where each pixel stops depends on its earlier samples, so render the first range and continue it with --resume".into());
            }
            Ok(())
        });
    if let Err(e) = part {
        errln!("lucent: error: {e}");
        return EXIT_BAD_INPUT;
    }
    let now = header(&job);
    let resumed = match &args.resume {
        Some(path) => match resume(path, &mut job, &now, &mut session.res.budget) {
            Ok(s) => Some(s),
            Err(e) => {
                errln!("lucent: error: --resume {}: {e}", path.display());
                return EXIT_BAD_INPUT;
            }
        },
        None => None,
    };
    // The picture's memory comes out of the run's budget too: a 8192 x 8192 render with
    // every auxiliary pass would take some 20 GB.
    // (The resumed film is one of the picture's: taken again below.)
    if let Some(s) = &resumed {
        session.res.budget.give_back(s.film_bytes());
    }
    let need = picture_bytes(&job, resumed.is_some(), &extras);
    if !take_picture_memory(&mut session.res.budget, &mut session.diags, &session.desc, &job, need) {
        report(&session.diags, &session.desc.sources, false);
        return EXIT_BAD_INPUT;
    }
    // Absurd work is this render's: its pixels and samples, not the whole picture's at
    // the scene's spp (a task of a plan, a region, --spp).
    let mut later = Diagnostics::default();
    let work = built.work.of_render(job.pixels.pixels(), job.samples.len() as u32);
    warn_if_absurd(&session.desc, &work, &mut later);
    report(&later, &session.desc.sources, false);
    let progress = Progress::new(job.pixels.pixels() * job.samples.len() as u64, args.quiet);
    let cancel = signals::cancel_flag();
    let t_render = Instant::now();
    let first = resumed.as_ref().map_or(job.samples.start, |s| s.header.samples.start);
    let mut wrote_partial = false;
    let mut save = |film: &Film, samples: &std::ops::Range<u32>| {
        let kept = StateHeader {
            samples: samples.clone(),
            ..header(&job)
        };
        // A signal meanwhile waits for the checkpoint (up to 30 s, as for the partial
        // render saved after it), and goes on waiting for that save.
        signals::saving(true);
        match partial.write(film, kept, &extras) {
            Ok(()) => wrote_partial = true,
            Err(e) => errln!("lucent: warning: checkpoint not written: {e}"),
        }
        if !cancel.load(Ordering::Relaxed) {
            signals::saving(false);
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
    // A signal as the last pass ended: the whole render is saved as a partial one.
    let outcome = match outcome {
        Outcome::Done(film, _) if cancel.load(Ordering::Relaxed) => {
            Outcome::Interrupted(Some((film, first..job.samples.end)))
        }
        o => o,
    };
    let (film, stats) = match outcome {
        Outcome::Done(film, stats) => (film, stats),
        Outcome::Interrupted(Some((film, samples))) => {
            signals::saving(true);
            let kept = StateHeader {
                samples: samples.clone(),
                ..header(&job)
            };
            let how = if pixel_sampling == "uniform" {
                format!("continue with: {}", resume_command(args, scene, &partial.state_name()))
            } else {
                format!(
                    "render the rest with --samples {}..{} --state REST.lstate and put them together with lucent merge",
                    samples.end,
                    job.spp - 1
                )
            };
            match partial.write(&film, kept, &extras) {
                Ok(()) => errln!(
                    "lucent: interrupted after samples {}..{} of every pixel: wrote {} and {}; {how}",
                    samples.start,
                    samples.end - 1,
                    partial.image_name(),
                    partial.state_name()
                ),
                Err(e) => errln!("lucent: interrupted; the partial render was not written: {e}"),
            }
            return signals::exit_code();
        }
        _ => {
            errln!("lucent: interrupted; nothing written");
            return signals::exit_code();
        }
    };
    let mut kept = header(&job);
    kept.samples = first..job.samples.end;

    let mut extra_warnings = 0;
    if stats.bad_samples > 0 {
        extra_warnings += 1;
        let at: Vec<String> = stats
            .bad_pixels
            .list()
            .iter()
            .map(|(x, y)| format!("({x}, {y})"))
            .collect();
        let more = if stats.bad_samples > at.len() as u64 {
            ", …"
        } else {
            ""
        };
        errln!(
            "lucent: warning: {} samples were NaN or infinite and were replaced by black, first at pixels {}{more}",
            stats.bad_samples,
            at.join(", ")
        );
    }
    if stats.cut_branches > 0 {
        extra_warnings += 1;
        errln!(
            "lucent: warning: {} ray branches were not traced: a camera sample's ray tree passed {MAX_TREE_RAYS} rays, or more than {MAX_PENDING} branches were waiting at once (glass, and mirrors that reflect everything, with a large maxdepth)",
            stats.cut_branches,
        );
    }
    // Once more before writing (the inputs are the same; a file may have been linked).
    if let Err(e) = check_targets(&final_targets, &named) {
        errln!("lucent: error: {e}");
        return EXIT_BAD_INPUT;
    }
    let writing = Progress::phase("writing", args.quiet);
    let _done_writing = Finish(&writing);
    let info = crate::output::image_info(&kept);
    // Every output is made first, then all are written together: where one cannot be
    // written, none replaces what was there.
    let mut files = match encode_picture(&out, &film, &kept, &extras) {
        Ok(f) => f,
        Err(e) => {
            errln!("lucent: error: {e}");
            return EXIT_BAD_INPUT;
        }
    };
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
        let linear = lucent_io::image::ImageInfo {
            gamma: 1.0,
            ..info.clone()
        };
        match encode_image(map, &counts, &linear) {
            Ok(f) => files.push(f),
            Err(e) => {
                errln!("lucent: error: {e}");
                return EXIT_BAD_INPUT;
            }
        }
    }
    if let Some((name, target)) = &state_out {
        let state = RenderState {
            header: kept,
            film: film.clone(),
        };
        files.push(Encoded {
            name: name.clone(),
            target: target.clone(),
            bytes: state.encode(),
        });
    }
    // (A signal from here on ends the run at once; one during a checkpoint's write, which
    // ended such runs too, lets the checkpoint finish and saves the render's samples.)
    signals::writing_final(true);
    let written = write_all(&files);
    // (The next scene of the run renders, and is interrupted, as this one was.)
    signals::writing_final(false);
    if let Err(e) = written {
        errln!("lucent: error: {e}");
        return EXIT_BAD_INPUT;
    }
    if wrote_partial {
        partial.remove(&extras);
    }
    writing.finish();
    let t_written = Instant::now();

    let scene = &built.scene;
    let render_s = (t_rendered - t_render).as_secs_f64();
    if !args.quiet {
        errln!(
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
        errln!("lucent: {warnings} warning{s} (see above)");
    }
    if job.noise_threshold.is_some() && !args.quiet {
        // From the film: with --resume it holds the earlier samples too.
        let counts = &film.counts;
        errln!(
            "adaptive sampling: {:.1} samples per pixel on average (min {}, max {}, cap {})",
            counts.iter().map(|&n| n as f64).sum::<f64>() / counts.len().max(1) as f64,
            counts.iter().min().copied().unwrap_or(0),
            counts.iter().max().copied().unwrap_or(0),
            job.samples.end - first
        );
    }
    if args.stats {
        errln!(
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

/// Worker threads for `--threads N` (all cores without it), or the exit code after
/// saying why they could not start.
pub fn start_renderer(threads: Option<u32>) -> Result<Renderer, u8> {
    Renderer::new(threads.map(|n| n as usize)).map_err(|e| {
        errln!("lucent: error: {e}");
        EXIT_BAD_INPUT
    })
}
