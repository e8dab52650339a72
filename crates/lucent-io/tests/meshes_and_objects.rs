//! `mesh`, `subdivmesh`, `objectbegin`/`objectend`/`instance`: every error is located
//! at its command, and the geometry they make renders exactly like the same triangles
//! and shapes written out by hand, with every acceleration structure.

mod common;

use common::TempDir;
use std::path::Path;

use lucent_core::accel::AccelKind;

const HEADER: &str = "size 48 36\ncamera 0 0 6 0 0 0 0 1 0 45\n";

/// `line:col: severity: message` for every diagnostic of parse and build.
fn diagnostics(scene: &str, text: &str) -> Vec<String> {
    common::diagnostics(scene, text, false)
}

fn render_bytes(scene: &str, text: &str, accel: AccelKind) -> Vec<u8> {
    common::render_rgb8(scene, text, accel, 1)
}

const LIGHTS: &str = "ambient 0 0 0\npoint 2 3 6 1 1 1\ndirectional -1 1 1 0.3 0.3 0.3\n";

/// A pyramid (square base, apex up) as OBJ text, and the same faces as `vertex`/`tri`.
const PYRAMID_OBJ: &str = "v -1 -1 -1\nv 1 -1 -1\nv 1 -1 1\nv -1 -1 1\nv 0 1 0\n\
                           f 1 2 3 4\nf 1 5 2\nf 2 5 3\nf 3 5 4\nf 4 5 1\n";
const PYRAMID_TRIS: &str = "vertex -1 -1 -1\nvertex 1 -1 -1\nvertex 1 -1 1\nvertex -1 -1 1\nvertex 0 1 0\n\
                            tri 0 1 2\ntri 0 2 3\ntri 0 4 1\ntri 1 4 2\ntri 2 4 3\ntri 3 4 0\n";

#[test]
fn an_obj_mesh_renders_exactly_like_the_same_triangles() {
    let dir = TempDir::new("obj");
    dir.write("pyramid.obj", PYRAMID_OBJ);
    let place = "rotate 0 1 0 30\nrotate 1 0 0 20\ndiffuse 0.8 0.4 0.2\nspecular 0.3 0.3 0.3\n";
    let with_mesh = format!("{HEADER}{LIGHTS}{place}mesh pyramid.obj\n");
    let with_tris = format!("{HEADER}{LIGHTS}{place}{PYRAMID_TRIS}");
    for accel in AccelKind::ALL {
        let a = render_bytes(&dir.scene(), &with_mesh, accel);
        let b = render_bytes(&dir.scene(), &with_tris, accel);
        assert_eq!(a, b, "{accel:?}");
        assert!(a.iter().any(|&v| v > 0));
    }
}

#[test]
fn a_ply_mesh_renders_exactly_like_the_obj() {
    let dir = TempDir::new("ply");
    dir.write("pyramid.obj", PYRAMID_OBJ);
    dir.write(
        "pyramid.ply",
        "ply\nformat ascii 1.0\ncomment the pyramid\nelement vertex 5\nproperty float x\nproperty float y\nproperty float z\n\
         element face 5\nproperty list uchar int vertex_indices\nend_header\n\
         -1 -1 -1\n1 -1 -1\n1 -1 1\n-1 -1 1\n0 1 0\n4 0 1 2 3\n3 0 4 1\n3 1 4 2\n3 2 4 3\n3 3 4 0\n",
    );
    let scene = |file: &str| format!("{HEADER}{LIGHTS}rotate 0 1 0 30\ndiffuse 0.5 0.5 0.9\nmesh {file}\n");
    assert_eq!(
        render_bytes(&dir.scene(), &scene("pyramid.obj"), AccelKind::Bvh),
        render_bytes(&dir.scene(), &scene("pyramid.ply"), AccelKind::Bvh)
    );
}

#[test]
fn instances_render_exactly_like_the_shapes_placed_by_hand() {
    // An object of a sphere, a box and a cone, placed three times with different
    // transforms, against the same shapes written out under the same transforms.
    let dir = TempDir::new("inst");
    dir.write("pyramid.obj", PYRAMID_OBJ);
    let parts = "diffuse 0.9 0.2 0.2\nsphere 0 0.5 0 0.5\ndiffuse 0.2 0.8 0.3\nbox -0.4 -1 -0.4 0.4 -0.2 0.4\n\
                 pushTransform\nscale 0.3 0.3 0.3\ntranslate 0 -3 2\nmesh pyramid.obj\npopTransform\n";
    let placements = [
        "translate -1.5 0 0\nrotate 0 1 0 40\n",
        "translate 1.4 0.3 -1\nscale 0.7 1.2 0.7\n",
        "translate 0 -1.2 1\nrotate 1 0 0 -30\nscale 0.5 0.5 0.5\n",
    ];
    let mut instanced = format!("{HEADER}{LIGHTS}objectbegin thing\n{parts}objectend\n");
    let mut by_hand = format!("{HEADER}{LIGHTS}");
    for p in placements {
        instanced += &format!("pushTransform\n{p}instance thing\npopTransform\n");
        by_hand += &format!("pushTransform\n{p}{parts}popTransform\n");
    }
    // A plane beside them (unbounded, outside the structures).
    let floor = "diffuse 0.5 0.5 0.5\nplane 0 -2 0 0 1 0\n";
    instanced += floor;
    by_hand += floor;
    for accel in AccelKind::ALL {
        let a = render_bytes(&dir.scene(), &instanced, accel);
        let b = render_bytes(&dir.scene(), &by_hand, accel);
        let differing = a.chunks(3).zip(b.chunks(3)).filter(|(x, y)| x != y).count();
        // Rays go into instance space in f32, so a hit can round differently from the
        // world-space test: a silhouette pixel may flip, nothing more.
        assert!(differing <= 3, "{accel:?}: {differing} pixels differ");
        assert!(a.iter().any(|&v| v > 0));
    }
}

#[test]
fn mesh_errors_point_at_the_command() {
    let dir = TempDir::new("errors");
    dir.write("broken.obj", "v 0 0 0\nv 1 0 0\nf 1 2 7\n");
    dir.write(
        "broken.ply",
        "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n",
    );
    dir.write("shape.stl", "solid\n");
    dir.write("textured.mtl", "newmtl wood\nKd 1 1 1\nmap_Kd wood.png\n");
    dir.write(
        "textured.obj",
        "mtllib textured.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl wood\nf 1 2 3\n",
    );
    dir.write(
        "nomtl.obj",
        "mtllib gone.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl wood\nf 1 2 3\n",
    );
    let s = dir.scene();
    let one = |line: &str| diagnostics(&s, &format!("{HEADER}{line}\n"));
    assert_eq!(
        one("mesh missing.obj"),
        [format!(
            "3:6: error: mesh: {}: cannot open: no such file",
            dir.path("missing.obj")
        )]
    );
    assert_eq!(
        one("mesh broken.obj"),
        [format!(
            "3:6: error: mesh: {}: line 3: a face refers to vertex 7, but the file has 2",
            dir.path("broken.obj")
        )]
    );
    assert!(one("mesh broken.ply")[0].starts_with(&format!("3:6: error: mesh: {}: ", dir.path("broken.ply"))));
    assert_eq!(
        one("mesh shape.stl"),
        [format!(
            "3:6: error: mesh: {}: unknown mesh format (expected a .obj or .ply file)",
            dir.path("shape.stl")
        )]
    );
    assert_eq!(
        one("mesh textured.obj"),
        [format!(
            "3:6: error: mesh: material 'wood': map_Kd {}: cannot open: no such file",
            dir.path("wood.png")
        )]
    );
    image::RgbImage::from_raw(1, 1, vec![255, 128, 0])
        .unwrap()
        .save(dir.0.join("wood.png"))
        .unwrap();
    assert!(one("mesh textured.obj").is_empty(), "map_Kd loads relative to the OBJ");
    assert_eq!(
        one("mesh nomtl.obj"),
        [format!(
            "3:6: warning: mesh: {}: cannot read the MTL material library (no such file); the current material is used",
            dir.path("nomtl.obj")
        )]
    );
    assert_eq!(
        one("mesh"),
        ["3:5: error: mesh: expected a file name (.obj or .ply), got 0 arguments"]
    );
}

#[test]
fn subdivision_errors_point_at_the_command() {
    let dir = TempDir::new("subdiv");
    // Three triangles on one edge: no surface can be made of that.
    dir.write(
        "fin.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n",
    );
    dir.write(
        "tet.obj",
        "v 1 1 1\nv -1 -1 1\nv -1 1 -1\nv 1 -1 -1\nf 1 2 3\nf 1 4 2\nf 1 3 4\nf 2 4 3\n",
    );
    let s = dir.scene();
    let one = |line: &str| diagnostics(&s, &format!("{HEADER}{line}\n"));
    assert_eq!(
        one("subdivmesh butterfly 2 tet.obj"),
        ["3:12: error: subdivmesh: unknown value 'butterfly' (expected loop or catmullclark)"]
    );
    assert_eq!(
        one("subdivmesh loop 9 tet.obj"),
        ["3:17: error: subdivmesh: levels must be between 0 and 8, got 9"]
    );
    assert_eq!(
        one("subdivmesh loop x tet.obj"),
        ["3:17: error: subdivmesh: 'x' is not a number"]
    );
    assert_eq!(
        one("subdivmesh loop 1 fin.obj"),
        [format!(
            "3:19: error: subdivmesh: {}: the edge between vertices 0 and 1 belongs to more than two faces",
            dir.path("fin.obj")
        )]
    );
    assert_eq!(
        one("subdivmesh loop 1"),
        ["3:18: error: subdivmesh: expected a scheme (loop or catmullclark), a number of levels and a file name, got 2 arguments"]
    );
    assert!(one("subdivmesh catmullclark 3 tet.obj").is_empty());
    assert!(one("subdivmesh loop 0 tet.obj").is_empty());
}

#[test]
fn object_errors_point_at_the_command() {
    let m = |text: &str| diagnostics("t.test", &format!("{HEADER}{text}"));
    assert_eq!(
        m("instance ghost\n"),
        ["3:10: error: instance: unknown object 'ghost' (no object is defined yet)"]
    );
    assert_eq!(
        m("objectbegin a\nsphere 0 0 0 1\nobjectend\ninstance b\n"),
        ["6:10: error: instance: unknown object 'b' (defined: a)"]
    );
    assert_eq!(
        m("objectbegin a\nobjectbegin b\nobjectend\n"),
        [
            "4:1: error: objectbegin: objects cannot be nested (object 'a' begun on line 3 has no objectend yet)",
            "5:1: warning: objectend: object 'a' is empty"
        ]
    );
    assert_eq!(m("objectend\n"), ["3:1: error: objectend without objectbegin"]);
    assert_eq!(
        m("objectbegin a\nsphere 0 0 0 1\n"),
        ["3:13: error: objectbegin: object 'a' has no objectend"]
    );
    assert_eq!(
        m("objectbegin a\nsphere 0 0 0 1\nobjectend\nobjectbegin a\nobjectend\n"),
        [
            "6:13: error: objectbegin: an object named 'a' is already defined on line 3",
            "7:1: error: objectend without objectbegin"
        ]
    );
    assert_eq!(
        m("objectbegin a\nsphere 0 0 0 1\nobjectend\nobjectbegin b\ninstance a\nobjectend\n"),
        [
            "7:1: error: instance: objects cannot contain instances (object 'b' begun on line 6 is still open)",
            "8:1: warning: objectend: object 'b' is empty"
        ]
    );
    assert_eq!(
        m("objectbegin a\npoint 0 0 0 1 1 1\nobjectend\n"),
        [
            "4:1: error: point: lights cannot be part of an object (object 'a' begun on line 3 is still open)",
            "5:1: warning: objectend: object 'a' is empty"
        ]
    );
    assert_eq!(
        m("objectbegin\n"),
        ["3:12: error: objectbegin: expected an object name, got 0 arguments"]
    );
    // An empty object may be instanced: it shows nothing.
    assert_eq!(
        m("objectbegin a\nobjectend\ninstance a\n"),
        [
            "4:1: warning: objectend: object 'a' is empty",
            "5:1: warning: the scene has no objects: the picture will show nothing"
        ]
    );
}

#[test]
fn the_shipped_mesh_scenes_load_without_a_word() {
    use lucent_io::session::{Session, SessionOptions};
    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    for name in ["meshes.test", "instances.test", "subdivision.test"] {
        let options = SessionOptions {
            strict: true,
            accel: lucent_core::accel::AccelKind::List,
            ..SessionOptions::default()
        };
        let s = Session::open(&scenes.join(name), options);
        assert!(
            s.built.is_some() && s.diags.items.is_empty(),
            "{name}: {}",
            s.diags.render(&s.desc.sources)
        );
    }
}
