//! Bounding volume hierarchy (`--accel bvh`, the default): a 16-wide BVH (8-wide on CPUs
//! whose best is AVX2) over packets of four triangles.
//!
//! Build ([`binary`], [`wide`]): a binned-SAH binary tree, collapsed into nodes of sixteen
//! children (eight for AVX2, [`Isa::node_width`]) whose boxes are stored as
//! structure-of-arrays; leaves become packets of four primitives with precomputed
//! triangle corners in SIMD layout ([`packet`]).
//!
//! Traversal ([`traverse`]): a box test per child per visit ([`box_test`]): sixteen with
//! AVX-512 (two groups of eight, compared into mask registers), eight in one group with
//! AVX2 and FMA, sixteen four at a time with SSE (the instruction set decided once, at
//! build time, by [`Isa::detect`]); nearest child first,
//! an explicit fixed-size stack, no allocation per ray; the packet test is bit-identical
//! to the scalar watertight triangle test, so the answers are exactly the brute-force
//! list's. Which box test and lane width a single ray's query runs on this CPU: [`query`].
//!
//! Coherent rays can also travel in packets ([`ray_packet`]): eight rays with AVX2,
//! sixteen with AVX-512 ([`Bvh::closest_hits`], [`Bvh::occluded_rays`]).

mod binary;
mod box_test;
mod build_ref;
mod collapse_plan;
mod lanes;
mod packet;
mod packet_frustum;
mod packet_rays;
mod query;
mod ray_lanes;
pub mod ray_packet;
mod ray_sphere;
mod ray_triangle;
mod sah_bins;
mod traverse;
mod wide;

use super::{Accelerator, PrimitiveSet};
use crate::hit::Hit;
use crate::huge_pages;
use crate::ray::{PreparedRay, Ray};
use packet::Packet;
use query::{Closest, Occluded};
use wide::WideNode;

/// The instruction set the traversal uses on this CPU, and with it the tree's node width.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Isa {
    /// AVX-512 F, VL and BW (with AVX2 and FMA) over nodes of sixteen: packets of sixteen
    /// rays; single rays test a node's boxes eight at a time, compared into mask
    /// registers (see `run_avx512`).
    Avx512,
    /// AVX2 with FMA (every AVX2 CPU has both): packets of eight rays.
    Avx2,
    Sse2,
    Scalar,
}

impl Isa {
    /// The best this CPU can run.
    pub fn detect() -> Isa {
        Isa::available()[0]
    }

    /// Every instruction set this CPU can run, best first.
    pub fn available() -> Vec<Isa> {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::is_x86_feature_detected as has;
            let mut v = Vec::new();
            let avx2 = has!("avx2") && has!("fma");
            if avx2 && has!("avx512f") && has!("avx512vl") && has!("avx512bw") {
                v.push(Isa::Avx512);
            }
            if avx2 {
                v.push(Isa::Avx2);
            }
            v.extend([Isa::Sse2, Isa::Scalar]);
            v
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            vec![Isa::Scalar]
        }
    }

    /// Whether this CPU has AVX2 and FMA (the fused box test and packets).
    pub fn has_avx2(self) -> bool {
        matches!(self, Isa::Avx512 | Isa::Avx2)
    }

    /// The children of the tree's nodes: sixteen, tested in two AVX-512 VL groups of
    /// eight (two AVX2-wide groups, four SSE ones), except for AVX2, which tests a node
    /// of eight in one group. (Measured on an AMD EPYC without AVX-512, Zen 3: nodes of
    /// eight 1.01–1.09× faster on primary rays than nodes of sixteen tested as two
    /// groups, 0.98–1.08× on the other sets and packets; with AVX-512, on an Intel Xeon,
    /// nodes of sixteen 1.00–1.07× faster than eight when both compare into mask
    /// registers; see docs/performance.md.)
    pub fn node_width(self) -> usize {
        match self {
            Isa::Avx2 => 8,
            _ => 16,
        }
    }

    /// How many rays a packet holds.
    pub fn packet_rays(self) -> usize {
        match self {
            Isa::Avx512 => 16,
            _ => 8,
        }
    }
}

pub struct Bvh {
    /// The nodes, of sixteen children or of eight ([`Isa::node_width`]); the other
    /// vector is empty.
    nodes16: Vec<WideNode<16>>,
    nodes8: Vec<WideNode<8>>,
    packets: Vec<Packet>,
    isa: Isa,
    /// More node levels than [`traverse::shallow_levels`]: queries take the paths with
    /// the large stack.
    deep: bool,
}

impl Bvh {
    pub fn build<P: PrimitiveSet + ?Sized>(prims: &P) -> Bvh {
        Bvh::build_for(prims, Isa::detect())
    }

    /// Builds for a given instruction set (tests use this to check every path).
    pub fn build_for<P: PrimitiveSet + ?Sized>(prims: &P, isa: Isa) -> Bvh {
        // The references in primitive order, their boxes computed on the pool's threads.
        let mut refs: Vec<build_ref::BuildRef> = huge_pages::vec_with_capacity(prims.count());
        {
            use rayon::prelude::*;
            // Indexed, so the references are written in place (a filtered parallel
            // iterator would gather chunks and copy them once more).
            refs.par_extend(
                (0..prims.count() as u32)
                    .into_par_iter()
                    .map(|i| build_ref::BuildRef::new(&prims.bounds(i), i)),
            );
        }
        refs.retain(|r| super::is_bounded(&r.bounds()));
        let tree = binary::build_refs(refs);
        assert!(Isa::available().contains(&isa), "{isa:?} requested on a CPU without it");
        let (nodes16, nodes8, packets, levels) = match isa.node_width() {
            8 => {
                let wide = wide::collapse::<8, P>(&tree, prims);
                let levels = wide::levels(&wide.nodes);
                (Vec::new(), wide.nodes, wide.packets, levels)
            }
            _ => {
                let wide = wide::collapse::<16, P>(&tree, prims);
                let levels = wide::levels(&wide.nodes);
                (wide.nodes, Vec::new(), wide.packets, levels)
            }
        };
        // The traversal stacks are sized by levels (the build bounds its depth).
        assert!(levels <= traverse::MAX_LEVELS, "a BVH of {levels} levels");
        Bvh {
            nodes16,
            nodes8,
            packets,
            isa,
            deep: levels > traverse::shallow_levels(isa.node_width()),
        }
    }

    /// The closest hits of `rays` (`out[i]` for `rays[i]`): coherent rays — camera rays
    /// of a tile, shadow rays toward one point — in packets of [`Bvh::packet_rays`] where
    /// the CPU has AVX2 ([`ray_packet`]), the others one by one. The same answers as
    /// [`Accelerator::closest_hit`] ray by ray.
    pub fn closest_hits<P: PrimitiveSet + ?Sized>(&self, prims: &P, rays: &[Ray], out: &mut [Option<Hit>]) {
        assert_eq!(rays.len(), out.len());
        self.in_packets::<ray_packet::ClosestQuery, P>(
            prims,
            rays,
            |i, s| out[i] = s.1,
            |r| (0.0, self.closest_hit(prims, &PreparedRay::new(*r))),
        );
    }

    /// Whether each of `rays` is blocked ([`Bvh::closest_hits`]'s packets, for any-hit
    /// queries).
    pub fn occluded_rays<P: PrimitiveSet + ?Sized>(&self, prims: &P, rays: &[Ray], out: &mut [bool]) {
        assert_eq!(rays.len(), out.len());
        self.in_packets::<ray_packet::AnyQuery, P>(
            prims,
            rays,
            |i, s| out[i] = s.1,
            |r| (0.0, self.occluded(prims, &PreparedRay::new(*r))),
        );
    }

    fn in_packets<Q: ray_packet::PacketQuery, P: PrimitiveSet + ?Sized>(
        &self,
        prims: &P,
        rays: &[Ray],
        mut answer: impl FnMut(usize, &Q::State),
        single: impl Fn(&Ray) -> Q::State,
    ) {
        let width = self.packet_rays();
        for (k, chunk) in rays.chunks(width).enumerate() {
            let base = k * width;
            #[cfg(target_arch = "x86_64")]
            // (Trees deeper than the packets' stack trace their rays one by one.)
            if self.isa.has_avx2() && self.node_count() > 0 && !self.deep {
                let mut states = [Q::start(&chunk[0]); ray_packet::MAX_PACKET];
                for (s, r) in states.iter_mut().zip(chunk) {
                    *s = Q::start(r);
                }
                let (packets, states) = (&self.packets, &mut states[..chunk.len()]);
                // SAFETY: `isa` was checked against the CPU when the tree was built for
                // these primitives (nodes of sixteen for AVX-512, eight for AVX2), and
                // the tree is not deep.
                let alone = unsafe {
                    if self.isa == Isa::Avx512 {
                        ray_packet::traverse_avx512::<Q, P, 16>(&self.nodes16, packets, prims, chunk, states)
                    } else {
                        ray_packet::traverse_avx2::<Q, P, 8>(&self.nodes8, packets, prims, chunk, states)
                    }
                };
                for i in packet::Lanes(alone) {
                    states[i] = single(&chunk[i]);
                }
                for (i, s) in states.iter().enumerate() {
                    answer(base + i, s);
                }
                continue;
            }
            for (i, r) in chunk.iter().enumerate() {
                answer(base + i, &single(r));
            }
        }
    }

    /// How many rays [`Bvh::closest_hits`] traces together: 16 with AVX-512, else 8.
    pub fn packet_rays(&self) -> usize {
        self.isa.packet_rays()
    }

    pub fn node_count(&self) -> usize {
        self.nodes16.len() + self.nodes8.len()
    }

    /// The node levels of the tree.
    #[cfg(test)]
    fn levels(&self) -> usize {
        wide::levels(&self.nodes16).max(wide::levels(&self.nodes8))
    }

    /// Every primitive index the leaves hold, in leaf order.
    #[cfg(test)]
    fn leaf_prims(&self) -> Vec<u32> {
        self.packets
            .iter()
            .flat_map(|p| (0..packet::LANES).filter_map(|l| p.prim(l)))
            .collect()
    }
}

impl<P: PrimitiveSet + ?Sized> Accelerator<P> for Bvh {
    fn closest_hit(&self, prims: &P, r: &PreparedRay) -> Option<Hit> {
        let mut best = None;
        self.query::<Closest, P>(prims, r, &mut best);
        best
    }

    fn closest_hit_into(&self, prims: &P, r: &PreparedRay, out: &mut Option<Hit>) {
        self.query::<Closest, P>(prims, r, out)
    }

    fn occluded(&self, prims: &P, r: &PreparedRay) -> bool {
        self.query::<Occluded, P>(prims, r, &mut ())
    }

    fn memory_bytes(&self) -> usize {
        std::mem::size_of_val(&self.nodes16[..])
            + std::mem::size_of_val(&self.nodes8[..])
            + std::mem::size_of_val(&self.packets[..])
    }

    fn closest_hits(&self, prims: &P, rays: &[Ray], out: &mut [Option<Hit>]) {
        Bvh::closest_hits(self, prims, rays, out)
    }

    fn occluded_rays(&self, prims: &P, rays: &[Ray], out: &mut [bool]) {
        Bvh::occluded_rays(self, prims, rays, out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::test_sets::Triangles;

    #[test]
    fn every_primitive_is_in_exactly_one_leaf_and_nodes_are_wide() {
        let prims = Triangles::random(11, 5000);
        // Every instruction set this CPU has (both node widths on an AVX2 CPU).
        for isa in Isa::available() {
            let bvh = Bvh::build_for(&prims, isa);
            let mut seen = bvh.leaf_prims();
            seen.sort_unstable();
            assert!(seen.iter().copied().eq(0..prims.0.len() as u32), "{isa:?}");
            // A binary tree with leaves of up to four would need about n/2 nodes; wide
            // nodes need several times fewer.
            assert!(
                bvh.node_count() > 50 && bvh.node_count() < prims.0.len() / 6,
                "{isa:?}: {}",
                bvh.node_count()
            );
            // Packets are mostly full.
            assert!(bvh.packets.len() * packet::LANES < prims.0.len() * 3 / 2, "{isa:?}");
        }
    }

    /// The nodes and packets as bytes, to compare whole structures.
    fn bytes(b: &Bvh) -> Vec<u8> {
        let raw = |p: *const u8, n: usize| unsafe { std::slice::from_raw_parts(p, n) }.to_vec();
        let mut v = raw(b.nodes16.as_ptr().cast(), std::mem::size_of_val(&b.nodes16[..]));
        v.extend(raw(b.nodes8.as_ptr().cast(), std::mem::size_of_val(&b.nodes8[..])));
        v.extend(raw(b.packets.as_ptr().cast(), std::mem::size_of_val(&b.packets[..])));
        v
    }

    #[test]
    fn the_parallel_build_is_the_one_thread_build_byte_for_byte() {
        // Enough triangles for several levels of parallel subtrees; each node width this
        // CPU builds (the build depends on the instruction set only through it).
        let prims = Triangles::random(5, 120_000);
        let mut widths = Vec::new();
        for isa in Isa::available() {
            if widths.contains(&isa.node_width()) {
                continue;
            }
            widths.push(isa.node_width());
            let expected = bytes(&pool(1).install(|| Bvh::build_for(&prims, isa)));
            for threads in [2, 5] {
                let bvh = pool(threads).install(|| Bvh::build_for(&prims, isa));
                assert!(bytes(&bvh) == expected, "{isa:?}, {threads} threads");
            }
        }
    }

    #[test]
    fn packets_of_rays_give_every_ray_its_single_answer() {
        use crate::accel::test_sets::Rng;
        use crate::math::Vec3A;
        let prims = Triangles::random(3, 20_000);
        let mut rng = Rng(77);
        // Camera-like rays from one point through a grid (coherent, in 8-ray rows), rays
        // from everywhere (incoherent), short shadow-like segments, and rays along an
        // axis (traced alone).
        let mut rays = Vec::new();
        let eye = Vec3A::new(0.0, 0.0, -30.0);
        for y in 0..32 {
            for x in 0..32 {
                let d = Vec3A::new(x as f32 / 16.0 - 1.0, y as f32 / 16.0 - 1.0, 1.0).normalize();
                rays.push(Ray::new(eye, d));
            }
        }
        for _ in 0..2000 {
            let o = rng.vec(15.0);
            rays.push(Ray::new(o, rng.vec(1.0).normalize()));
        }
        for _ in 0..1000 {
            let o = rng.vec(12.0);
            let d = rng.vec(1.0).normalize();
            rays.push(Ray::segment(o, d, 1e-3, rng.range(0.5, 8.0)));
        }
        for k in 0..16 {
            rays.push(Ray::new(Vec3A::new(k as f32 - 8.0, 0.5, -40.0), Vec3A::Z));
        }
        // Packets that mix rays the packet can take with rays it cannot (an axis they do
        // not move along, a negative t_min, a NaN direction): the latter are traced alone.
        for y in 0..8 {
            for x in 0..16 {
                let d = Vec3A::new(x as f32 / 8.0 - 1.0, y as f32 / 4.0 - 1.0, 1.0).normalize();
                rays.push(match (x + y) % 7 {
                    0 => Ray::new(eye, Vec3A::new(0.0, d.y, d.z).normalize()),
                    3 => Ray::segment(eye, d, -1.0, f32::INFINITY),
                    5 if y == 2 => Ray::new(eye, Vec3A::new(f32::NAN, 0.0, 1.0)),
                    _ => Ray::new(eye, d),
                });
            }
        }
        let prepared: Vec<PreparedRay> = rays.iter().copied().map(PreparedRay::new).collect();
        // Every instruction set this CPU has (each packet path).
        for isa in Isa::available() {
            let bvh = Bvh::build_for(&prims, isa);
            let mut hits = vec![None; prepared.len()];
            bvh.closest_hits(&prims, &rays, &mut hits);
            let mut blocked = vec![false; prepared.len()];
            bvh.occluded_rays(&prims, &rays, &mut blocked);
            let mut found = 0;
            for (i, r) in prepared.iter().enumerate() {
                assert_eq!(hits[i], bvh.closest_hit(&prims, r), "{isa:?}, ray {i}");
                assert_eq!(blocked[i], bvh.occluded(&prims, r), "{isa:?}, ray {i}");
                found += hits[i].is_some() as usize;
            }
            assert!(
                found > 500 && found < prepared.len() - 500,
                "{isa:?}: {found} hits: a test of both"
            );
        }
    }

    #[test]
    fn trees_know_their_levels_and_deep_trees_give_the_same_answers() {
        use crate::accel::test_sets::Rng;
        let few = Triangles::random(1, 6);
        assert_eq!(Bvh::build(&few).levels(), 1);
        let prims = Triangles::random(4, 20_000);
        let shallow = Bvh::build(&prims);
        let levels = shallow.levels();
        // 20,000 triangles under nodes of sixteen (or eight) whose leaves hold at
        // most eight: at least 3 levels (16³ · 8 = 32,768), and SAH trees are not much
        // deeper.
        assert!((3..=14).contains(&levels), "{levels} levels");
        assert!(!shallow.deep);
        // The same tree through the large-stack path every ISA has.
        for isa in Isa::available() {
            let mut deep = Bvh::build_for(&prims, isa);
            deep.deep = true;
            let mut rng = Rng(5);
            for k in 0..3000 {
                let o = rng.vec(15.0);
                let mut d = rng.vec(1.0).normalize();
                if k % 10 == 0 {
                    d.x = 0.0; // a zero component: the slab test's other case
                }
                let r = PreparedRay::new(Ray::segment(o, d.normalize(), 1e-3, rng.range(1.0, 40.0)));
                assert_eq!(
                    deep.closest_hit(&prims, &r),
                    shallow.closest_hit(&prims, &r),
                    "{isa:?} ray {k}"
                );
                assert_eq!(
                    deep.occluded(&prims, &r),
                    shallow.occluded(&prims, &r),
                    "{isa:?} ray {k}"
                );
            }
        }
    }

    /// A tree no build makes, to hold the traversal stacks to their bound: a chain of
    /// `levels` nodes of `W` children, each node's first child the next node and the
    /// others leaves (the last node's children all leaves), every leaf the one packet,
    /// every leaf's box one cube and every node's a slightly larger one around it. A ray
    /// through the cube enters every child of every node and goes down the chain first
    /// (its box is nearer), single rays and packets alike, leaving `W - 1` entries behind
    /// at each level and pushing `W` more at the last: the most any tree of that many
    /// levels can ask of the stacks.
    fn chain<const W: usize>(levels: usize) -> Vec<WideNode<W>> {
        let size = std::mem::size_of::<WideNode<W>>() as u32;
        (0..levels)
            .map(|level| {
                let mut node = WideNode::<W>::EMPTY;
                for slot in 0..W {
                    let inner = slot == 0 && level + 1 < levels;
                    let half = if inner { 1.1 } else { 1.0 };
                    for axis in 0..3 {
                        node.bounds[axis][slot] = -half;
                        node.bounds[axis + 3][slot] = half;
                    }
                    node.child[slot] = if inner {
                        (level as u32 + 1) * size
                    } else {
                        wide::LEAF // packet 0, one packet
                    };
                }
                node
            })
            .collect()
    }

    #[test]
    fn the_stacks_hold_the_deepest_trees_each_path_takes() {
        use crate::math::Vec3A;
        let prims = Triangles(vec![[
            Vec3A::new(-0.9, -0.9, 0.0),
            Vec3A::new(0.9, -0.9, 0.0),
            Vec3A::new(0.0, 0.9, 0.0),
        ]]);
        // Rows of rays through the cube onto the triangle: along z (the plain box test,
        // for directions with zero components) and slightly tilted (the fused one).
        let rays: Vec<Ray> = (0..32)
            .map(|k| {
                let o = Vec3A::new((k % 16) as f32 * 0.02 - 0.16, 0.1, -5.0);
                let d = if k < 16 {
                    Vec3A::Z
                } else {
                    Vec3A::new(0.01, -0.02, 1.0).normalize()
                };
                Ray::new(o, d)
            })
            .collect();
        for isa in Isa::available() {
            let width = isa.node_width();
            let shallow = traverse::shallow_levels(width);
            for levels in [shallow, shallow + 1, traverse::MAX_LEVELS] {
                let (nodes16, nodes8) = match width {
                    8 => (Vec::new(), chain::<8>(levels)),
                    _ => (chain::<16>(levels), Vec::new()),
                };
                let bvh = Bvh {
                    nodes16,
                    nodes8,
                    packets: vec![Packet::new(&prims, &[0])],
                    isa,
                    deep: levels > shallow,
                };
                assert_eq!(bvh.levels(), levels);
                let mut hits = vec![None; rays.len()];
                bvh.closest_hits(&prims, &rays, &mut hits);
                let mut blocked = vec![false; rays.len()];
                bvh.occluded_rays(&prims, &rays, &mut blocked);
                for (i, ray) in rays.iter().enumerate() {
                    let r = PreparedRay::new(*ray);
                    let want = prims.intersect(0, &r, f32::INFINITY);
                    assert!(want.is_some());
                    assert_eq!(bvh.closest_hit(&prims, &r), want, "{isa:?}, {levels} levels, ray {i}");
                    assert!(bvh.occluded(&prims, &r), "{isa:?}, {levels} levels, ray {i}");
                    assert_eq!(hits[i], want, "{isa:?}, {levels} levels, packets, ray {i}");
                    assert!(blocked[i], "{isa:?}, {levels} levels, packets, ray {i}");
                }
            }
        }
    }

    fn pool(threads: usize) -> rayon::ThreadPool {
        rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap()
    }
}
