//! Every malformed-scene case gets an exact `file:line:col` message. Each case is a
//! scene with a valid header plus one bad line (line 3).

mod common;

use lucent_io::cse167::{parse_bytes, ParseOptions};

const HEADER: &str = "size 64 48\ncamera 0 0 5 0 0 0 0 1 0 45\n";

/// The first line of every error and warning (parse and build), in order.
/// The parser's and the build's messages about `text`, but for the warning that a
/// scene has no objects (most scenes here have none; that warning has its own test in
/// the `lucent` crate's cli.rs).
fn messages(text: &str, strict: bool) -> Vec<String> {
    common::diagnostics("t.test", text, strict)
        .into_iter()
        .filter(|m| !m.contains("warning: the scene has no objects"))
        .map(|m| format!("t.test:{m}"))
        .collect()
}

fn first_error(bad_line: &str) -> String {
    let all = messages(&format!("{HEADER}{bad_line}\n"), false);
    all.into_iter()
        .find(|m| m.contains(": error: "))
        .unwrap_or_else(|| panic!("no error for {bad_line:?}"))
}

#[test]
fn argument_counts() {
    assert_eq!(
        first_error("camera 0 0 5 0 0 0 0 1 0"),
        "t.test:3:25: error: camera: expected 10 numbers, got 9 arguments"
    );
    assert_eq!(
        first_error("sphere 0 0 0 1 2"),
        "t.test:3:16: error: sphere: expected 4 numbers, got 5 arguments"
    );
    assert_eq!(
        first_error("pushTransform 1"),
        "t.test:3:15: error: pushTransform: expected no arguments, got 1 argument"
    );
    assert_eq!(
        first_error("output"),
        "t.test:3:7: error: output: expected a file name, got 0 arguments"
    );
}

#[test]
fn malformed_and_non_finite_numbers() {
    assert_eq!(
        first_error("translate 1 x 2"),
        "t.test:3:13: error: translate: 'x' is not a number"
    );
    assert_eq!(
        first_error("translate 1 inf 2"),
        "t.test:3:13: error: translate: 'inf' is not a number"
    );
    assert_eq!(
        first_error("translate nan 0 2"),
        "t.test:3:11: error: translate: 'nan' is not a number"
    );
    assert_eq!(
        first_error("translate 0x10 0 2"),
        "t.test:3:11: error: translate: '0x10' is not a number"
    );
    assert_eq!(
        first_error("translate 1e39 0 2"),
        "t.test:3:11: error: translate: 1e39 is out of range"
    );
    assert_eq!(
        first_error("maxdepth 2.5"),
        "t.test:3:10: error: maxdepth: '2.5' is not an integer"
    );
    assert_eq!(
        first_error("tri 0 1 two"),
        "t.test:3:9: error: tri: 'two' is not a number"
    );
}

#[test]
fn impossible_values() {
    assert_eq!(
        first_error("sphere 0 0 0 -1"),
        "t.test:3:14: error: sphere: radius must be positive, got -1"
    );
    assert_eq!(
        first_error("sphere 0 0 0 0"),
        "t.test:3:14: error: sphere: radius must be positive, got 0"
    );
    assert_eq!(
        first_error("rotate 0 0 0 30"),
        "t.test:3:8: error: rotate: the rotation axis is zero"
    );
    assert_eq!(
        first_error("scale 1 0 1"),
        "t.test:3:9: error: scale: a zero factor makes the transform singular"
    );
    assert_eq!(
        first_error("directional 0 0 0 1 1 1"),
        "t.test:3:13: error: directional: the direction is zero"
    );
    assert_eq!(
        first_error("attenuation 0 0 0"),
        "t.test:3:13: error: attenuation: all three coefficients are zero (infinite light)"
    );
    assert_eq!(
        first_error("attenuation 1 -1 0"),
        "t.test:3:15: error: attenuation: coefficients must not be negative"
    );
    assert_eq!(
        first_error("maxdepth -2"),
        "t.test:3:10: error: maxdepth: depth must be -1 (unbounded) or between 0 and 2147483647, got -2"
    );
    assert_eq!(
        first_error("shininess -3"),
        "t.test:3:11: error: shininess: must not be negative, got -3"
    );
    assert_eq!(
        first_error("spp 0"),
        "t.test:3:5: error: spp: must be at least 1, got 0"
    );
    assert_eq!(
        first_error("lightsamples -4"),
        "t.test:3:14: error: lightsamples: must be at least 1, got -4"
    );
    assert_eq!(
        first_error("gamma 0"),
        "t.test:3:7: error: gamma: must be positive, got 0"
    );
    assert_eq!(
        first_error("roughness 0"),
        "t.test:3:11: error: roughness: must be positive, got 0"
    );
    assert_eq!(
        first_error("quadLight 0 0 0 1 0 0 2 0 0 1 1 1"),
        "t.test:3:17: error: quadLight: the edges ab and ac are parallel or zero (the light has no area)"
    );
    assert_eq!(
        first_error("vertexnormal 0 0 0 0 0 0"),
        "t.test:3:20: error: vertexnormal: the normal has zero length"
    );
}

#[test]
fn indices_out_of_range() {
    assert_eq!(
        first_error("tri 0 1 2"),
        "t.test:3:5: error: tri: vertex index 0 out of range (no vertex defined yet)"
    );
    let text = format!("{HEADER}vertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\ntri 0 1 3\n");
    assert_eq!(
        messages(&text, false)[0],
        "t.test:6:9: error: tri: vertex index 3 out of range (3 vertices defined, valid 0..2)"
    );
    let text = format!("{HEADER}vertex 0 0 0\ntri -1 0 0\n");
    assert_eq!(
        messages(&text, false)[0],
        "t.test:4:5: error: tri: vertex index -1 out of range (1 vertex defined, valid 0..0)"
    );
    assert_eq!(
        first_error("trinormal 0 0 0"),
        "t.test:3:11: error: trinormal: vertex index 0 out of range (no vertexnormal defined yet)"
    );
}

#[test]
fn transform_stack() {
    assert_eq!(
        first_error("popTransform"),
        "t.test:3:1: error: popTransform: transform stack is empty"
    );
    let ok = format!("{HEADER}pushTransform\npushTransform\npopTransform\n");
    assert!(messages(&ok, false).is_empty());
}

#[test]
fn camera_and_size() {
    assert_eq!(
        first_error("camera 0 0 5 0 0 0 0 1 0 180"),
        "t.test:3:26: error: camera: field of view must be between 0 and 180 degrees, got 180"
    );
    assert_eq!(
        first_error("camera 1 2 3 1 2 3 0 1 0 45"),
        "t.test:3:8: error: camera: the eye and the look-at point are the same"
    );
    assert_eq!(
        first_error("camera 0 5 0 0 0 0 0 2 0 45"),
        "t.test:3:20: error: camera: the up vector is parallel to the viewing direction"
    );
    assert_eq!(
        first_error("size 0 10"),
        "t.test:3:6: error: size: width and height must be at least 1, got 0"
    );
    assert_eq!(
        first_error("size 100000 100000"),
        "t.test:3:6: error: size: 100000 x 100000 is too large (at most 67108864 pixels)"
    );
    assert_eq!(
        messages("camera 0 0 5 0 0 0 0 1 0 45\n", false),
        ["t.test:1:1: error: the scene has no 'size' command (required: size width height)"]
    );
    assert_eq!(
        messages("size 10 10\n", false),
        ["t.test:1:1: error: the scene has no 'camera' command (required: camera from at up fovy)"]
    );
    assert_eq!(messages("", false).len(), 2);
}

#[test]
fn keywords() {
    assert_eq!(first_error("integrator magic"), "t.test:3:12: error: integrator: unknown value 'magic' (expected raytracer, analyticdirect, direct or pathtracer)");
    assert_eq!(
        first_error("lightstratify yes"),
        "t.test:3:15: error: lightstratify: unknown value 'yes' (expected on or off)"
    );
    assert_eq!(
        first_error("brdf lambert"),
        "t.test:3:6: error: brdf: unknown value 'lambert' (expected phong, ggx or mirror)"
    );
    assert_eq!(
        first_error("sampler halton"),
        "t.test:3:9: error: sampler: unknown value 'halton' (expected independent or sobol)"
    );
    let text = format!("{HEADER}lightsamples 8\nlightstratify on\n");
    assert_eq!(
        messages(&text, false),
        ["t.test:3:14: error: lightsamples: 'lightstratify on' needs a perfect square, got 8"]
    );
}

#[test]
fn binary_garbage_and_encoding() {
    let mut bytes = HEADER.as_bytes().to_vec();
    bytes.extend_from_slice(b"sphere 0 0 \xff\xfe 1\n");
    let (_, diags) = parse_bytes("t.test", &bytes, ParseOptions::default());
    assert_eq!(
        diags.items[0].message,
        "invalid UTF-8 (byte 0xFF): scene files are text"
    );
    assert_eq!((diags.items[0].loc.line, diags.items[0].loc.col), (3, 12));
    let (_, diags) = parse_bytes("t.test", b"size 1 1\x00\n", ParseOptions::default());
    assert_eq!(
        diags.items[0].message,
        "unexpected control character U+0000: scene files are text"
    );
    assert_eq!(diags.items[0].loc.col, 9);
    // A large binary blob stops after a bounded number of errors.
    let blob: Vec<u8> = (0..200_000u32)
        .map(|i| (i.wrapping_mul(2654435761) >> 13) as u8)
        .collect();
    let (_, diags) = parse_bytes("t.test", &blob, ParseOptions::default());
    assert!(diags.has_errors() && diags.items.len() < 200);
}

#[test]
fn unknown_commands_warn_or_fail_in_strict_mode() {
    let text = format!("{HEADER}pushtransform\nfrobnicate 1\n");
    assert_eq!(
        messages(&text, false),
        [
            "t.test:3:1: warning: unknown command 'pushtransform' ignored; did you mean 'pushTransform'?",
            "t.test:4:1: warning: unknown command 'frobnicate' ignored"
        ]
    );
    assert_eq!(
        messages(&text, true)[0],
        "t.test:3:1: error: unknown command 'pushtransform'; did you mean 'pushTransform'?"
    );
}

#[test]
fn monte_carlo_settings_are_checked_where_they_stand() {
    assert_eq!(
        first_error("integrator photonmapper"),
        "t.test:3:12: error: integrator: unknown value 'photonmapper' (expected raytracer, analyticdirect, direct or pathtracer)"
    );
    assert!(first_error("nexteventestimation maybe").starts_with("t.test:3:21: error: nexteventestimation: "));
    assert!(first_error("importancesampling light").starts_with("t.test:3:20: error: importancesampling: "));
    assert!(first_error("roughness -0.1").starts_with("t.test:3:11: error: roughness: "));
    assert!(first_error("spp 0").starts_with("t.test:3:5: error: spp: must be at least 1"));
    // A non-square count with stratification: reported at the lightsamples line.
    let all = messages(
        &format!("{HEADER}integrator direct\nlightsamples 8\nlightstratify on\n"),
        false,
    );
    assert!(
        all.iter().any(
            |m| m.starts_with("t.test:4:14: error: lightsamples: 'lightstratify on' needs a perfect square, got 8")
        ),
        "{all:?}"
    );
    // Lights an integrator cannot use are named in a warning.
    let all = messages(
        &format!("{HEADER}integrator analyticdirect\npoint 0 1 0 1 1 1\n"),
        false,
    );
    assert!(
        all.iter()
            .any(|m| m.contains("t.test:4:1: warning: point: integrator analyticdirect renders quad lights only")),
        "{all:?}"
    );
    assert!(first_error("quadLight 0 1 0  1 0 0  2 0 0  1 1 1").contains("quadLight"));
}

#[test]
fn sampling_and_camera_extensions() {
    assert_eq!(first_error("ior 0"), "t.test:3:5: error: ior: must be positive, got 0");
    assert_eq!(
        first_error("ior -1.5"),
        "t.test:3:5: error: ior: must be positive, got -1.5"
    );
    assert_eq!(
        first_error("glossy 10 0"),
        "t.test:3:11: error: glossy: samples must be between 1 and 4096, got 0"
    );
    assert_eq!(
        first_error("glossy -1 4"),
        "t.test:3:8: error: glossy: the exponent must not be negative, got -1"
    );
    assert_eq!(
        first_error("glossy 10"),
        "t.test:3:10: error: glossy: expected an exponent and a number of samples, or 'off', got 1 argument"
    );
    assert_eq!(
        first_error("lens -0.1 5"),
        "t.test:3:6: error: lens: the aperture must not be negative, got -0.1"
    );
    assert_eq!(
        first_error("lens 0.1 0"),
        "t.test:3:10: error: lens: the focus distance must be positive, got 0"
    );
    assert_eq!(
        first_error("orthocamera 0 0 5 0 0 0 0 1 0 0"),
        "t.test:3:31: error: orthocamera: the view height must be positive, got 0"
    );
    assert_eq!(
        first_error("spp -4"),
        "t.test:3:5: error: spp: must be at least 1, got -4"
    );
    assert_eq!(
        first_error("lightsamples 0"),
        "t.test:3:14: error: lightsamples: must be at least 1, got 0"
    );
    let ortho_lens = "size 8 8\northocamera 0 0 5 0 0 0 0 1 0 3\nlens 0.1 4\n";
    assert_eq!(
        messages(ortho_lens, false),
        ["t.test:3:1: error: lens: depth of field needs the perspective camera (this scene uses orthocamera)"]
    );
    for ok in [
        "glossy off",
        "glossy 50 16",
        "transparent 1 1 1",
        "ior 1.5",
        "spp 16",
        "lens 0.2 5",
        "lightsamples 9",
    ] {
        let all = messages(&format!("{HEADER}{ok}\n"), true);
        assert!(all.is_empty(), "{ok}: {all:?}");
    }
}

#[test]
fn warnings() {
    let text = "camera 0 0 5 0 0 0 0 1 0 45\nsize 8 8\nsize 9 9\nmaxverts 1\nvertex 0 0 0\nvertex 1 0 0\nvertex 2 0 0\ntri 0 1 2\ndiffuse -1 0 0\ntranslate 1 0 0\npoint 0 0 0 1 1 1\n";
    assert_eq!(
        messages(text, false),
        [
            "t.test:2:1: warning: size: should be the first command of the file",
            "t.test:3:1: warning: size: given again (previously on line 2); the last one wins",
            "t.test:6:1: warning: vertex: vertex #1 exceeds 'maxverts 1' (line 4); continuing (hint only)",
            "t.test:9:9: warning: diffuse: negative colour component -1",
            "t.test:11:1: warning: point: the light is transformed by the current transform (the course's renderers ignore transforms on lights)",
            "t.test:8:1: warning: degenerate triangle (zero area) skipped",
        ]
    );
}

#[test]
fn lexical_rules() {
    // BOM, CRLF, tabs, trailing comments, comment lines, blank lines, +1 and .5.
    let text = "\u{feff}# comment\r\nsize 8 8\r\n\r\n   \t\ncamera\t0 0 +5  0 0 0 0 1 0 45 # trailing\r\n  # indented comment\nsphere .5 -.25 0 +1\n";
    assert!(messages(text, false).is_empty());
    let (desc, _) = parse_bytes("t.test", text.as_bytes(), ParseOptions::default());
    assert_eq!(desc.shapes.len(), 1);
    assert_eq!(desc.camera.unwrap().value.eye.z, 5.0);
}

#[test]
fn state_is_captured_per_object() {
    let text = format!(
        "{HEADER}vertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\ndiffuse 1 0 0\npushTransform\ntranslate 0 0 2\ntri 0 1 2\npopTransform\ndiffuse 0 1 0\ntri 0 1 2\nattenuation 1 2 3\npoint 0 0 0 1 1 1\nattenuation 1 0 0\n"
    );
    let (desc, diags) = parse_bytes("t.test", text.as_bytes(), ParseOptions::default());
    assert!(!diags.has_errors());
    let [a, b] = [desc.shapes[0], desc.shapes[1]];
    assert_eq!(desc.materials[a.material as usize].diffuse.x, 1.0);
    assert_eq!(desc.materials[b.material as usize].diffuse.y, 1.0);
    assert_eq!(desc.transforms[a.transform as usize].point(glam::DVec3::ZERO).z, 2.0);
    assert!(desc.transforms[b.transform as usize].is_identity());
    match desc.lights[0].kind {
        lucent_io::desc::LightKind::Point { attenuation, .. } => {
            assert_eq!(attenuation, glam::DVec3::new(1.0, 2.0, 3.0))
        }
        _ => panic!(),
    }
}

#[test]
fn analytic_shapes() {
    for (line, msg) in [
        (
            "plane 0 0 0 0 0 0",
            "t.test:3:13: error: plane: the normal must not be zero",
        ),
        (
            "plane 0 0 0 0 1",
            "t.test:3:16: error: plane: expected 6 numbers, got 5 arguments",
        ),
        (
            "box 0 0 0 1 0 1",
            "t.test:3:13: error: box: the corners have the same y (the box would be flat)",
        ),
        (
            "cylinder 0 0 1",
            "t.test:3:10: error: cylinder: radius must be positive, got 0",
        ),
        (
            "cylinder 1 2 1",
            "t.test:3:14: error: cylinder: zmax (1) must be greater than zmin (2)",
        ),
        ("disk -1", "t.test:3:6: error: disk: radius must be positive, got -1"),
        ("cone 1 0", "t.test:3:8: error: cone: height must not be zero"),
        ("cone 1 x", "t.test:3:8: error: cone: 'x' is not a number"),
        (
            "quadric 0 0 0 0 0 0 0 0 0 0 -1 -1 -1 1 1 1",
            "t.test:3:9: error: quadric: all ten coefficients are zero (no surface)",
        ),
        (
            "quadric 1 1 1 0 0 0 0 0 0 -1 -1 -1 -1 1 1 -1",
            "t.test:3:43: error: quadric: the clip box needs z1 > z0, got -1 and -1",
        ),
    ] {
        assert_eq!(first_error(line), msg, "{line}");
    }
    // Valid forms parse without a word.
    let ok = "plane 0 -1 0 0 1 0\nbox 1 1 1 -1 -1 -1\ncylinder 1 -1 1\ndisk 2\ncone 1 -2\nquadric 1 1 -1 0 0 0 0 0 0 -0.1 -1 -1 -1 1 1 1\n";
    assert!(messages(&format!("{HEADER}{ok}"), true).is_empty());
}

#[test]
fn bezier_patch_files() {
    let temp = common::TempDir::new("patches");
    let dir = &temp.0;
    std::fs::write(
        dir.join("bad.bpt"),
        "1\n1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16\n2\n0 0 0\n1 1\n",
    )
    .unwrap();
    let scene = dir.join("s.test");
    let name = scene.display().to_string();
    let errors = |line: &str| common::errors(&name, &format!("{HEADER}{line}\n"));
    let bad = dir.join("bad.bpt").display().to_string();
    let missing = dir.join("missing.bpt").display().to_string();
    assert_eq!(
        errors("bezierpatches missing.bpt"),
        [format!("3:15: bezierpatches: cannot read '{missing}': no such file")]
    );
    assert_eq!(
        errors("bezierpatches bad.bpt"),
        [format!(
            "3:15: bezierpatches: {bad}:5: point 2: expected three numbers x y z"
        )]
    );
    assert_eq!(
        errors("bezierpatches bad.bpt 0"),
        ["3:23: bezierpatches: divisions must be between 1 and 256, got 0"]
    );
    assert_eq!(
        errors("bezierpatches"),
        ["3:1: bezierpatches: expected a file name and optionally a number of divisions, got 0 arguments"]
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_shipped_teapot_scene_tessellates() {
    // 32 patches × 16 × 16 quads × 2 triangles, less the empty ones at the poles.
    use lucent_core::geometry::primitive::Shape;
    use lucent_io::session::{Session, SessionOptions};
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/teapot.test");
    let options = SessionOptions {
        strict: true,
        accel: lucent_core::accel::AccelKind::List,
        ..SessionOptions::default()
    };
    let session = Session::open(&path, options);
    let (desc, diags) = (&session.desc, &session.diags);
    assert!(
        !diags.has_errors() && diags.items.is_empty(),
        "{}",
        diags.render(&desc.sources)
    );
    assert_eq!(desc.shapes.len(), 2, "one mesh and the floor plane");
    let built = session.built.as_ref().unwrap();
    let mesh = built
        .scene
        .geometry
        .primitives
        .iter()
        .find_map(|p| match &p.shape {
            Shape::Mesh(m) => Some(&m.mesh),
            _ => None,
        })
        .unwrap();
    let tris = mesh.indices.len();
    assert!((16_000..=16_384).contains(&tris), "{tris}");
    assert_eq!(mesh.positions.len(), 32 * 17 * 17);
    assert!(mesh.normals.iter().all(|n| (n.length() - 1.0).abs() < 1e-6));
    assert_eq!(mesh.uvs.len(), mesh.positions.len());
}

#[test]
fn nurbs_surfaces() {
    let knots_ok = "knotsu 0 0 1 1\nknotsv 0 0 1 1\n";
    let points = "cpoint 0 0 0 1\ncpoint 1 0 0 1\ncpoint 0 1 0 1\ncpoint 1 1 0 1\n";
    let ok = format!("{HEADER}nurbs 1 1 2 2\n{knots_ok}{points}");
    assert!(messages(&ok, true).is_empty(), "{:?}", messages(&ok, true));
    for (text, msg) in [
        (
            "nurbs 0 1 2 2",
            "t.test:3:7: error: nurbs: degree must be between 1 and 16, got 0",
        ),
        (
            "nurbs 2 1 2 2",
            "t.test:3:11: error: nurbs: degree 2 needs at least 3 control points, got 2",
        ),
        (
            "nurbs 1 1 2 2\nknotsu 0 0 1",
            "t.test:4:1: error: knotsu: expected 4 knots (2 control points of degree 1), got 3",
        ),
        (
            "nurbs 1 1 2 2\nknotsu 0 1 0.5 1",
            "t.test:4:12: error: knotsu: knots must not decrease (0.5 after 1)",
        ),
        (
            "nurbs 1 1 2 2\nknotsu 0 1 1 1",
            "t.test:4:1: error: knotsu: the knots leave no parameter range (knot 1 equals knot 2)",
        ),
        (
            "nurbs 1 1 2 2\nknotsv 0 0 1 1",
            "t.test:4:1: error: knotsv: out of order in the nurbs surface of line 3 (expected knotsu)",
        ),
        (
            "nurbs 1 1 2 2\nknotsu 0 0 1 1\nknotsv 0 0 1 1\ncpoint 0 0 0 0",
            "t.test:6:14: error: cpoint: weight must be positive, got 0",
        ),
        (
            "nurbs 1 1 2 2\nknotsu 0 0 1 1\nsphere 0 0 0 1",
            "t.test:5:1: error: 'sphere' inside the nurbs surface of line 3 (expected knotsv)",
        ),
        (
            "nurbs 1 1 2 2\nknotsu 0 0 1 1\nknotsv 0 0 1 1\ncpoint 0 0 0 1",
            "t.test:3:1: error: nurbs: the file ends before the surface is complete (expected 3 more cpoint lines)",
        ),
        (
            "cpoint 0 0 0 1",
            "t.test:3:1: error: cpoint: only allowed right after a 'nurbs' command",
        ),
    ] {
        assert_eq!(first_error(text), msg, "{text}");
    }
}

#[test]
fn quad_lights_as_large_as_single_precision_holds_are_lights() {
    // An area of 4·10³⁶: the edges' cross product is representable, the sum of its
    // components' squares is not (it was refused as having no area).
    let huge = messages(&format!("{HEADER}quadLight 0 0 0 2e18 0 0 0 2e18 0 1 1 1\n"), false);
    assert!(huge.iter().all(|m| !m.contains(": error: ")), "{huge:?}");
    assert_eq!(
        first_error("quadLight 0 0 0 1e20 0 0 0 1e20 0 1 1 1"),
        "t.test:3:1: error: quadLight: the transformed light is too large: its area, or its edges' products, beyond single precision (about 3.4e38)"
    );
}
