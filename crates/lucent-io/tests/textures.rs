//! `texture`, `checker`, `diffusemap`, `bumpmap` and `envmap`, rendered, with values
//! worked out by hand; and their errors, located.

mod common;

use common::TempDir;

use lucent_core::accel::AccelKind;

fn render_film(scene: &str, text: &str) -> Vec<[f32; 3]> {
    let (film, _) = common::render_scene(scene, text, AccelKind::Bvh, 1);
    film.pixels.iter().map(|p| p.to_array()).collect()
}

fn errors(scene: &str, text: &str) -> Vec<String> {
    common::errors(scene, text)
}

/// A unit square `[0, 1]²` in z = 0 facing +z, its texture coordinates its x and y (two
/// triangles of an OBJ file with `vt`), seen straight on by an orthographic camera.
const SQUARE_OBJ: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n";

#[test]
fn a_diffuse_map_multiplies_the_diffuse_colour_at_the_texture_coordinates() {
    let dir = TempDir::new("diffuse");
    std::fs::write(dir.0.join("square.obj"), SQUARE_OBJ).unwrap();
    // 2 × 2 texels: top row white and black, bottom row red and sRGB 188 grey (≈ 0.5).
    image::RgbImage::from_raw(2, 2, vec![255, 255, 255, 0, 0, 0, 255, 0, 0, 188, 188, 188])
        .unwrap()
        .save(dir.0.join("t.png"))
        .unwrap();
    let text = |size: u32| {
        format!(
            "size {size} {size}\northocamera 0.5 0.5 5 0.5 0.5 0 0 1 0 1\nambient 0 0 0\ndirectional 0 0 1 1 1 1\n\
             texture tiles t.png\ndiffusemap tiles\ndiffuse 1 1 1\nmesh square.obj\n"
        )
    };
    // 2 × 2 pixels: their centres (u, v = 1/4, 3/4) are the texel centres.
    let film = render_film(&dir.scene(), &text(2));
    assert_eq!(film[0], [1.0, 1.0, 1.0], "top left: white");
    assert_eq!(film[1], [0.0, 0.0, 0.0], "top right: black");
    assert_eq!(film[2], [1.0, 0.0, 0.0], "bottom left: red");
    assert!((film[3][0] - 0.5).abs() < 0.01, "bottom right: sRGB 188 is linear 0.5");
    // 4 × 4: pixel (1, 1) is a quarter texel right of and below the white texel's
    // centre: bilinear weights 9/16 white, 3/16 black, 3/16 red, 1/16 grey.
    let film = render_film(&dir.scene(), &text(4));
    let p = film[4 + 1];
    let (r, g) = (9.0 / 16.0 + 3.0 / 16.0 + 0.5 / 16.0, 9.0 / 16.0 + 0.5 / 16.0);
    assert!(
        (p[0] - r).abs() < 0.01 && (p[1] - g).abs() < 0.01 && (p[2] - g).abs() < 0.01,
        "{p:?}"
    );
}

#[test]
fn a_checker_alternates_in_world_space() {
    let text = "size 8 1\northocamera 4 0.5 5 4 0.5 0 0 1 0 1\nambient 0 0 0\ndirectional 0 0 1 1 1 1\n\
                checker c 1 1 1 0.2 0.2 0.2 1\ndiffusemap c\ndiffuse 1 0.5 1\n\
                vertex 0 0 0\nvertex 8 0 0\nvertex 8 1 0\nvertex 0 1 0\ntri 0 1 2\ntri 0 2 3\n";
    let film = render_film("t.test", text);
    for (x, p) in film.iter().enumerate() {
        let expect = if x % 2 == 0 { 1.0 } else { 0.2 };
        assert!(
            (p[0] - expect).abs() < 1e-6 && (p[1] - expect * 0.5).abs() < 1e-6,
            "{x}: {p:?}"
        );
    }
}

#[test]
fn a_bump_map_tilts_the_normal_by_the_height_gradient() {
    // A ramp texture (luminance rising linearly with u across 64 texels) on the square,
    // bump strength s: the surface z = s·u rises by s over the unit square, so the normal
    // is (−s, 0, 1)/√(1 + s²). Lit by a directional light along +x, the diffuse term is
    // s/√(1 + s²).
    let dir = TempDir::new("bump");
    std::fs::write(dir.0.join("square.obj"), SQUARE_OBJ).unwrap();
    let ramp: Vec<f32> = (0..64).flat_map(|x| [x as f32 / 63.0; 3]).collect();
    image::Rgb32FImage::from_raw(64, 1, ramp)
        .unwrap()
        .save(dir.0.join("ramp.exr"))
        .unwrap();
    let s = 0.5f32;
    let text = format!(
        "size 4 4\northocamera 0.5 0.5 5 0.5 0.5 0 0 1 0 1\nambient 0 0 0\ndirectional -1 0 0 1 1 1\n\
         texture ramp ramp.exr\nbumpmap ramp {s}\ndiffuse 1 1 1\nmesh square.obj\n"
    );
    let film = render_film(&dir.scene(), &text);
    // Away from the wrapping edge the gradient is the ramp's: 63/64 per texel width...
    let expect = {
        let slope = s * 64.0 / 63.0;
        slope / (1.0 + slope * slope).sqrt()
    };
    for x in 1..3 {
        let got = film[4 + x][0];
        assert!((got - expect).abs() < 0.01, "{x}: {got} vs {expect}");
    }
    // Without the bump map the light grazes the square: black.
    let flat = render_film(&dir.scene(), &text.replace("bumpmap ramp 0.5\n", ""));
    assert_eq!(flat[5][0], 0.0);
}

#[test]
fn the_environment_map_is_seen_by_escaping_rays_and_in_mirrors() {
    // A 2 × 1 environment: the half of the sky around −z is 0.25, the half around +z is 1
    // (longitude u = 0.5 looks along −z).
    let dir = TempDir::new("env");
    image::Rgb32FImage::from_raw(
        4,
        1,
        vec![1.0, 1.0, 1.0, 0.25, 0.25, 0.25, 0.25, 0.25, 0.25, 1.0, 1.0, 1.0],
    )
    .unwrap()
    .save(dir.0.join("sky.exr"))
    .unwrap();
    let text = "size 3 3\ncamera 0 0 5 0 0 0 0 1 0 10\nenvmap sky.exr 2\n";
    let film = render_film(&dir.scene(), text);
    assert!(
        (film[4][0] - 0.5).abs() < 1e-5,
        "looking along −z: 0.25 × 2, got {:?}",
        film[4]
    );
    // A mirror facing the camera sends the ray back along +z: 1 × 2, times the mirror's 0.5.
    let mirror = format!("{text}ambient 0 0 0\nspecular 0.5 0.5 0.5\nvertex -9 -9 0\nvertex 9 -9 0\nvertex 9 9 0\nvertex -9 9 0\ntri 0 1 2\ntri 0 2 3\n");
    let film = render_film(&dir.scene(), &mirror);
    assert!((film[4][0] - 1.0).abs() < 1e-5, "{:?}", film[4]);
}

#[test]
fn texture_errors_point_at_the_command() {
    let dir = TempDir::new("errors");
    std::fs::write(dir.0.join("bad.png"), "not an image").unwrap();
    let s = dir.scene();
    let head = "size 8 8\ncamera 0 0 5 0 0 0 0 1 0 45\n";
    let one = |line: &str| errors(&s, &format!("{head}{line}\n"));
    let path = |f: &str| dir.0.join(f).display().to_string();
    assert_eq!(
        one("texture t missing.png"),
        [format!(
            "3:11: texture: {}: cannot open: no such file",
            path("missing.png")
        )]
    );
    assert!(one("texture t bad.png")[0].starts_with(&format!("3:11: texture: {}: ", path("bad.png"))));
    assert_eq!(
        one("diffusemap wood"),
        ["3:12: diffusemap: unknown texture 'wood' (no texture is defined yet)"]
    );
    assert_eq!(
        one("checker c 1 1 1 0 0 0 1\nbumpmap wood 1"),
        ["4:9: bumpmap: unknown texture 'wood' (defined: c)"]
    );
    assert_eq!(
        one("checker c 1 1 1 0 0 0 0"),
        ["3:23: checker: the cell size must be positive, got 0"]
    );
    assert_eq!(
        one("checker c 1 1 1 0 0 0 1\nchecker c 1 1 1 0 0 0 2"),
        ["4:9: checker: a texture named 'c' is already defined on line 3"]
    );
    assert_eq!(
        one("envmap sky.hdr 1 2"),
        ["3:1: envmap: expected an image file and optionally an intensity, got 3 arguments"]
    );
    assert_eq!(
        one("envmap missing.hdr"),
        [format!(
            "3:8: envmap: {}: cannot open: no such file",
            path("missing.hdr")
        )]
    );
    assert_eq!(
        one("bumpmap"),
        ["3:8: bumpmap: expected a texture name and a strength, or 'off', got 0 arguments"]
    );
}

#[test]
fn a_displacement_map_moves_the_surface_before_it_is_rendered() {
    // The unit square displaced by a uniform texture of luminance 1 and scale 0.5 moves
    // to z = 0.5 along its normal (+z): a camera looking down from z = 5 sees it 0.5
    // closer, which a distance-dependent point light shows.
    let dir = TempDir::new("displace");
    std::fs::write(dir.0.join("square.obj"), SQUARE_OBJ).unwrap();
    image::RgbImage::from_raw(1, 1, vec![255, 255, 255])
        .unwrap()
        .save(dir.0.join("white.png"))
        .unwrap();
    let scene = |extra: &str| {
        format!(
            "size 2 2\northocamera 0.5 0.5 5 0.5 0.5 0 0 1 0 1\nambient 0 0 0\nattenuation 0 0 1\n\
             point 0.5 0.5 2 1 1 1\ndiffuse 1 1 1\ntexture white white.png\n{extra}mesh square.obj\n"
        )
    };
    let flat = render_film(&dir.scene(), &scene(""));
    let raised = render_film(&dir.scene(), &scene("displacementmap white 0.5\n"));
    // Pixel centres are (0.25, 0.25) … from the surface; the light is 2 (flat) or 1.5
    // (raised) above the square: irradiance cos θ / r² with r² = 0.125 + h².
    let expect = |h: f32| h / (0.125f32 + h * h).powf(1.5);
    assert!((flat[0][0] - expect(2.0)).abs() < 1e-3, "{:?}", flat[0]);
    assert!((raised[0][0] - expect(1.5)).abs() < 1e-3, "{:?}", raised[0]);
    // Without texture coordinates an image cannot be looked up: an error at the mesh.
    std::fs::write(dir.0.join("bare.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let errs = errors(
        &dir.scene(),
        "size 2 2\ncamera 0 0 5 0 0 0 0 1 0 45\ntexture white white.png\ndisplacementmap white 1\nmesh bare.obj\n",
    );
    assert_eq!(
        errs,
        ["5:1: mesh: displacementmap: the surface has no texture coordinates to look the image up at"]
    );
}
