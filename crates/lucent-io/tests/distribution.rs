//! The distribution effects of the `raytracer` integrator, rendered: antialiasing,
//! soft shadows, refraction, glossy reflection, the orthographic camera — each checked
//! against what can be worked out by hand, and all of them the same bytes for any
//! thread count.

mod common;

use lucent_core::accel::AccelKind;

fn render_bytes(text: &str, threads: usize) -> Vec<u8> {
    common::render_rgb8("t.test", text, AccelKind::Bvh, threads)
}

/// An emissive rectangle `x0..x1 × y0..y1` in the plane z = 0, seen from +z.
fn emitter(x0: f64, x1: f64, y0: f64, y1: f64, first_vertex: usize) -> String {
    let v = first_vertex;
    format!(
        "ambient 0 0 0\nemission 1 1 1\nvertex {x0} {y0} 0\nvertex {x1} {y0} 0\nvertex {x1} {y1} 0\nvertex {x0} {y1} 0\n\
         tri {} {} {}\ntri {} {} {}\nemission 0 0 0\n",
        v,
        v + 1,
        v + 2,
        v,
        v + 2,
        v + 3
    )
}

#[test]
fn antialiasing_averages_stratified_samples_over_the_pixel() {
    // One pixel covering [-1, 1]² through an orthographic camera; the left half of it is
    // an emitter of value 1. A 4 × 4 stratified grid puts exactly 8 samples on it: 0.5,
    // which the 8-bit truncation makes 127.
    let scene = |spp: u32| {
        format!(
            "size 1 1\northocamera 0 0 5 0 0 0 0 1 0 2\nspp {spp}\n{}",
            emitter(-10.0, 0.0, -10.0, 10.0, 0)
        )
    };
    assert_eq!(render_bytes(&scene(16), 1), [127, 127, 127]);
    // Nine samples (3 × 3): the middle column straddles the edge, so between 3/9 and 6/9.
    let nine = render_bytes(&scene(9), 1)[0];
    assert!((85..=170).contains(&nine), "{nine}");
}

#[test]
fn the_orthographic_camera_sees_a_sphere_at_its_true_size() {
    // Height 4 over 40 pixels: a unit sphere covers a disc of radius 10 pixels.
    let text = "size 40 40\northocamera 0 0 5 0 0 0 0 1 0 4\nambient 0 0 0\nemission 1 1 1\nsphere 0 0 0 1\n";
    let img = render_bytes(text, 1);
    let lit = img.chunks(3).filter(|p| p[0] == 255).count();
    let disc = std::f64::consts::PI * 100.0;
    assert!((lit as f64 - disc).abs() < 20.0, "{lit} pixels vs {disc}");
}

#[test]
fn area_lights_cast_soft_shadows_and_point_lights_hard_ones() {
    // A floor lit from above, a small box hovering over it; a row of pixels across the
    // shadow's edge. The point light gives lit and shadowed pixels only; the quad light
    // gives a penumbra of values in between, rising steadily from the umbra outward.
    // The camera looks down from just above the floor, under the box, so it sees only
    // the floor.
    let common = "size 64 8\northocamera 0 0.3 0 0 0 0 0 0 -1 2\nambient 0 0 0\ndiffuse 1 1 1\n\
                  vertex -20 0 -20\nvertex 20 0 -20\nvertex 20 0 20\nvertex -20 0 20\ntri 0 2 1\ntri 0 3 2\n\
                  box -8 1 -8 0 1.1 8\n";
    let hard = render_bytes(&format!("{common}point 0 2 0 1 1 1\n"), 1);
    let soft = render_bytes(
        &format!("{common}lightsamples 64\nlightstratify on\nquadLight -3 2 -3 0 0 6 6 0 0 2 2 2\n"),
        1,
    );
    let row = |img: &[u8]| -> Vec<u8> { (0..64).map(|x| img[3 * (4 * 64 + x)]).collect() };
    let (hard, soft) = (row(&hard), row(&soft));
    // Hard: black, then at once (nearly) full light.
    let edge = hard.iter().position(|&v| v > 0).unwrap();
    assert!(edge > 0 && hard[edge] > 200, "{hard:?}");
    // Soft: from black up to the brightest pixel through a penumbra, never darkening.
    let peak = soft.iter().enumerate().max_by_key(|(_, &v)| v).unwrap().0;
    let rise = &soft[..=peak];
    assert!(rise.windows(2).all(|w| w[1] >= w[0]), "{soft:?}");
    let penumbra = rise
        .iter()
        .filter(|&&v| v > 0 && (v as u32) < 9 * soft[peak] as u32 / 10)
        .count();
    assert!(penumbra >= 6 && soft[0] == 0, "{soft:?}");
}

#[test]
fn glass_of_index_one_is_invisible_and_glass_of_index_one_and_a_half_is_not() {
    // Behind the sphere an emitter with a sharp edge; no lights, so shading is only what
    // the rays see. With ior 1 and no reflection the sphere bends nothing.
    let backdrop = emitter(-10.0, 0.3, -10.0, 10.0, 0);
    let base = format!("size 40 30\ncamera 0 0 6 0 0 0 0 1 0 40\nmaxdepth 4\n{backdrop}");
    let empty = render_bytes(&base, 1);
    let glass = |ior: f64| {
        format!("{base}pushTransform\ntranslate 0 0 2\nambient 0 0 0\nspecular 0 0 0\ntransparent 1 1 1\nior {ior}\nsphere 0 0 0 1\npopTransform\n")
    };
    let same = render_bytes(&glass(1.0), 1);
    let differing = empty.chunks(3).zip(same.chunks(3)).filter(|(a, b)| a != b).count();
    assert!(differing <= 2, "{differing} pixels differ");
    let bent = render_bytes(&glass(1.5), 1);
    let differing = empty.chunks(3).zip(bent.chunks(3)).filter(|(a, b)| a != b).count();
    assert!(differing > 40, "{differing}");
}

#[test]
fn every_effect_gives_the_same_bytes_for_any_thread_count() {
    let text = "size 48 36\ncamera 0 2 6 0 0.5 0 0 1 0 45\nspp 4\nlightsamples 4\nlightstratify on\nlens 0.1 6\n\
                quadLight -1 4 -1 0 0 2 2 0 0 5 5 5\nambient 0.05 0.05 0.05\ndiffuse 0.6 0.6 0.6\n\
                plane 0 0 0 0 1 0\nspecular 0.7 0.7 0.7\nglossy 30 4\nsphere -1 1 0 1\nglossy off\n\
                transparent 0.9 0.9 0.9\nior 1.5\nspecular 1 1 1\ndiffuse 0 0 0\nsphere 1.2 0.7 0.5 0.7\n";
    let one = render_bytes(text, 1);
    assert_eq!(one, render_bytes(text, 2));
    assert_eq!(one, render_bytes(text, 3));
    assert!(one.iter().any(|&v| v > 50));
}

/// A small noisy scene: jittered pixel samples, a quad light's soft shadow and glossy
/// reflection, on an image whose sides are not multiples of the 16-pixel tiles.
const NOISY: &str = "size 37 23\ncamera 0 1 4 0 0 0 0 1 0 50\nspp 4\nlightsamples 4\n\
    quadLight -0.5 3 -0.5 0 0 1 1 0 0 4 4 4\nambient 0.05 0.05 0.05\ndiffuse 0.6 0.6 0.6\n\
    plane 0 -1 0 0 1 0\nspecular 0.5 0.5 0.5\nglossy 50 2\nsphere 0 0 0 0.8\n";

#[test]
fn a_crop_is_exactly_those_pixels_of_the_whole_image() {
    use lucent_core::render::job::PixelRect;
    let whole = common::render_job("t.test", NOISY, |_| {});
    assert_eq!((whole.width, whole.height), (37, 23));
    let rect = PixelRect {
        x0: 5,
        y0: 3,
        x1: 30,
        y1: 20,
    };
    let crop = common::render_job("t.test", NOISY, |job| job.pixels = rect);
    assert_eq!((crop.width, crop.height), (25, 17));
    for y in 0..17 {
        for x in 0..25 {
            let a = crop.pixels[(y * 25 + x) as usize];
            let b = whole.pixels[((y + 3) * 37 + x + 5) as usize];
            assert_eq!(a, b, "pixel ({}, {})", x + 5, y + 3);
        }
    }
}

#[test]
fn the_seed_picks_the_noise_and_sample_ranges_take_their_samples() {
    let whole = common::render_job("t.test", NOISY, |_| {});
    let same = common::render_job("t.test", NOISY, |job| job.seed = 0);
    assert_eq!(whole, same, "seed 0 is the default");
    let reseeded = common::render_job("t.test", NOISY, |job| job.seed = 7);
    let changed = whole
        .pixels
        .iter()
        .zip(&reseeded.pixels)
        .filter(|(a, b)| a != b)
        .count();
    assert!(changed > whole.pixels.len() / 2, "{changed} pixels changed");
    // A noise-free scene (one sample through each pixel centre, point lights) does not
    // depend on the seed.
    let clean = "size 8 8\ncamera 0 0 4 0 0 0 0 1 0 45\npoint 1 1 3 1 1 1\ndiffuse 1 0 0\nsphere 0 0 0 1\n";
    assert_eq!(
        common::render_job("t.test", clean, |_| {}),
        common::render_job("t.test", clean, |job| job.seed = 99)
    );
    // Samples 0..2 and 2..4, each averaged, average to the whole (to rounding).
    let first = common::render_job("t.test", NOISY, |job| job.samples = 0..2);
    let second = common::render_job("t.test", NOISY, |job| job.samples = 2..4);
    assert_ne!(first, second);
    for ((a, b), w) in first.pixels.iter().zip(&second.pixels).zip(&whole.pixels) {
        let mean = (*a + *b) * 0.5;
        assert!(
            (mean - *w).abs().max_element() <= 1e-6 * (1.0 + w.max_element()),
            "{mean} vs {w}"
        );
    }
}

#[test]
fn the_largest_sample_count_needs_no_table_of_its_samples() {
    // With a lens, lens strata are shuffled by a table of spp entries: 2³² − 1 of them
    // would be 16 GB for every pixel. Beyond 65,536 the lens samples are independent.
    let text = "size 2 2\ncamera 0 0 5 0 0 0 0 1 0 45\nlens 0.1 5\nspp 4294967295\nambient 1 1 1\nsphere 0 0 0 1\n";
    let film = common::render_job("t.test", text, |job| *job = job.probe(2, 3));
    assert_eq!((film.width, film.height), (2, 2));
    assert!(film.pixels.iter().all(|c| c.is_finite()));
}

#[test]
fn the_ray_tracer_gives_each_sample_of_a_batch_its_own_colour() {
    use lucent_core::integrator::{CameraHit, TraceCounts};
    use lucent_core::math::Color;
    use lucent_core::sampler::{Sampler, SamplerKind};
    use lucent_io::session::{Session, SessionOptions};
    // The renderer hands the ray tracer its camera samples in batches, whose first
    // shadow rays toward point and directional lights it traces together. Every sample
    // must come out as it does alone — the same bits, the same rays counted — here with
    // two point lights (one attenuated, one hidden from part of the floor by a sphere), a
    // directional light, an area light, glass, glossy and mirror surfaces, and rays that
    // meet nothing.
    let text = "size 24 18\ncamera 0 2 6 0 0.5 0 0 1 0 50\nlightsamples 4\nmaxdepth 4\n\
                attenuation 1 0.1 0\npoint 2 5 3 0.8 0.8 0.8\nattenuation 1 0 0\npoint -3 3 1 0.5 0.4 0.3\n\
                directional 1 1 1 0.3 0.3 0.3\nquadLight -1 4 -1 0 0 2 2 0 0 2 2 2\n\
                ambient 0.05 0.05 0.05\ndiffuse 0.6 0.6 0.6\nspecular 0.3 0.3 0.3\nshininess 20\n\
                plane 0 0 0 0 1 0\nsphere 2.2 0.6 -0.5 0.6\nspecular 0.7 0.7 0.7\nglossy 30 4\nsphere -1 1 0 1\n\
                glossy off\ntransparent 0.9 0.9 0.9\nior 1.5\nspecular 1 1 1\ndiffuse 0 0 0\nsphere 1.2 0.7 0.5 0.7\n";
    let mut session = Session::parse_text("t.test", text.as_bytes(), SessionOptions::default());
    session.build();
    let built = session.built.as_ref().expect("the scene builds");
    let (scene, integrator) = (&built.scene, &built.integrator);
    let res = built.settings.resolution;
    let (mut rays, mut samplers) = (Vec::new(), Vec::new());
    for y in 0..res.height {
        for x in 0..res.width {
            for i in 0..2 {
                let mut s = Sampler::start(SamplerKind::Independent, 0, x, y, i);
                let (u, v) = s.uniform2();
                rays.push(
                    scene
                        .camera
                        .ray(res, (x as f32 + u) as f64, (y as f32 + v) as f64, (0.5, 0.5)),
                );
                samplers.push(s);
            }
        }
    }
    let mut hits = vec![None; rays.len()];
    scene.closest_hits(&rays, &mut hits);
    let misses = hits.iter().filter(|h| h.is_none()).count();
    assert!(misses > 50 && misses < rays.len() - 300, "{misses} of {}", rays.len());

    let mut alone_counts = TraceCounts::default();
    let alone: Vec<Color> = rays
        .iter()
        .zip(&samplers)
        .map(|(r, s)| integrator.radiance(scene, r, CameraHit::Untraced, &mut s.clone(), &mut alone_counts))
        .collect();
    let distinct: std::collections::HashSet<[u32; 3]> = alone.iter().map(|c| c.to_array().map(f32::to_bits)).collect();
    assert!(distinct.len() > 300, "{}", distinct.len());
    // Batches of the renderer's size, of an odd size, and one of every sample.
    for size in [64, 7, rays.len()] {
        let mut counts = TraceCounts::default();
        let mut out = vec![Color::ZERO; rays.len()];
        let mut batch_samplers = samplers.clone();
        for (((r, h), s), o) in rays
            .chunks(size)
            .zip(hits.chunks(size))
            .zip(batch_samplers.chunks_mut(size))
            .zip(out.chunks_mut(size))
        {
            integrator.radiances(scene, r, h, s, &mut counts, o);
        }
        for (k, (a, b)) in alone.iter().zip(&out).enumerate() {
            assert_eq!(
                a.to_array().map(f32::to_bits),
                b.to_array().map(f32::to_bits),
                "sample {k}, batches of {size}"
            );
        }
        assert_eq!(counts, alone_counts, "batches of {size}");
    }
}
