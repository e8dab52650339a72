//! Scenes whose pixel values can be worked out by hand. Each expected value is computed
//! here in f64 from the formulas of SCENE_FORMAT.md §3.2 and §4.3, independently of the
//! renderer's own code, and compared byte for byte (±1 for f32 rounding at a truncation
//! boundary). Pixels whose ray grazes a silhouette or a shadow edge are skipped.

mod common;

use glam::{DMat3, DVec3};
use lucent_core::accel::AccelKind;

fn render_bytes(text: &str, accel: AccelKind, threads: usize) -> (u32, u32, Vec<u8>) {
    let (film, gamma) = common::render_scene("t.test", text, accel, threads);
    (film.width, film.height, film.to_rgb8(gamma))
}

fn pixel(img: &(u32, u32, Vec<u8>), x: u32, y: u32) -> [u8; 3] {
    let i = 3 * (y * img.0 + x) as usize;
    [img.2[i], img.2[i + 1], img.2[i + 2]]
}

fn byte(c: f64) -> u8 {
    (255.0 * c.clamp(0.0, 1.0)).floor() as u8
}

/// The primary ray of SCENE_FORMAT.md §3.2 through the centre of pixel (j, i).
#[allow(clippy::too_many_arguments)]
fn camera_ray(eye: DVec3, at: DVec3, up: DVec3, fovy: f64, w: u32, h: u32, j: u32, i: u32) -> DVec3 {
    let wv = (eye - at).normalize();
    let u = up.cross(wv).normalize();
    let v = wv.cross(u);
    let t = (fovy.to_radians() / 2.0).tan();
    let a = t * (w as f64 / h as f64) * (2.0 * (j as f64 + 0.5) / w as f64 - 1.0);
    let b = t * (1.0 - 2.0 * (i as f64 + 0.5) / h as f64);
    (u * a + v * b - wv).normalize()
}

/// Smallest t > 1e-9 where o + t d meets the unit sphere, and how far from grazing it is.
fn unit_sphere(o: DVec3, d: DVec3) -> Option<(f64, f64)> {
    let a = d.dot(d);
    let b = o.dot(d);
    let c = o.dot(o) - 1.0;
    let disc = b * b - a * c;
    if disc < 0.0 {
        return None;
    }
    let t = (-b - disc.sqrt()) / a;
    (t > 1e-9).then_some((t, disc / (a * a)))
}

fn assert_close(got: [u8; 3], want: [u8; 3], what: &str) {
    for k in 0..3 {
        assert!(got[k].abs_diff(want[k]) <= 1, "{what}: got {got:?}, expected {want:?}");
    }
}

#[test]
fn sphere_under_a_directional_light() {
    let scene = "size 41 41\ncamera 0 0 5 0 0 0 0 1 0 30\nambient 0.05 0.05 0.05\ndiffuse 0.5 0.25 0.125\ndirectional 0 0.6 0.8 1 1 1\nsphere 0 0 0 1\n";
    let img = render_bytes(scene, AccelKind::Bvh, 2);
    let (eye, l) = (DVec3::new(0.0, 0.0, 5.0), DVec3::new(0.0, 0.6, 0.8));
    let mut lit = 0;
    for i in 0..41 {
        for j in 0..41 {
            let d = camera_ray(eye, DVec3::ZERO, DVec3::Y, 30.0, 41, 41, j, i);
            let want = match unit_sphere(eye, d) {
                Some((_, margin)) if margin < 1e-3 => continue,
                Some((t, _)) => {
                    let n = eye + d * t;
                    let k = n.dot(l).max(0.0);
                    lit += (k > 0.0) as usize;
                    [byte(0.05 + 0.5 * k), byte(0.05 + 0.25 * k), byte(0.05 + 0.125 * k)]
                }
                None => [0, 0, 0],
            };
            assert_close(pixel(&img, j, i), want, &format!("pixel ({j}, {i})"));
        }
    }
    assert!(lit > 300);
    // The centre by hand: N = +z, N·L = 0.8: 0.05 + (0.5, 0.25, 0.125)·0.8 = (0.45, 0.25, 0.15)
    // → floor(255 ·) = (114, 63, 38).
    assert_eq!(pixel(&img, 20, 20), [114, 63, 38]);
}

#[test]
fn ellipsoid_normals_follow_the_inverse_transpose() {
    // M = T(0.3, 0, 0) · R_z(30°) · S(2, 1, 0.5), applied to the unit sphere.
    let scene = "size 48 36\ncamera 0 0 6 0 0 0 0 1 0 40\nambient 0 0 0\ndiffuse 1 1 1\ndirectional 0.3 0.5 0.8 0.9 0.9 0.9\ntranslate 0.3 0 0\nrotate 0 0 1 30\nscale 2 1 0.5\nsphere 0 0 0 1\n";
    let img = render_bytes(scene, AccelKind::Bvh, 2);
    let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
    let r = DMat3::from_cols(DVec3::new(c, s, 0.0), DVec3::new(-s, c, 0.0), DVec3::Z);
    let m = r * DMat3::from_diagonal(DVec3::new(2.0, 1.0, 0.5));
    let m_inv = m.inverse();
    let shift = DVec3::new(0.3, 0.0, 0.0);
    let eye = DVec3::new(0.0, 0.0, 6.0);
    let l = DVec3::new(0.3, 0.5, 0.8).normalize();
    let mut hits = 0;
    for i in 0..36 {
        for j in 0..48 {
            let d = camera_ray(eye, DVec3::ZERO, DVec3::Y, 40.0, 48, 36, j, i);
            let (o_obj, d_obj) = (m_inv * (eye - shift), m_inv * d);
            let want = match unit_sphere(o_obj, d_obj) {
                Some((_, margin)) if margin < 1e-3 => continue,
                Some((t, _)) => {
                    hits += 1;
                    let n = (m_inv.transpose() * (o_obj + d_obj * t)).normalize();
                    [byte(0.9 * n.dot(l).max(0.0)); 3]
                }
                None => [0, 0, 0],
            };
            assert_close(pixel(&img, j, i), want, &format!("pixel ({j}, {i})"));
        }
    }
    assert!(hits > 200);
}

#[test]
fn point_light_attenuation() {
    let scene = "size 21 21\ncamera 0 0 5 0 0 0 0 1 0 30\nambient 0 0 0\ndiffuse 0.9 0.9 0.9\nattenuation 1 0.5 0.25\npoint 0 0 2 1 1 1\nvertex -50 -50 0\nvertex 50 -50 0\nvertex 50 50 0\nvertex -50 50 0\ntri 0 1 2\ntri 0 2 3\n";
    let img = render_bytes(scene, AccelKind::Bvh, 1);
    // By hand at the centre: r = 2, att = 1 + 0.5·2 + 0.25·4 = 3, 0.9 / 3 = 0.3 → 76.
    assert_eq!(pixel(&img, 10, 10), [76, 76, 76]);
    let (eye, light) = (DVec3::new(0.0, 0.0, 5.0), DVec3::new(0.0, 0.0, 2.0));
    for i in 0..21 {
        for j in 0..21 {
            let d = camera_ray(eye, DVec3::ZERO, DVec3::Y, 30.0, 21, 21, j, i);
            let x = eye + d * (-eye.z / d.z);
            let r = (light - x).length();
            let v = 0.9 * ((light - x) / r).z / (1.0 + 0.5 * r + 0.25 * r * r);
            assert_close(pixel(&img, j, i), [byte(v); 3], &format!("pixel ({j}, {i})"));
        }
    }
}

#[test]
fn shadows_and_lights_in_front_of_occluders() {
    // A floor, a point light above its centre and a sphere between them. The camera sees
    // the floor's centre from the side.
    let base = "size 31 31\ncamera 0 -5 5 0 0 0 0 1 0 40\nvertex -50 -50 0\nvertex 50 -50 0\nvertex 50 50 0\nvertex -50 50 0\nambient 0.1 0.1 0.1\ndiffuse 0.5 0.5 0.5\ntri 0 1 2\ntri 0 2 3\n";
    let shadowed = render_bytes(
        &format!("{base}point 0 0 3 1 1 1\nsphere 0 0 1.5 0.5\n"),
        AccelKind::Bvh,
        2,
    );
    // By hand: the centre is in the sphere's shadow: ambient only, 0.1 → 25.
    assert_eq!(pixel(&shadowed, 15, 15), [25, 25, 25]);
    let eye = DVec3::new(0.0, -5.0, 5.0);
    let (light, centre) = (DVec3::new(0.0, 0.0, 3.0), DVec3::new(0.0, 0.0, 1.5));
    let mut dark = 0;
    for i in 0..31 {
        for j in 0..31 {
            let d = camera_ray(eye, DVec3::ZERO, DVec3::Y, 40.0, 31, 31, j, i);
            if unit_sphere((eye - centre) / 0.5, d / 0.5).is_some() || d.z >= 0.0 {
                continue; // sees the sphere, or the sky
            }
            let x = eye + d * (-eye.z / d.z);
            let to_light = light - x;
            // Does the segment x → light pass through the sphere? Skip near-tangent rays.
            let s = to_light.normalize();
            let oc = x - centre;
            let b = oc.dot(s);
            let disc = b * b - (oc.dot(oc) - 0.25);
            if disc.abs() < 1e-3 {
                continue;
            }
            let blocked = disc > 0.0 && -b - disc.sqrt() > 0.0 && -b - disc.sqrt() < to_light.length();
            dark += blocked as usize;
            let v = 0.1 + if blocked { 0.0 } else { 0.5 * s.z };
            assert_close(pixel(&shadowed, j, i), [byte(v); 3], &format!("pixel ({j}, {i})"));
        }
    }
    assert!(dark > 5);

    // An object beyond the point light casts no shadow on the floor (SCENE_FORMAT §4.3).
    let beyond = render_bytes(
        &format!("{base}point 0 0 1 1 1 1\nsphere 0 0 2.5 0.3\n"),
        AccelKind::Bvh,
        2,
    );
    // By hand: 0.1 + 0.5 · 1 = 0.6 → 153 (f32: 152 or 153).
    assert_close(pixel(&beyond, 15, 15), [153, 153, 153], "centre beyond the light");
}

#[test]
fn mirror_bounces_count_to_maxdepth() {
    // Two facing mirrors with ambient 0.1 and specular 0.5, no lights: the centre ray
    // bounces between them and collects 0.1 · (1 + 0.5 + … + 0.5^d) = 0.1 · (2 − 0.5^d).
    let mirrors = "vertex -100 -100 0\nvertex 100 -100 0\nvertex 100 100 0\nvertex -100 100 0\nvertex -100 -100 10\nvertex 100 -100 10\nvertex 100 100 10\nvertex -100 100 10\nambient 0.1 0.1 0.1\nspecular 0.5 0.5 0.5\ntri 0 1 2\ntri 0 2 3\ntri 4 6 5\ntri 4 7 6\n";
    for (depth, want) in [(0, 25u8), (1, 38), (2, 44), (5, 50)] {
        let img = render_bytes(
            &format!("size 11 11\ncamera 0 0 5 0 0 0 0 1 0 30\nmaxdepth {depth}\n{mirrors}"),
            AccelKind::Bvh,
            2,
        );
        assert_eq!(pixel(&img, 5, 5), [want; 3], "maxdepth {depth}");
    }
    // A huge depth between facing mirrors must end (no recursion that could exhaust a
    // thread's stack) and converge to 0.1 · 2 = 0.2 → 51.
    let img = render_bytes(
        &format!("size 1 1\ncamera 0 0 5 0 0 0 0 1 0 30\nmaxdepth 200000\n{mirrors}"),
        AccelKind::Bvh,
        1,
    );
    assert_close(pixel(&img, 0, 0), [51; 3], "maxdepth 200000");
}

#[test]
fn blinn_phong_highlight() {
    // Light at the eye: H = normalize(L + V) = N at the centre.
    let scene = "size 41 41\ncamera 0 0 5 0 0 0 0 1 0 30\nmaxdepth 0\nambient 0.05 0.05 0.05\ndiffuse 0.25 0.25 0.25\nspecular 0.25 0.25 0.25\nshininess 10\npoint 0 0 5 1 1 1\nsphere 0 0 0 1\n";
    let img = render_bytes(scene, AccelKind::Bvh, 2);
    assert_eq!(pixel(&img, 20, 20), [140, 140, 140]); // 0.05 + 0.25 + 0.25 = 0.55
    let eye = DVec3::new(0.0, 0.0, 5.0);
    for i in 0..41 {
        for j in 0..41 {
            let d = camera_ray(eye, DVec3::ZERO, DVec3::Y, 30.0, 41, 41, j, i);
            let Some((t, margin)) = unit_sphere(eye, d) else {
                continue;
            };
            if margin < 1e-3 {
                continue;
            }
            let x = eye + d * t;
            let n = x;
            let l = (eye - x).normalize();
            let h = (l - d).normalize();
            let v = 0.05 + 0.25 * n.dot(l).max(0.0) + 0.25 * n.dot(h).max(0.0).powf(10.0);
            assert_close(pixel(&img, j, i), [byte(v); 3], &format!("pixel ({j}, {i})"));
        }
    }
}

/// A busy scene: 300 spheres and ellipsoids, 600 triangles, mirrors, shadows, two lights.
fn busy_scene() -> String {
    let mut s = String::from("size 96 72\ncamera 0 -12 9 0 0 0 0 0 1 50\nmaxdepth 4\nattenuation 1 0.05 0.01\npoint 3 -4 8 1 1 1\ndirectional -1 -1 2 .4 .4 .4\n");
    let mut seed = 42u64;
    let mut rnd = || {
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (seed >> 33) as f64 / (1u64 << 31) as f64
    };
    for k in 0..300 {
        let (x, y, z) = (rnd() * 16.0 - 8.0, rnd() * 16.0 - 8.0, rnd() * 3.0);
        s += &format!(
            "diffuse {:.3} {:.3} {:.3}\nspecular {:.2} {:.2} {:.2}\nshininess {}\n",
            rnd(),
            rnd(),
            rnd(),
            rnd() * 0.6,
            rnd() * 0.6,
            rnd() * 0.6,
            1 + k % 50
        );
        s += &format!("pushTransform\ntranslate {x:.3} {y:.3} {z:.3}\nrotate 1 1 0 {}\nscale 1 {:.2} 0.7\nsphere 0 0 0 {:.3}\npopTransform\n", k * 7, 0.5 + rnd(), 0.2 + rnd() * 0.5);
    }
    for k in 0..600 {
        let (x, y, z) = (rnd() * 20.0 - 10.0, rnd() * 20.0 - 10.0, rnd() * 2.0 - 1.0);
        for _ in 0..3 {
            s += &format!(
                "vertex {:.3} {:.3} {:.3}\n",
                x + rnd() * 2.0,
                y + rnd() * 2.0,
                z + rnd()
            );
        }
        s += &format!("tri {} {} {}\n", 3 * k, 3 * k + 1, 3 * k + 2);
    }
    s
}

#[test]
fn thread_count_and_acceleration_structure_do_not_change_a_byte() {
    let scene = busy_scene();
    let reference = render_bytes(&scene, AccelKind::Bvh, 1);
    assert!(
        reference.2.iter().filter(|&&b| b > 0).count() > 5000,
        "the scene should not be empty"
    );
    assert_eq!(
        reference,
        render_bytes(&scene, AccelKind::Bvh, 2),
        "bvh: 1 vs 2 threads"
    );
    assert_eq!(
        reference,
        render_bytes(&scene, AccelKind::Bvh, 3),
        "bvh: 1 vs 3 threads"
    );
    assert_eq!(reference, render_bytes(&scene, AccelKind::List, 2), "bvh vs list");
}

#[test]
fn a_rotated_cylinder_in_front_of_an_infinite_plane() {
    // The cylinder x² + z² = 1, |y| ≤ 1.5 (object z axis turned onto world y), and the
    // plane z = −3 behind it, lit head-on: N·L is the normal's z.
    let scene = "size 60 40\ncamera 0 0 6 0 0 0 0 1 0 40\nambient 0.1 0.1 0.1\ndiffuse 0.6 0.5 0.4\ndirectional 0 0 1 1 1 1\nplane 0 0 -3 0 0 1\nrotate 1 0 0 -90\ncylinder 1 -1.5 1.5\n";
    for accel in AccelKind::ALL {
        let img = render_bytes(scene, accel, 2);
        let eye = DVec3::new(0.0, 0.0, 6.0);
        let shade = |nz: f64| [byte(0.1 + 0.6 * nz), byte(0.1 + 0.5 * nz), byte(0.1 + 0.4 * nz)];
        let (mut side, mut floor) = (0, 0);
        for i in 0..40 {
            for j in 0..60 {
                let d = camera_ray(eye, DVec3::ZERO, DVec3::Y, 40.0, 60, 40, j, i);
                // Ray against the infinite cylinder x² + z² = 1.
                let a = d.x * d.x + d.z * d.z;
                let b = eye.x * d.x + eye.z * d.z;
                let c = eye.x * eye.x + eye.z * eye.z - 1.0;
                let disc = b * b - a * c;
                let want = if disc > 0.0 {
                    let t = (-b - disc.sqrt()) / a;
                    let p = eye + d * t;
                    if disc / (a * a) < 1e-3 || (p.y.abs() - 1.5).abs() < 0.05 {
                        continue; // silhouette or rim
                    }
                    if p.y.abs() <= 1.5 {
                        side += 1;
                        shade(p.z.max(0.0))
                    } else {
                        floor += 1;
                        shade(1.0)
                    }
                } else {
                    floor += 1;
                    shade(1.0)
                };
                assert_close(pixel(&img, j, i), want, &format!("{accel:?}: pixel ({j}, {i})"));
            }
        }
        assert!(side > 200 && floor > 1000, "{side} {floor}");
    }
}

/// The `nurbs` lines of the textbook rational quadratic sphere of radius `r`.
fn nurbs_sphere_text(r: f64) -> String {
    let s = lucent_core::tessellate::nurbs::sphere(r);
    let mut text = String::from("nurbs 2 2 9 5\n");
    let knots = |k: &[f64]| k.iter().map(|x| x.to_string()).collect::<Vec<_>>().join(" ");
    text += &format!("knotsu {}\nknotsv {}\n", knots(&s.knots_u), knots(&s.knots_v));
    for p in &s.points {
        let q = p.truncate() / p.w;
        text += &format!("cpoint {} {} {} {}\n", q.x, q.y, q.z, p.w);
    }
    text
}

#[test]
fn a_nurbs_sphere_has_the_silhouette_of_the_analytic_sphere() {
    // White where the ray hits, black where it misses; the two pictures may differ only
    // on pixels within one pixel of the analytic silhouette.
    let head = "size 160 120\ncamera 0.3 -0.2 4 0 0 0 0 1 0 45\nambient 0 0 0\nemission 1 1 1\ntranslate 0.2 0.1 0\nrotate 1 1 0 40\n";
    let analytic = render_bytes(&format!("{head}sphere 0 0 0 1.3\n"), AccelKind::Bvh, 2);
    let nurbs = render_bytes(&format!("{head}{}", nurbs_sphere_text(1.3)), AccelKind::Bvh, 2);
    let hit = |img: &(u32, u32, Vec<u8>), x: i64, y: i64| pixel(img, x as u32, y as u32)[0] > 128;
    let (mut inside, mut differ) = (0, 0);
    for y in 0..120i64 {
        for x in 0..160i64 {
            let a = hit(&analytic, x, y);
            inside += a as usize;
            if a == hit(&nurbs, x, y) {
                continue;
            }
            differ += 1;
            let near_edge = (-1..=1).any(|dy| {
                (-1..=1).any(|dx| {
                    let (nx, ny) = (x + dx, y + dy);
                    (0..160).contains(&nx) && (0..120).contains(&ny) && hit(&analytic, nx, ny) != a
                })
            });
            assert!(near_edge, "pixel ({x}, {y}) differs away from the silhouette");
        }
    }
    assert!(inside > 3000, "{inside}");
    assert!(differ < 40, "{differ} pixels differ");
}
