//! `lucent bench rays MESH.obj RAYS.bin [--accel A] [--threads N] [--reps R] [--occluded]
//! [--hits OUT.bin]`: the ray–triangle kernel benchmark, run on the same files as the
//! Embree harness in `../shared/bench/` (formats in its README).
//!
//! Ray files are 32-byte records of little-endian f32 `ox oy oz tnear dx dy dz tfar`.
//! `--hits` writes 8 bytes per ray: f32 `t` and u32 triangle index (`inf`/`0xffffffff`
//! for a miss); with `--occluded` `t` is 0 for an occluded ray and `inf` for a free one.
//! One warm-up pass, then R timed passes; the last line reports medians.
//!
//! The queries are those of Embree's `rtcIntersect1`/`rtcOccluded1`, which the harness
//! times beside them: they answer `t` and the triangle and read nothing else of the hit.
//! The renderer's queries also ask the cache for the hit triangle's indices, which its
//! shading reads next ([`PrimitiveSet::prefetch`]); here no one reads them, so that
//! request is left out unless `--prefetch-hits` asks for the renderer's queries.

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use lucent_core::aabb::Aabb;
use lucent_core::accel::bvh::{Bvh, Isa};
use lucent_core::accel::{AccelKind, Accelerator, PrimitiveSet};
use lucent_core::geometry::mesh::TriangleMesh;
use lucent_core::hit::Hit;
use lucent_core::math::Vec3A;
use lucent_core::ray::{PreparedRay, Ray};
use lucent_io::obj::load_obj;
use lucent_io::resources::budget::Budget;
use lucent_io::resources::input::MAX_MESH_BYTES;
use lucent_io::resources::{read_input, Inputs, OutputTarget, Resources};
use rayon::prelude::*;

use crate::EXIT_BAD_INPUT;

#[derive(Args)]
pub struct RaysBenchArgs {
    /// Triangle mesh (Wavefront OBJ; polygons are fan-triangulated in file order).
    pub mesh: PathBuf,
    /// Ray file: 32-byte records `ox oy oz tnear dx dy dz tfar` (little-endian f32).
    pub rays: PathBuf,
    #[arg(long, default_value = "bvh", value_parser = clap::builder::PossibleValuesParser::new(AccelKind::NAMES))]
    pub accel: String,
    /// Worker threads (default: all cores).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub threads: Option<u32>,
    /// Timed passes over the rays (the median is reported); builds are timed min(R, 3) times.
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub reps: u32,
    /// Threads of the build (default 1: on the main thread, so that a harness that
    /// counts the worker threads' CPU time counts the tracing alone).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub build_threads: u32,
    /// The BVH's instruction set (default: the best this CPU has), to compare them on
    /// one machine: avx512, avx2, sse2 or scalar.
    #[arg(long, value_parser = ["avx512", "avx2", "sse2", "scalar"])]
    pub isa: Option<String>,
    /// Trace the rays in packets of consecutive rays (16 with AVX-512, 8 with AVX2: the
    /// ray files' 8 × 8-tile order), as the renderer does for coherent rays (`bvh` only).
    #[arg(long)]
    pub packets: bool,
    /// Any-hit queries (shadow rays) instead of closest hits.
    #[arg(long)]
    pub occluded: bool,
    /// Write the answers here (8 bytes per ray).
    #[arg(long, value_name = "OUT.bin")]
    pub hits: Option<PathBuf>,
    /// Ask the cache for each hit triangle's indices, as the renderer's queries do for
    /// the shading that follows (by default left out: nothing here reads them, and
    /// Embree's queries, timed beside these, do not read them either).
    #[arg(long)]
    pub prefetch_hits: bool,
}

/// The mesh as this benchmark's queries see it: the same triangles and the same tests,
/// and a hit's indices asked for only with `--prefetch-hits` (see the module docs).
struct Queried {
    mesh: TriangleMesh,
    prefetch_hits: bool,
}

impl PrimitiveSet for Queried {
    fn count(&self) -> usize {
        PrimitiveSet::count(&self.mesh)
    }
    fn bounds(&self, i: u32) -> Aabb {
        PrimitiveSet::bounds(&self.mesh, i)
    }
    fn triangle(&self, i: u32) -> Option<[Vec3A; 3]> {
        PrimitiveSet::triangle(&self.mesh, i)
    }
    #[inline(always)]
    fn intersect(&self, i: u32, ray: &PreparedRay, t_max: f32) -> Option<Hit> {
        PrimitiveSet::intersect(&self.mesh, i, ray, t_max)
    }
    #[inline(always)]
    fn occludes(&self, i: u32, ray: &PreparedRay, t_max: f32) -> bool {
        PrimitiveSet::occludes(&self.mesh, i, ray, t_max)
    }
    #[inline(always)]
    fn prefetch(&self, i: u32) {
        if self.prefetch_hits {
            PrimitiveSet::prefetch(&self.mesh, i);
        }
    }
}

const RECORD: usize = 32;
const MISS: u32 = u32::MAX;

/// The ray file at `path`, recorded in `inputs` (so that `--hits` cannot replace it).
fn read_rays(path: &std::path::Path, inputs: &mut Inputs) -> Result<Vec<Ray>, String> {
    let bytes = read_input(path, MAX_MESH_BYTES, inputs)
        .map_err(|e| format!("{}: cannot read ray file: {e}", path.display()))?;
    if bytes.len() % RECORD != 0 {
        return Err(format!(
            "{}: {} bytes is not a whole number of 32-byte ray records",
            path.display(),
            bytes.len()
        ));
    }
    let rays: Vec<Ray> = bytes
        .chunks_exact(RECORD)
        .map(|r| {
            let f = |k: usize| f32::from_le_bytes(r[4 * k..4 * k + 4].try_into().expect("4 bytes"));
            Ray::segment(Vec3A::new(f(0), f(1), f(2)), Vec3A::new(f(4), f(5), f(6)), f(3), f(7))
        })
        .collect();
    if let Some(k) = rays
        .iter()
        .position(|r| !r.origin.is_finite() || !r.dir.is_finite() || r.t_min.is_nan() || r.t_max.is_nan())
    {
        return Err(format!(
            "{}: ray {k} has a NaN or infinite origin or direction",
            path.display()
        ));
    }
    Ok(rays)
}

/// One query: `(t, triangle)` as the answer file stores it.
#[inline(always)]
fn answer(accel: &dyn Accelerator<Queried>, prims: &Queried, ray: &Ray, occluded: bool) -> (f32, u32) {
    let ray = &PreparedRay::new(*ray);
    if occluded {
        if accel.occluded(prims, ray) {
            (0.0, 0)
        } else {
            (f32::INFINITY, 0)
        }
    } else {
        // (Into a local read by reference, as the renderer does: see
        // `Accelerator::closest_hit_into`.)
        let mut hit = None;
        accel.closest_hit_into(prims, ray, &mut hit);
        match &hit {
            Some(h) => (h.t, h.prim),
            None => (f32::INFINITY, MISS),
        }
    }
}

/// [`answer`] for a run of rays, in packets ([`Bvh::closest_hits`]), one 8 × 8 tile of
/// the ray files at a time, as the renderer traces a tile's rays.
fn trace_packets(bvh: &Bvh, prims: &Queried, rays: &[Ray], out: &mut [(f32, u32)], occluded: bool) {
    const TILE: usize = 64;
    let mut hits = [None; TILE];
    let mut blocked = [false; TILE];
    for (rays, out) in rays.chunks(TILE).zip(out.chunks_mut(TILE)) {
        let n = rays.len();
        if occluded {
            bvh.occluded_rays(prims, rays, &mut blocked[..n]);
            for (a, &b) in out.iter_mut().zip(&blocked) {
                *a = if b { (0.0, 0) } else { (f32::INFINITY, 0) };
            }
        } else {
            bvh.closest_hits(prims, rays, &mut hits[..n]);
            for (a, h) in out.iter_mut().zip(&hits) {
                *a = h.map_or((f32::INFINITY, MISS), |h| (h.t, h.prim));
            }
        }
    }
}

pub fn run(args: &RaysBenchArgs) -> u8 {
    match bench(args) {
        Ok(()) => 0,
        Err(msg) => {
            errln!("error: {msg}");
            EXIT_BAD_INPUT
        }
    }
}

fn bench(args: &RaysBenchArgs) -> Result<(), String> {
    let kind: AccelKind = args.accel.parse()?;
    let target = match &args.hits {
        Some(out) => Some(OutputTarget::resolve(out).map_err(|e| format!("cannot write {}: {e}", out.display()))?),
        None => None,
    };
    let mut res = Resources::new(Budget::machine_default());
    let mesh = load_obj(&args.mesh, &mut res)
        .map_err(|e| format!("{}: {e}", args.mesh.display()))?
        .mesh;
    let mesh = &Queried {
        mesh,
        prefetch_hits: args.prefetch_hits,
    };
    let rays = read_rays(&args.rays, &mut res.inputs)?;

    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads.unwrap_or(0) as usize)
        .build()
        .map_err(|e| format!("cannot start worker threads: {e}"))?;

    // Builds run on a pool of their own that includes this thread (the BVH splits its
    // large subtrees across the pool's threads; the other structures build on one).
    let build_pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.build_threads as usize)
        .use_current_thread()
        .build()
        .map_err(|e| format!("cannot start build threads: {e}"))?;
    let isa = match args.isa.as_deref() {
        None => Isa::detect(),
        Some(name) => {
            let isa = match name {
                "avx512" => Isa::Avx512,
                "avx2" => Isa::Avx2,
                "sse2" => Isa::Sse2,
                _ => Isa::Scalar,
            };
            if kind != AccelKind::Bvh {
                return Err("--isa chooses the bvh's instruction set".into());
            }
            if !Isa::available().contains(&isa) {
                return Err(format!("--isa {name}: this CPU does not have it"));
            }
            isa
        }
    };
    let build = || -> Box<dyn Accelerator<Queried>> {
        match kind {
            AccelKind::Bvh => Box::new(Bvh::build_for(mesh, isa)),
            _ => kind.build(mesh),
        }
    };
    let mut build_times = Vec::new();
    let mut accel = None;
    for _ in 0..args.reps.min(3) {
        drop(accel.take());
        let t = Instant::now();
        accel = Some(build_pool.install(build));
        build_times.push(t.elapsed().as_secs_f64());
    }
    let accel = accel.expect("at least one build");
    let build_s = super::median(build_times);

    let mut answers = vec![(0.0f32, 0u32); rays.len()];
    if args.packets && kind != AccelKind::Bvh {
        return Err("--packets traces with the bvh".into());
    }
    let packed = args.packets.then(|| build_pool.install(|| Bvh::build_for(mesh, isa)));
    let trace = |answers: &mut [(f32, u32)]| {
        const CHUNK: usize = 4096;
        answers.par_chunks_mut(CHUNK).enumerate().for_each(|(c, out)| {
            let rays = &rays[c * CHUNK..];
            match &packed {
                Some(bvh) => trace_packets(bvh, mesh, &rays[..out.len()], out, args.occluded),
                None => {
                    for (a, ray) in out.iter_mut().zip(rays) {
                        *a = answer(accel.as_ref(), mesh, ray, args.occluded);
                    }
                }
            }
        });
    };
    pool.install(|| trace(&mut answers)); // warm-up
    let mut times = Vec::new();
    for _ in 0..args.reps {
        let t = Instant::now();
        pool.install(|| trace(&mut answers));
        times.push(t.elapsed().as_secs_f64());
    }
    let trace_s = super::median(times);
    let hits = answers
        .iter()
        .filter(|&&(t, prim)| if args.occluded { t == 0.0 } else { prim != MISS })
        .count();

    if let (Some(target), Some(out)) = (&target, &args.hits) {
        let bytes: Vec<u8> = answers
            .iter()
            .flat_map(|&(t, prim)| t.to_le_bytes().into_iter().chain(prim.to_le_bytes()))
            .collect();
        target
            .check_not_input(&res.inputs)
            .map_err(|e| format!("cannot write {}: {e}", out.display()))?;
        target
            .write(&bytes)
            .map_err(|e| format!("cannot write {}: {e}", out.display()))?;
    }
    outln!(
        "mrays_per_s={:.4} build_s={build_s:.4} bytes_per_tri={:.1} rays={} hits={hits} accel={}{} isa={isa:?} threads={} build_threads={} tris={} trace_s={trace_s:.4}",
        rays.len() as f64 / trace_s / 1e6,
        accel.memory_bytes() as f64 / mesh.mesh.indices.len().max(1) as f64,
        rays.len(),
        kind.name(),
        if args.packets { "+packets" } else { "" },
        pool.current_num_threads(),
        args.build_threads,
        mesh.mesh.indices.len(),
    );
    Ok(())
}
