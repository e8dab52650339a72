//! Any bytes as a scene, rendered: parse, build, and a few pixels of the picture through
//! the integrator — what a scene can make the renderer do (deep ray trees, huge sample
//! counts, degenerate shapes), not only what it can make the parser do. Nothing may
//! panic or overflow the stack. Run with `cargo +nightly fuzz run render_scene`.
//!
//! Capped in the harness: `lucent_fuzz::built_scene`'s caps, four pixels at most (the
//! middle of the image), at most four samples of each, and no render that may trace
//! more than 200,000 rays (the work estimate's upper bound, which this checks: a render
//! that passes it by far hangs the fuzzer, and libFuzzer reports the timeout).
#![no_main]

use std::sync::atomic::AtomicBool;

use libfuzzer_sys::fuzz_target;
use lucent_io::session::Renderer;

fuzz_target!(|data: &[u8]| {
    let Some(session) = lucent_fuzz::built_scene(data) else {
        return;
    };
    let Some(built) = &session.built else {
        return;
    };
    let job = built.job().probe(2, 4);
    let samples = job.pixels.pixels() as f64 * job.samples.len() as f64;
    if built.work.most_rays_per_pixel / built.settings.spp as f64 * samples > 200_000.0 {
        return;
    }
    let renderer = Renderer::new(Some(1)).expect("a thread");
    let cancel = AtomicBool::new(false);
    let _ = renderer.render(built, &job, &|_| {}, &cancel);
});
