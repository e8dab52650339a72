//! `lucent bench scene SCENE [--reps R] [--threads N] [--accel A]`: the whole-renderer
//! benchmark. Parses and builds once, renders R times without writing, and prints one
//! line with the median render time and rays per second. Speed is measured here, never
//! asserted in tests.

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

use clap::Args;
use lucent_core::accel::AccelKind;
use lucent_io::session::{Session, SessionOptions};

use crate::output::report;
use crate::EXIT_BAD_INPUT;

#[derive(Args)]
pub struct SceneBenchArgs {
    pub scene: PathBuf,
    /// Renders to time (the median is reported).
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub reps: u32,
    /// Worker threads for the build and the renders (default: all cores).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub threads: Option<u32>,
    #[arg(long, default_value = "bvh", value_parser = clap::builder::PossibleValuesParser::new(AccelKind::NAMES))]
    pub accel: String,
}

pub fn run(args: &SceneBenchArgs) -> u8 {
    let accel: AccelKind = args.accel.parse().expect("clap checked the value");
    let options = SessionOptions {
        accel,
        ..SessionOptions::default()
    };
    let renderer = match crate::render::start_renderer(args.threads) {
        Ok(r) => r,
        Err(code) => return code,
    };
    // Built as `lucent render` builds.
    let mut session = Session::parse_file(&args.scene, options);
    renderer.build(|| session.build());
    report(&session.diags, &session.desc.sources, false);
    let Some(built) = &session.built else {
        return EXIT_BAD_INPUT;
    };
    let (parse_s, build_s) = (session.parse_seconds, session.build_seconds);
    let job = built.job();
    let cancel = AtomicBool::new(false);
    let mut times = Vec::new();
    let mut rays = 0;
    for _ in 0..args.reps {
        let t = Instant::now();
        let (_, stats) = renderer.render(built, &job, &|_| {}, &cancel).expect("not cancelled");
        times.push(t.elapsed().as_secs_f64());
        rays = stats.rays;
    }
    let median = super::median(times);
    let name = args
        .scene
        .file_stem()
        .map_or_else(String::new, |s| s.to_string_lossy().into_owned());
    outln!(
        "scene={name} accel={} threads={} parse_s={parse_s:.4} build_s={build_s:.4} render_s={median:.4} rays={rays} mrays_per_s={:.2} reps={}",
        accel.name(),
        renderer.threads(),
        rays as f64 / median / 1e6,
        args.reps
    );
    0
}
