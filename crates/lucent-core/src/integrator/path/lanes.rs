//! The path tracer's paths eight at a time, in the lanes of AVX2 vectors, for the scenes
//! whose every surface scatters the same simple way: `nexteventestimation mis`,
//! `importancesampling cosine` or `brdf`, Russian roulette on or off, quad lights only,
//! and Lambertian materials (`brdf phong` with `specular 0`, no maps, no emission, no
//! glass).
//!
//! Eight paths go together, bounce by bounce. Each path's segment is traced one lane at
//! a time (the BVH); then what each found is looked at, lane by lane: a light, or the
//! surface point of any shape but a flat triangle. Then, for all eight at once: the flat
//! triangles' surface points, the light sample, the BSDF's value and densities, the MIS
//! weight, the next direction, the offset origins and the rays' traversal constants. The
//! shadow rays are traced, and Russian roulette is played, one lane at a time again. A
//! lane whose path ends takes the batch's next camera sample.
//!
//! Every number is the one [`PathTracer::radiance`] computes for that path: the same
//! operations in the same order, lane by lane (IEEE arithmetic gives the same bits in a
//! vector lane as in a scalar register; glam's order of operations is followed, and the
//! azimuth's sine and cosine are the same polynomial, `warp::sin_cos_turns`), and each
//! path draws from its own sampler in the same order. `tests/path_lanes.rs` compares the
//! two, sample by sample, bit for bit. The eight-lane arithmetic itself is in [`vector`].

use std::arch::x86_64::*;
use std::f32::consts::FRAC_1_PI;

use super::{Came, DirectionSampling, Nee, PathTracer};
use crate::geometry::primitive::Shape;
use crate::hit::Hit;
use crate::integrator::TraceCounts;
use crate::light::Light;
use crate::math::{gamma, Color};
use crate::ray::{Ray, EPSILON};
use crate::sampler::Sampler;
use crate::sampling::ONE_BELOW;
use crate::scene::Scene;

mod prepared;
mod vector;

use prepared::PreparedLanes;
use vector::*;

/// Whether the scene and settings are ones the lanes render (see the module's docs) on
/// this CPU.
pub(super) fn applies(pt: &PathTracer, scene: &Scene) -> bool {
    let settings = pt.nee == Nee::Mis && matches!(pt.sampling, DirectionSampling::Cosine | DirectionSampling::Brdf);
    settings && scene.lambertian_and_quad_lit() && std::is_x86_feature_detected!("avx2")
}

/// Eight paths on their way, and what their current vertices hold.
#[derive(Default)]
struct Paths {
    total: L3,
    beta: L3,
    /// The density of the BSDF sample that made each path's current segment.
    came_pdf: [f32; W],
    rays: [Option<Ray>; W],
    // A flat triangle's corners and the hit's barycentric weights, for the lanes whose
    // vertex is on one.
    p0: L3,
    p1: L3,
    p2: L3,
    b1: L,
    b2: L,
    /// The surface points made one lane at a time (shapes other than flat triangles).
    other_shape: ShapePoints,
    // The vertex each live path is at (written for the lanes in `shading`).
    point: L3,
    error: L3,
    ng: L3,
    n: L3,
    kd: L3,
    // The light sample's numbers (the light's own, after the choice) and the light's data.
    light_u: L,
    light_v: L,
    corner: L3,
    ab: L3,
    ac: L3,
    light_normal: L3,
    area: L,
    radiance: L3,
    // The next direction's numbers.
    bounce_u: L,
    bounce_v: L,
    /// The lanes with a vertex to shade, and those whose light sample nothing blocks.
    shading: [bool; W],
    lit: [bool; W],
    // What the vector code gives back.
    light: LightLanes,
    bounce: BounceLanes,
}

/// Surface points in lanes: the point, its error bound, the geometric and the shading
/// normals.
#[derive(Default)]
struct ShapePoints {
    point: L3,
    error: L3,
    ng: L3,
    n: L3,
}

/// The light sample of each lane, before its shadow ray.
#[derive(Default)]
struct LightLanes {
    /// `f · Le · cos / pdf`, zero where there is no sample (the light faces away, or its
    /// density is not finite) and where the light is below either normal: the lanes
    /// that cast a shadow ray are the others.
    unshadowed: L3,
    /// That times the MIS weight: what the sample adds if nothing blocks it.
    weighted: L3,
    /// The shadow ray toward it.
    shadow: PreparedLanes,
}

/// The next segment of each lane.
#[derive(Default)]
struct BounceLanes {
    /// Whether a direction was found (above both surfaces, of positive density), and
    /// whether the path goes on with it (a finite throughput that is not black).
    valid: [bool; W],
    on: [bool; W],
    pdf: L,
    beta: L3,
    /// The next segment's ray.
    ray: PreparedLanes,
}

/// [`PathTracer::radiances`] for a scene where [`applies`] holds.
pub(super) fn radiances(
    pt: &PathTracer,
    scene: &Scene,
    rays: &[Ray],
    hits: &[Option<Hit>],
    samplers: &mut [Sampler],
    counts: &mut TraceCounts,
    out: &mut [Color],
) {
    run(pt, scene, rays, hits, samplers, counts, out);
}

/// No camera sample: a lane that carries no path.
const FREE: usize = usize::MAX;

/// Takes the batch's paths to their ends, eight at a time: a lane whose path ends takes
/// the batch's next camera sample (its camera ray traced already, to `camera_hits`), so
/// that the lanes stay full until the batch runs out. Each path's numbers are its own
/// whatever lane carries it and whoever its neighbours are.
fn run(
    pt: &PathTracer,
    scene: &Scene,
    camera_rays: &[Ray],
    camera_hits: &[Option<Hit>],
    samplers: &mut [Sampler],
    counts: &mut TraceCounts,
    out: &mut [Color],
) {
    let count = scene.lights.len();
    let mut paths = Paths::default();
    // The camera sample each lane carries, and the index of the vertex its current
    // segment will hit.
    let mut sample = [FREE; W];
    let mut k = [0u32; W];
    let mut next = 0;
    loop {
        // Lanes whose paths ended hand their light in and take the next sample.
        for i in 0..W {
            if paths.rays[i].is_some() {
                continue;
            }
            if sample[i] != FREE {
                out[sample[i]] = paths.total.get(i);
                sample[i] = FREE;
            }
            if next < camera_rays.len() {
                sample[i] = next;
                k[i] = 1;
                paths.rays[i] = Some(camera_rays[next]);
                paths.total.set(i, Color::ZERO);
                paths.beta.set(i, Color::ONE);
                next += 1;
            }
        }
        // Trace every lane's segment first, then turn each hit into a vertex to shade (or
        // end the path): the hit primitive, which the search asked the cache for, is read
        // after the other lanes' searches instead of stalling right after its own.
        let segments = std::mem::replace(&mut paths.rays, [None; W]);
        let mut hits = [None; W];
        for i in 0..W {
            if segments[i].is_none() {
                continue;
            }
            counts.rays += 1;
            if k[i] == 1 {
                hits[i] = camera_hits[sample[i]];
            } else {
                scene.closest_hit_into(&paths.bounce.ray.get(i), &mut hits[i]);
            }
        }
        let live = segments.iter().any(Option::is_some);
        let mut shading = [false; W];
        let mut flat = [false; W];
        let mut any = false;
        for i in 0..W {
            let Some(ray) = segments[i] else {
                continue;
            };
            let first = k[i] == 1;
            // A segment that escapes finds nothing (no environment here).
            // (By reference: a copy would read the hit back whole just after the search
            // wrote it piece by piece, a stalled store-to-load forward.)
            let Some(hit) = &hits[i] else {
                continue;
            };
            let came = if first {
                Came::Camera
            } else {
                Came::Bsdf(paths.came_pdf[i])
            };
            // A flat triangle's surface point is made in the lanes below; any other
            // shape (and a light's surface) makes its own here.
            let prim = &scene.geometry.primitives[hit.prim as usize];
            let material = match (&prim.shape, prim.light) {
                (Shape::Triangle { p, normals: None }, None) => {
                    paths.p0.set(i, p[0]);
                    paths.p1.set(i, p[1]);
                    paths.p2.set(i, p[2]);
                    paths.b1.0[i] = hit.b1;
                    paths.b2.0[i] = hit.b2;
                    flat[i] = true;
                    prim.material
                }
                _ => {
                    let sp = scene.surface_point(hit, &ray);
                    if let Some(index) = sp.light {
                        let light = &scene.lights[index as usize];
                        let le = light.radiance_seen(ray.dir, sp.normal);
                        if le != Color::ZERO {
                            let p_light = || light.pdf_li(hit.t, ray.dir) / count as f32;
                            let beta = paths.beta.get(i);
                            let total = paths.total.get(i) + beta * le * pt.found_weight(came, true, p_light);
                            paths.total.set(i, total);
                        }
                        continue;
                    }
                    let other = &mut paths.other_shape;
                    other.point.set(i, sp.point);
                    other.error.set(i, sp.error);
                    other.ng.set(i, sp.geometric_normal);
                    other.n.set(i, sp.normal);
                    sp.material
                }
            };
            if !pt.within_depth(k[i]) {
                continue;
            }
            paths.kd.set(i, scene.materials[material as usize].diffuse);
            // The light sample's numbers: the light chosen by the first, what is left of
            // it the point's first coordinate (as `one_light_mis` does).
            let sampler = &mut samplers[sample[i]];
            let (u, v) = sampler.uniform2();
            let scaled = u * count as f32;
            let index = (scaled as usize).min(count - 1);
            paths.light_u.0[i] = (scaled - index as f32).clamp(0.0, ONE_BELOW);
            paths.light_v.0[i] = v;
            let Light::Quad(q) = &scene.lights[index] else {
                unreachable!("`applies` admits quad lights only");
            };
            paths.corner.set(i, q.corner);
            paths.ab.set(i, q.ab);
            paths.ac.set(i, q.ac);
            paths.light_normal.set(i, q.normal);
            paths.area.0[i] = q.area;
            paths.radiance.set(i, q.radiance);
            // The next direction's numbers (`sample_reusing` of a single lobe clamps the
            // first as the lobe's share of it).
            let (u, v) = sampler.uniform2();
            paths.bounce_u.0[i] = match pt.sampling {
                DirectionSampling::Brdf => ((u - 0.0) / (1.0 - 0.0)).clamp(0.0, ONE_BELOW),
                _ => u,
            };
            paths.bounce_v.0[i] = v;
            shading[i] = true;
            any = true;
        }
        if !live {
            return;
        }
        if !any {
            continue;
        }
        // SAFETY: `applies` checked that the CPU has AVX2.
        unsafe { surface_points(&mut paths, flat) };
        // SAFETY: `applies` checked that the CPU has AVX2.
        unsafe { light_samples(&mut paths, count as f32) };
        for i in (0..W).filter(|&i| shading[i]) {
            let l = &paths.light;
            if l.unshadowed.get(i) != Color::ZERO {
                counts.rays += 1;
                paths.lit[i] = !scene.occluded_prepared(&l.shadow.get(i));
            } else {
                paths.lit[i] = false;
            }
        }
        paths.shading = shading;
        // SAFETY: as above.
        unsafe { bounces(&mut paths) };
        for i in (0..W).filter(|&i| shading[i]) {
            let b = &paths.bounce;
            // Russian roulette (`go_on`), lane by lane, on the paths whose bounce found
            // a direction; without it the lanes have decided already.
            let on = if pt.russian_roulette && b.valid[i] {
                let mut beta = b.beta.get(i);
                let last = !pt.within_depth(k[i] + 1);
                pt.go_on(&mut beta, last, &mut samplers[sample[i]]) && {
                    paths.bounce.beta.set(i, beta);
                    true
                }
            } else {
                b.on[i]
            };
            let b = &paths.bounce;
            if on {
                paths.beta.set(i, b.beta.get(i));
                paths.came_pdf[i] = b.pdf.0[i];
                paths.rays[i] = Some(Ray::new(b.ray.origin.get(i), b.ray.dir.get(i)));
                k[i] += 1;
            }
        }
    }
}

/// The surface points of all lanes: made here for the lanes in `flat`, on flat
/// triangles (`spawn::barycentric_point` and `triangle::geometric_normal`, the shading
/// normal the same), taken from `other_shape` for the others.
#[target_feature(enable = "avx2")]
fn surface_points(p: &mut Paths, flat: [bool; W]) {
    let flat = lane_mask(flat);
    let (p0, p1, p2) = (load3(&p.p0), load3(&p.p1), load3(&p.p2));
    let (b1, b2) = (load(&p.b1), load(&p.b2));
    let b0 = _mm256_sub_ps(_mm256_sub_ps(_mm256_set1_ps(1.0), b1), b2);
    let (a, b, c) = (scale(p0, b0), scale(p1, b1), scale(p2, b2));
    let point = add(add(a, b), c);
    let error = scale(add(add(abs(a), abs(b)), abs(c)), _mm256_set1_ps(gamma(8)));
    let ng = normalize(cross(sub(p1, p0), sub(p2, p0)));
    // Whole stores of blends from two sources (a store of a blend with the old contents
    // becomes a masked store, which Zen 4 runs in microcode).
    let o = &p.other_shape;
    let (point, error, ng, n) = (
        select(flat, point, load3(&o.point)),
        select(flat, error, load3(&o.error)),
        select(flat, ng, load3(&o.ng)),
        select(flat, ng, load3(&o.n)),
    );
    store3(&mut p.point, point);
    store3(&mut p.error, error);
    store3(&mut p.ng, ng);
    store3(&mut p.n, n);
}

/// The light samples of all lanes (`QuadLight::sample_li`, the density divided by the
/// `count` lights, `unshadowed` of `light_sampling`, the shadow ray's origin and extent)
/// and the prelude of the next direction (its polar cosine and sine).
#[target_feature(enable = "avx2")]
fn light_samples(p: &mut Paths, count: f32) {
    let x = load3(&p.point);
    let (u, v) = (load(&p.light_u), load(&p.light_v));
    let y = add(add(load3(&p.corner), scale(load3(&p.ab), u)), scale(load3(&p.ac), v));
    let to_light = sub(y, x);
    let r2 = dot(to_light, to_light);
    let distance = _mm256_sqrt_ps(r2);
    let wi = divide(to_light, distance);
    let cos_times_distance = dot(load3(&p.light_normal), to_light);
    let pdf = _mm256_div_ps(
        _mm256_mul_ps(r2, distance),
        _mm256_mul_ps(load(&p.area), cos_times_distance),
    );
    let valid = _mm256_and_ps(positive(cos_times_distance), finite(pdf));
    let pdf = _mm256_div_ps(pdf, _mm256_set1_ps(count));
    // The BSDF strategy's density of `wi`: cosine-weighted (`brdf` with one diffuse lobe
    // is the same density, times 1).
    let n = load3(&p.n);
    let cos = dot(n, wi);
    let bsdf_pdf = _mm256_mul_ps(max0(cos), _mm256_set1_ps(FRAC_1_PI));
    let ng = load3(&p.ng);
    let lit = _mm256_and_ps(positive(cos), positive(dot(wi, ng)));
    let f = scale(load3(&p.kd), _mm256_set1_ps(FRAC_1_PI));
    let c = scale(mul(f, load3(&p.radiance)), _mm256_div_ps(cos, pdf));
    let zero = V::zero();
    let l = &mut p.light;
    let unshadowed = select(_mm256_and_ps(valid, lit), c, zero);
    store3(&mut l.unshadowed, unshadowed);
    store3(&mut l.weighted, scale(unshadowed, power_heuristic_lanes(pdf, bsdf_pdf)));
    let origin = offset_origin(x, load3(&p.error), ng, wi);
    let t_max = _mm256_sub_ps(distance, _mm256_set1_ps(EPSILON));
    l.shadow.prepare(origin, wi, t_max);
}

/// The next direction of all lanes (a cosine-weighted direction around the shading
/// normal, from the numbers and the azimuth's sine and cosine in `p`), its value and
/// density, the throughput after it, and the ray's origin.
#[target_feature(enable = "avx2")]
fn bounces(p: &mut Paths) {
    // The light sample's share, added with the throughput before this bounce (as
    // `one_light_mis`'s result is: nothing where the shadow ray was blocked).
    let zero = V::zero();
    // Lanes not shading add nothing: `0 · β` to a total that is never −0 (a sum of
    // products of non-negative numbers), with a finite β (`go_on` keeps only those).
    let lit = _mm256_and_ps(lane_mask(p.lit), lane_mask(p.shading));
    let c = select(lit, load3(&p.light.weighted), zero);
    let total = add(load3(&p.total), mul(load3(&p.beta), c));
    store3(&mut p.total, total);
    let one = _mm256_set1_ps(1.0);
    let cos_t = _mm256_sqrt_ps(load(&p.bounce_u));
    let sin_t = _mm256_sqrt_ps(max0(_mm256_sub_ps(one, _mm256_mul_ps(cos_t, cos_t))));
    let (sin_phi, cos_phi) = sin_cos_turns(load(&p.bounce_v));
    let local = V {
        x: _mm256_mul_ps(sin_t, cos_phi),
        y: _mm256_mul_ps(sin_t, sin_phi),
        z: cos_t,
    };
    // `Frame::around(n)`.
    let n = load3(&p.n);
    let sign = _mm256_or_ps(one, _mm256_and_ps(n.z, _mm256_set1_ps(-0.0)));
    let a = _mm256_div_ps(_mm256_set1_ps(-1.0), _mm256_add_ps(sign, n.z));
    let b = _mm256_mul_ps(_mm256_mul_ps(n.x, n.y), a);
    let negate = |v: F| _mm256_xor_ps(v, _mm256_set1_ps(-0.0));
    let t1 = V {
        x: _mm256_add_ps(one, _mm256_mul_ps(_mm256_mul_ps(_mm256_mul_ps(sign, n.x), n.x), a)),
        y: _mm256_mul_ps(sign, b),
        z: _mm256_mul_ps(negate(sign), n.x),
    };
    let t2 = V {
        x: b,
        y: _mm256_add_ps(sign, _mm256_mul_ps(_mm256_mul_ps(n.y, n.y), a)),
        z: negate(n.y),
    };
    let wi = add(add(scale(t1, local.x), scale(t2, local.y)), scale(n, local.z));
    let cos = dot(n, wi);
    let pdf = _mm256_mul_ps(max0(cos), _mm256_set1_ps(FRAC_1_PI));
    let f = scale(load3(&p.kd), _mm256_set1_ps(FRAC_1_PI));
    let ng = load3(&p.ng);
    let valid = _mm256_and_ps(_mm256_and_ps(positive(cos), positive(pdf)), positive(dot(wi, ng)));
    let beta = mul(load3(&p.beta), scale(f, _mm256_div_ps(cos, pdf)));
    // `go_on` without Russian roulette: a finite throughput that is not black.
    let nonzero = |a: F| _mm256_cmp_ps::<_CMP_NEQ_UQ>(a, _mm256_setzero_ps());
    let on = _mm256_and_ps(
        _mm256_and_ps(
            valid,
            _mm256_and_ps(finite(beta.x), _mm256_and_ps(finite(beta.y), finite(beta.z))),
        ),
        _mm256_or_ps(nonzero(beta.x), _mm256_or_ps(nonzero(beta.y), nonzero(beta.z))),
    );
    let b = &mut p.bounce;
    b.valid = mask(valid);
    b.on = mask(on);
    store(&mut b.pdf, pdf);
    store3(&mut b.beta, beta);
    let origin = offset_origin(load3(&p.point), load3(&p.error), ng, wi);
    b.ray.prepare(origin, wi, _mm256_set1_ps(f32::INFINITY));
}
