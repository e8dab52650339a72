//! Packets of coherent rays (camera rays of a tile, shadow rays toward one light) walked
//! through the wide BVH together, one SIMD lane per ray: eight with AVX2, sixteen with
//! AVX-512 ([`super::ray_lanes`]). At a node, when the rays all move the same way along
//! each axis, the interval test of [`super::packet_frustum`] first drops the children no
//! ray of the packet can enter (camera rays enter one or two of a node's children); a
//! closest-hit packet goes on into the inner nodes it keeps with all its rays. Each other child box
//! is tested against every active ray of the packet; a child that some ray enters is
//! pushed with the mask of those rays. At a leaf reached by several rays that share
//! their dominant axis, each triangle is tested against all of them at once
//! ([`super::ray_triangle`]), and so is each sphere ([`super::ray_sphere`], the scalar
//! sphere test's bits in every lane); otherwise each ray runs the single-ray
//! four-triangle test.
//! A node is fetched once for the whole packet (its cache lines asked for when it is
//! pushed), and the lanes' independent work fills the pipeline that one ray's chain of
//! dependent loads leaves idle. The rays' lanes, and the test of one child box against
//! all of them, are made in [`super::packet_rays`]; this file walks the tree with them.
//!
//! **The same answers.** Each ray's box test is the fused test of [`super::traverse`]
//! (`plane · (1/d) − o/d` with the offsets of [`super::box_test::FmaOffsets`]), which never rejects a box
//! the exact slab test enters: the planes are chosen by the direction's signs when the
//! whole packet shares them, else both are computed and the `min`/`max` taken (the
//! bound holds for both). So every ray visits at least the boxes that hold its closest
//! hit, against its own closest hit so far and search limit. Both leaf tests compute the
//! scalar triangle test's bits (a large triangle's accepted hits then go to the scalar
//! test itself, for its bound on the error of `t`), accept `t ≤ t_max` and keep ties by
//! primitive index, so neither the order of visits nor the order of triangles within a
//! leaf can change a ray's answer. The interval test never drops a box the exact slab test has some ray
//! enter, and its near bound (an inner node's key and entry distance) is at most every
//! ray's, so it keeps the same guarantee. Rays without the fused test's constants (an
//! axis they do not move along, a constant that is not finite, a negative `t_min`) are
//! traced alone.

use super::packet::{LaneKind, Lanes as Bits, Packet};
use super::packet_rays::packet_lanes;
use super::ray_lanes::RayLanes;
use super::ray_sphere::SphereRays;
use super::ray_triangle::{self, ShearedRays};
use super::traverse::leaf_packets;
use super::wide::{WideNode, EMPTY, LEAF, MAX_WIDTH};
use crate::accel::{PrimitiveSet, SEARCH_SLACK};
use crate::hit::Hit;
use crate::ray::{PreparedRay, Ray};
use std::mem::MaybeUninit;

/// The most rays a packet holds (AVX-512's sixteen lanes).
pub const MAX_PACKET: usize = 16;
// A visit pushes every entered child (up to the node width W) and pops one: fewer than W
// more per level. Packets only walk trees of at most `STACK_SIZE / W` levels (deeper
// ones trace their rays one by one, see `Bvh::in_packets` and `traverse::shallow_levels`):
// sized for the 112 levels any tree may have, the entry distances alone took 57 KB of
// stack, probed page by page on every packet.
pub(super) const STACK_SIZE: usize = MAX_WIDTH * super::traverse::SHALLOW_LEVELS;
/// A leaf reached by at least this many rays of a packet that shares its axes is tested
/// triangle by triangle across the rays; by fewer, ray by ray (four triangles at a time).
const LANE_LEAF_RAYS: u32 = 3;

/// What a packet query does with hits, for one ray: closest hit or any hit.
pub trait PacketQuery {
    /// Whether a ray's search distance shrinks as hits are found (closest hits): then
    /// children are visited nearest first and each entry keeps its rays' entry distances
    /// to drop rays that have found something nearer. Any-hit queries need neither.
    const SHRINKS: bool;
    /// Per ray: the answer so far, and its search distance.
    type State: Copy;
    fn start(r: &Ray) -> Self::State;
    /// The ray's current far limit.
    fn t_max(s: &Self::State) -> f32;
    /// Tests the leaf's packets; whether the ray is finished (an any-hit query found one).
    fn leaf<P: PrimitiveSet + ?Sized>(
        s: &mut Self::State,
        packets: &[Packet],
        prims: &P,
        r: &PreparedRay,
        reference: u32,
    ) -> bool;
    /// Takes a triangle hit within the ray's limits; whether the ray is finished.
    fn record(s: &mut Self::State, hit: Hit) -> bool;
    /// Tests primitive `id`, which is not a triangle; whether the ray is finished.
    fn other<P: PrimitiveSet + ?Sized>(s: &mut Self::State, prims: &P, r: &PreparedRay, id: u32) -> bool;
}

pub struct ClosestQuery;
pub struct AnyQuery;

impl PacketQuery for ClosestQuery {
    const SHRINKS: bool = true;
    type State = (f32, Option<Hit>);
    fn start(r: &Ray) -> Self::State {
        (r.t_max, None)
    }
    #[inline(always)]
    fn t_max(s: &Self::State) -> f32 {
        s.0
    }
    #[inline(always)]
    fn leaf<P: PrimitiveSet + ?Sized>(
        s: &mut Self::State,
        packets: &[Packet],
        prims: &P,
        r: &PreparedRay,
        reference: u32,
    ) -> bool {
        for p in leaf_packets(reference) {
            packets[p].closest(prims, r, &mut s.0, &mut s.1);
        }
        false
    }
    #[inline(always)]
    fn record(s: &mut Self::State, hit: Hit) -> bool {
        // The packet test's rule: nearer, or as near with a lower primitive index.
        if Hit::is_closer_than(hit.t, hit.prim, &s.1) {
            s.0 = hit.t;
            s.1 = Some(hit);
        }
        false
    }
    #[inline(always)]
    fn other<P: PrimitiveSet + ?Sized>(s: &mut Self::State, prims: &P, r: &PreparedRay, id: u32) -> bool {
        match prims.intersect(id, r, s.0) {
            Some(hit) => Self::record(s, hit),
            None => false,
        }
    }
}

impl PacketQuery for AnyQuery {
    const SHRINKS: bool = false;
    type State = (f32, bool);
    fn start(r: &Ray) -> Self::State {
        (r.t_max, false)
    }
    #[inline(always)]
    fn t_max(s: &Self::State) -> f32 {
        s.0
    }
    #[inline(always)]
    fn leaf<P: PrimitiveSet + ?Sized>(
        s: &mut Self::State,
        packets: &[Packet],
        prims: &P,
        r: &PreparedRay,
        reference: u32,
    ) -> bool {
        if leaf_packets(reference).any(|p| packets[p].any_hit(prims, r, s.0)) {
            s.1 = true;
        }
        s.1
    }
    #[inline(always)]
    fn record(s: &mut Self::State, _hit: Hit) -> bool {
        s.1 = true;
        true
    }
    #[inline(always)]
    fn other<P: PrimitiveSet + ?Sized>(s: &mut Self::State, prims: &P, r: &PreparedRay, id: u32) -> bool {
        s.1 |= prims.occludes(id, r, s.0);
        s.1
    }
}

/// A stack entry: a node (or leaf) reference, the rays that entered it, and the entry
/// distance of the lowest of them (for the order of visits only).
#[derive(Clone, Copy)]
struct Entry {
    reference: u32,
    rays: u32,
    key: f32,
}

/// The packet's rays prepared for the single-ray tests, each made when first needed
/// (most rays of a coherent packet never need it).
struct Prepared<'a> {
    rays: &'a [Ray],
    made: u32,
    prepared: [MaybeUninit<PreparedRay>; MAX_PACKET],
}

impl Prepared<'_> {
    #[inline(always)]
    fn get(&mut self, i: usize) -> &PreparedRay {
        if self.made & 1 << i == 0 {
            self.prepared[i].write(PreparedRay::new(self.rays[i]));
            self.made |= 1 << i;
        }
        // SAFETY: written above or earlier (its bit is set).
        unsafe { self.prepared[i].assume_init_ref() }
    }
}

/// Walks a packet of 1 to 8 rays through the tree with AVX2 lanes; returns the rays it
/// did not take (to be traced alone).
///
/// # Safety
/// The CPU must have AVX2 and FMA; `nodes` and `packets` must be a tree built for `prims`,
/// of at most [`super::traverse::shallow_levels`]`(W)` levels.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
pub unsafe fn traverse_avx2<Q: PacketQuery, P: PrimitiveSet + ?Sized, const W: usize>(
    nodes: &[WideNode<W>],
    packets: &[Packet],
    prims: &P,
    rays: &[Ray],
    states: &mut [Q::State],
) -> u32 {
    traverse::<super::ray_lanes::Rays8, Q, P, W>(nodes, packets, prims, rays, states)
}

/// Walks a packet of 1 to 16 rays through the tree with AVX-512 lanes; returns the rays
/// it did not take (to be traced alone).
///
/// # Safety
/// The CPU must have AVX-512 F, VL and BW, AVX2 and FMA; `nodes` and `packets` must be a
/// tree built for `prims`, of at most [`super::traverse::shallow_levels`]`(W)` levels.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl,avx512bw,avx2,fma")]
pub unsafe fn traverse_avx512<Q: PacketQuery, P: PrimitiveSet + ?Sized, const W: usize>(
    nodes: &[WideNode<W>],
    packets: &[Packet],
    prims: &P,
    rays: &[Ray],
    states: &mut [Q::State],
) -> u32 {
    traverse::<super::ray_lanes::Rays16, Q, P, W>(nodes, packets, prims, rays, states)
}

/// Walks the packet `rays` (1 to `L::N` rays) through the tree; `states` start as
/// [`PacketQuery::start`] and end as the answers, except for the rays returned, which
/// cannot travel in a packet.
#[inline(always)]
unsafe fn traverse<L: RayLanes, Q: PacketQuery, P: PrimitiveSet + ?Sized, const W: usize>(
    nodes: &[WideNode<W>],
    packets: &[Packet],
    prims: &P,
    rays: &[Ray],
    states: &mut [Q::State],
) -> u32 {
    debug_assert!(!rays.is_empty() && rays.len() <= L::N && states.len() == rays.len());
    let lanes = packet_lanes::<L>(rays);
    let (l, sheared) = (&lanes.boxes, &lanes.sheared);
    let all = L::ALL >> (L::N - rays.len());
    let mut live = lanes.ok;
    if live == 0 {
        return all;
    }
    let mut prepared = Prepared {
        rays,
        made: 0,
        prepared: [const { MaybeUninit::uninit() }; MAX_PACKET],
    };
    // Each ray's closest hit so far (its far limit), and the limit boxes are searched to.
    let mut t_max = [0f32; MAX_PACKET];
    for (i, s) in states.iter().enumerate() {
        t_max[i] = Q::t_max(s);
    }
    let mut t_max_lanes = L::load(t_max.as_ptr());
    let mut limit = t_max_lanes.mul(L::splat(SEARCH_SLACK));
    // The largest search limit of the packet's rays, for the interval test. Not brought
    // up to date as hits are found (a reduction across the lanes after every leaf cost
    // more than it saved): the rays' own limits drop the entries when they are popped.
    let packet_limit = limit.max_of(live);
    let mut stack = [const { MaybeUninit::<Entry>::uninit() }; STACK_SIZE];
    // Each entry's rays' entry distances: a ray that has since found a hit nearer than
    // its entry is dropped from the entry when it is popped.
    let mut entry_near = [const { MaybeUninit::<L>::uninit() }; STACK_SIZE];
    let mut sp = 1usize;
    stack[0].write(Entry {
        reference: 0,
        rays: live,
        key: 0.0,
    });
    if Q::SHRINKS {
        entry_near[0].write(l.t_min);
    }
    let mut near = [0f32; MAX_PACKET];
    while sp > 0 {
        sp -= 1;
        // SAFETY: entries below `sp` were written.
        let e = stack[sp].assume_init();
        let mut mask = e.rays & live;
        if Q::SHRINKS {
            mask &= entry_near[sp].assume_init().le(limit);
        }
        if mask == 0 {
            continue;
        }
        if e.reference & LEAF != 0 {
            match sheared {
                Some(sh) if mask.count_ones() >= LANE_LEAF_RAYS => {
                    let done = leaf_by_lanes::<L, Q, P>(
                        sh,
                        states,
                        packets,
                        prims,
                        &mut prepared,
                        e.reference,
                        mask,
                        &mut t_max_lanes,
                    );
                    live &= !done;
                }
                _ => {
                    for i in Bits(mask) {
                        if Q::leaf(&mut states[i], packets, prims, prepared.get(i), e.reference) {
                            live &= !(1 << i);
                        }
                    }
                    if Q::SHRINKS {
                        t_max_lanes.store(t_max.as_mut_ptr());
                        for i in Bits(mask) {
                            t_max[i] = Q::t_max(&states[i]);
                        }
                        t_max_lanes = L::load(t_max.as_ptr());
                    }
                }
            }
            if live == 0 {
                break;
            }
            if Q::SHRINKS {
                limit = t_max_lanes.mul(L::splat(SEARCH_SLACK));
            }
            continue;
        }
        let node = &*nodes
            .as_ptr()
            .cast::<u8>()
            .add(e.reference as usize)
            .cast::<WideNode<W>>();
        // The children some active ray enters; for closest-hit queries keyed by the entry
        // distance of the lowest such ray and ordered so that the nearest is popped first
        // (any-hit queries pop the last slot first, as single rays do). When the rays
        // allow it, the interval test first drops the slots no ray can enter.
        let base = sp;
        let mut bound = [0f32; W];
        let slots = match &lanes.frustum {
            Some(f) => f.children(node, packet_limit, &mut bound),
            None => (1 << W) - 1,
        };
        for c in Bits(slots) {
            let child = node.child[c];
            if child == EMPTY {
                continue;
            }
            if Q::SHRINKS && lanes.frustum.is_some() && child & LEAF == 0 {
                // A closest-hit query takes an inner node the interval test keeps with
                // all the rays of this one, keyed by the interval's near bound (no ray
                // enters it nearer, so the bound also drops rays that have found a
                // nearer hit by the time it is popped); only leaves are worth a test
                // per ray. (Any-hit packets spread wider, and gained nothing from it.)
                // Like every entry pushed, its cache lines are asked for now, to have
                // arrived when it is popped (1.6M dragon primary packets 1.05–1.12×).
                super::traverse::prefetch(nodes, packets, child);
                entry_near[sp].write(L::splat(bound[c]));
                stack[sp].write(Entry {
                    reference: child,
                    rays: mask,
                    key: bound[c],
                });
                sp += 1;
                continue;
            }
            let (hits, n) = if l.rows.is_some() {
                l.enters::<true, W>(node, c, limit)
            } else {
                l.enters::<false, W>(node, c, limit)
            };
            let m = hits & mask;
            if m == 0 {
                continue;
            }
            let key = if Q::SHRINKS {
                n.store(near.as_mut_ptr());
                entry_near[sp].write(n);
                near[m.trailing_zeros() as usize]
            } else {
                0.0
            };
            super::traverse::prefetch(nodes, packets, child);
            stack[sp].write(Entry {
                reference: child,
                rays: m,
                key,
            });
            sp += 1;
        }
        if Q::SHRINKS {
            // SAFETY: entries `base..sp` were written just above.
            sort_farthest_first(
                std::slice::from_raw_parts_mut(stack.as_mut_ptr().add(base).cast::<Entry>(), sp - base),
                std::slice::from_raw_parts_mut(entry_near.as_mut_ptr().add(base).cast::<L>(), sp - base),
            );
        }
    }
    all & !lanes.ok
}

/// Tests the leaf `reference` for the rays of `mask`, one triangle against all of them at
/// a time, keeping `t_max_lanes` (every ray's far limit) up to date; returns the rays
/// that are finished (any-hit queries that found one).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
unsafe fn leaf_by_lanes<L: RayLanes, Q: PacketQuery, P: PrimitiveSet + ?Sized>(
    sh: &ShearedRays<L>,
    states: &mut [Q::State],
    packets: &[Packet],
    prims: &P,
    prepared: &mut Prepared,
    reference: u32,
    mask: u32,
    t_max_lanes: &mut L,
) -> u32 {
    let mut t_max = [0f32; MAX_PACKET];
    let mut sphere_rays: Option<SphereRays<L>> = None;
    let mut active = mask;
    let mut finished = 0;
    let (mut t, mut v, mut w, mut inv_det) = (
        [0f32; MAX_PACKET],
        [0f32; MAX_PACKET],
        [0f32; MAX_PACKET],
        [0f32; MAX_PACKET],
    );
    for p in leaf_packets(reference) {
        let packet = &packets[p];
        for lane in 0..super::packet::LANES {
            let (changed, accepted, lane_t) = match packet.lane_kind(lane) {
                LaneKind::Unused => break,
                LaneKind::Other(id) => {
                    match prims.sphere(id) {
                        // A sphere against all the rays at once (the rays' fields gathered
                        // once per leaf): each root is its ray's scalar answer.
                        Some(m) if active.count_ones() >= 2 => {
                            for i in Bits(active) {
                                t_max[i] = Q::t_max(&states[i]);
                            }
                            if sphere_rays.is_none() {
                                sphere_rays = Some(SphereRays::gather(prepared.rays));
                            }
                            // (Set just above.)
                            let rays = sphere_rays.as_ref().unwrap_unchecked();
                            rays.roots(m, L::load(t_max.as_ptr())).store(t.as_mut_ptr());
                            for i in Bits(active) {
                                if !t[i].is_nan() && Q::record(&mut states[i], Hit::new(t[i], id, 0.0, 0.0)) {
                                    finished |= 1 << i;
                                }
                            }
                        }
                        _ => {
                            for i in Bits(active) {
                                if Q::other(&mut states[i], prims, prepared.get(i), id) {
                                    finished |= 1 << i;
                                }
                            }
                        }
                    }
                    (active, 0, *t_max_lanes)
                }
                LaneKind::Triangle { id, checked } => {
                    let h = ray_triangle::test(packet, lane, sh, *t_max_lanes, active);
                    // A checked triangle's hits go to the scalar test, which applies the
                    // bound on the error of `t`; its misses are the scalar test's too.
                    let (accept, scalar) = if checked {
                        (0, h.accept | h.scalar)
                    } else {
                        (h.accept, h.scalar)
                    };
                    if accept != 0 {
                        if Q::SHRINKS {
                            // A closest hit will be shaded: its data on the way (see
                            // `PrimitiveSet::prefetch`).
                            prims.prefetch(id);
                        }
                        h.t.store(t.as_mut_ptr());
                        h.v.store(v.as_mut_ptr());
                        h.w.store(w.as_mut_ptr());
                        h.inv_det.store(inv_det.as_mut_ptr());
                        for i in Bits(accept) {
                            let hit = Hit::new(t[i], id, v[i] * inv_det[i], w[i] * inv_det[i]);
                            if Q::record(&mut states[i], hit) {
                                finished |= 1 << i;
                            }
                        }
                    }
                    for i in Bits(scalar) {
                        let limit = Q::t_max(&states[i]);
                        if let Some((t, b1, b2)) = packet.scalar_triangle(prepared.get(i), lane, limit) {
                            if Q::record(&mut states[i], Hit::new(t, id, b1, b2)) {
                                finished |= 1 << i;
                            }
                        }
                    }
                    (accept | scalar, accept, h.t)
                }
            };
            if changed != 0 {
                active &= !finished;
                if active == 0 {
                    return finished;
                }
                if Q::SHRINKS {
                    // A closest-hit query's limit becomes the distance of every hit the
                    // lane test accepted (a tie it keeps the old hit for is that same
                    // distance); lanes the scalar code decided are read back.
                    *t_max_lanes = L::select(accepted, lane_t, *t_max_lanes);
                    let read = changed & !accepted;
                    if read != 0 {
                        t_max_lanes.store(t_max.as_mut_ptr());
                        for i in Bits(read) {
                            t_max[i] = Q::t_max(&states[i]);
                        }
                        *t_max_lanes = L::load(t_max.as_ptr());
                    }
                }
            }
        }
    }
    finished
}

/// Orders pushed entries (and their entry distances) by decreasing key.
#[inline(always)]
fn sort_farthest_first<T: Copy>(e: &mut [Entry], near: &mut [T]) {
    for i in 1..e.len() {
        let (x, n) = (e[i], near[i]);
        let mut j = i;
        while j > 0 && e[j - 1].key < x.key {
            e[j] = e[j - 1];
            near[j] = near[j - 1];
            j -= 1;
        }
        e[j] = x;
        near[j] = n;
    }
}
