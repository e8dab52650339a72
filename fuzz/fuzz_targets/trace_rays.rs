//! Any bytes as triangles and rays, traced by every acceleration structure, on every
//! instruction set the CPU has, one ray at a time and in packets: nothing may panic,
//! hang or touch memory it does not own (the BVH's traversal is unsafe code with a fixed
//! stack), whatever the rays hold. Rays on a small integer lattice must get exactly the
//! brute-force list's answers; rays of arbitrary bits (NaN, infinities, subnormals,
//! huge values) must end, and find nothing when they are not lines. Run with
//! `cargo +nightly fuzz run trace_rays` from this folder.
//!
//! Layout: a byte `n` (1 to 64 triangles), `9 n` signed bytes of corners (lattice
//! coordinates), then records of 17 bytes: a kind byte and 16 bytes of ray. Kind even:
//! a lattice ray (origin and direction from signed bytes, the direction's length kept,
//! `t_min` 0 or 1e-4, `t_max` infinite or a small integer); kind odd: the 16 bytes as the
//! bits of `t_max` and of the origin, with the direction from the first bytes again
//! (arbitrary floats).
#![no_main]

use libfuzzer_sys::fuzz_target;
use lucent_core::accel::bvh::{Bvh, Isa};
use lucent_core::accel::list::PrimitiveList;
use lucent_core::accel::{AccelKind, Accelerator};
use lucent_core::geometry::primitive::{Primitive, Shape};
use lucent_core::math::Vec3A;
use lucent_core::ray::{PreparedRay, Ray};

/// A lattice coordinate: a signed byte, scaled so that the lattice spans a small scene
/// and its points are exact in binary.
fn lattice(b: u8) -> f32 {
    b as i8 as f32 * 0.25
}

fn float(bytes: &[u8]) -> f32 {
    f32::from_le_bytes(bytes.try_into().expect("4 bytes"))
}

fuzz_target!(|data: &[u8]| {
    let Some((&n, rest)) = data.split_first() else {
        return;
    };
    let n = (n as usize % 64) + 1;
    if rest.len() < 9 * n {
        return;
    }
    let (corners, records) = rest.split_at(9 * n);
    let prims: Vec<Primitive> = corners
        .chunks_exact(9)
        .map(|c| {
            let v = |k: usize| Vec3A::new(lattice(c[k]), lattice(c[k + 1]), lattice(c[k + 2]));
            Primitive::new(
                Shape::Triangle {
                    p: [v(0), v(3), v(6)],
                    normals: None,
                },
                0,
            )
        })
        .collect();
    let prims = &prims[..];
    // (ray, whether its answers must be the list's)
    let rays: Vec<(Ray, bool)> = records
        .chunks_exact(17)
        .take(64)
        .map(|r| {
            let b = &r[1..];
            if r[0] % 2 == 0 {
                let origin = Vec3A::new(lattice(b[0]), lattice(b[1]), lattice(b[2]));
                let dir = Vec3A::new(b[3] as i8 as f32, b[4] as i8 as f32, b[5] as i8 as f32);
                let t_min = if b[6] % 2 == 0 { 0.0 } else { 1e-4 };
                let t_max = if b[7] % 4 == 0 {
                    b[8] as f32 * 0.5
                } else {
                    f32::INFINITY
                };
                (Ray::segment(origin, dir, t_min, t_max), true)
            } else {
                let origin = Vec3A::new(float(&b[0..4]), float(&b[4..8]), float(&b[8..12]));
                let dir = Vec3A::new(float(&b[4..8]), float(&b[8..12]), float(&b[12..16]));
                (
                    Ray::segment(origin, dir, float(&b[0..4]).abs(), float(&b[12..16])),
                    false,
                )
            }
        })
        .collect();
    if rays.is_empty() {
        return;
    }

    let list = PrimitiveList::new(prims);
    let expected: Vec<_> = rays
        .iter()
        .map(|(r, _)| {
            let p = PreparedRay::new(*r);
            (list.closest_hit(prims, &p), list.occluded(prims, &p))
        })
        .collect();
    let mut structures: Vec<(String, Box<dyn Accelerator<[Primitive]>>)> = AccelKind::ALL
        .iter()
        .map(|&k| (k.name().to_string(), k.build(prims)))
        .collect();
    for isa in Isa::available() {
        structures.push((format!("bvh/{isa:?}"), Box::new(Bvh::build_for(prims, isa))));
    }
    for (name, accel) in &structures {
        for ((ray, exact), (hit, occluded)) in rays.iter().zip(&expected) {
            let p = PreparedRay::new(*ray);
            let got = (accel.closest_hit(prims, &p), accel.occluded(prims, &p));
            if !ray.is_line() {
                assert_eq!(got, (None, false), "{name}: {ray:?} is not a line");
            } else if *exact {
                assert_eq!(got, (*hit, *occluded), "{name}: {ray:?}");
            }
        }
    }
    // Packets: the rays in the given order, as the renderer passes a tile's.
    let all: Vec<Ray> = rays.iter().map(|(r, _)| *r).collect();
    for isa in Isa::available() {
        let bvh = Bvh::build_for(prims, isa);
        let mut hits = vec![None; all.len()];
        let mut blocked = vec![false; all.len()];
        bvh.closest_hits(prims, &all, &mut hits);
        bvh.occluded_rays(prims, &all, &mut blocked);
        for (i, ((ray, exact), (hit, occluded))) in rays.iter().zip(&expected).enumerate() {
            if *exact || !ray.is_line() {
                assert_eq!((hits[i], blocked[i]), (*hit, *occluded), "packets/{isa:?}: {ray:?}");
            }
        }
    }
});
