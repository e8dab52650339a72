//! One query of one ray (closest hit or any hit) on the instruction set the tree was built
//! for: the box test and lane width each instruction set takes ([`box_test`], [`lanes`]),
//! the rays that the fused test cannot take, and trees too deep for the small stack. The
//! traversal itself is [`traverse`]'s.

use super::box_test::{self, BoxTest, FmaOffsets, RayBoxes, Slab};
use super::packet::Packet;
use super::traverse::{self, DEEP_STACK, SHALLOW_STACK};
use super::wide::WideNode;
use super::{lanes, Bvh, Isa};
use crate::accel::PrimitiveSet;
use crate::hit::Hit;
use crate::ray::PreparedRay;

/// The two queries, so that the choice of box test is written once.
pub(super) trait Query<P: PrimitiveSet + ?Sized> {
    /// Where the query keeps its answer as it goes: the caller's closest hit (searched
    /// for in place: a hit copied out of the traversal would be read back whole just
    /// after it was written piece by piece, a stalled store-to-load forward per ray), or
    /// nothing for any-hit queries, which return theirs in a register.
    type Out;
    /// What the query returns.
    type Answer;
    /// The answer when the tree is empty.
    fn nothing(out: &mut Self::Out) -> Self::Answer;
    /// # Safety
    /// `T`'s instructions must be available, `ZERO` set when the ray has a zero
    /// direction component, and the tree (`nodes`, `packets`) built for `prims` and at
    /// most [`traverse::levels_held`]`(STACK, W)` levels deep.
    unsafe fn run<T: BoxTest, const ZERO: bool, const STACK: usize, const W: usize>(
        nodes: &[WideNode<W>],
        packets: &[Packet],
        prims: &P,
        r: &PreparedRay,
        rb: &T::Ray,
        out: &mut Self::Out,
    ) -> Self::Answer;
}

pub(super) struct Closest;
pub(super) struct Occluded;

impl<P: PrimitiveSet + ?Sized> Query<P> for Closest {
    type Out = Option<Hit>;
    type Answer = ();
    fn nothing(out: &mut Option<Hit>) {
        *out = None;
    }
    #[inline(always)]
    unsafe fn run<T: BoxTest, const ZERO: bool, const STACK: usize, const W: usize>(
        nodes: &[WideNode<W>],
        packets: &[Packet],
        prims: &P,
        r: &PreparedRay,
        rb: &T::Ray,
        out: &mut Option<Hit>,
    ) {
        traverse::closest::<T, ZERO, P, STACK, W>(nodes, packets, prims, r, rb, out)
    }
}

impl<P: PrimitiveSet + ?Sized> Query<P> for Occluded {
    type Out = ();
    type Answer = bool;
    fn nothing(_: &mut ()) -> bool {
        false
    }
    #[inline(always)]
    unsafe fn run<T: BoxTest, const ZERO: bool, const STACK: usize, const W: usize>(
        nodes: &[WideNode<W>],
        packets: &[Packet],
        prims: &P,
        r: &PreparedRay,
        rb: &T::Ray,
        _: &mut (),
    ) -> bool {
        traverse::occluded::<T, ZERO, P, STACK, W>(nodes, packets, prims, r, rb)
    }
}

/// The AVX2 paths, compiled with AVX2 and FMA enabled: the fused box test for rays
/// that have its constants, the plain one for the others. Shallow trees of nodes of
/// eight (one group of eight boxes a visit) only.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn run_avx2<Q: Query<P>, P: PrimitiveSet + ?Sized>(
    nodes: &[WideNode<8>],
    packets: &[Packet],
    prims: &P,
    r: &PreparedRay,
    out: &mut Q::Out,
) -> Q::Answer {
    run_fused::<Q, P, lanes::Avx, 8>(nodes, packets, prims, r, out)
}

/// The AVX-512 paths ([`Isa::Avx512`], nodes of sixteen): both queries test a node's
/// boxes as two groups of eight lanes of AVX-512 VL ([`lanes::Avx512Vl8`]: 32 vector
/// registers, so the ray's constants stay in registers, and comparisons into mask
/// registers).
///
/// Measured on an Intel Xeon with full-width AVX-512 (docs/performance.md, 2026-11-30),
/// paired: against the same operations comparing into vectors ([`run_avx2`]'s code
/// compiled for AVX-512, which closest hits ran before) 1.17–1.18× on the 100k dragon's
/// closest hits; against nodes of eight with the same lanes 1.00–1.07× on every set. Any-hit
/// queries ran as one 16-lane group before (measured 1.037× faster than two
/// vector-compared groups on an AMD EPYC, Zen 4); each paired against nodes of eight,
/// that group made the dragons' shadow rays 0.871× and 1.004×, two mask-compared groups
/// 1.034× and 1.070×: about 1.19× and 1.07× between the two. On the Zen 4 this path is
/// still to be measured.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl,avx512bw,avx2,fma")]
unsafe fn run_avx512<Q: Query<P>, P: PrimitiveSet + ?Sized>(
    nodes: &[WideNode<16>],
    packets: &[Packet],
    prims: &P,
    r: &PreparedRay,
    out: &mut Q::Out,
) -> Q::Answer {
    run_fused::<Q, P, lanes::Avx512Vl8, 16>(nodes, packets, prims, r, out)
}

/// The body of [`run_avx2`] and [`run_avx512`], compiled into each with its caller's
/// instruction set: the fused box test on lanes `L` for rays that have its constants,
/// the plain one for the others.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn run_fused<Q: Query<P>, P: PrimitiveSet + ?Sized, L: lanes::FusedLanes, const W: usize>(
    nodes: &[WideNode<W>],
    packets: &[Packet],
    prims: &P,
    r: &PreparedRay,
    out: &mut Q::Out,
) -> Q::Answer {
    // The ray's constants are made here, in this function, rather than passed in: handing
    // them over through memory costs a stalled store-to-load forward per ray.
    use box_test::Fused;
    if let Some(offsets) = FmaOffsets::new(r) {
        Q::run::<Fused<L>, false, SHALLOW_STACK, W>(
            nodes,
            packets,
            prims,
            r,
            &Fused::prepare(&RayBoxes::new(r), &offsets, nodes),
            out,
        )
    } else {
        run_avx2_plain::<Q, P, W>(nodes, packets, prims, r, out)
    }
}

/// The rare rays the fused test cannot take, among them every ray that is not a line
/// ([`crate::ray::Ray::is_line`]: it finds nothing; [`FmaOffsets::new`] sends them
/// here); kept out of line so that the common path has the registers to itself.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
#[inline(never)]
#[cold]
unsafe fn run_avx2_plain<Q: Query<P>, P: PrimitiveSet + ?Sized, const W: usize>(
    nodes: &[WideNode<W>],
    packets: &[Packet],
    prims: &P,
    r: &PreparedRay,
    out: &mut Q::Out,
) -> Q::Answer {
    use lanes::Avx;
    if !r.ray.is_line() {
        return Q::nothing(out);
    }
    // (Made here, not passed in: a reference to it would make the common path store it.)
    let rb = RayBoxes::new(r);
    let prepared = Slab::prepare(&rb, nodes);
    if r.zero_axes.any() {
        Q::run::<Slab<Avx>, true, SHALLOW_STACK, W>(nodes, packets, prims, r, &prepared, out)
    } else {
        Q::run::<Slab<Avx>, false, SHALLOW_STACK, W>(nodes, packets, prims, r, &prepared, out)
    }
}

/// The paths without AVX2 (nodes of sixteen), shallow trees only; out of line, so that
/// their frames do not add to the AVX2 path's caller.
#[inline(never)]
unsafe fn run_portable<Q: Query<P>, P: PrimitiveSet + ?Sized>(
    b: &Bvh,
    prims: &P,
    r: &PreparedRay,
    out: &mut Q::Out,
) -> Q::Answer {
    if !r.ray.is_line() {
        return Q::nothing(out);
    }
    let zero = r.zero_axes.any();
    let rb = RayBoxes::new(r);
    let (nodes, packets) = (&b.nodes16[..], &b.packets[..]);
    match b.isa {
        #[cfg(target_arch = "x86_64")]
        Isa::Sse2 if zero => Q::run::<Slab<lanes::Sse>, true, SHALLOW_STACK, 16>(
            nodes,
            packets,
            prims,
            r,
            &Slab::prepare(&rb, nodes),
            out,
        ),
        #[cfg(target_arch = "x86_64")]
        Isa::Sse2 => Q::run::<Slab<lanes::Sse>, false, SHALLOW_STACK, 16>(
            nodes,
            packets,
            prims,
            r,
            &Slab::prepare(&rb, nodes),
            out,
        ),
        _ if zero => {
            Q::run::<Slab<f32>, true, SHALLOW_STACK, 16>(nodes, packets, prims, r, &Slab::prepare(&rb, nodes), out)
        }
        _ => Q::run::<Slab<f32>, false, SHALLOW_STACK, 16>(nodes, packets, prims, r, &Slab::prepare(&rb, nodes), out),
    }
}

/// Trees deeper than [`traverse::shallow_levels`] (only pathological inputs make them):
/// the plain box test (it takes every ray; every box test enters the same boxes the
/// answers depend on, so the answers are the same) with the large stack.
#[cold]
#[inline(never)]
unsafe fn run_deep<Q: Query<P>, P: PrimitiveSet + ?Sized, const W: usize>(
    isa: Isa,
    nodes: &[WideNode<W>],
    packets: &[Packet],
    prims: &P,
    r: &PreparedRay,
    out: &mut Q::Out,
) -> Q::Answer {
    if !r.ray.is_line() {
        return Q::nothing(out);
    }
    let rb = RayBoxes::new(r);
    match isa {
        #[cfg(target_arch = "x86_64")]
        Isa::Sse2 | Isa::Avx2 | Isa::Avx512 => {
            Q::run::<Slab<lanes::Sse>, true, DEEP_STACK, W>(nodes, packets, prims, r, &Slab::prepare(&rb, nodes), out)
        }
        _ => Q::run::<Slab<f32>, true, DEEP_STACK, W>(nodes, packets, prims, r, &Slab::prepare(&rb, nodes), out),
    }
}

impl Bvh {
    /// One query (see [`Query::Out`] for `out`).
    #[inline(always)]
    pub(super) fn query<Q: Query<P>, P: PrimitiveSet + ?Sized>(
        &self,
        prims: &P,
        r: &PreparedRay,
        out: &mut Q::Out,
    ) -> Q::Answer {
        if self.node_count() == 0 {
            return Q::nothing(out);
        }
        // SAFETY: node and packet references were built by `wide::collapse` for these
        // primitives, in nodes of `isa.node_width()` children (`nodes8` for AVX2,
        // `nodes16` else), with at most `MAX_LEVELS` levels (asserted at build) and at
        // most `shallow_levels` unless `deep`; the AVX2 and AVX-512 paths are only taken
        // when the CPU has them (`isa` checked at build); SSE2 is part of x86-64.
        unsafe {
            if self.deep {
                return match self.isa.node_width() {
                    8 => run_deep::<Q, P, 8>(self.isa, &self.nodes8, &self.packets, prims, r, out),
                    _ => run_deep::<Q, P, 16>(self.isa, &self.nodes16, &self.packets, prims, r, out),
                };
            }
            match self.isa {
                #[cfg(target_arch = "x86_64")]
                Isa::Avx512 => run_avx512::<Q, P>(&self.nodes16, &self.packets, prims, r, out),
                #[cfg(target_arch = "x86_64")]
                Isa::Avx2 => run_avx2::<Q, P>(&self.nodes8, &self.packets, prims, r, out),
                _ => run_portable::<Q, P>(self, prims, r, out),
            }
        }
    }
}
