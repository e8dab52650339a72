//! Packets of up to eight coherent rays (camera rays of a tile, shadow rays toward one
//! light) walked through the wide BVH together: one AVX lane per ray. At a node, each
//! child box is tested against every active ray of the packet; a child that some ray
//! enters is pushed with the mask of those rays; at a leaf, each of them runs the
//! single-ray packet test. The work per ray is that of a single ray, but eight rays'
//! independent tests fill the pipeline that one ray's chain of dependent loads leaves
//! idle, and a node is fetched once for all of them.
//!
//! **The same answers.** Each ray's box test is the plain slab test of
//! [`super::traverse`] (`(plane − origin) · (1/d)`, the far reciprocal widened by
//! `1 + 2γ(3)`), written with `min`/`max` of the two planes instead of choosing them by
//! the direction's sign — the same two products, so the same entry and exit distances,
//! and a ray enters exactly the boxes it enters alone (against its own closest hit so far
//! and search limit). Leaves use the single-ray triangle tests, which accept `t ≤ t_max`
//! and keep ties by primitive index, so the order of visits cannot change a ray's
//! answer. Rays that do not move along an axis, or whose reciprocals are not finite, are
//! traced alone.

use super::packet::Packet;
use super::traverse::{leaf_packets, FAR_WIDENING};
use super::wide::{WideNode, EMPTY, LEAF, WIDTH};
use crate::accel::{search_limit, PrimitiveSet};
use crate::hit::Hit;
use crate::ray::PreparedRay;

/// Rays per packet.
pub const PACKET_RAYS: usize = 8;
// A visit pushes every entered child (up to `WIDTH`) and pops one: 7 more per level, and
// the tree is at most ~100 levels deep.
const STACK_SIZE: usize = WIDTH * 112;

/// Whether a ray can travel in a packet.
pub fn packable(r: &PreparedRay) -> bool {
    !r.zero_axes.any()
        && r.inv_dir.is_finite()
        && r.ray.origin.is_finite()
        && r.ray.t_min >= 0.0
        && (r.inv_dir * FAR_WIDENING).is_finite()
}

/// The rays' constants, one lane each (unused lanes copy lane 0 and are never active).
#[cfg(target_arch = "x86_64")]
struct Lanes8 {
    origin: [std::arch::x86_64::__m256; 3],
    inv: [std::arch::x86_64::__m256; 3],
    inv_far: [std::arch::x86_64::__m256; 3],
    t_min: std::arch::x86_64::__m256,
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn lanes8(rays: &[PreparedRay]) -> Lanes8 {
    use std::arch::x86_64::*;
    let pick = |f: &dyn Fn(&PreparedRay) -> f32| {
        let mut v = [0f32; PACKET_RAYS];
        for (i, x) in v.iter_mut().enumerate() {
            *x = f(rays.get(i).unwrap_or(&rays[0]));
        }
        _mm256_loadu_ps(v.as_ptr())
    };
    Lanes8 {
        origin: [0, 1, 2].map(|a| pick(&|r| r.ray.origin[a])),
        inv: [0, 1, 2].map(|a| pick(&|r| r.inv_dir[a])),
        inv_far: [0, 1, 2].map(|a| pick(&|r| r.inv_dir[a] * FAR_WIDENING)),
        t_min: pick(&|r| r.ray.t_min),
    }
}

/// Which rays of `active` enter child `c` of `node`, given each ray's search limit, and
/// the entry distances.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn enters(
    node: &WideNode,
    c: usize,
    l: &Lanes8,
    limit: std::arch::x86_64::__m256,
) -> (u32, std::arch::x86_64::__m256) {
    use std::arch::x86_64::*;
    let mut near = l.t_min;
    let mut far = limit;
    for a in 0..3 {
        let lo = _mm256_sub_ps(_mm256_set1_ps(node.bounds[a][c]), l.origin[a]);
        let hi = _mm256_sub_ps(_mm256_set1_ps(node.bounds[a + 3][c]), l.origin[a]);
        let n = _mm256_min_ps(_mm256_mul_ps(lo, l.inv[a]), _mm256_mul_ps(hi, l.inv[a]));
        let f = _mm256_max_ps(_mm256_mul_ps(lo, l.inv_far[a]), _mm256_mul_ps(hi, l.inv_far[a]));
        near = _mm256_max_ps(n, near);
        far = _mm256_min_ps(f, far);
    }
    let ok = _mm256_cmp_ps::<_CMP_LE_OQ>(near, far);
    (_mm256_movemask_ps(ok) as u32, near)
}

/// What a packet query does at a leaf for one ray: closest hit or any hit.
pub trait PacketQuery {
    /// Per ray: the answer so far, and its search distance.
    type State: Copy;
    fn start(r: &PreparedRay) -> Self::State;
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
}

pub struct ClosestQuery;
pub struct AnyQuery;

impl PacketQuery for ClosestQuery {
    type State = (f32, Option<Hit>);
    fn start(r: &PreparedRay) -> Self::State {
        (r.ray.t_max, None)
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
}

impl PacketQuery for AnyQuery {
    type State = (f32, bool);
    fn start(r: &PreparedRay) -> Self::State {
        (r.ray.t_max, false)
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
}

/// Walks the packet `rays` (1 to 8 packable rays) through the tree; `states` start as
/// [`PacketQuery::start`] and end as the answers.
///
/// # Safety
/// The CPU must have AVX2 and FMA; `nodes` and `packets` must be a tree built for `prims`.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
pub unsafe fn traverse<Q: PacketQuery, P: PrimitiveSet + ?Sized>(
    nodes: &[WideNode],
    packets: &[Packet],
    prims: &P,
    rays: &[PreparedRay],
    states: &mut [Q::State],
) {
    use std::arch::x86_64::*;
    debug_assert!(!rays.is_empty() && rays.len() <= PACKET_RAYS && states.len() == rays.len());
    let l = lanes8(rays);
    let mut limits = [0f32; PACKET_RAYS];
    for (i, s) in states.iter().enumerate() {
        limits[i] = search_limit(Q::t_max(s));
    }
    let mut limit = _mm256_loadu_ps(limits.as_ptr());
    let mut live: u32 = (1u32 << rays.len()) - 1;
    let mut stack = [std::mem::MaybeUninit::<(u32, u32)>::uninit(); STACK_SIZE];
    // Each entry's rays' entry distances: a ray that has since found a hit nearer than
    // its entry is dropped from the entry when it is popped.
    let mut entry_near = [std::mem::MaybeUninit::<__m256>::uninit(); STACK_SIZE];
    let mut sp = 1usize;
    stack[0].write((0, live));
    entry_near[0].write(l.t_min);
    let mut near = [0f32; PACKET_RAYS];
    while sp > 0 {
        sp -= 1;
        // SAFETY: entries below `sp` were written.
        let (reference, word) = stack[sp].assume_init();
        let still = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(entry_near[sp].assume_init(), limit)) as u32;
        let mask = word & 0xff & live & still;
        if mask == 0 {
            continue;
        }
        if reference & LEAF != 0 {
            let mut bits = mask;
            while bits != 0 {
                let i = bits.trailing_zeros() as usize;
                bits &= bits - 1;
                if Q::leaf(&mut states[i], packets, prims, &rays[i], reference) {
                    live &= !(1 << i);
                }
                limits[i] = search_limit(Q::t_max(&states[i]));
            }
            if live == 0 {
                return;
            }
            limit = _mm256_loadu_ps(limits.as_ptr());
            continue;
        }
        let node = &*nodes.as_ptr().cast::<u8>().add(reference as usize).cast::<WideNode>();
        // The children some active ray enters, keyed by the entry distance of the
        // lowest such ray, pushed farthest first.
        let base = sp;
        for c in 0..WIDTH {
            let child = node.child[c];
            if child == EMPTY {
                continue;
            }
            let (hits, n) = enters(node, c, &l, limit);
            let m = hits & mask;
            if m == 0 {
                continue;
            }
            _mm256_storeu_ps(near.as_mut_ptr(), n);
            // Non-negative floats order like their bits; the low 8 bits carry the mask.
            let key = near[m.trailing_zeros() as usize].max(0.0);
            stack[sp].write((child, m | (key.to_bits() >> 8 << 8)));
            entry_near[sp].write(n);
            sp += 1;
        }
        // SAFETY: entries `base..sp` were written just above.
        sort_farthest_first(
            std::slice::from_raw_parts_mut(stack.as_mut_ptr().add(base).cast::<(u32, u32)>(), sp - base),
            std::slice::from_raw_parts_mut(entry_near.as_mut_ptr().add(base).cast::<__m256>(), sp - base),
        );
    }
}

/// Orders pushed entries (and their entry distances) by decreasing key (the high 24 bits
/// of the second word; the low 8 are the ray mask).
#[inline(always)]
fn sort_farthest_first<T: Copy>(e: &mut [(u32, u32)], near: &mut [T]) {
    for i in 1..e.len() {
        let (x, n) = (e[i], near[i]);
        let mut j = i;
        while j > 0 && (e[j - 1].1 >> 8) < (x.1 >> 8) {
            e[j] = e[j - 1];
            near[j] = near[j - 1];
            j -= 1;
        }
        e[j] = x;
        near[j] = n;
    }
}
