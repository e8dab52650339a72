//! Walking the wide BVH: closest-hit and any-hit queries.
//!
//! Each node visit tests the ray against all eight child boxes at once (AVX when the CPU
//! has it — detected at run time — else two SSE halves), then continues with the nearest
//! child and pushes the others, farthest first, on a fixed stack together with their
//! entry distance; a popped entry that starts beyond the closest hit found since is
//! dropped. The box test is the conservative slab test of [`crate::aabb::Aabb::intersect`]
//! in SIMD form: the far distance is widened by `1 + 2γ(3)`, and axes along which the
//! ray does not move are decided by where the origin lies (a separate instantiation,
//! since such rays are rare).

use std::mem::MaybeUninit;

use super::packet::Packet;
use super::wide::{WideNode, FIRST_MASK, LEAF, PACKET_SHIFT, WIDTH};
use crate::accel::search_limit;
use crate::accel::PrimitiveSet;
use crate::hit::Hit;
use crate::math::gamma;
use crate::ray::PreparedRay;

/// Each visit pushes at most `WIDTH - 1` entries and the tree is at most ~100 levels deep.
const STACK_SIZE: usize = (WIDTH - 1) * 112;
const FAR_WIDENING: f32 = 1.0 + 2.0 * gamma(3);

/// What the box test needs of a ray, per axis.
#[derive(Clone, Copy)]
pub struct RayBoxes {
    origin: [f32; 3],
    inv_dir: [f32; 3],
    /// Rows of `WideNode::bounds` holding the planes the ray enters and leaves by.
    near_row: [usize; 3],
    far_row: [usize; 3],
    zero: [bool; 3],
    t_min: f32,
}

impl RayBoxes {
    pub fn new(r: &PreparedRay) -> RayBoxes {
        let inv = r.inv_dir.to_array();
        RayBoxes {
            origin: r.ray.origin.to_array(),
            inv_dir: inv,
            near_row: [0, 1, 2].map(|a| if inv[a] >= 0.0 { a } else { a + 3 }),
            far_row: [0, 1, 2].map(|a| if inv[a] >= 0.0 { a + 3 } else { a }),
            zero: [r.zero_axes.test(0), r.zero_axes.test(1), r.zero_axes.test(2)],
            t_min: r.ray.t_min,
        }
    }
}

/// Which child boxes a ray enters before `t_max`, and where.
pub trait BoxTest {
    /// The ray in the form the test wants it (SIMD broadcasts), made once per ray.
    type Ray;
    unsafe fn prepare(r: &RayBoxes) -> Self::Ray;
    /// `ZERO`: the ray has direction components that are zero.
    unsafe fn test<const ZERO: bool>(node: &WideNode, r: &Self::Ray, t_max: f32, dist: &mut [f32; WIDTH]) -> u32;
}

pub struct Scalar;

impl BoxTest for Scalar {
    type Ray = RayBoxes;
    #[inline(always)]
    unsafe fn prepare(r: &RayBoxes) -> RayBoxes {
        *r
    }
    #[inline(always)]
    unsafe fn test<const ZERO: bool>(node: &WideNode, r: &RayBoxes, t_max: f32, dist: &mut [f32; WIDTH]) -> u32 {
        let mut mask = 0;
        for (i, d) in dist.iter_mut().enumerate() {
            let (mut near, mut far) = (r.t_min, f32::INFINITY);
            let mut inside = true;
            for a in 0..3 {
                let (lo, hi) = (node.bounds[a][i], node.bounds[a + 3][i]);
                if ZERO && r.zero[a] {
                    inside &= lo <= r.origin[a] && r.origin[a] <= hi;
                } else {
                    let n = (node.bounds[r.near_row[a]][i] - r.origin[a]) * r.inv_dir[a];
                    let f = (node.bounds[r.far_row[a]][i] - r.origin[a]) * r.inv_dir[a];
                    near = if n > near { n } else { near };
                    far = if f < far { f } else { far };
                }
            }
            far *= FAR_WIDENING;
            far = if t_max < far { t_max } else { far };
            *d = near;
            if inside && near <= far {
                mask |= 1 << i;
            }
        }
        mask
    }
}

#[cfg(target_arch = "x86_64")]
pub use x86::{Avx, Sse};

#[cfg(target_arch = "x86_64")]
mod x86 {
    use super::*;
    use std::arch::x86_64::*;

    pub struct Sse;
    pub struct Avx;

    /// The ray as SIMD broadcasts (`N` is `__m128` or `__m256`).
    #[derive(Clone, Copy)]
    pub struct Broadcast<N> {
        origin: [N; 3],
        inv_dir: [N; 3],
        t_min: N,
        rb: RayBoxes,
    }

    impl BoxTest for Sse {
        type Ray = Broadcast<__m128>;
        #[inline(always)]
        unsafe fn prepare(r: &RayBoxes) -> Self::Ray {
            Broadcast {
                origin: r.origin.map(|x| _mm_set1_ps(x)),
                inv_dir: r.inv_dir.map(|x| _mm_set1_ps(x)),
                t_min: _mm_set1_ps(r.t_min),
                rb: *r,
            }
        }
        #[inline(always)]
        unsafe fn test<const ZERO: bool>(node: &WideNode, r: &Self::Ray, t_max: f32, dist: &mut [f32; WIDTH]) -> u32 {
            let mut mask = 0;
            let rb = &r.rb;
            for half in 0..2 {
                let row = |k: usize| _mm_load_ps(node.bounds.get_unchecked(k).as_ptr().add(4 * half));
                let mut near = r.t_min;
                let mut far = _mm_set1_ps(f32::INFINITY);
                let mut inside = _mm_castsi128_ps(_mm_set1_epi32(-1));
                for a in 0..3 {
                    let o = r.origin[a];
                    if ZERO && rb.zero[a] {
                        inside = _mm_and_ps(inside, _mm_and_ps(_mm_cmple_ps(row(a), o), _mm_cmple_ps(o, row(a + 3))));
                    } else {
                        let n = _mm_mul_ps(_mm_sub_ps(row(rb.near_row[a]), o), r.inv_dir[a]);
                        let f = _mm_mul_ps(_mm_sub_ps(row(rb.far_row[a]), o), r.inv_dir[a]);
                        near = _mm_max_ps(n, near);
                        far = _mm_min_ps(f, far);
                    }
                }
                far = _mm_min_ps(_mm_mul_ps(far, _mm_set1_ps(FAR_WIDENING)), _mm_set1_ps(t_max));
                _mm_storeu_ps(dist.as_mut_ptr().add(4 * half), near);
                let hit = _mm_and_ps(_mm_cmple_ps(near, far), inside);
                mask |= (_mm_movemask_ps(hit) as u32) << (4 * half);
            }
            mask
        }
    }

    impl BoxTest for Avx {
        type Ray = Broadcast<__m256>;
        #[inline(always)]
        unsafe fn prepare(r: &RayBoxes) -> Self::Ray {
            Broadcast {
                origin: r.origin.map(|x| _mm256_set1_ps(x)),
                inv_dir: r.inv_dir.map(|x| _mm256_set1_ps(x)),
                t_min: _mm256_set1_ps(r.t_min),
                rb: *r,
            }
        }
        #[inline(always)]
        unsafe fn test<const ZERO: bool>(node: &WideNode, r: &Self::Ray, t_max: f32, dist: &mut [f32; WIDTH]) -> u32 {
            let rb = &r.rb;
            let row = |k: usize| _mm256_load_ps(node.bounds.get_unchecked(k).as_ptr());
            let mut near = r.t_min;
            let mut far = _mm256_set1_ps(f32::INFINITY);
            let mut inside = _mm256_castsi256_ps(_mm256_set1_epi32(-1));
            for a in 0..3 {
                let o = r.origin[a];
                if ZERO && rb.zero[a] {
                    inside = _mm256_and_ps(
                        inside,
                        _mm256_and_ps(
                            _mm256_cmp_ps::<_CMP_LE_OQ>(row(a), o),
                            _mm256_cmp_ps::<_CMP_LE_OQ>(o, row(a + 3)),
                        ),
                    );
                } else {
                    let n = _mm256_mul_ps(_mm256_sub_ps(row(rb.near_row[a]), o), r.inv_dir[a]);
                    let f = _mm256_mul_ps(_mm256_sub_ps(row(rb.far_row[a]), o), r.inv_dir[a]);
                    near = _mm256_max_ps(n, near);
                    far = _mm256_min_ps(f, far);
                }
            }
            far = _mm256_min_ps(_mm256_mul_ps(far, _mm256_set1_ps(FAR_WIDENING)), _mm256_set1_ps(t_max));
            _mm256_storeu_ps(dist.as_mut_ptr(), near);
            let hit = _mm256_and_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(near, far), inside);
            _mm256_movemask_ps(hit) as u32
        }
    }
}

/// Asks for the first cache lines of a child that was pushed on the stack: by the time
/// it is popped, after the nearer subtree, they have arrived.
#[inline(always)]
unsafe fn prefetch(nodes: &[WideNode], packets: &[Packet], reference: u32) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        let p = if reference & LEAF == 0 {
            nodes.as_ptr().cast::<i8>().add(reference as usize)
        } else {
            packets.as_ptr().add(leaf_packets(reference).start).cast::<i8>()
        };
        for line in 0..4 {
            _mm_prefetch::<_MM_HINT_T0>(p.add(64 * line));
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (nodes, packets, reference);
}

/// The node at byte offset `offset` (see [`super::wide::LEAF`]).
#[inline(always)]
unsafe fn node_at(nodes: &[WideNode], offset: u32) -> &WideNode {
    debug_assert!((offset as usize) < std::mem::size_of_val(nodes));
    &*nodes.as_ptr().cast::<u8>().add(offset as usize).cast::<WideNode>()
}

#[inline(always)]
fn leaf_packets(reference: u32) -> std::ops::Range<usize> {
    let first = (reference & FIRST_MASK) as usize;
    let n = ((reference & !LEAF) >> PACKET_SHIFT) as usize + 1;
    first..first + n
}

/// A stack entry: the entry distance in the high half (non-negative floats order like
/// their bits), the node reference in the low half.
#[inline(always)]
fn entry(dist: f32, reference: u32) -> u64 {
    (dist.to_bits() as u64) << 32 | reference as u64
}

#[inline(always)]
pub unsafe fn closest<T: BoxTest, const ZERO: bool, P: PrimitiveSet + ?Sized>(
    nodes: &[WideNode],
    packets: &[Packet],
    prims: &P,
    r: &PreparedRay,
) -> Option<Hit> {
    let rb = T::prepare(&RayBoxes::new(r));
    let mut best = None;
    let mut t_max = r.ray.t_max;
    let mut stack = [const { MaybeUninit::<u64>::uninit() }; STACK_SIZE];
    let mut sp = 0usize;
    let mut dist = [0.0f32; WIDTH];
    let mut cur = 0u32;
    loop {
        if cur & LEAF == 0 {
            let node = node_at(nodes, cur);
            let mask = T::test::<ZERO>(node, &rb, search_limit(t_max), &mut dist);
            if mask != 0 {
                let first = mask.trailing_zeros() as usize;
                let rest = mask & (mask - 1);
                if rest == 0 {
                    cur = *node.child.get_unchecked(first);
                    continue;
                }
                if rest & (rest - 1) == 0 {
                    // Two children, the common case: no sorting loop.
                    let second = rest.trailing_zeros() as usize;
                    let (d0, d1) = (*dist.get_unchecked(first), *dist.get_unchecked(second));
                    let (near, far) = if d0 <= d1 { (first, second) } else { (second, first) };
                    prefetch(nodes, packets, *node.child.get_unchecked(far));
                    let far_entry = entry(*dist.get_unchecked(far), *node.child.get_unchecked(far));
                    stack.get_unchecked_mut(sp).write(far_entry);
                    sp += 1;
                    cur = *node.child.get_unchecked(near);
                    continue;
                }
                // Sort the entered children by distance: push all, then order the new
                // entries so that the nearest ends on top.
                let base = sp;
                for i in super::packet::Lanes(mask) {
                    prefetch(nodes, packets, *node.child.get_unchecked(i));
                    let e = entry(*dist.get_unchecked(i), *node.child.get_unchecked(i));
                    stack.get_unchecked_mut(sp).write(e);
                    sp += 1;
                }
                for i in base + 1..sp {
                    let e = stack.get_unchecked(i).assume_init();
                    let mut j = i;
                    while j > base && stack.get_unchecked(j - 1).assume_init() < e {
                        *stack.get_unchecked_mut(j) = *stack.get_unchecked(j - 1);
                        j -= 1;
                    }
                    stack.get_unchecked_mut(j).write(e);
                }
                sp -= 1;
                cur = stack.get_unchecked(sp).assume_init() as u32;
                continue;
            }
        } else {
            for p in leaf_packets(cur) {
                packets.get_unchecked(p).closest(prims, r, &mut t_max, &mut best);
            }
        }
        loop {
            if sp == 0 {
                return best;
            }
            sp -= 1;
            let e = stack.get_unchecked(sp).assume_init();
            // Keep an entry whose box starts at (or, by rounding, just beyond) the closest
            // hit: it may hold a tie.
            if f32::from_bits((e >> 32) as u32) <= search_limit(t_max) {
                cur = e as u32;
                break;
            }
        }
    }
}

#[inline(always)]
pub unsafe fn occluded<T: BoxTest, const ZERO: bool, P: PrimitiveSet + ?Sized>(
    nodes: &[WideNode],
    packets: &[Packet],
    prims: &P,
    r: &PreparedRay,
) -> bool {
    let rb = T::prepare(&RayBoxes::new(r));
    let t_max = r.ray.t_max;
    let mut stack = [const { MaybeUninit::<u32>::uninit() }; STACK_SIZE];
    let mut sp = 0usize;
    let mut dist = [0.0f32; WIDTH];
    let mut cur = 0u32;
    loop {
        if cur & LEAF == 0 {
            let node = node_at(nodes, cur);
            let mut mask = T::test::<ZERO>(node, &rb, search_limit(t_max), &mut dist);
            if mask != 0 {
                cur = *node.child.get_unchecked(mask.trailing_zeros() as usize);
                mask &= mask - 1;
                for i in super::packet::Lanes(mask) {
                    prefetch(nodes, packets, *node.child.get_unchecked(i));
                    stack.get_unchecked_mut(sp).write(*node.child.get_unchecked(i));
                    sp += 1;
                }
                continue;
            }
        } else {
            for p in leaf_packets(cur) {
                if packets.get_unchecked(p).any_hit(prims, r, t_max) {
                    return true;
                }
            }
        }
        if sp == 0 {
            return false;
        }
        sp -= 1;
        cur = stack.get_unchecked(sp).assume_init();
    }
}
