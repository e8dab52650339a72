//! The path tracer's paths eight at a time, in the lanes of AVX2 vectors, for the scenes
//! whose every surface scatters the same simple way: `nexteventestimation mis`,
//! `importancesampling cosine` or `brdf`, Russian roulette on or off, quad lights only,
//! and Lambertian materials (`brdf phong` with `specular 0`, no maps, no emission, no
//! glass).
//!
//! Eight paths go together, bounce by bounce. Each path's segment is traced one lane at
//! a time (the BVH), and what it finds is looked at there: a light, or the surface point
//! of any shape but a flat triangle. Then, for all eight at once: the flat triangles'
//! surface points, the light sample, the BSDF's value and densities, the MIS weight, the
//! next direction, the offset origins and the rays' traversal constants. The shadow rays
//! are traced, and Russian roulette is played, one lane at a time again. A lane whose
//! path ends takes the batch's next camera sample.
//!
//! Every number is the one [`PathTracer::radiance`] computes for that path: the same
//! operations in the same order, lane by lane (IEEE arithmetic gives the same bits in a
//! vector lane as in a scalar register; glam's order of operations is followed, and the
//! azimuth's sine and cosine are the same polynomial, `warp::sin_cos_turns`), and each
//! path draws from its own sampler in the same order. `tests/path_lanes.rs` compares the
//! two, sample by sample, bit for bit.

use std::arch::x86_64::*;
use std::f32::consts::FRAC_1_PI;

use super::{Came, DirectionSampling, Nee, PathTracer};
use crate::geometry::primitive::Shape;
use crate::hit::Hit;
use crate::integrator::TraceCounts;
use crate::light::{Light, QuadLight};
use crate::math::{gamma, Color, Vec3A};
use crate::ray::{PreparedRay, Ray, AXES_AROUND, EPSILON};
use crate::sampler::Sampler;
use crate::sampling::warp::{COS_TURN, SIN_TURN};
use crate::sampling::ONE_BELOW;
use crate::scene::Scene;

/// Paths carried together.
const W: usize = 8;

/// Whether the scene and settings are ones the lanes render (see the module's docs) on
/// this CPU.
pub(super) fn applies(pt: &PathTracer, scene: &Scene) -> bool {
    let settings = pt.nee == Nee::Mis && matches!(pt.sampling, DirectionSampling::Cosine | DirectionSampling::Brdf);
    settings && scene.lambertian_and_quad_lit() && std::is_x86_feature_detected!("avx2")
}

/// Eight lanes of one number.
#[derive(Clone, Copy, Default)]
#[repr(C, align(32))]
struct L([f32; W]);

/// Eight lanes of a vector, one array per axis.
#[derive(Clone, Copy, Default)]
struct L3 {
    x: L,
    y: L,
    z: L,
}

impl L3 {
    #[inline(always)]
    fn set(&mut self, i: usize, v: Vec3A) {
        self.x.0[i] = v.x;
        self.y.0[i] = v.y;
        self.z.0[i] = v.z;
    }

    #[inline(always)]
    fn get(&self, i: usize) -> Vec3A {
        Vec3A::new(self.x.0[i], self.y.0[i], self.z.0[i])
    }
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

/// Rays of all lanes with what traversal needs of them ([`PreparedRay::new`], made in
/// the lanes: the same numbers), one array per field.
#[derive(Default)]
struct PreparedLanes {
    origin: L3,
    dir: L3,
    t_max: L,
    inv_dir: L3,
    origin_k: L3,
    shear: L3,
    /// The dominant axis and whether the direction points down it.
    kz: [i32; W],
    down: [i32; W],
}

impl PreparedLanes {
    /// Rays from `origin` along the unit `dir`, from ε to `t_max`.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn prepare(&mut self, origin: V, dir: V, t_max: F) {
        let splat = _mm256_set1_ps;
        let finite = |a: F| _mm256_cmp_ps::<_CMP_LT_OQ>(_mm256_andnot_ps(splat(-0.0), a), splat(f32::INFINITY));
        // `1/d`, an infinite component replaced by `f32::MAX` with `d`'s sign (+ for ±0).
        let fix = |d: F| {
            let r = _mm256_div_ps(splat(1.0), d);
            let signed_max = _mm256_or_ps(splat(f32::MAX), _mm256_and_ps(d, splat(-0.0)));
            let zero = _mm256_cmp_ps::<_CMP_EQ_OQ>(d, _mm256_setzero_ps());
            let fixed = _mm256_blendv_ps(signed_max, splat(f32::MAX), zero);
            _mm256_blendv_ps(fixed, r, finite(r))
        };
        let inv = V {
            x: fix(dir.x),
            y: fix(dir.y),
            z: fix(dir.z),
        };
        // `max_abs_axis`: x where it beats both, else y where it beats z, else z.
        let a = abs(dir);
        let gt = |p: F, q: F| _mm256_cmp_ps::<_CMP_GT_OQ>(p, q);
        let x_wins = _mm256_and_ps(gt(a.x, a.y), gt(a.x, a.z));
        let y_wins = _mm256_andnot_ps(gt(a.x, a.y), gt(a.y, a.z));
        let int = _mm256_castps_si256;
        let kz = _mm256_blendv_epi8(
            _mm256_blendv_epi8(_mm256_set1_epi32(2), _mm256_set1_epi32(1), int(y_wins)),
            _mm256_setzero_si256(),
            int(x_wins),
        );
        let down = _mm256_srli_epi32::<31>(int(_mm256_cmp_ps::<_CMP_LT_OQ>(by_axis(kz, dir), _mm256_setzero_ps())));
        // `AXES_AROUND[2 kz + down]`, as two tables of lanes.
        let row = _mm256_add_epi32(_mm256_add_epi32(kz, kz), down);
        let table = |k: usize| {
            let t = |r: usize| AXES_AROUND[r.min(5)][k] as i32;
            _mm256_setr_epi32(t(0), t(1), t(2), t(3), t(4), t(5), 0, 0)
        };
        let kx = _mm256_permutevar8x32_epi32(table(0), row);
        let ky = _mm256_permutevar8x32_epi32(table(1), row);
        let sz = by_axis(kz, inv);
        store3(&mut self.origin, origin);
        store3(&mut self.dir, dir);
        store(&mut self.t_max, t_max);
        store3(&mut self.inv_dir, inv);
        store3(
            &mut self.origin_k,
            V {
                x: by_axis(kx, origin),
                y: by_axis(ky, origin),
                z: by_axis(kz, origin),
            },
        );
        store3(
            &mut self.shear,
            V {
                x: _mm256_mul_ps(by_axis(kx, dir), sz),
                y: _mm256_mul_ps(by_axis(ky, dir), sz),
                z: sz,
            },
        );
        // SAFETY: eight `i32` each.
        unsafe {
            _mm256_storeu_si256(self.kz.as_mut_ptr().cast(), kz);
            _mm256_storeu_si256(self.down.as_mut_ptr().cast(), down);
        }
    }

    /// Lane `i`'s prepared ray.
    #[inline]
    fn get(&self, i: usize) -> PreparedRay {
        let dir = self.dir.get(i);
        let kz = self.kz[i] as usize;
        let [kx, ky] = AXES_AROUND[2 * kz + self.down[i] as usize];
        let shear = self.shear.get(i);
        let origin_k = self.origin_k.get(i);
        PreparedRay {
            ray: Ray::segment(self.origin.get(i), dir, EPSILON, self.t_max.0[i]),
            inv_dir: self.inv_dir.get(i),
            zero_axes: dir.cmpeq(Vec3A::ZERO),
            kx,
            ky,
            kz,
            origin_k: [origin_k.x, origin_k.y, origin_k.z],
            sx: shear.x,
            sy: shear.y,
            sz: shear.z,
        }
    }
}

/// The light sample of each lane, before its shadow ray.
#[derive(Default)]
struct LightLanes {
    /// Whether the sample is one (the light faces the point, its density is finite).
    valid: [bool; W],
    /// Its density (both choices), and the BSDF strategy's for the same direction.
    pdf: L,
    bsdf_pdf: L,
    /// `f · Le · cos / pdf`, zero where the light is below either normal.
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
    let quads: Vec<&QuadLight> = scene
        .lights
        .iter()
        .map(|l| match l {
            Light::Quad(q) => q,
            _ => unreachable!("`applies` admits quad lights only"),
        })
        .collect();
    run(pt, scene, &quads, rays, hits, samplers, counts, out);
}

/// No camera sample: a lane that carries no path.
const FREE: usize = usize::MAX;

/// Takes the batch's paths to their ends, eight at a time: a lane whose path ends takes
/// the batch's next camera sample (its camera ray traced already, to `camera_hits`), so
/// that the lanes stay full until the batch runs out. Each path's numbers are its own
/// whatever lane carries it and whoever its neighbours are.
#[allow(clippy::too_many_arguments)]
fn run(
    pt: &PathTracer,
    scene: &Scene,
    quads: &[&QuadLight],
    camera_rays: &[Ray],
    camera_hits: &[Option<Hit>],
    samplers: &mut [Sampler],
    counts: &mut TraceCounts,
    out: &mut [Color],
) {
    let count = quads.len();
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
        // Trace, and turn each hit into a vertex to shade (or end the path).
        let mut shading = [false; W];
        let mut flat = [false; W];
        let mut any = false;
        let mut live = false;
        for i in 0..W {
            let Some(ray) = paths.rays[i] else {
                continue;
            };
            live = true;
            let first = k[i] == 1;
            counts.rays += 1;
            let hit = if first {
                camera_hits[sample[i]]
            } else {
                scene.closest_hit_prepared(&paths.bounce.ray.get(i))
            };
            paths.rays[i] = None;
            // A segment that escapes finds nothing (no environment here).
            let Some(hit) = hit else {
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
                    let sp = scene.surface_point(&hit, &ray);
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
            let q = quads[index];
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
            if l.valid[i] && l.unshadowed.get(i) != Color::ZERO {
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

/// One lane group's numbers.
type F = __m256;

/// Three of them: a vector per lane.
#[derive(Clone, Copy)]
struct V {
    x: F,
    y: F,
    z: F,
}

#[inline]
#[target_feature(enable = "avx2")]
fn load(l: &L) -> F {
    // SAFETY: `L` is 32-byte aligned and holds eight floats.
    unsafe { _mm256_load_ps(l.0.as_ptr()) }
}

#[inline]
#[target_feature(enable = "avx2")]
fn store(l: &mut L, v: F) {
    // SAFETY: as in `load`.
    unsafe { _mm256_store_ps(l.0.as_mut_ptr(), v) }
}

#[inline]
#[target_feature(enable = "avx2")]
fn load3(l: &L3) -> V {
    V {
        x: load(&l.x),
        y: load(&l.y),
        z: load(&l.z),
    }
}

#[inline]
#[target_feature(enable = "avx2")]
fn store3(l: &mut L3, v: V) {
    store(&mut l.x, v.x);
    store(&mut l.y, v.y);
    store(&mut l.z, v.z);
}

#[inline]
#[target_feature(enable = "avx2")]
fn mask(m: F) -> [bool; W] {
    let bits = _mm256_movemask_ps(m);
    std::array::from_fn(|i| bits & (1 << i) != 0)
}

// Vector operations with glam's order of operations (its SSE2 `Vec3A`): a dot product is
// `(x·x' + y·y') + z·z'`, a normalisation a division by the square root of that.

#[inline]
#[target_feature(enable = "avx2")]
fn add(a: V, b: V) -> V {
    V {
        x: _mm256_add_ps(a.x, b.x),
        y: _mm256_add_ps(a.y, b.y),
        z: _mm256_add_ps(a.z, b.z),
    }
}

#[inline]
#[target_feature(enable = "avx2")]
fn sub(a: V, b: V) -> V {
    V {
        x: _mm256_sub_ps(a.x, b.x),
        y: _mm256_sub_ps(a.y, b.y),
        z: _mm256_sub_ps(a.z, b.z),
    }
}

#[inline]
#[target_feature(enable = "avx2")]
fn mul(a: V, b: V) -> V {
    V {
        x: _mm256_mul_ps(a.x, b.x),
        y: _mm256_mul_ps(a.y, b.y),
        z: _mm256_mul_ps(a.z, b.z),
    }
}

#[inline]
#[target_feature(enable = "avx2")]
fn scale(a: V, s: F) -> V {
    V {
        x: _mm256_mul_ps(a.x, s),
        y: _mm256_mul_ps(a.y, s),
        z: _mm256_mul_ps(a.z, s),
    }
}

#[inline]
#[target_feature(enable = "avx2")]
fn divide(a: V, s: F) -> V {
    V {
        x: _mm256_div_ps(a.x, s),
        y: _mm256_div_ps(a.y, s),
        z: _mm256_div_ps(a.z, s),
    }
}

#[inline]
#[target_feature(enable = "avx2")]
fn dot(a: V, b: V) -> F {
    _mm256_add_ps(
        _mm256_add_ps(_mm256_mul_ps(a.x, b.x), _mm256_mul_ps(a.y, b.y)),
        _mm256_mul_ps(a.z, b.z),
    )
}

/// glam's `cross`: `(a.y·b.z − a.z·b.y, a.z·b.x − a.x·b.z, a.x·b.y − a.y·b.x)`.
#[inline]
#[target_feature(enable = "avx2")]
fn cross(a: V, b: V) -> V {
    V {
        x: _mm256_sub_ps(_mm256_mul_ps(a.y, b.z), _mm256_mul_ps(a.z, b.y)),
        y: _mm256_sub_ps(_mm256_mul_ps(a.z, b.x), _mm256_mul_ps(a.x, b.z)),
        z: _mm256_sub_ps(_mm256_mul_ps(a.x, b.y), _mm256_mul_ps(a.y, b.x)),
    }
}

/// glam's `normalize`: divided by the square root of the dot product with itself.
#[inline]
#[target_feature(enable = "avx2")]
fn normalize(a: V) -> V {
    divide(a, _mm256_sqrt_ps(dot(a, a)))
}

#[inline]
#[target_feature(enable = "avx2")]
fn abs(a: V) -> V {
    let m = _mm256_set1_ps(-0.0);
    V {
        x: _mm256_andnot_ps(m, a.x),
        y: _mm256_andnot_ps(m, a.y),
        z: _mm256_andnot_ps(m, a.z),
    }
}

#[inline]
#[target_feature(enable = "avx2")]
fn select(m: F, a: V, b: V) -> V {
    V {
        x: _mm256_blendv_ps(b.x, a.x, m),
        y: _mm256_blendv_ps(b.y, a.y, m),
        z: _mm256_blendv_ps(b.z, a.z, m),
    }
}

/// `warp::sin_cos_turns` in every lane: `(sin 2πv, cos 2πv)`, the same operations.
#[inline]
#[target_feature(enable = "avx2")]
fn sin_cos_turns(v: F) -> (F, F) {
    let splat = _mm256_set1_ps;
    let q = _mm256_floor_ps(_mm256_add_ps(_mm256_mul_ps(splat(4.0), v), splat(0.5)));
    let r = _mm256_sub_ps(v, _mm256_mul_ps(q, splat(0.25)));
    let z = _mm256_mul_ps(r, r);
    let horner = |k: [f32; 5]| {
        let mut p = splat(k[4]);
        for &c in k[..4].iter().rev() {
            p = _mm256_add_ps(splat(c), _mm256_mul_ps(z, p));
        }
        p
    };
    let s = _mm256_mul_ps(r, horner(SIN_TURN));
    let c = _mm256_add_ps(splat(1.0), _mm256_mul_ps(z, horner(COS_TURN)));
    // Quarter turns: odd ones exchange the two, and the sine is negated in the second
    // half turn (bit 1 of q), the cosine in the second and third quarters (bit 1 of q + 1).
    let q = _mm256_cvttps_epi32(q);
    let sign = _mm256_set1_epi32(i32::MIN);
    let odd = _mm256_castsi256_ps(_mm256_slli_epi32::<31>(q));
    let negate_sin = _mm256_castsi256_ps(_mm256_and_si256(_mm256_slli_epi32::<30>(q), sign));
    let negate_cos = _mm256_castsi256_ps(_mm256_and_si256(
        _mm256_slli_epi32::<30>(_mm256_add_epi32(q, _mm256_set1_epi32(1))),
        sign,
    ));
    (
        _mm256_xor_ps(_mm256_blendv_ps(s, c, odd), negate_sin),
        _mm256_xor_ps(_mm256_blendv_ps(c, s, odd), negate_cos),
    )
}

/// The component of `v` each lane's `axis` (0, 1 or 2) names.
#[inline]
#[target_feature(enable = "avx2")]
fn by_axis(axis: __m256i, v: V) -> F {
    let is = |k: i32| _mm256_castsi256_ps(_mm256_cmpeq_epi32(axis, _mm256_set1_epi32(k)));
    _mm256_blendv_ps(_mm256_blendv_ps(v.z, v.y, is(1)), v.x, is(0))
}

/// A mask of the lanes set in `b`.
#[inline]
#[target_feature(enable = "avx2")]
fn lane_mask(b: [bool; W]) -> F {
    _mm256_castsi256_ps(_mm256_setr_epi32(
        -(b[0] as i32),
        -(b[1] as i32),
        -(b[2] as i32),
        -(b[3] as i32),
        -(b[4] as i32),
        -(b[5] as i32),
        -(b[6] as i32),
        -(b[7] as i32),
    ))
}

/// `sampling::mis::power_heuristic` in every lane (in `f64`, as it is computed there).
#[inline]
#[target_feature(enable = "avx2")]
fn power_heuristic_lanes(pa: F, pb: F) -> F {
    // Four lanes at a time, widened to `f64`.
    let half = |pa: __m128, pb: __m128| -> __m128 {
        let (pa, pb) = (_mm256_cvtps_pd(pa), _mm256_cvtps_pd(pb));
        let (a, b) = (_mm256_mul_pd(pa, pa), _mm256_mul_pd(pb, pb));
        let sum = _mm256_add_pd(a, b);
        let positive = _mm256_cmp_pd::<_CMP_GT_OQ>(sum, _mm256_setzero_pd());
        _mm256_cvtpd_ps(_mm256_and_pd(_mm256_div_pd(a, sum), positive))
    };
    let low = half(_mm256_castps256_ps128(pa), _mm256_castps256_ps128(pb));
    let high = half(_mm256_extractf128_ps::<1>(pa), _mm256_extractf128_ps::<1>(pb));
    let infinite = _mm256_cmp_ps::<_CMP_EQ_OQ>(
        _mm256_andnot_ps(_mm256_set1_ps(-0.0), pa),
        _mm256_set1_ps(f32::INFINITY),
    );
    _mm256_blendv_ps(_mm256_set_m128(high, low), _mm256_set1_ps(1.0), infinite)
}

/// Lanes where `a > 0` (false for NaN).
#[inline]
#[target_feature(enable = "avx2")]
fn positive(a: F) -> F {
    _mm256_cmp_ps::<_CMP_GT_OQ>(a, _mm256_setzero_ps())
}

/// `x.max(0.0)` as Rust computes it for `f32` (NaN gives 0).
#[inline]
#[target_feature(enable = "avx2")]
fn max0(a: F) -> F {
    _mm256_max_ps(a, _mm256_setzero_ps())
}

/// [`crate::spawn::offset_origin`] in every lane.
#[inline]
#[target_feature(enable = "avx2")]
fn offset_origin(point: V, error: V, ng: V, dir: V) -> V {
    let distance = dot(abs(ng), error);
    let offset = scale(ng, distance);
    let flip = _mm256_cmp_ps::<_CMP_LT_OQ>(dot(dir, ng), _mm256_setzero_ps());
    let sign = _mm256_and_ps(flip, _mm256_set1_ps(-0.0));
    let offset = V {
        x: _mm256_xor_ps(offset.x, sign),
        y: _mm256_xor_ps(offset.y, sign),
        z: _mm256_xor_ps(offset.z, sign),
    };
    let m = add(point, offset);
    V {
        x: one_ulp_along(m.x, offset.x),
        y: one_ulp_along(m.y, offset.y),
        z: one_ulp_along(m.z, offset.z),
    }
}

/// `m` one ulp further along the sign of `o`, lane by lane (`crate::spawn`'s
/// `one_ulp_along`, eight lanes wide: the same bits).
#[inline]
#[target_feature(enable = "avx2")]
fn one_ulp_along(m: F, o: F) -> F {
    let zero = _mm256_setzero_ps();
    let int = _mm256_castps_si256;
    let select = |mask: __m256i, a: __m256i, b: __m256i| _mm256_blendv_epi8(b, a, mask);
    let (up, down) = (
        int(_mm256_cmp_ps::<_CMP_GT_OQ>(o, zero)),
        int(_mm256_cmp_ps::<_CMP_LT_OQ>(o, zero)),
    );
    let outward = _mm256_or_si256(
        _mm256_and_si256(int(_mm256_cmp_ps::<_CMP_GT_OQ>(m, zero)), up),
        _mm256_and_si256(int(_mm256_cmp_ps::<_CMP_LT_OQ>(m, zero)), down),
    );
    let stepped = _mm256_sub_epi32(int(m), _mm256_or_si256(outward, _mm256_set1_epi32(1)));
    let smallest = _mm256_or_si256(
        _mm256_set1_epi32(1),
        _mm256_and_si256(down, _mm256_set1_epi32(i32::MIN)),
    );
    let from_zero = int(_mm256_cmp_ps::<_CMP_EQ_OQ>(m, zero));
    let infinite = int(_mm256_cmp_ps::<_CMP_EQ_OQ>(
        _mm256_andnot_ps(_mm256_set1_ps(-0.0), m),
        _mm256_set1_ps(f32::INFINITY),
    ));
    let keep = _mm256_or_si256(
        _mm256_andnot_si256(_mm256_or_si256(up, down), _mm256_set1_epi32(-1)),
        _mm256_or_si256(
            int(_mm256_cmp_ps::<_CMP_UNORD_Q>(m, m)),
            _mm256_and_si256(infinite, outward),
        ),
    );
    _mm256_castsi256_ps(select(keep, int(m), select(from_zero, smallest, stepped)))
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
    let finite = _mm256_cmp_ps::<_CMP_LT_OQ>(
        _mm256_andnot_ps(_mm256_set1_ps(-0.0), pdf),
        _mm256_set1_ps(f32::INFINITY),
    );
    let valid = _mm256_and_ps(positive(cos_times_distance), finite);
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
    let zero = V {
        x: _mm256_setzero_ps(),
        y: _mm256_setzero_ps(),
        z: _mm256_setzero_ps(),
    };
    let l = &mut p.light;
    l.valid = mask(valid);
    store(&mut l.pdf, pdf);
    store(&mut l.bsdf_pdf, bsdf_pdf);
    let unshadowed = select(lit, c, zero);
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
    let zero = V {
        x: _mm256_setzero_ps(),
        y: _mm256_setzero_ps(),
        z: _mm256_setzero_ps(),
    };
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
    let finite =
        |a: F| _mm256_cmp_ps::<_CMP_LT_OQ>(_mm256_andnot_ps(_mm256_set1_ps(-0.0), a), _mm256_set1_ps(f32::INFINITY));
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spawn::{next_down, next_up};

    #[target_feature(enable = "avx2")]
    fn stepped(m: &L, o: &L) -> L {
        let mut r = L::default();
        store(&mut r, one_ulp_along(load(m), load(o)));
        r
    }

    #[target_feature(enable = "avx2")]
    fn turns(v: &L) -> (L, L) {
        let (s, c) = sin_cos_turns(load(v));
        let (mut a, mut b) = (L::default(), L::default());
        store(&mut a, s);
        store(&mut b, c);
        (a, b)
    }

    #[test]
    fn a_lanes_sine_and_cosine_are_the_scalar_ones_bit_for_bit() {
        if !std::is_x86_feature_detected!("avx2") {
            eprintln!("skipped: no AVX2 on this CPU");
            return;
        }
        let n = 1u32 << 18;
        let values = (0..=n)
            .map(|i| i as f32 / n as f32)
            .chain([crate::spawn::next_down(1.0), f32::from_bits(1)]);
        let values: Vec<f32> = values.collect();
        for chunk in values.chunks(W) {
            let mut v = L::default();
            v.0[..chunk.len()].copy_from_slice(chunk);
            // SAFETY: the CPU has AVX2 (checked above).
            let (s, c) = unsafe { turns(&v) };
            for (k, &x) in chunk.iter().enumerate() {
                let (ws, wc) = crate::sampling::warp::sin_cos_turns(x);
                assert_eq!(
                    (s.0[k].to_bits(), c.0[k].to_bits()),
                    (ws.to_bits(), wc.to_bits()),
                    "v = {x}"
                );
            }
        }
    }

    #[target_feature(enable = "avx2")]
    fn prepared(origin: &L3, dir: &L3, t_max: &L) -> PreparedLanes {
        let mut p = PreparedLanes::default();
        p.prepare(load3(origin), load3(dir), load(t_max));
        p
    }

    #[test]
    fn rays_prepared_in_lanes_are_prepared_ray_new_field_for_field() {
        if !std::is_x86_feature_detected!("avx2") {
            eprintln!("skipped: no AVX2 on this CPU");
            return;
        }
        let mut x = 0x9e37_79b9u32;
        let mut random = || {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            x as f32 / u32::MAX as f32 * 2.0 - 1.0
        };
        // Directions of every sign, along the axes (±0 components), on the diagonals
        // (ties between axes) and at random.
        let mut dirs = vec![Vec3A::X, -Vec3A::X, Vec3A::Y, -Vec3A::Y, Vec3A::Z, -Vec3A::Z];
        dirs.push(Vec3A::new(-0.0, 1.0, 0.0));
        dirs.push(Vec3A::new(1.0, 1.0, 0.0).normalize());
        dirs.push(Vec3A::new(-1.0, 1.0, -1.0).normalize());
        dirs.push(Vec3A::new(0.0, -1.0, -1.0).normalize());
        dirs.push(Vec3A::new(1e-30, 1.0, -1e-39).normalize());
        while dirs.len() < 4000 {
            dirs.push(Vec3A::new(random(), random(), random()).normalize());
        }
        for chunk in dirs.chunks(W) {
            let (mut o, mut d, mut t) = (L3::default(), L3::default(), L::default());
            for (i, &dir) in chunk.iter().enumerate() {
                o.set(i, Vec3A::new(random(), random(), random()) * 10.0);
                d.set(i, dir);
                t.0[i] = if i % 2 == 0 { f32::INFINITY } else { 5.0 + random() };
            }
            // SAFETY: the CPU has AVX2 (checked above).
            let lanes = unsafe { prepared(&o, &d, &t) };
            for i in 0..chunk.len() {
                let (got, want) = (
                    lanes.get(i),
                    PreparedRay::new(Ray::segment(o.get(i), d.get(i), EPSILON, t.0[i])),
                );
                let bits = |v: Vec3A| [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()];
                assert_eq!(bits(got.ray.origin), bits(want.ray.origin));
                assert_eq!(bits(got.ray.dir), bits(want.ray.dir));
                assert_eq!(got.ray.t_min.to_bits(), want.ray.t_min.to_bits());
                assert_eq!(got.ray.t_max.to_bits(), want.ray.t_max.to_bits());
                assert_eq!(bits(got.inv_dir), bits(want.inv_dir), "{}", d.get(i));
                assert_eq!(got.zero_axes.bitmask(), want.zero_axes.bitmask());
                assert_eq!((got.kx, got.ky, got.kz), (want.kx, want.ky, want.kz), "{}", d.get(i));
                assert_eq!(got.origin_k.map(f32::to_bits), want.origin_k.map(f32::to_bits));
                assert_eq!(
                    [got.sx, got.sy, got.sz].map(f32::to_bits),
                    [want.sx, want.sy, want.sz].map(f32::to_bits)
                );
            }
        }
    }

    #[test]
    fn a_lane_steps_one_ulp_as_next_up_and_next_down_do() {
        if !std::is_x86_feature_detected!("avx2") {
            eprintln!("skipped: no AVX2 on this CPU");
            return;
        }
        let (values, offsets) = crate::spawn::tests::ulp_step_cases();
        for (i, chunk) in values.chunks(W).enumerate() {
            let mut m = L::default();
            let mut o = L::default();
            for (k, &v) in chunk.iter().enumerate() {
                m.0[k] = v;
                o.0[k] = offsets[(i + k) % offsets.len()];
            }
            // SAFETY: the CPU has AVX2 (checked above).
            let got = unsafe { stepped(&m, &o) };
            for k in 0..W {
                let (m, o) = (m.0[k], o.0[k]);
                let want = if o > 0.0 {
                    next_up(m)
                } else if o < 0.0 {
                    next_down(m)
                } else {
                    m
                };
                assert_eq!(got.0[k].to_bits(), want.to_bits(), "{m} along {o}");
            }
        }
    }
}
