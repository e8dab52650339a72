//! The path tracer's eight-lane code (`integrator/path/lanes.rs`, taken for Lambertian
//! scenes lit by quad lights on CPUs with AVX2) against its one-path-at-a-time code: the
//! same colour to the bit, and the same rays traced, for every camera sample of scenes
//! with every kind of vertex the lanes meet (flat and smooth-shaded triangles, spheres
//! and ellipsoids, black surfaces, lights seen directly and found by bounces, rays that
//! escape), with both ways of drawing the next direction, several depths and Russian
//! roulette on and off.

use lucent_core::integrator::{CameraHit, TraceCounts};
use lucent_core::math::Color;
use lucent_core::sampler::Sampler;
use lucent_io::session::{Session, SessionOptions};

/// An open box (no front wall) with two boxes of spheres, a smooth-shaded wedge, a black
/// panel and two quad lights, one of them facing the camera.
fn scene(sampling: &str, depth: i32, roulette: &str) -> String {
    format!(
        "size 20 16
integrator pathtracer
spp 3
nexteventestimation mis
importancesampling {sampling}
russianroulette {roulette}
maxdepth {depth}
camera 0 1 3 0 1 0 0 1 0 50
quadLight -0.25 1.999 -0.25 0 0 0.5 0.5 0 0 30 26 21
quadLight -0.95 0.3 -0.6 0 0.5 0 0 0 0.6 4 5 8
maxverts 8
vertex -1 0 -1
vertex 1 0 -1
vertex 1 0 1
vertex -1 0 1
vertex -1 2 -1
vertex 1 2 -1
vertex 1 2 1
vertex -1 2 1
diffuse 0.8 0.8 0.8
tri 0 2 1
tri 0 3 2
tri 4 5 6
tri 4 6 7
tri 0 1 5
tri 0 5 4
diffuse 0.7 0.1 0.1
tri 0 4 7
tri 0 7 3
diffuse 0.1 0.7 0.1
tri 1 2 6
tri 1 6 5
diffuse 0.5 0.5 0.9
sphere 0.4 0.35 0.1 0.35
pushTransform
translate -0.4 0.5 -0.3
scale 0.3 0.5 0.2
sphere 0 0 0 1
popTransform
diffuse 0 0 0
pushTransform
translate 0.6 1.2 -0.9
rotate 0 1 0 30
tri 0 1 5
popTransform
maxvertnorms 3
vertexnormal -0.2 0.1 0.3 -0.6 0.8 0
vertexnormal 0.3 0.1 0.5 0.6 0.8 0
vertexnormal 0 0.6 0.2 0 0.8 0.6
diffuse 0.9 0.6 0.2
trinormal 0 1 2
"
    )
}

/// Every camera sample of the scene, in batches of 64 as the renderer makes them: the
/// batch through `radiances` (the lanes) against each sample through `radiance`.
fn the_lanes_give_every_paths_bits(text: &str) {
    let mut session = Session::parse_text("lanes.test", text.as_bytes(), SessionOptions::default());
    session.build();
    let built = session
        .built
        .as_ref()
        .unwrap_or_else(|| panic!("{}", session.diags.render(&session.desc.sources)));
    let scene = &built.scene;
    assert!(scene.lambertian_and_quad_lit(), "the lanes' kind of scene");
    if !std::is_x86_feature_detected!("avx2") {
        eprintln!("skipped: this CPU has no AVX2, so the path tracer runs one path at a time only");
        return;
    }
    let job = built.job();
    let (w, h) = (job.resolution.width, job.resolution.height);
    let (mut rays, mut samplers) = (Vec::new(), Vec::new());
    for y in 0..h {
        for x in 0..w {
            for i in 0..job.spp {
                let mut s = Sampler::start(job.sampler, job.seed, x, y, i);
                let (u, v) = s.uniform2();
                rays.push(
                    scene
                        .camera
                        .ray(job.resolution, x as f64 + u as f64, y as f64 + v as f64, (0.5, 0.5)),
                );
                samplers.push(s);
            }
        }
    }
    let (mut lit, mut bounced) = (0, 0);
    for (rays, samplers) in rays.chunks(64).zip(samplers.chunks(64)) {
        let mut hits = vec![None; rays.len()];
        scene.closest_hits(rays, &mut hits);
        let (mut lanes, mut one) = (TraceCounts::default(), TraceCounts::default());
        let mut batch = samplers.to_vec();
        let mut out = vec![Color::ZERO; rays.len()];
        built
            .integrator
            .radiances(scene, rays, &hits, &mut batch, &mut lanes, &mut out);
        for (k, ray) in rays.iter().enumerate() {
            let mut s = samplers[k].clone();
            let want = built
                .integrator
                .radiance(scene, ray, CameraHit::Traced(hits[k]), &mut s, &mut one);
            for a in 0..3 {
                assert_eq!(
                    out[k][a].to_bits(),
                    want[a].to_bits(),
                    "sample {k}: {} against {want}",
                    out[k]
                );
            }
            lit += (want != Color::ZERO) as u32;
        }
        assert_eq!(lanes, one, "the same rays traced");
        bounced += one.rays - rays.len() as u64;
    }
    // Not a vacuous comparison: with a scattering event or more, a good part of the
    // samples gather light (about 40 % at depth 1: the box's edges and the shadows stay
    // dark), and paths go on past the camera; at depth 0 only the light facing the
    // camera is seen.
    let depth_zero = text.contains("maxdepth 0");
    let least = if depth_zero { 1 } else { rays.len() / 3 };
    assert!(lit as usize >= least, "{lit} of {} samples lit", rays.len());
    assert!(
        depth_zero || bounced > rays.len() as u64,
        "{bounced} rays after the camera's"
    );
}

#[test]
fn cosine_sampled_paths_in_lanes_are_the_one_path_code_bit_for_bit() {
    for depth in [1, 3, 7] {
        the_lanes_give_every_paths_bits(&scene("cosine", depth, "off"));
    }
}

#[test]
fn brdf_sampled_paths_in_lanes_are_the_one_path_code_bit_for_bit() {
    for depth in [0, 2, 5] {
        the_lanes_give_every_paths_bits(&scene("brdf", depth, "off"));
    }
}

#[test]
fn paths_ended_by_russian_roulette_in_lanes_are_the_one_path_code_bit_for_bit() {
    // Unbounded (ended by the roulette alone) and bounded depths, both samplings.
    for (sampling, depth) in [("cosine", -1), ("brdf", -1), ("cosine", 4), ("brdf", 2)] {
        the_lanes_give_every_paths_bits(&scene(sampling, depth, "on"));
    }
}
