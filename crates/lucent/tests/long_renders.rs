//! Regions, sample ranges, state files, `lucent merge` and `--resume`, end to end: a
//! render put together from parts is the bytes of the render made in one go (PNG and
//! EXR), for every integrator and any thread count; inputs that do not belong together
//! are refused with a message that names them.

use std::fs;
use std::path::Path;
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

mod common;

fn workdir(name: &str) -> common::WorkDir {
    common::workdir("long", name)
}

fn lucent(dir: &Path, args: &[&str]) -> Output {
    let o = Command::new(env!("CARGO_BIN_EXE_lucent"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run lucent");
    o
}

fn ok(dir: &Path, args: &[&str]) {
    let o = lucent(dir, args);
    assert!(
        o.status.success(),
        "lucent {args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
}

fn fails(dir: &Path, args: &[&str], says: &str) {
    let o = lucent(dir, args);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "lucent {args:?}: {err}");
    assert!(err.contains(says), "lucent {args:?}: expected «{says}» in {err}");
}

/// Starts a render in `dir` whose standard error the test reads when it has ended.
fn start(dir: &Path, args: &[&str]) -> Child {
    Command::new(env!("CARGO_BIN_EXE_lucent"))
        .args(args)
        .current_dir(dir)
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

/// Waits (up to a minute) for a running render to write `path`; `what` names it if it never does.
fn wait_for(path: &Path, what: &str) {
    let start = Instant::now();
    while !path.exists() {
        assert!(start.elapsed() < Duration::from_secs(60), "{what}");
        std::thread::sleep(Duration::from_millis(50));
    }
}

/// A small scene with glass, a sphere, a floor and a quad light, in `integrator`.
fn scene(integrator: &str) -> String {
    format!(
        "size 40 30\n{integrator}\ngamma 2.2\ncamera 0 1 3 0 0.8 0 0 1 0 45\nambient 0.02 0.02 0.02\n\
         quadLight -0.25 1.999 -0.25 0 0 0.5  0.5 0 0  30 26 21\ndiffuse 0.7 0.7 0.7\nspecular 0.2 0.2 0.2\n\
         maxverts 4\nvertex -2 0 -2\nvertex 2 0 -2\nvertex 2 0 2\nvertex -2 0 2\ntri 0 2 1\ntri 0 3 2\n\
         diffuse 0.2 0.6 0.3\nsphere 0 0.5 0 0.4\ntransparent 1 1 1\nior 1.5\ndiffuse 0 0 0\nspecular 0 0 0\n\
         sphere 0.5 0.3 0.4 0.25\n"
    )
}

const INTEGRATORS: [&str; 3] = [
    "spp 16\nmaxdepth 3",
    "integrator direct\nspp 12\nlightsamples 4",
    "integrator pathtracer\nspp 16\nnexteventestimation mis\nimportancesampling brdf\nrussianroulette on\nmaxdepth -1",
];

#[test]
fn regions_and_sample_ranges_merge_into_the_bytes_of_the_one_go_render() {
    let dir = workdir("merge");
    for (k, integrator) in INTEGRATORS.iter().enumerate() {
        fs::write(dir.join("s.test"), scene(integrator)).unwrap();
        ok(&dir, &["render", "s.test", "-o", "one.png", "-q", "--threads", "2"]);
        ok(&dir, &["render", "s.test", "-o", "one.exr", "-q", "--threads", "1"]);
        // Four parts: the top rows in two sample ranges (one with one thread, one with
        // two), the bottom left and bottom right by fractions; the last range is
        // whatever the scene's spp leaves.
        let spp = if k == 1 { 12 } else { 16 };
        let last = format!("5..{}", spp - 1);
        let parts: [&[&str]; 4] = [
            &[
                "--pixel-bounds",
                "0",
                "40",
                "0",
                "11",
                "--samples",
                "0..4",
                "--threads",
                "1",
            ],
            &[
                "--pixel-bounds",
                "0",
                "40",
                "0",
                "11",
                "--samples",
                &last,
                "--threads",
                "2",
            ],
            &["--crop", "0", "0.5", "0.35", "1"],
            &["--crop", "0.5", "1", "0.35", "1"],
        ];
        let mut states = Vec::new();
        for (i, extra) in parts.iter().enumerate() {
            let state = format!("p{i}.lstate");
            let mut args = vec!["render", "s.test", "-o", "part.png", "-q", "--state", &state];
            args.extend_from_slice(extra);
            ok(&dir, &args);
            states.push(state);
        }
        let mut args: Vec<&str> = vec!["merge"];
        args.extend(states.iter().map(String::as_str));
        ok(&dir, &[&args[..], &["-o", "m.png", "--state", "m.lstate"]].concat());
        ok(&dir, &["merge", "m.lstate", "-o", "m.exr"]);
        assert!(
            fs::read(dir.join("one.png")).unwrap() == fs::read(dir.join("m.png")).unwrap(),
            "{integrator:?}: PNG"
        );
        assert!(
            fs::read(dir.join("one.exr")).unwrap() == fs::read(dir.join("m.exr")).unwrap(),
            "{integrator:?}: EXR"
        );
        // A region's own image is the region: 20 × 20 pixels here (rows 11..30 of 30).
        let part = image::open(dir.join("part.png")).unwrap();
        assert_eq!((part.width(), part.height()), (20, 19), "{integrator:?}");
    }
}

#[test]
fn a_resumed_render_is_the_render_made_in_one_go() {
    let dir = workdir("resume");
    fs::write(dir.join("s.test"), scene(INTEGRATORS[2])).unwrap();
    ok(&dir, &["render", "s.test", "-o", "one.exr", "-q", "--spp", "24"]);
    ok(
        &dir,
        &[
            "render", "s.test", "-o", "a.exr", "-q", "--spp", "8", "--state", "a.lstate",
        ],
    );
    ok(
        &dir,
        &[
            "render", "s.test", "-o", "b.exr", "-q", "--resume", "a.lstate", "--spp", "16", "--state", "b.lstate",
        ],
    );
    ok(
        &dir,
        &[
            "render", "s.test", "-o", "c.exr", "-q", "--resume", "b.lstate", "--spp", "24",
        ],
    );
    assert!(fs::read(dir.join("one.exr")).unwrap() == fs::read(dir.join("c.exr")).unwrap());
    // More samples asked for as a scene setting on the command line, as with --spp.
    ok(
        &dir,
        &[
            "render", "s.test", "-o", "b2.exr", "-q", "--resume", "a.lstate", "-D", "spp=16",
        ],
    );
    assert!(fs::read(dir.join("b.exr")).unwrap() == fs::read(dir.join("b2.exr")).unwrap());
    fails(
        &dir,
        &["render", "s.test", "-o", "d.exr", "--resume", "b.lstate", "--spp", "16"],
        "already holds samples 0..15",
    );
    // The ray tracer's samples sit on a grid of spp cells: it cannot be continued.
    fs::write(dir.join("w.test"), scene(INTEGRATORS[0])).unwrap();
    ok(&dir, &["render", "w.test", "-o", "w.png", "-q", "--state", "w.lstate"]);
    fails(
        &dir,
        &["render", "w.test", "-o", "x.png", "--resume", "w.lstate", "--spp", "32"],
        "only renders of the Monte Carlo integrators",
    );
    // Another scene text, another seed.
    fs::write(
        dir.join("t.test"),
        scene(INTEGRATORS[2]).replace("0.7 0.7 0.7", "0.6 0.7 0.7"),
    )
    .unwrap();
    fails(
        &dir,
        &["render", "t.test", "-o", "x.exr", "--resume", "a.lstate", "--spp", "16"],
        "the scene's text (or its -D, --size or --maxdepth overrides) has changed",
    );
    fails(
        &dir,
        &[
            "render", "s.test", "-o", "x.exr", "--resume", "a.lstate", "--spp", "16", "--seed", "5",
        ],
        "the seed differs",
    );
}

#[test]
fn merging_refuses_other_scenes_overlaps_gaps_and_damaged_files() {
    let dir = workdir("refuse");
    fs::write(dir.join("s.test"), scene(INTEGRATORS[2])).unwrap();
    fs::write(
        dir.join("t.test"),
        scene(INTEGRATORS[2]).replace("size 40 30", "size 40 30\nmaxdepth 4"),
    )
    .unwrap();
    let half = |name: &str, scene: &str, y0: &str, y1: &str| {
        ok(
            &dir,
            &[
                "render",
                scene,
                "-o",
                "x.png",
                "-q",
                "--pixel-bounds",
                "0",
                "40",
                y0,
                y1,
                "--state",
                name,
            ],
        );
    };
    half("top.lstate", "s.test", "0", "15");
    half("bottom.lstate", "s.test", "15", "30");
    half("other.lstate", "t.test", "15", "30");
    half("big.lstate", "s.test", "10", "30");
    fails(
        &dir,
        &["merge", "top.lstate", "other.lstate", "-o", "m.png"],
        "other.lstate and top.lstate are renders of a different scene",
    );
    fails(&dir, &["merge", "top.lstate", "big.lstate", "-o", "m.png"], "overlap");
    ok(
        &dir,
        &[
            "render",
            "s.test",
            "-o",
            "x.png",
            "-q",
            "--pixel-bounds",
            "0",
            "40",
            "15",
            "30",
            "--samples",
            "0..7",
            "--state",
            "few.lstate",
        ],
    );
    fails(
        &dir,
        &["merge", "top.lstate", "few.lstate", "-o", "m.png"],
        "a gap: pixel (0, 15) has 8 of the samples 0..15",
    );
    let mut bytes = fs::read(dir.join("bottom.lstate")).unwrap();
    let n = bytes.len();
    bytes[n - 100] ^= 0x40;
    fs::write(dir.join("bad.lstate"), &bytes).unwrap();
    fails(
        &dir,
        &["merge", "top.lstate", "bad.lstate", "-o", "m.png"],
        "bad.lstate: its pixel data does not match its checksum",
    );
    assert!(!dir.join("m.png").exists(), "a refused merge writes nothing");
    ok(&dir, &["merge", "top.lstate", "bottom.lstate", "-o", "m.png"]);
    // Bad options are located errors too.
    fails(
        &dir,
        &["render", "s.test", "-o", "x.png", "--samples", "0..99"],
        "--samples 0..99: the render has 16 samples per pixel",
    );
    fails(
        &dir,
        &["render", "s.test", "-o", "x.png", "--crop", "0.5", "0.2", "0", "1"],
        "--crop: pixels 20..8",
    );
    fails(
        &dir,
        &[
            "render",
            "s.test",
            "-o",
            "x.png",
            "--noise-threshold",
            "0.1",
            "--samples",
            "4..7",
        ],
        "must start at 0",
    );
}

/// Ctrl-C in the second scene of a run saves that scene's samples (the first scene's
/// final write must not leave the run ending at once on the next signal).
#[test]
fn ctrl_c_in_a_later_scene_of_a_run_saves_its_samples() {
    let dir = workdir("interrupt-later");
    fs::write(dir.join("a.test"), scene(INTEGRATORS[2])).unwrap();
    fs::write(
        dir.join("b.test"),
        scene(INTEGRATORS[2]).replace("spp 16", "spp 1000000"),
    )
    .unwrap();
    let child = start(&dir, &["render", "a.test", "b.test", "-q", "--checkpoint", "0.3"]);
    wait_for(&dir.join("b.partial.lstate"), "no checkpoint of b.test");
    // SAFETY: signalling our own child.
    unsafe { libc::kill(child.id() as i32, libc::SIGINT) };
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(130));
    let said = String::from_utf8_lossy(&out.stderr);
    assert!(said.contains("wrote b.partial.png and b.partial.lstate"), "{said}");
    assert!(dir.join("a.png").exists() && !dir.join("b.png").exists());
}

#[test]
fn ctrl_c_saves_the_finished_samples_and_the_render_resumes_from_them() {
    let dir = workdir("interrupt");
    // Far more samples than the test waits for; an earlier final image must survive.
    let text = scene(INTEGRATORS[2]).replace("spp 16", "spp 1000000");
    fs::write(dir.join("s.test"), &text).unwrap();
    fs::write(dir.join("out.exr"), b"an earlier render").unwrap();
    let child = start(
        &dir,
        &["render", "s.test", "-o", "out.exr", "-q", "--checkpoint", "0.5"],
    );
    // A checkpoint appears while the render runs.
    wait_for(&dir.join("out.partial.lstate"), "no checkpoint");
    std::thread::sleep(Duration::from_millis(700));
    // SAFETY: signalling our own child.
    unsafe { libc::kill(child.id() as i32, libc::SIGINT) };
    let stopped = Instant::now();
    let out = child.wait_with_output().unwrap();
    assert!(
        stopped.elapsed() < Duration::from_secs(3),
        "took {:?}",
        stopped.elapsed()
    );
    assert_eq!(out.status.code(), Some(130));
    // The command it prints continues this very render (the options as given).
    let said = String::from_utf8_lossy(&out.stderr);
    assert!(
        said.contains("continue with: lucent render s.test -o out.exr --checkpoint 0.5 --resume out.partial.lstate"),
        "{said}"
    );
    assert_eq!(
        fs::read(dir.join("out.exr")).unwrap(),
        b"an earlier render",
        "the final output is never replaced by a partial one"
    );
    let state = lucent_io::state::RenderState::decode(&fs::read(dir.join("out.partial.lstate")).unwrap()).unwrap();
    let done = state.header.samples.clone();
    assert!(done.start == 0 && done.end >= 2, "{done:?}");
    assert!(dir.join("out.partial.exr").exists());
    // Resumed to a few more samples, it is the one-go render of that many.
    let spp = (done.end + 3).to_string();
    ok(
        &dir,
        &[
            "render",
            "s.test",
            "-o",
            "resumed.exr",
            "-q",
            "--resume",
            "out.partial.lstate",
            "--spp",
            &spp,
        ],
    );
    ok(&dir, &["render", "s.test", "-o", "one.exr", "-q", "--spp", &spp]);
    assert!(fs::read(dir.join("resumed.exr")).unwrap() == fs::read(dir.join("one.exr")).unwrap());
}

/// A task killed by Slurm (SIGTERM) leaves its partial state beside `--state`, never at
/// it: a resubmission takes an existing state for a finished task.
#[test]
fn a_killed_task_leaves_no_state_but_a_partial_one_beside_it() {
    let dir = workdir("killed-task");
    fs::write(
        dir.join("s.test"),
        scene(INTEGRATORS[2]).replace("spp 16", "spp 1000000"),
    )
    .unwrap();
    let child = start(
        &dir,
        &[
            "render",
            "s.test",
            "-o",
            "/dev/null",
            "-q",
            "--state",
            "t.lstate",
            "--checkpoint",
            "0.5",
        ],
    );
    wait_for(&dir.join("t.partial.lstate"), "no checkpoint");
    // SAFETY: signalling our own child.
    unsafe { libc::kill(child.id() as i32, libc::SIGTERM) };
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(143));
    assert!(!dir.join("t.lstate").exists(), "a killed task wrote its final state");
    let said = String::from_utf8_lossy(&out.stderr);
    assert!(
        said.contains("--state t.lstate --checkpoint 0.5 --resume t.partial.lstate"),
        "{said}"
    );
}

#[test]
fn checkpoints_are_removed_when_the_render_completes() {
    let dir = workdir("checkpoint");
    fs::write(dir.join("s.test"), scene(INTEGRATORS[2])).unwrap();
    ok(
        &dir,
        &[
            "render",
            "s.test",
            "-o",
            "a.png",
            "-q",
            "--checkpoint",
            "0.001",
            "--state",
            "a.lstate",
        ],
    );
    ok(&dir, &["render", "s.test", "-o", "b.png", "-q"]);
    assert!(fs::read(dir.join("a.png")).unwrap() == fs::read(dir.join("b.png")).unwrap());
    let names = common::files_in(&dir);
    assert_eq!(
        names,
        ["a.lstate", "a.png", "b.png", "s.test"],
        "no partial files are left"
    );
}

#[test]
fn a_regions_exr_records_where_it_belongs() {
    let dir = workdir("window");
    fs::write(dir.join("s.test"), scene(INTEGRATORS[2])).unwrap();
    ok(
        &dir,
        &[
            "render",
            "s.test",
            "-o",
            "part.exr",
            "-q",
            "--pixel-bounds",
            "10",
            "30",
            "5",
            "20",
        ],
    );
    let exr = fs::read(dir.join("part.exr")).unwrap();
    // An attribute: name, type name, size, value (here a box2i: xmin ymin xmax ymax).
    let box2i = |name: &str| {
        let key = format!("{name}\0box2i\0");
        let at = exr.windows(key.len()).position(|w| w == key.as_bytes()).unwrap() + key.len() + 4;
        let v: Vec<i32> = (0..4)
            .map(|k| i32::from_le_bytes(exr[at + 4 * k..at + 4 * k + 4].try_into().unwrap()))
            .collect();
        v
    };
    assert_eq!(box2i("dataWindow"), [10, 5, 29, 19]);
    assert_eq!(box2i("displayWindow"), [0, 0, 39, 29]);
    let text = String::from_utf8_lossy(&exr);
    assert!(
        text.contains("pixels 10..30 x 5..20"),
        "the header says where the region belongs"
    );
    assert!(text.contains(&format!("lucent {}", env!("CARGO_PKG_VERSION"))));
    // A reader shows it in its place in the whole picture, with the one-go render's values.
    ok(&dir, &["render", "s.test", "-o", "one.exr", "-q"]);
    let part = image::open(dir.join("part.exr")).unwrap().to_rgb32f();
    let one = image::open(dir.join("one.exr")).unwrap().to_rgb32f();
    assert_eq!((part.width(), part.height()), (40, 30));
    assert_eq!(part.get_pixel(15, 10), one.get_pixel(15, 10));
    assert_eq!(part.get_pixel(29, 19), one.get_pixel(29, 19));
    assert_eq!(part.get_pixel(0, 0).0, [0.0; 3], "outside the data window");
}

/// Runs `lucent render` with `args`, the passes of `--aov` all on.
fn with_aovs<'a>(args: &[&'a str]) -> Vec<&'a str> {
    [args, &["--aov", "albedo,normal,depth,alpha", "-q"]].concat()
}

#[test]
fn auxiliary_passes_merge_and_resume_into_the_one_go_bytes() {
    let dir = workdir("aovs");
    fs::write(dir.join("s.test"), scene(INTEGRATORS[2])).unwrap();
    ok(
        &dir,
        &with_aovs(&["render", "s.test", "-o", "one.exr", "--threads", "2"]),
    );
    // The layers are there, named as Blender and Nuke name them.
    let exr = fs::read(dir.join("one.exr")).unwrap();
    for name in ["albedo.R", "normal.X", "depth.Z", "A\0"] {
        assert!(exr.windows(name.len()).any(|w| w == name.as_bytes()), "{name}");
    }
    // A region, and the other region in two sample ranges.
    let bounds = |y0: &'static str, y1: &'static str| ["--pixel-bounds", "0", "40", y0, y1];
    ok(
        &dir,
        &with_aovs(
            &[
                &["render", "s.test", "-o", "p.png", "--state", "a.lstate"][..],
                &bounds("0", "15"),
            ]
            .concat(),
        ),
    );
    ok(
        &dir,
        &with_aovs(
            &[
                &[
                    "render",
                    "s.test",
                    "-o",
                    "p.png",
                    "--state",
                    "b.lstate",
                    "--samples",
                    "0..6",
                    "--threads",
                    "1",
                ][..],
                &bounds("15", "30"),
            ]
            .concat(),
        ),
    );
    ok(
        &dir,
        &with_aovs(
            &[
                &[
                    "render",
                    "s.test",
                    "-o",
                    "p.png",
                    "--state",
                    "c.lstate",
                    "--samples",
                    "7..15",
                ][..],
                &bounds("15", "30"),
            ]
            .concat(),
        ),
    );
    assert!(
        dir.join("p.aovs.exr").exists(),
        "the passes of a PNG output go beside it"
    );
    ok(
        &dir,
        &[
            "merge",
            "a.lstate",
            "b.lstate",
            "c.lstate",
            "-o",
            "m.exr",
            "--aov",
            "albedo,normal,depth,alpha",
        ],
    );
    assert!(fs::read(dir.join("m.exr")).unwrap() == exr, "merged");
    // Resumed: the passes the state keeps are continued.
    ok(
        &dir,
        &with_aovs(&["render", "s.test", "-o", "r.png", "--spp", "5", "--state", "r.lstate"]),
    );
    ok(
        &dir,
        &with_aovs(&["render", "s.test", "-o", "r.exr", "--resume", "r.lstate", "--spp", "16"]),
    );
    assert!(fs::read(dir.join("r.exr")).unwrap() == exr, "resumed");
    // States without passes cannot give them.
    ok(
        &dir,
        &[
            "render", "s.test", "-o", "n.png", "-q", "--spp", "4", "--state", "n.lstate",
        ],
    );
    fails(
        &dir,
        &["merge", "n.lstate", "-o", "x.exr", "--aov", "depth"],
        "keep none",
    );
    fails(
        &dir,
        &[
            "render", "s.test", "-o", "x.exr", "--resume", "n.lstate", "--spp", "8", "--aov", "depth",
        ],
        "keeps no auxiliary passes",
    );
    fails(
        &dir,
        &["render", "s.test", "-o", "x.exr", "--aov", "albedo,Z"],
        "'Z' is not a pass",
    );
    fails(
        &dir,
        &["render", "s.test", "-o", "-", "--aov", "depth"],
        "--aov writes its passes to a file",
    );
}

#[test]
fn adaptive_sampling_resumes_and_merges_into_the_one_go_bytes() {
    let dir = workdir("adaptive");
    fs::write(
        dir.join("s.test"),
        scene(INTEGRATORS[2]).replace("spp 16", "spp 64\nnoisethreshold 0.08"),
    )
    .unwrap();
    ok(
        &dir,
        &["render", "s.test", "-o", "one.exr", "-q", "--spp-map", "one.spp.exr"],
    );
    let one = fs::read(dir.join("one.exr")).unwrap();
    // The samples per pixel differ: adaptive sampling did stop some pixels early.
    let map = image::open(dir.join("one.spp.exr")).unwrap().to_rgb32f();
    let counts: Vec<f32> = map.pixels().map(|p| p.0[0]).collect();
    let (lo, hi) = counts.iter().fold((f32::MAX, 0f32), |(a, b), &c| (a.min(c), b.max(c)));
    assert!(lo < hi && hi == 64.0 && lo >= 16.0, "{lo}..{hi}");
    // The first 20 samples, then resumed (each pixel's estimate goes on from the state).
    ok(
        &dir,
        &[
            "render",
            "s.test",
            "-o",
            "a.png",
            "-q",
            "--samples",
            "0..19",
            "--state",
            "a.lstate",
        ],
    );
    ok(
        &dir,
        &[
            "render",
            "s.test",
            "-o",
            "r.exr",
            "-q",
            "--resume",
            "a.lstate",
            "--spp",
            "64",
            "--threads",
            "1",
        ],
    );
    assert!(fs::read(dir.join("r.exr")).unwrap() == one, "resumed");
    // Regions merged.
    ok(
        &dir,
        &[
            "render", "s.test", "-o", "t.png", "-q", "--crop", "0", "1", "0", "0.5", "--state", "t.lstate",
        ],
    );
    ok(
        &dir,
        &[
            "render", "s.test", "-o", "b.png", "-q", "--crop", "0", "1", "0.5", "1", "--state", "b.lstate",
        ],
    );
    ok(&dir, &["merge", "t.lstate", "b.lstate", "-o", "m.exr"]);
    assert!(fs::read(dir.join("m.exr")).unwrap() == one, "merged");
    // A later range alone cannot know where the pixels stopped.
    fails(
        &dir,
        &["render", "s.test", "-o", "x.png", "--samples", "20..63"],
        "must start at 0",
    );
}

#[test]
fn denoising_needs_the_library_and_cleans_the_noise_when_it_is_there() {
    let dir = workdir("denoise");
    fs::write(dir.join("s.test"), scene(INTEGRATORS[2])).unwrap();
    // Without the library: a clear error that says how to install it, and no output.
    let o = Command::new(env!("CARGO_BIN_EXE_lucent"))
        .args(["render", "s.test", "-o", "d.png", "--denoise"])
        .env("OIDN_LIB", dir.join("nowhere/libOpenImageDenoise.so.2"))
        .current_dir(&dir)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("scripts/install_oidn.sh") && err.contains("OIDN_LIB"),
        "{err}"
    );
    assert!(!dir.join("d.png").exists());
    // With it (found where scripts/install_oidn.sh or pip put it).
    // 160 × 120: a denoiser needs some room around each pixel to tell noise from detail.
    let o = lucent(
        &dir,
        &[
            "render",
            "s.test",
            "-o",
            "d.exr",
            "-q",
            "--denoise",
            "--spp",
            "4",
            "--size",
            "160",
            "120",
        ],
    );
    if String::from_utf8_lossy(&o.stderr).contains("was not found") {
        eprintln!("SKIPPED: Open Image Denoise is not installed (scripts/install_oidn.sh installs it)");
        return;
    }
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    ok(
        &dir,
        &[
            "render",
            "s.test",
            "-o",
            "again.exr",
            "-q",
            "--denoise",
            "--spp",
            "4",
            "--size",
            "160",
            "120",
        ],
    );
    assert!(
        fs::read(dir.join("d.exr")).unwrap() == fs::read(dir.join("again.exr")).unwrap(),
        "deterministic"
    );
    ok(
        &dir,
        &[
            "render",
            "s.test",
            "-o",
            "noisy.exr",
            "-q",
            "--spp",
            "4",
            "--size",
            "160",
            "120",
        ],
    );
    ok(
        &dir,
        &[
            "render", "s.test", "-o", "ref.exr", "-q", "--spp", "256", "--size", "160", "120",
        ],
    );
    let read = |name: &str| image::open(dir.join(name)).unwrap().to_rgb32f();
    let reference = read("ref.exr");
    // On displayed values (clamped to [0, 1], encoded with the scene's gamma 2.2): in
    // linear values the quad light, 30 times brighter than white, and the caustic would
    // be most of the error.
    let rmse = |img: &image::Rgb32FImage| {
        let shown = |v: f32| (v.clamp(0.0, 1.0) as f64).powf(1.0 / 2.2);
        let sum: f64 = img
            .pixels()
            .zip(reference.pixels())
            .flat_map(|(a, b)| (0..3).map(move |k| (shown(a.0[k]) - shown(b.0[k])).powi(2)))
            .sum();
        (sum / (3 * img.width() * img.height()) as f64).sqrt()
    };
    let (noisy, denoised) = (rmse(&read("noisy.exr")), rmse(&read("d.exr")));
    // At 4 samples the noise dominates the error; the denoiser must remove much of it
    // (measured: about half of the noisy error; asked: under two thirds, a margin for
    // other OIDN versions — the reference's own noise, 1/8 of the noisy image's, is small).
    assert!(denoised < 0.67 * noisy, "denoised {denoised} against noisy {noisy}");
    eprintln!("denoised RMSE {denoised:.4}, noisy {noisy:.4}");
    // The noisy colour is kept as a layer.
    let exr = fs::read(dir.join("d.exr")).unwrap();
    assert!(exr.windows(7).any(|w| w == b"noisy.R"));
}

#[test]
fn the_tasks_of_a_plan_merge_into_the_one_go_bytes() {
    let dir = workdir("plan");
    for (integrator, by, expect) in [
        (INTEGRATORS[2], "auto", "by samples"),
        (INTEGRATORS[2], "tiles", "by tiles"),
        (INTEGRATORS[0], "auto", "by tiles"),
        (INTEGRATORS[1], "auto", "by tiles x samples"),
    ] {
        fs::write(dir.join("s.test"), scene(integrator)).unwrap();
        let tasks = if expect.contains(" x ") { "24" } else { "5" };
        let o = lucent(
            &dir,
            &["plan", "s.test", "--tasks", tasks, "--by", by, "--json", "plan.json"],
        );
        let table = String::from_utf8_lossy(&o.stdout);
        assert!(
            o.status.success() && table.contains(expect),
            "{integrator:?} {by}: {table}"
        );
        let json = fs::read_to_string(dir.join("plan.json")).unwrap();
        assert_eq!(json.matches("\"index\"").count(), tasks.parse::<usize>().unwrap());
        // `--json -`: standard output is the JSON alone, the table goes to standard error.
        let piped = lucent(&dir, &["plan", "s.test", "--tasks", tasks, "--by", by, "--json", "-"]);
        assert_eq!(String::from_utf8_lossy(&piped.stdout), json);
        assert!(String::from_utf8_lossy(&piped.stderr).contains(expect));
        let n: u32 = tasks.parse().unwrap();
        let mut states = Vec::new();
        for i in 0..n {
            let (task, state) = (format!("{i}/{n}"), format!("t{i}.lstate"));
            let threads = if i % 2 == 0 { "1" } else { "2" };
            ok(
                &dir,
                &[
                    "render",
                    "s.test",
                    "--task",
                    &task,
                    "--by",
                    by,
                    "--state",
                    &state,
                    "-o",
                    "/dev/null",
                    "-q",
                    "--threads",
                    threads,
                ],
            );
            states.push(state);
        }
        ok(&dir, &["render", "s.test", "-o", "one.png", "-q"]);
        let mut args = vec!["merge", "-o", "m.png"];
        args.extend(states.iter().map(String::as_str));
        ok(&dir, &args);
        assert!(
            fs::read(dir.join("one.png")).unwrap() == fs::read(dir.join("m.png")).unwrap(),
            "{integrator:?} {by}"
        );
    }
    fails(
        &dir,
        &["render", "s.test", "--task", "5/5", "--state", "x.lstate"],
        "tasks are numbered 0..4",
    );
    let o = lucent(&dir, &["render", "s.test", "--task", "1/5"]);
    assert_eq!(o.status.code(), Some(2), "--task needs --state");
    fails(&dir, &["plan", "s.test", "--tasks", "31"], "at least 31 rows");
}
