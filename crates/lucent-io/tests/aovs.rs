//! The auxiliary passes (`--aov`, the guides of `--denoise`) against answers known in
//! closed form: the distance to a sphere straight ahead, its normal, its albedo; glass
//! seen through to the wall behind; coverage; and that computing them changes no bit of
//! the colour.

mod common;

use common::render_film;
use lucent_core::film::AovImages;
use lucent_core::math::Color;

/// A 33 × 33 image whose centre pixel looks down −z from (0, 0, 5) at the origin.
const CAMERA: &str = "size 33 33\ncamera 0 0 5 0 0 0 0 1 0 30\ndirectional 0 0 1 1 1 1\n";

fn aovs(text: &str) -> AovImages {
    let (film, _) = render_film("aov.test", text, 2, |job| job.aovs = true);
    film.resolve_aovs().expect("a job with aovs keeps them")
}

const CENTRE: usize = 16 * 33 + 16;

#[test]
fn a_sphere_straight_ahead_shows_its_distance_normal_and_albedo() {
    let a = aovs(&format!(
        "{CAMERA}diffuse 0.5 0.25 0.125\nspecular 0.1 0.1 0.1\nsphere 0 0 0 1\n"
    ));
    // One sample through the pixel centre: the ray along −z meets the sphere at z = 1.
    assert!((a.depth[CENTRE] - 4.0).abs() < 1e-5, "{}", a.depth[CENTRE]);
    assert!((a.normal.pixels[CENTRE] - Color::Z).length() < 1e-5);
    // Albedo: diffuse + specular.
    assert!((a.albedo.pixels[CENTRE] - Color::new(0.6, 0.35, 0.225)).length() < 1e-6);
    assert_eq!(a.alpha[CENTRE], 1.0);
    // The corner sees nothing: no coverage, infinite depth, zero normal and albedo.
    assert_eq!((a.alpha[0], a.depth[0]), (0.0, f32::INFINITY));
    assert_eq!((a.albedo.pixels[0], a.normal.pixels[0]), (Color::ZERO, Color::ZERO));
}

#[test]
fn glass_is_seen_through_to_the_surface_behind_it() {
    let wall = "maxverts 4\nvertex -9 -9 -3\nvertex 9 -9 -3\nvertex 9 9 -3\nvertex -9 9 -3\ndiffuse 0.2 0.7 0.3\ntri 0 1 2\ntri 0 2 3\n";
    let glass = "diffuse 0 0 0\ntransparent 1 1 1\nior 1.5\nsphere 0 0 0 1\n";
    let a = aovs(&format!("{CAMERA}{wall}{glass}"));
    // The centre ray meets the glass head on, goes straight through, and finds the wall:
    // its albedo and normal, with the depth of the glass.
    assert!((a.albedo.pixels[CENTRE] - Color::new(0.2, 0.7, 0.3)).length() < 1e-6);
    assert!((a.normal.pixels[CENTRE] - Color::Z).length() < 1e-5);
    assert!((a.depth[CENTRE] - 4.0).abs() < 1e-5);
    // The corner pixel sees the wall 8 away along the axis, along a ray tilted by
    // tan 15° × 32/33 in x and y.
    let t = 15f64.to_radians().tan() * 32.0 / 33.0;
    let corner = 8.0 * (1.0 + 2.0 * t * t).sqrt();
    assert!(
        (a.depth[0] as f64 - corner).abs() < 1e-4,
        "{} against {corner}",
        a.depth[0]
    );
    assert_eq!(a.alpha[0], 1.0);
}

#[test]
fn coverage_is_the_fraction_of_samples_that_hit_and_the_colour_does_not_change() {
    // A sphere whose silhouette crosses pixels: alpha strictly between 0 and 1 there, and
    // the colour's sums are the same bits with and without the passes (they draw no
    // random number of the integrator's).
    let text = format!(
        "{CAMERA}integrator pathtracer\nspp 16\nquadLight -1 3 -1 2 0 0 0 0 2 5 5 5\ndiffuse 0.7 0.7 0.7\nsphere 0 0 0 1.2\n"
    );
    let (with, _) = render_film("aov.test", &text, 2, |job| job.aovs = true);
    let (without, _) = render_film("aov.test", &text, 1, |_| {});
    let sums = |f: &lucent_core::film::Film| (0..f.counts.len()).map(|i| f.sum(i)).collect::<Vec<_>>();
    assert_eq!((sums(&with), &with.counts), (sums(&without), &without.counts));
    let a = with.resolve_aovs().unwrap();
    let edge = a.alpha.iter().filter(|&&v| v > 0.0 && v < 1.0).count();
    assert!(edge >= 8, "{edge} pixels on the silhouette");
    // Alpha is hits / samples: multiples of 1/16.
    assert!(a.alpha.iter().all(|&v| (v * 16.0).fract() == 0.0));
}
