//! The parser, the build step and the renderer never panic and never take long on small
//! input, whatever it says: random mutations of a valid scene, and random scenes made of
//! every command with random arguments, rendered (deterministic fuzzers that run with the
//! tests; `fuzz/` has the coverage-guided ones).

use lucent_io::cse167::{command_names, parse_bytes, ParseOptions};
use lucent_io::session::{Session, SessionOptions};

const SEED_SCENE: &str = "size 16 12\ncamera 0 0 5 0 0 0 0 1 0 45\nmaxdepth 3\nattenuation 1 0.1 0.01\npoint 1 2 3 1 1 1\ndirectional 0 1 1 .5 .5 .5\nmaxverts 4\nvertex -1 -1 0\nvertex 1 -1 0\nvertex 1 1 0\nvertexnormal 0 0 0 0 0 1\nvertexnormal 1 0 0 0 1 1\nvertexnormal 0 1 0 1 0 1\ndiffuse 0.5 0.2 0.1\nspecular .3 .3 .3\nshininess 20\npushTransform\nrotate 0 1 0 30\nscale 1 2 0.5\nsphere 0 0 0 1\ntri 0 1 2\ntrinormal 0 1 2\npopTransform\nplane 0 -1 0 0 1 0\nbox -1 -1 -1 1 1 1\ncylinder 1 -1 1\ndisk 1\ncone 1 2\nquadric 1 1 -1 0 0 0 0 0 0 -0.1 -1 -1 -1 1 1 1\nnurbs 2 1 3 2\nknotsu 0 0 0 1 1 1\nknotsv 0 0 1 1\ncpoint 0 0 0 1\ncpoint 1 0 1 .7\ncpoint 2 0 0 1\ncpoint 0 1 0 1\ncpoint 1 1 1 .7\ncpoint 2 1 0 1\nobjectbegin thing\nsphere 0 0 0 1\ntri 0 1 2\nobjectend\npushTransform\ntranslate 1 0 0\ninstance thing\npopTransform\nintegrator raytracer\ngamma 2.2\n";

struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

/// Tokens worth inserting besides every command name and the seed's own tokens.
const INTERESTING: &[&str] = &[
    "0",
    "-1",
    "1e38",
    "-1e38",
    "1e-45",
    "nan",
    "inf",
    "99999999999999999999",
    "+",
    ".",
    "\u{0}",
    "\u{ff}",
    "#",
    "\t",
    "thing",
    "4294967296",
    "-2147483649",
    "\r",
    "\n",
];

#[test]
fn random_mutations_never_panic() {
    let (seed, seed_diags) = parse_bytes("seed.test", SEED_SCENE.as_bytes(), ParseOptions { strict: true });
    assert!(
        !seed_diags.has_errors() && seed.shapes.len() == 13,
        "{}",
        seed_diags.render(&seed.sources)
    );
    let mut rng = Rng(0x5eed);
    let tokens: Vec<&str> = SEED_SCENE.split([' ', '\n']).collect();
    let interesting: Vec<&str> = INTERESTING.iter().copied().chain(command_names()).collect();
    for _ in 0..3000 {
        let mut bytes = SEED_SCENE.as_bytes().to_vec();
        for _ in 0..1 + rng.below(6) {
            let pos = rng.below(bytes.len() + 1);
            match rng.below(5) {
                0 if pos < bytes.len() => bytes[pos] = rng.next() as u8,
                1 if pos < bytes.len() => {
                    bytes.remove(pos);
                }
                2 => {
                    let t = interesting[rng.below(interesting.len())];
                    bytes.splice(pos..pos, t.bytes());
                }
                3 => {
                    let t = tokens[rng.below(tokens.len())];
                    bytes.splice(pos..pos, format!(" {t}").into_bytes());
                }
                _ => {
                    let end = (pos + rng.below(40)).min(bytes.len());
                    bytes.drain(pos..end);
                }
            }
        }
        let options = SessionOptions {
            strict: rng.below(2) == 0,
            ..SessionOptions::default()
        };
        let mut session = Session::parse_text("fuzz.test", &bytes, options);
        if session.build() {
            // A few rays across the picture, with the shading data of what they hit.
            let built = session.built.as_ref().unwrap();
            let scene = &built.scene;
            let resolution = built.settings.resolution;
            for k in 0..16 {
                let (x, y) = ((k % 4) as f64 * 4.0 + 0.5, (k / 4) as f64 * 3.0 + 0.5);
                let ray = scene.camera.ray(resolution, x, y, (0.5, 0.5));
                if let Some(hit) = scene.closest_hit(&ray) {
                    let _ = scene.surface_point(&hit, &ray);
                }
                let _ = scene.occluded(&ray);
            }
        }
        let _ = session.diags.render(&session.desc.sources);
    }
}

/// Arguments worth giving any command: numbers from the ordinary to the absurd, names,
/// files that do not exist, devices.
const ARGUMENTS: &[&str] = &[
    "0",
    "1",
    "2",
    "-1",
    "0.5",
    "3",
    "16",
    "100",
    "1e-3",
    "1e6",
    "1e9",
    "1e30",
    "3e38",
    "1e-37",
    "2147483647",
    "4294967295",
    "-2147483648",
    "on",
    "off",
    "mis",
    "ggx",
    "phong",
    "brdf",
    "cosine",
    "hemisphere",
    "loop",
    "catmullclark",
    "pathtracer",
    "raytracer",
    "t",
    "thing",
    "missing.obj",
    "/dev/zero",
    "x.png",
];

/// A random scene of `lines` commands from the command table after a valid `size` and
/// `camera`. Each line is drawn until the parser takes it in the scene so far (up to 40
/// tries, else the line is left out; one in fifty is kept whatever it says), so that most
/// scenes get past the parser to the build and the renderer.
fn random_scene(rng: &mut Rng, lines: usize) -> String {
    let commands: Vec<&str> = command_names().collect();
    let mut text = String::from("size 8 6\ncamera 0 0 5 0 0 0 0 1 0 45\n");
    for _ in 0..lines {
        let command = commands[rng.below(commands.len())];
        let lenient = rng.below(50) == 0;
        for _ in 0..40 {
            let mut line = command.to_string();
            for _ in 0..rng.below(13) {
                line.push(' ');
                line.push_str(ARGUMENTS[rng.below(ARGUMENTS.len())]);
            }
            let candidate = format!("{text}{line}\n");
            let (_, diags) = parse_bytes("fuzz.test", candidate.as_bytes(), ParseOptions::default());
            if lenient || !diags.has_errors() {
                text = candidate;
                break;
            }
        }
    }
    text
}

/// 600 random scenes, each parsed, built and rendered at its centre (four pixels, four
/// samples at most, as the render fuzz target does), none allowed to panic or to take
/// more than two seconds: the test profile is ~5 times slower than release, and a case
/// that rendered the whole of what an absurd scene asks for (a billion samples, a
/// maxdepth of 2^31 between mirrors) would take hours. Typical cases take milliseconds.
#[test]
fn random_scenes_render_quickly_and_never_panic() {
    use lucent_core::accel::AccelKind;
    use lucent_io::session::Renderer;
    use std::time::{Duration, Instant};
    let renderer = Renderer::new(Some(1)).unwrap();
    let cancel = std::sync::atomic::AtomicBool::new(false);
    let mut rng = Rng(0xfeed_5eed);
    let mut rendered = 0;
    for case in 0..600 {
        let lines = 1 + rng.below(20);
        let text = random_scene(&mut rng, lines);
        let start = Instant::now();
        let options = SessionOptions {
            strict: false,
            accel: AccelKind::List,
            memory_limit: 64 << 20,
        };
        let mut session = Session::parse_text("fuzz.test", text.as_bytes(), options);
        if session.build() {
            let built = session.built.as_ref().unwrap();
            let job = built.job().probe(2, 4);
            let samples = job.pixels.pixels() as f64 * job.samples.len() as f64;
            let most = built.work.most_rays_per_pixel / built.settings.spp as f64 * samples;
            if most <= 200_000.0 {
                let (_, stats) = renderer.render(built, &job, &|_| {}, &cancel).unwrap();
                // The estimate's bound holds.
                assert!(
                    stats.rays as f64 <= most,
                    "case {case}: {} rays > {most}:\n{text}",
                    stats.rays
                );
                rendered += 1;
            }
        }
        let _ = session.diags.render(&session.desc.sources);
        let took = start.elapsed();
        assert!(took < Duration::from_secs(2), "case {case} took {took:?}:\n{text}");
    }
    assert!(rendered > 100, "only {rendered} scenes got as far as rendering");
}

/// Builds `text` (with the list, as the fuzzers do) and renders `side` × `side` pixels at
/// its centre, up to four samples each: the render's statistics, the bound on its rays
/// from the work estimate, and the warnings.
fn rays_and_bound(text: &str, side: u32) -> (lucent_core::render::RenderStats, f64, String) {
    use lucent_core::accel::AccelKind;
    use lucent_io::session::Renderer;
    let options = SessionOptions {
        strict: true,
        accel: AccelKind::List,
        memory_limit: 64 << 20,
    };
    let mut session = Session::parse_text("tree.test", text.as_bytes(), options);
    assert!(session.build(), "{}", session.diags.render(&session.desc.sources));
    let built = session.built.as_ref().unwrap();
    let job = built.job().probe(side, 4);
    let samples = job.pixels.pixels() as f64 * job.samples.len() as f64;
    let most = built.work.most_rays_per_pixel / built.settings.spp as f64 * samples;
    let cancel = std::sync::atomic::AtomicBool::new(false);
    let (_, stats) = Renderer::new(Some(1))
        .unwrap()
        .render(built, &job, &|_| {}, &cancel)
        .unwrap();
    (stats, most, session.diags.render(&session.desc.sources))
}

/// Glass splits every ray in two: between facing glass planes and inside a mirror box the
/// ray trees of the Whitted tracer grow with the depth — geometrically where a material
/// reflects more than it receives. Each render traces no more rays than the work
/// estimate's bound says (which `lucent check`, the warning about absurd work and the
/// fuzzers rely on), and no camera sample more than `MAX_TREE_RAYS` of its tree.
#[test]
fn ray_trees_stay_within_the_work_bound_and_the_cap() {
    use lucent_core::integrator::whitted::MAX_TREE_RAYS;
    let planes = "camera 0 0 0.5  0.3 0.1 -1  0 1 0  60\nplane 0 0 -1 0 0 1\nplane 0 0 1 0 0 -1\n";
    let box_and_sphere = "camera 0 0 0.9  0 0 0  0 1 0  60\nbox -1 -1 -1 1 1 1\nsphere 0 0 0 0.5\n";
    for depth in [1, 2, 5, 9, 12] {
        for (specular, glossy) in [
            ("1 1 1", ""),
            ("0.9 0.5 0.2", "glossy 50 4\n"),
            ("0 0 30", ""),
            ("2 2 2", "glossy 20 3\n"),
        ] {
            for (geometry, light) in [(planes, ""), (box_and_sphere, "point 0 0.5 0.5 1 1 1\n")] {
                let text = format!(
                    "size 8 8\nmaxdepth {depth}\n{light}specular {specular}\n{glossy}transparent 1 1 1\nior 1.5\n{geometry}"
                );
                let (stats, most, _) = rays_and_bound(&text, 2);
                assert!(stats.rays as f64 <= most, "{} rays > {most}:\n{text}", stats.rays);
                assert_eq!(stats.cut_branches, 0, "{text}");
            }
        }
    }
    // The fuzzer's hang: 2^5001 rays asked for (glass in a mirror box, both gaining
    // weight in blue). One sample traces its tree's first
    // MAX_TREE_RAYS rays, then cuts the rest, and says so before it starts.
    let text = "size 1 1\nmaxdepth 5001\ncamera 0 0 0.9  0 0 0  0 1 0  60\nspecular 0 0 30\nbox -1 -1 -1 1 1 1\ntransparent 1 1 1\nior 1.5\nsphere 0 0 0 0.5\n";
    let (stats, most, warnings) = rays_and_bound(text, 1);
    assert_eq!(most, MAX_TREE_RAYS as f64);
    assert_eq!(stats.rays, MAX_TREE_RAYS as u64);
    assert!(stats.cut_branches > 0);
    assert!(
        warnings.contains(
            "maxdepth: glass splits every ray it meets in two, so one camera sample may trace more than 1048576 rays"
        ),
        "{warnings}"
    );
}

/// The work estimate measures what it can: a gallery-like scene (glass, a glossy sphere,
/// a quad light of 16 samples, 16 samples a pixel) whose settings alone ask for 55,872
/// rays a pixel — every pixel's tree full of glass and glossy rays — traces about 280.
/// The estimate must be within a factor of two of the rays the render traces, and the
/// scene at 640 × 480 (9e7 rays, seconds) must not be called hours of work.
#[test]
fn the_work_estimate_is_near_what_the_render_traces() {
    use lucent_core::accel::AccelKind;
    use lucent_io::session::Renderer;
    let scene = |size: &str| {
        format!(
            "size {size}\ncamera 0 2.2 7.5  0 0.7 0  0 1 0  40\nmaxdepth 6\nspp 16\nlightsamples 16\nlightstratify on\n\
             quadLight -1 4.5 -1  0 0 2  2 0 0  6 6 5.5\ndirectional 0.3 1 0.6  0.15 0.15 0.17\n\
             diffuse 0.7 0.7 0.7\nplane 0 0 0 0 1 0\nspecular 1 1 1\nshininess 200\ntransparent 1 1 1\nior 1.5\n\
             sphere -1.2 1 0.6 1\ntransparent 0 0 0\nspecular 0.8 0.6 0.35\nglossy 60 16\nsphere 1.1 0.9 -1.4 0.9\n"
        )
    };
    let options = || SessionOptions {
        strict: true,
        accel: AccelKind::Bvh,
        memory_limit: 64 << 20,
    };
    let mut large = Session::parse_text("large.test", scene("640 480").as_bytes(), options());
    assert!(large.build(), "{}", large.diags.render(&large.desc.sources));
    let warnings = large.diags.render(&large.desc.sources);
    assert!(!warnings.contains("this render traces"), "{warnings}");
    let work = large.built.as_ref().unwrap().work;
    assert!(work.rays_per_pixel < 1000.0, "{work:?}");
    assert!(work.most_rays_per_pixel > 100_000.0, "{work:?}");

    let mut small = Session::parse_text("small.test", scene("80 60").as_bytes(), options());
    assert!(small.build());
    let built = small.built.as_ref().unwrap();
    let cancel = std::sync::atomic::AtomicBool::new(false);
    let (_, stats) = Renderer::new(None)
        .unwrap()
        .render(built, &built.job(), &|_| {}, &cancel)
        .unwrap();
    let ratio = built.work.rays / stats.rays as f64;
    assert!(
        (0.5..2.0).contains(&ratio),
        "estimated {:.3e}, traced {}",
        built.work.rays,
        stats.rays
    );
}
