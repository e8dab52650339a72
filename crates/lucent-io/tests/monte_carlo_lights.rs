//! Everything a lucent scene can light with, in the Monte Carlo integrators
//! (EXTENSIONS.md, "In the Monte Carlo integrators"): the environment map, emissive
//! objects (spheres, stretched spheres, boxes, OBJ meshes with `Ke`), point and
//! directional lights, and textures — against answers known in closed form and against
//! the ray tracer, which shares their meaning.
//!
//! Every comparison is in linear radiance, and every tolerance says why it is right.

mod common;

use common::{diagnostics, render_scene, TempDir};

use lucent_core::accel::AccelKind;
use lucent_core::image::Image;

fn render(scene: &str, text: &str) -> Image {
    render_scene(scene, text, AccelKind::Bvh, 2).0
}

/// Mean of the green channel and its standard error, from the spread of the pixels
/// (each an independent estimate of the same radiance).
fn mean_and_error(img: &Image) -> (f64, f64) {
    let v: Vec<f64> = img.pixels.iter().map(|p| p.y as f64).collect();
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

fn rmse(a: &Image, b: &Image) -> f64 {
    let sum: f64 = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .map(|(p, q)| ((*p - *q).length_squared() / 3.0) as f64)
        .sum();
    (sum / a.pixels.len() as f64).sqrt()
}

/// Writes a `w × h` linear EXR environment whose texel (x, y) has grey value `f(x, y)`.
fn write_sky(dir: &TempDir, name: &str, w: u32, h: u32, f: impl Fn(u32, u32) -> f32) {
    let f = &f;
    let data: Vec<f32> = (0..h).flat_map(|y| (0..w).flat_map(move |x| [f(x, y); 3])).collect();
    image::Rgb32FImage::from_raw(w, h, data)
        .unwrap()
        .save(dir.0.join(name))
        .unwrap();
}

const MODES: [(&str, &str, &str); 5] = [
    ("pathtracer", "off", "brdf"),
    ("pathtracer", "off", "cosine"),
    ("pathtracer", "on", "cosine"),
    ("pathtracer", "mis", "brdf"),
    ("direct", "on", "cosine"),
];

fn integrator(mode: (&str, &str, &str)) -> String {
    let (integrator, nee, sampling) = mode;
    if integrator == "direct" {
        "integrator direct\n".into()
    } else {
        format!("integrator pathtracer\nmaxdepth -1\nnexteventestimation {nee}\nimportancesampling {sampling}\n")
    }
}

#[test]
fn a_diffuse_sphere_under_a_constant_sky_has_radiance_albedo_times_sky() {
    // A convex object sees nothing but sky over every hemisphere: L = ρ · L_sky, for
    // every mode (the sky is found by paths, sampled by NEE, or both under MIS). The
    // camera sees only the sphere. 24 × 24 pixels × 16 samples: the tolerance is 5
    // standard errors of the mean (from the pixels' spread) and at most 1.5%; a light
    // pdf off by the sin θ of the map's rows, or a sky counted twice, is off by more.
    let dir = TempDir::new("sky");
    write_sky(&dir, "sky.exr", 8, 4, |_, _| 0.4);
    for mode in MODES {
        let text = format!(
            "size 24 24\nspp 16\n{}camera 0 0 3 0 0 0 0 1 0 15\nenvmap sky.exr 2\nambient 0 0 0\ndiffuse 0.5 0.5 0.5\nsphere 0 0 0 1\n",
            integrator(mode)
        );
        let (mean, se) = mean_and_error(&render(&dir.scene(), &text));
        eprintln!("sky {mode:?}: {mean:.4} ± {se:.4}");
        assert!(
            (mean - 0.4).abs() <= 5.0 * se + 1e-6 && (mean - 0.4).abs() <= 0.006,
            "{mode:?}: {mean} ± {se}, want 0.4"
        );
    }
    // Looking past the sphere: the sky itself, exactly.
    let text = format!(
        "size 4 4\nspp 4\n{}camera 0 0 3 0 0 6 0 1 0 15\nenvmap sky.exr 2\nsphere 0 0 0 1\n",
        integrator(MODES[3])
    );
    let img = render(&dir.scene(), &text);
    assert!(
        img.pixels.iter().all(|p| (p.y - 0.8).abs() < 1e-6),
        "{:?}",
        img.pixels[0]
    );
}

#[test]
fn a_sun_in_the_sky_gives_a_clean_shadow_with_mis_at_16_samples() {
    // A floor and a sphere under a dim sky with a small, very bright sun (4 texels of a
    // 64 × 32 map, 99% of its power). BSDF sampling alone finds the sun with a chance of
    // about 1% per path; MIS samples the map where the sun is. Against a 1024-sample MIS
    // reference, at 16 samples MIS must be at least 20 times closer than BSDF sampling
    // (measured: 72 times; 17 with a piecewise-constant instead of bilinear density in
    // the map's cells) and within 6% of the image's mean radiance (measured: 4.4%).
    let dir = TempDir::new("sun");
    write_sky(&dir, "sun.exr", 64, 32, |x, y| {
        if (20..22).contains(&x) && (8..10).contains(&y) {
            3000.0
        } else {
            0.05
        }
    });
    let scene = |settings: &str, spp: u32| {
        format!(
            "size 32 24\nspp {spp}\nintegrator pathtracer\nmaxdepth 3\n{settings}\n\
             camera 0 3 6 0 0 0 0 1 0 45\nenvmap sun.exr\nambient 0 0 0\ndiffuse 0.6 0.6 0.6\n\
             maxverts 4\nvertex -8 0 -8\nvertex 8 0 -8\nvertex 8 0 8\nvertex -8 0 8\ntri 0 2 1\ntri 0 3 2\n\
             sphere 0 1 0 1\n"
        )
    };
    let reference = render(
        &dir.scene(),
        &scene("nexteventestimation mis\nimportancesampling brdf", 1024),
    );
    let mis = render(
        &dir.scene(),
        &scene("nexteventestimation mis\nimportancesampling brdf", 16),
    );
    let brdf = render(
        &dir.scene(),
        &scene("nexteventestimation off\nimportancesampling brdf", 16),
    );
    let mean = reference.pixels.iter().map(|p| p.y as f64).sum::<f64>() / reference.pixels.len() as f64;
    let (e_mis, e_brdf) = (rmse(&mis, &reference), rmse(&brdf, &reference));
    eprintln!(
        "sun: mean {mean:.3}, RMSE at 16 spp: MIS {e_mis:.4}, BSDF sampling {e_brdf:.4} ({:.1}x)",
        e_brdf / e_mis
    );
    assert!(e_mis * 20.0 < e_brdf, "MIS {e_mis}, BSDF sampling {e_brdf}");
    assert!(e_mis < 0.06 * mean, "MIS {e_mis}, mean {mean}");
    // The shadow is there: on pixel row 13 the floor in the sphere's shadow (column 21)
    // gets the sky alone, 2–3% of what the open floor (column 2) gets.
    let row = 13 * 32;
    let (under, open) = (reference.pixels[row + 21].y, reference.pixels[row + 2].y);
    assert!(under < 0.05 * open, "shadow {under}, open floor {open}");
}

/// A closed box of emitters around the origin, as an OBJ file with an `Ke` material
/// (its faces wound inward, though emission is two-sided anyway).
fn emissive_obj(dir: &TempDir) {
    dir.write("glow.mtl", "newmtl glow\nKd 0 0 0\nKe 1 1 1\n");
    let mut obj = String::from("mtllib glow.mtl\nusemtl glow\n");
    for i in 0..8 {
        let c = |bit: u32| if i >> bit & 1 == 1 { 3 } else { -3 };
        obj += &format!("v {} {} {}\n", c(0), c(1), c(2));
    }
    for f in ["1 2 4 3", "5 7 8 6", "1 5 6 2", "3 4 8 7", "1 3 7 5", "2 6 8 4"] {
        obj += &format!("f {f}\n");
    }
    dir.write("glow.obj", &obj);
}

#[test]
fn a_diffuse_sphere_inside_an_emitter_has_radiance_albedo_times_emission() {
    // Whatever shape the emitter around it has — a sphere, a stretched sphere (points
    // drawn with rejection, its area by quadrature), a box (twelve triangles), an OBJ
    // mesh with Ke — a diffuse sphere of albedo ρ that sees only emitter everywhere has
    // L = ρ · E, in every mode. The emitters do not reflect (diffuse 0). 24 × 24 × 16:
    // tolerance 5 standard errors and at most 3% (one light sample per point on a box
    // seen at grazing angles has a standard error near 1.4% here): a pdf by area off by
    // the stretch (up to 5×), or emission counted by both NEE and the path (2×), is off
    // by far more.
    let dir = TempDir::new("enclosed");
    emissive_obj(&dir);
    let emitters = [
        "emission 1 1 1\nsphere 0 0 0 4",
        "emission 1 1 1\npushTransform\nscale 3 4 5\nrotate 1 1 0 30\nsphere 0 0 0 1\npopTransform",
        "emission 1 1 1\nbox -3 -3 -3 3 3 3",
        "mesh glow.obj",
    ];
    for emitter in emitters {
        for mode in MODES {
            let text = format!(
                "size 24 24\nspp 16\n{}camera 0 0 2 0 0 0 0 1 0 20\nambient 0 0 0\ndiffuse 0 0 0\n{emitter}\n\
                 emission 0 0 0\ndiffuse 0.5 0.5 0.5\nsphere 0 0 0 0.5\n",
                integrator(mode)
            );
            let (mean, se) = mean_and_error(&render(&dir.scene(), &text));
            eprintln!("inside {emitter:?} {mode:?}: {mean:.4} ± {se:.4}");
            assert!(
                (mean - 0.5).abs() <= 5.0 * se + 1e-6 && (mean - 0.5).abs() <= 0.015,
                "{emitter:?} {mode:?}: {mean} ± {se}, want 0.5"
            );
        }
    }
}

#[test]
fn an_emissive_plane_is_counted_by_the_paths_alone_and_said_so() {
    // A plane cannot be light-sampled: a warning says so, and NEE on (which could not
    // sample it) still sees it through the paths: an infinite emissive plane under a
    // diffuse floor of albedo ρ... seen from between them, the floor shows ρ·E.
    let text = |nee: &str| {
        format!(
            "size 16 16\nspp 16\nintegrator pathtracer\nmaxdepth 1\nnexteventestimation {nee}\n\
             camera 0 1 0 0 0 0 0 0 -1 20\nambient 0 0 0\ndiffuse 0 0 0\nemission 1 1 1\nplane 0 2 0 0 -1 0\n\
             emission 0 0 0\ndiffuse 0.5 0.5 0.5\nplane 0 0 0 0 1 0\n"
        )
    };
    let d = diagnostics("plane.test", &text("on"), false);
    assert!(
        d.iter()
            .any(|w| w.contains("warning: emission: light sampling cannot draw points on a plane")),
        "{d:?}"
    );
    for nee in ["off", "on", "mis"] {
        let (mean, se) = mean_and_error(&render("plane.test", &text(nee)));
        eprintln!("emissive plane, nee {nee}: {mean:.4} ± {se:.4}");
        assert!((mean - 0.5).abs() <= 5.0 * se + 1e-6, "nee {nee}: {mean} ± {se}");
    }
}

/// A floor, a sphere and a textured, bump-mapped plate under a point light with
/// attenuation and a directional light: diffuse only, no ambient.
fn lit_by_delta_lights(dir: &TempDir, integrator: &str) -> String {
    // A 4 × 4 texture of greys and colours, and a height field of ridges.
    let tex: Vec<u8> = (0..16u8)
        .flat_map(|i| [40 + 13 * i, 200 - 11 * i, 90 + (i % 4) * 40])
        .collect();
    image::RgbImage::from_raw(4, 4, tex)
        .unwrap()
        .save(dir.0.join("tex.png"))
        .unwrap();
    let bumps: Vec<u8> = (0..64u32).map(|i| if (i % 8) < 4 { 30 } else { 220 }).collect();
    image::GrayImage::from_raw(8, 8, bumps)
        .unwrap()
        .save(dir.0.join("bumps.png"))
        .unwrap();
    format!(
        "size 40 30\nspp 1\n{integrator}\ncamera 0 4 7 0 0 0 0 1 0 50\nambient 0 0 0\nspecular 0 0 0\n\
         attenuation 1 0.1 0.05\npoint 1 3 2 2 2 2\ndirectional -1 2 1 0.4 0.35 0.3\n\
         checker squares 0.9 0.9 0.9 0.2 0.3 0.4 0.5\ndiffusemap squares\ndiffuse 1 1 1\n\
         maxverts 4\nvertex -5 0 -5\nvertex 5 0 -5\nvertex 5 0 5\nvertex -5 0 5\ntri 0 2 1\ntri 0 3 2\n\
         texture tex tex.png\ndiffusemap tex\nsphere -1 1 0 1\n\
         texture bumps bumps.png\ndiffusemap off\nbumpmap bumps 0.05\ndiffuse 0.7 0.5 0.3\nsphere 1.5 0.8 0.5 0.8\n"
    )
}

#[test]
fn point_and_directional_lights_and_textures_light_as_in_the_ray_tracer() {
    // EXTENSIONS.md: a delta light contributes f · max(n·ω, 0) · L / attenuation(d),
    // one shadow ray each; textures and bump maps act as in the ray tracer. With a
    // diffuse BRDF f = kd/π, so at the pixel centres (spp 1) `direct` and the path
    // tracer with NEE and one scattering event must give the ray tracer's image
    // (ambient 0, no specular, no mirror rays) divided by π — a deterministic answer:
    // 10⁻⁵ relative, rounding of the sums.
    let dir = TempDir::new("delta");
    let whitted = render(&dir.scene(), &lit_by_delta_lights(&dir, "maxdepth 0"));
    let lit = whitted.pixels.iter().filter(|p| p.y > 0.01).count();
    assert!(lit > 600, "the scene is lit: {lit} pixels");
    for integrator in [
        "integrator direct",
        "integrator pathtracer\nmaxdepth 1\nnexteventestimation on",
    ] {
        let mc = render(&dir.scene(), &lit_by_delta_lights(&dir, integrator));
        for (i, (w, m)) in whitted.pixels.iter().zip(&mc.pixels).enumerate() {
            let want = *w / std::f32::consts::PI;
            assert!(
                (*m - want).abs().max_element() <= 1e-5 * want.max_element().max(1e-3),
                "{integrator:?}, pixel ({}, {}): {m} against {want}",
                i % 40,
                i / 40
            );
        }
    }
}
