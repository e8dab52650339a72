//! The `lucent` binary end to end: exit codes, messages, and what is (not) written.

use std::fs;
use std::path::Path;
use std::process::{Command, Output};

const SCENE: &str = "size 32 24\ncamera 0 0 5 0 0 0 0 1 0 45\npoint 1 1 3 1 1 1\ndiffuse 0.6 0.3 0.2\nspecular 0.3 0.3 0.3\nsphere 0 0 0 1\nvertex -3 -1 -3\nvertex 3 -1 -3\nvertex 3 -1 3\ntri 0 2 1\n";

mod common;

use common::files_in;

/// A fresh, empty directory for one test.
fn workdir(name: &str) -> common::WorkDir {
    common::workdir("cli", name)
}

fn lucent(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_lucent"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run lucent")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn renders_a_png_named_by_the_option_the_scene_or_the_default() {
    let dir = workdir("names");
    fs::write(dir.join("a.test"), SCENE).unwrap();
    let o = lucent(&dir, &["render", "a.test", "-o", "x.png"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let png = fs::read(dir.join("x.png")).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    // Summary line: resolution, primitives, rays, seconds, Mrays/s.
    let err = stderr(&o);
    assert!(
        err.contains("32x24, 2 primitives, ") && err.contains(" rays, ") && err.contains(" Mrays/s"),
        "{err}"
    );

    fs::write(dir.join("b.test"), format!("{SCENE}output named.png\n")).unwrap();
    assert!(lucent(&dir, &["render", "b.test", "-q"]).status.success());
    assert!(dir.join("named.png").exists());
    assert!(lucent(&dir, &["render", "a.test", "--quiet"]).status.success());
    assert!(dir.join("raytrace.png").exists());
    assert_eq!(
        files_in(&dir),
        ["a.test", "b.test", "named.png", "raytrace.png", "x.png"],
        "no stray temporary files"
    );
}

#[test]
fn stats_report_every_phase() {
    let dir = workdir("stats");
    fs::write(dir.join("a.test"), SCENE).unwrap();
    let o = lucent(&dir, &["render", "a.test", "--stats", "-o", "a.png"]);
    let err = stderr(&o);
    for phase in ["parse ", "build ", "render ", "write "] {
        assert!(err.contains(phase), "{err}");
    }
}

#[test]
fn bad_input_exits_2_with_a_located_message_and_writes_nothing() {
    let dir = workdir("bad");
    fs::write(dir.join("bad.test"), format!("{SCENE}sphere 0 0 0 -2\n")).unwrap();
    let o = lucent(&dir, &["render", "bad.test", "-o", "out.png"]);
    assert_eq!(o.status.code(), Some(2));
    let err = stderr(&o);
    assert!(
        err.starts_with("bad.test:11:14: error: sphere: radius must be positive, got -2\n"),
        "{err}"
    );
    assert!(err.contains("11 | sphere 0 0 0 -2\n   |              ^~\n"), "{err}");
    assert!(!dir.join("out.png").exists());
}

#[test]
fn a_failed_run_leaves_an_existing_output_untouched() {
    let dir = workdir("keep");
    fs::write(dir.join("out.png"), b"precious").unwrap();
    fs::write(dir.join("bad.test"), format!("{SCENE}tri 0 1 7\n")).unwrap();
    assert_eq!(
        lucent(&dir, &["render", "bad.test", "-o", "out.png"]).status.code(),
        Some(2)
    );
    assert_eq!(fs::read(dir.join("out.png")).unwrap(), b"precious");
    assert_eq!(files_in(&dir), ["bad.test", "out.png"]);
}

#[test]
fn missing_scene_and_unwritable_output() {
    let dir = workdir("missing");
    let o = lucent(&dir, &["render", "nope.test"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).starts_with("nope.test:1:1: error: cannot read scene file: no such file"),
        "{}",
        stderr(&o)
    );

    fs::write(dir.join("a.test"), SCENE).unwrap();
    let o = lucent(&dir, &["render", "a.test", "-o", "no/such/dir/out.png"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("error: cannot write no/such/dir/out.png: no such folder: no/such/dir"),
        "{}",
        stderr(&o)
    );
    fs::create_dir(dir.join("adir.png")).unwrap();
    let o = lucent(&dir, &["render", "a.test", "-o", "adir.png"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("it is a directory"), "{}", stderr(&o));
}

#[test]
fn garbage_never_panics() {
    let dir = workdir("garbage");
    let blob: Vec<u8> = (0..50_000u32)
        .map(|i| (i.wrapping_mul(2654435761) >> 11) as u8)
        .collect();
    fs::write(dir.join("g.test"), &blob).unwrap();
    let o = lucent(&dir, &["render", "g.test"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("g.test:1:"));
    assert!(!stderr(&o).contains("panicked"));
}

#[test]
fn strict_mode_turns_unknown_commands_into_errors() {
    let dir = workdir("strict");
    fs::write(dir.join("a.test"), format!("{SCENE}frobnicate 1 2\n")).unwrap();
    let o = lucent(&dir, &["render", "a.test", "-o", "a.png"]);
    assert!(o.status.success());
    assert!(stderr(&o).contains("a.test:11:1: warning: unknown command 'frobnicate' ignored"));
    let o = lucent(&dir, &["render", "a.test", "-o", "b.png", "--strict"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("a.test:11:1: error: unknown command 'frobnicate'"));
    assert!(!dir.join("b.png").exists());
}

#[test]
fn check_summarises_and_reports_errors_like_render() {
    let dir = workdir("check");
    fs::write(dir.join("a.test"), SCENE).unwrap();
    let o = lucent(&dir, &["check", "a.test"]);
    assert!(o.status.success());
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("size:       32 x 24"), "{out}");
    assert!(
        out.contains("objects:    1 spheres, 1 triangles (0 with vertex normals)\n"),
        "{out}"
    );
    assert!(out.contains("lights:     1 point, 0 directional, 0 quad"), "{out}");
    // The extension shapes are named when present.
    fs::write(
        dir.join("s.test"),
        format!("{SCENE}plane 0 0 0 0 1 0\ndisk 1\ndisk 2\n"),
    )
    .unwrap();
    let o = lucent(&dir, &["check", "s.test"]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        out.contains("objects:    1 spheres, 1 triangles (0 with vertex normals), 1 plane, 2 disks\n"),
        "{out}"
    );
    fs::write(dir.join("bad.test"), "size 10 10\npopTransform\n").unwrap();
    let o = lucent(&dir, &["check", "bad.test"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("bad.test:2:1: error: popTransform: transform stack is empty"));
    assert!(stderr(&o).contains("bad.test:2:1: error: the scene has no 'camera' command"));
}

#[test]
fn same_bytes_for_any_thread_count_and_structure() {
    let dir = workdir("same");
    let mut scene = String::from(SCENE);
    for k in 0..60 {
        scene += &format!(
            "specular 0.4 0.4 0.4\nsphere {} {} {} 0.3\n",
            (k % 8) as f32 - 3.5,
            (k / 8) as f32 * 0.4 - 1.0,
            -(k % 5) as f32
        );
    }
    fs::write(dir.join("s.test"), scene).unwrap();
    for (name, args) in [
        ("t1", vec!["--threads", "1"]),
        ("t2", vec!["--threads", "2"]),
        ("list", vec!["--accel", "list"]),
        ("kdtree", vec!["--accel", "kdtree"]),
        ("grid", vec!["--accel", "grid"]),
        ("octree", vec!["--accel", "octree"]),
    ] {
        let out = format!("{name}.png");
        let mut a = vec!["render", "s.test", "-q", "-o", &out];
        a.extend(args);
        assert!(lucent(&dir, &a).status.success());
    }
    let t1 = fs::read(dir.join("t1.png")).unwrap();
    for other in ["t2", "list", "kdtree", "grid", "octree"] {
        assert_eq!(t1, fs::read(dir.join(format!("{other}.png"))).unwrap(), "{other}");
    }
}

#[test]
fn rays_in_packets_give_the_bytes_of_single_rays() {
    // The BVH traces a tile's camera rays, and the shadow rays from a point toward an
    // area light (81 of them: two batches), in packets (16 or 8 rays); the list traces
    // them one by one. Triangles (tested across the rays of a packet), spheres (ray by
    // ray), a plane (outside every structure), several samples per pixel, the ray
    // tracer, `direct` and the path tracer.
    let dir = workdir("packets");
    let mut scene = String::from(SCENE);
    scene += "vertex -1 -0.5 -1\nvertex 1 -0.5 -1\nvertex 0 0.5 -1.2\n";
    for k in 0..40 {
        let (x, y) = ((k % 8) as f32 - 3.5, (k / 8) as f32 * 0.5 - 1.0);
        let z = -(k % 3) as f32;
        scene += &format!("pushTransform\ntranslate {x} {y} {z}\ntri 3 4 5\npopTransform\n");
        scene += &format!("sphere {} {y} -2 0.25\n", x + 0.3);
    }
    scene += "plane 0 -2.5 0 0 1 0\n";
    fs::write(dir.join("s.test"), format!("{scene}spp 4\n")).unwrap();
    let path = "spp 8\nintegrator pathtracer\nquadLight -1 3 -1 2 0 0 0 0 2 5 5 5\n";
    fs::write(dir.join("p.test"), format!("{scene}{path}")).unwrap();
    let area = "lightsamples 81\nlightstratify on\nquadLight -1 3 -1 2 0 0 0 0 2 5 5 5\n";
    fs::write(dir.join("q.test"), format!("{scene}{area}")).unwrap();
    fs::write(dir.join("d.test"), format!("{scene}integrator direct\n{area}")).unwrap();
    for s in ["s", "p", "q", "d"] {
        for accel in ["bvh", "list"] {
            let out = format!("{s}-{accel}.png");
            let o = lucent(
                &dir,
                &["render", &format!("{s}.test"), "-q", "-o", &out, "--accel", accel],
            );
            assert!(o.status.success(), "{}", stderr(&o));
        }
        let bvh = fs::read(dir.join(format!("{s}-bvh.png"))).unwrap();
        assert_eq!(bvh, fs::read(dir.join(format!("{s}-list.png"))).unwrap(), "{s}");
    }
}

#[test]
fn an_empty_scene_renders_black() {
    let dir = workdir("empty");
    fs::write(dir.join("e.test"), "size 8 6\ncamera 0 0 -1 0 0 1 0 1 0 60\n").unwrap();
    let o = lucent(&dir, &["render", "e.test", "-o", "e.png"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = lucent(&dir, &["render", "e.test", "-o", "l.png", "--accel", "list"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        fs::read(dir.join("e.png")).unwrap(),
        fs::read(dir.join("l.png")).unwrap()
    );
}

#[test]
fn diff_compares_images() {
    let dir = workdir("diff");
    fs::write(dir.join("a.test"), SCENE).unwrap();
    assert!(lucent(&dir, &["render", "a.test", "-q", "-o", "a.png"])
        .status
        .success());
    let o = lucent(&dir, &["diff", "a.png", "a.png", "--max-pixels", "0"]);
    assert!(o.status.success());
    assert!(String::from_utf8_lossy(&o.stdout).starts_with("pixels_over=0 pixels=768 "));
}

/// Eight little-endian f32 per ray: origin, t_near, direction, t_far.
fn ray_records(rays: &[[f32; 8]]) -> Vec<u8> {
    rays.iter().flatten().flat_map(|f| f.to_le_bytes()).collect()
}

#[test]
fn bench_rays_traces_a_ray_file_and_writes_the_answers() {
    let dir = workdir("bench-rays");
    // A unit quad in z = 0 (two triangles, fan order) and a triangle behind it at z = -1.
    fs::write(
        dir.join("m.obj"),
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 -1\nv 3 0 -1\nv 0 3 -1\nf 1 2 3 4\nf 5 6 7\n",
    )
    .unwrap();
    let inf = f32::INFINITY;
    let rays = [
        [0.75, 0.25, 1.0, 0.0, 0.0, 0.0, -1.0, inf], // first triangle of the quad, t = 1
        [0.25, 0.75, 1.0, 0.0, 0.0, 0.0, -1.0, inf], // second triangle, t = 1
        [2.0, 0.5, 1.0, 0.0, 0.0, 0.0, -1.0, inf],   // misses the quad, hits the back one at t = 2
        [5.0, 5.0, 1.0, 0.0, 0.0, 0.0, -1.0, inf],   // misses everything
        [2.0, 0.5, 1.0, 0.0, 0.0, 0.0, -1.0, 1.5],   // stops short of the back triangle
    ];
    fs::write(dir.join("r.bin"), ray_records(&rays)).unwrap();
    let answers = |bytes: Vec<u8>| -> Vec<(f32, u32)> {
        bytes
            .chunks_exact(8)
            .map(|c| {
                (
                    f32::from_le_bytes(c[..4].try_into().unwrap()),
                    u32::from_le_bytes(c[4..].try_into().unwrap()),
                )
            })
            .collect()
    };
    for accel in ["bvh", "kdtree", "grid", "octree", "list"] {
        // `bench rays m.obj r.bin --accel ACCEL` with `options`.
        let bench = |options: &[&str]| {
            let o = lucent(
                &dir,
                &[&["bench", "rays", "m.obj", "r.bin", "--accel", accel], options].concat(),
            );
            assert!(o.status.success(), "{accel} {options:?}: {}", stderr(&o));
            o
        };
        let o = bench(&["--reps", "2", "--threads", "1", "--hits", "h.bin"]);
        let line = String::from_utf8_lossy(&o.stdout).into_owned();
        assert!(line.starts_with("mrays_per_s=") && line.contains(" build_s=") && line.contains(" bytes_per_tri="));
        assert!(line.contains(" rays=5 hits=3 "), "{line}");
        let miss = (inf, u32::MAX);
        assert_eq!(
            answers(fs::read(dir.join("h.bin")).unwrap()),
            [(1.0, 0), (1.0, 1), (2.0, 2), miss, miss]
        );
        // The renderer's queries (which also ask the cache for the hit's indices): the
        // same answers.
        bench(&["--reps", "1", "--prefetch-hits", "--hits", "p.bin"]);
        assert_eq!(
            fs::read(dir.join("p.bin")).unwrap(),
            fs::read(dir.join("h.bin")).unwrap()
        );

        bench(&["--occluded", "--reps", "1", "--hits", "o.bin"]);
        let free = (inf, 0);
        assert_eq!(
            answers(fs::read(dir.join("o.bin")).unwrap()),
            [(0.0, 0), (0.0, 0), (0.0, 0), free, free]
        );
    }
}

#[test]
fn bench_rays_rejects_bad_files_without_writing() {
    let dir = workdir("bench-bad");
    fs::write(dir.join("m.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    fs::write(dir.join("short.bin"), [0u8; 33]).unwrap();
    fs::write(
        dir.join("nan.bin"),
        ray_records(&[[f32::NAN, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 1.0]]),
    )
    .unwrap();
    fs::write(
        dir.join("ok.bin"),
        ray_records(&[[0.0, 0.0, 1.0, 0.0, 0.0, 0.0, -1.0, 9.0]]),
    )
    .unwrap();
    for (args, message) in [
        (vec!["m.obj", "short.bin"], "not a whole number of 32-byte ray records"),
        (vec!["m.obj", "nan.bin"], "ray 0 has a NaN"),
        (vec!["m.obj", "missing.bin"], "cannot read ray file"),
        (vec!["missing.obj", "ok.bin"], "missing.obj: cannot open: no such file"),
    ] {
        let mut a = vec!["bench", "rays"];
        a.extend(args);
        a.extend(["--hits", "h.bin"]);
        let o = lucent(&dir, &a);
        assert_eq!(o.status.code(), Some(2), "{a:?}");
        assert!(stderr(&o).contains(message), "{a:?}: {}", stderr(&o));
        assert!(!dir.join("h.bin").exists());
    }
}

#[test]
fn exr_and_hdr_keep_the_linear_values_png_encodes() {
    // An emitter of 2.5 (beyond what 8 bits can hold) and one of 0.25.
    let dir = workdir("exr");
    let scene = "size 20 10\northocamera 0 0 5 0 0 0 0 1 0 2\nambient 0 0 0\nemission 2.5 0.25 1\n\
                 vertex -10 -10 0\nvertex 0 -10 0\nvertex 0 10 0\nvertex -10 10 0\ntri 0 1 2\ntri 0 2 3\n";
    fs::write(dir.join("e.test"), scene).unwrap();
    for name in ["out.exr", "out.hdr", "out.png"] {
        let o = lucent(&dir, &["render", "e.test", "-o", name, "-q"]);
        assert!(o.status.success(), "{name}: {}", stderr(&o));
    }
    let exr = image::open(dir.join("out.exr")).unwrap().to_rgb32f();
    assert_eq!(exr.dimensions(), (20, 10));
    assert_eq!(exr.get_pixel(2, 5).0, [2.5, 0.25, 1.0], "linear values, exactly");
    assert_eq!(exr.get_pixel(17, 5).0, [0.0, 0.0, 0.0]);
    let hdr = image::open(dir.join("out.hdr")).unwrap().to_rgb32f();
    let p = hdr.get_pixel(2, 5).0;
    assert!((p[0] - 2.5).abs() < 0.02 && (p[1] - 0.25).abs() < 0.01, "{p:?}");
    let png = image::open(dir.join("out.png")).unwrap().to_rgb8();
    assert_eq!(png.get_pixel(2, 5).0, [255, 63, 255]);
    assert_eq!(files_in(&dir), ["e.test", "out.exr", "out.hdr", "out.png"]);
}

#[test]
fn images_carry_what_they_are() {
    let dir = workdir("metadata");
    fs::write(dir.join("a.test"), format!("{SCENE}gamma 2.2\n")).unwrap();
    let o = lucent(&dir, &["render", "a.test", "-o", "x.png", "-q"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let png = fs::read(dir.join("x.png")).unwrap();
    let find = |needle: &[u8]| png.windows(needle.len()).position(|w| w == needle);
    // gAMA holds 1/2.2 × 100000 = 45455; text names lucent, the scene and the options.
    let g = find(b"gAMA").expect("a gAMA chunk");
    assert_eq!(u32::from_be_bytes(png[g + 4..g + 8].try_into().unwrap()), 45455);
    assert!(find(b"cHRM").is_some());
    assert!(find(format!("Software\0lucent {}", env!("CARGO_PKG_VERSION")).as_bytes()).is_some());
    assert!(find(b"Source\0a.test").is_some());
    assert!(find(b"32 x 24 image, pixels 0..32 x 0..24, samples 0..0 of 1 per pixel").is_some());
    // A scene named past Latin-1 (which tEXt and the EXR crate's text hold): its name in
    // an iTXt chunk, and as UTF-8 bytes in an EXR's comments (before, the PNG was refused
    // and the EXR write panicked, after the whole render).
    let name = "场景 ✓.test";
    fs::write(dir.join(name), SCENE).unwrap();
    for out in ["u.png", "u.exr"] {
        let o = lucent(&dir, &["render", name, "-o", out, "-q"]);
        assert!(o.status.success(), "{out}: {}", stderr(&o));
        let bytes = fs::read(dir.join(out)).unwrap();
        assert!(bytes.windows(name.len()).any(|w| w == name.as_bytes()), "{out}");
    }
    let png = fs::read(dir.join("u.png")).unwrap();
    assert!(png.windows(11).any(|w| w == b"iTXtSource\0"));
    // Linear output says so: gAMA 1.
    fs::write(dir.join("b.test"), SCENE).unwrap();
    assert!(lucent(&dir, &["render", "b.test", "-o", "y.png", "-q"])
        .status
        .success());
    let png = fs::read(dir.join("y.png")).unwrap();
    let g = png.windows(4).position(|w| w == b"gAMA").unwrap();
    assert_eq!(u32::from_be_bytes(png[g + 4..g + 8].try_into().unwrap()), 100000);
    // A JPEG is a JPEG; an unknown extension is an error, and nothing is written.
    assert!(lucent(&dir, &["render", "a.test", "-o", "x.jpg", "-q"])
        .status
        .success());
    assert_eq!(&fs::read(dir.join("x.jpg")).unwrap()[..2], b"\xff\xd8");
    let o = lucent(&dir, &["render", "a.test", "-o", "x.tif"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("'x.tif' does not end in .png, .jpg, .exr or .hdr"),
        "{}",
        stderr(&o)
    );
    assert!(!dir.join("x.tif").exists());
}

#[test]
fn the_command_line_overrides_scene_settings() {
    let dir = workdir("overrides");
    fs::write(dir.join("a.test"), format!("{SCENE}spp 9\n")).unwrap();
    let size = |name: &str| image::image_dimensions(dir.join(name)).unwrap();
    // -D (the last wins, commas or spaces), --size and --quick.
    let o = lucent(
        &dir,
        &[
            "render",
            "a.test",
            "-o",
            "d.png",
            "-D",
            "size=8,6",
            "-D",
            "size=10 4",
            "-D",
            "spp=1",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(size("d.png"), (10, 4));
    assert!(
        !stderr(&o).contains("given again"),
        "overrides replace silently: {}",
        stderr(&o)
    );
    assert!(lucent(
        &dir,
        &[
            "render",
            "a.test",
            "-o",
            "s.png",
            "--size",
            "16",
            "12",
            "--maxdepth",
            "-1",
            "-q"
        ]
    )
    .status
    .success());
    assert_eq!(size("s.png"), (16, 12));
    assert!(lucent(&dir, &["render", "a.test", "-o", "q.png", "--quick", "-q"])
        .status
        .success());
    assert_eq!(size("q.png"), (16, 12));
    // An override with the same value renders the same pixels as the scene itself.
    assert!(
        lucent(&dir, &["render", "a.test", "-o", "same.png", "-D", "spp=9", "-q"])
            .status
            .success()
    );
    assert!(lucent(&dir, &["render", "a.test", "-o", "plain.png", "-q"])
        .status
        .success());
    let pixels = |name: &str| image::open(dir.join(name)).unwrap().to_rgb8().into_raw();
    assert_eq!(pixels("same.png"), pixels("plain.png"));
    // Errors point into the command line.
    let o = lucent(&dir, &["render", "a.test", "-o", "x.png", "-D", "spp=0"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("command line:1:5: error: spp: "), "{}", stderr(&o));
    let o = lucent(&dir, &["render", "a.test", "-o", "x.png", "-D", "sphere=1"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("-D: 'sphere' is not a scene setting"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn a_scene_that_can_only_be_black_says_so_and_counts_its_warnings() {
    let dir = workdir("dark");
    fs::write(
        dir.join("typo.test"),
        "size 8 8\ncamera 0 0 5 0 0 0 0 1 0 45\npoint 0 0 5 1 1 1\nsphre 0 0 0 1\n",
    )
    .unwrap();
    let o = lucent(&dir, &["render", "typo.test", "-o", "t.png"]);
    assert!(o.status.success());
    let err = stderr(&o);
    assert!(err.contains("did you mean 'sphere'"), "{err}");
    assert!(err.contains("warning: the scene has no objects"), "{err}");
    assert!(err.contains("lucent: 2 warnings (see above)"), "{err}");
    fs::write(
        dir.join("dark.test"),
        "size 8 8\nintegrator pathtracer\ncamera 0 0 5 0 0 0 0 1 0 45\nsphere 0 0 0 1\n",
    )
    .unwrap();
    let err = stderr(&lucent(&dir, &["render", "dark.test", "-o", "d.png"]));
    assert!(
        err.contains("warning: the scene has no light, no emissive object and no environment map"),
        "{err}"
    );
    assert!(err.contains("lucent: 1 warning (see above)"), "{err}");
}

#[test]
fn several_scenes_in_one_run_and_a_scene_on_standard_input() {
    use std::io::Write;
    let dir = workdir("several");
    fs::write(dir.join("a.test"), SCENE).unwrap();
    fs::write(dir.join("b.test"), format!("{SCENE}output named.png\n")).unwrap();
    let o = lucent(&dir, &["render", "a.test", "b.test", "-q"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(dir.join("a.png").exists() && dir.join("named.png").exists());
    let o = lucent(&dir, &["render", "a.test", "b.test", "-o", "x.png"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("-o names one file, and 2 scenes were given"),
        "{}",
        stderr(&o)
    );
    // A broken scene among good ones: the others are rendered, the exit code says it.
    fs::write(dir.join("bad.test"), "size 8 8\nsphere 1\n").unwrap();
    let o = lucent(&dir, &["render", "bad.test", "a.test", "-q"]);
    assert_eq!(o.status.code(), Some(2));
    // Standard input.
    let mut child = Command::new(env!("CARGO_BIN_EXE_lucent"))
        .args(["render", "-", "-o", "stdin.png", "-q"])
        .current_dir(&dir)
        .stdin(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    child.stdin.take().unwrap().write_all(SCENE.as_bytes()).unwrap();
    let o = child.wait_with_output().unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let pixels = |name: &str| image::open(dir.join(name)).unwrap().to_rgb8().into_raw();
    assert_eq!(pixels("stdin.png"), pixels("a.png"));
    // `check -` reads it too.
    let mut child = Command::new(env!("CARGO_BIN_EXE_lucent"))
        .args(["check", "-"])
        .current_dir(&dir)
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    child.stdin.take().unwrap().write_all(SCENE.as_bytes()).unwrap();
    let o = child.wait_with_output().unwrap();
    assert!(o.status.success());
    assert!(String::from_utf8_lossy(&o.stdout).contains("scene:      -"));
}

#[test]
fn closed_output_streams_lose_the_text_not_the_run() {
    // A pipe whose reader is gone (`lucent check … | head -1` once head has quit):
    // writing to it fails at once, which `println!` would turn into a panic.
    let closed = || {
        let (reader, writer) = std::io::pipe().unwrap();
        drop(reader);
        writer
    };
    let dir = workdir("closed_streams");
    fs::write(dir.join("a.test"), SCENE).unwrap();
    let run = |args: &[&str], stdout_closed: bool| {
        let mut c = Command::new(env!("CARGO_BIN_EXE_lucent"));
        c.args(args).current_dir(&*dir);
        if stdout_closed {
            c.stdout(closed()).stderr(std::process::Stdio::piped());
        } else {
            c.stdout(std::process::Stdio::piped()).stderr(closed());
        }
        c.output().expect("run lucent")
    };
    for (args, stdout_closed) in [
        (&["check", "a.test"][..], true),
        (&["check", "a.test"][..], false),
        (&["check", "missing.test"][..], false),
        (&["render", "a.test", "-o", "a.png"][..], false),
        (&["render", "a.test", "-o", "b.png", "--stats"][..], true),
        (&["diff", "a.png", "b.png"][..], true),
    ] {
        let o = run(args, stdout_closed);
        let code = o.status.code();
        let expected = if args[1] == "missing.test" { Some(2) } else { Some(0) };
        assert_eq!(code, expected, "{args:?}: {}", stderr(&o));
        assert!(!stderr(&o).contains("panicked"), "{args:?}: {}", stderr(&o));
    }
    assert!(dir.join("a.png").exists() && dir.join("b.png").exists());
}
