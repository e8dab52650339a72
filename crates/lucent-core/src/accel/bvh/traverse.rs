//! Walking the wide BVH: closest-hit and any-hit queries.
//!
//! Each node visit tests the ray against all the node's child boxes, `W` of them (sixteen,
//! or eight in the AVX2 trees; [`super::box_test`]),
//! then continues with the nearest child and pushes the others, farthest first, on a
//! fixed stack together with their entry distance; a popped entry that starts beyond the
//! closest hit found since is dropped.

use std::mem::MaybeUninit;

use super::box_test::BoxTest;
use super::packet::Packet;
use super::wide::{WideNode, FIRST_MASK, LEAF, MAX_WIDTH, PACKET_SHIFT};
use crate::accel::search_limit;
use crate::accel::PrimitiveSet;
use crate::hit::Hit;
use crate::ray::PreparedRay;

/// The most node levels any tree has: the binary build's depth is bounded (object-median
/// splits below depth 48 halve every node), and each wide level takes at least one
/// binary level. [`super::Bvh`] asserts it at build time.
pub const MAX_LEVELS: usize = 112;
/// The node levels of the trees of nodes of sixteen the fast paths are compiled for:
/// every tree a real scene makes (a billion triangles in balanced nodes of sixteen need
/// 7; the dragons' trees have 7 and 9). Deeper trees take the paths with [`DEEP_STACK`].
/// Trees of nodes of eight may have more levels in the same stacks: [`shallow_levels`].
pub const SHALLOW_LEVELS: usize = 16;

/// Stack entries for trees of `levels` node levels of the widest nodes: a visit at the
/// deepest level finds at most `MAX_WIDTH - 1` entries left by each level above it and
/// pushes up to `MAX_WIDTH` (every child it enters) before it pops the nearest, so
/// `(MAX_WIDTH - 1) · levels + 1` in all. ([`closest`] pushes before it pops;
/// [`occluded`] keeps its next child out of the stack and needs one fewer.)
const fn stack_entries(levels: usize) -> usize {
    (MAX_WIDTH - 1) * levels + 1
}

/// The most node levels a tree of nodes of `width` children may have to take the fast
/// paths: what their single-ray stack ([`SHALLOW_STACK`], `width - 1` entries a level
/// and one more) and their packets' stack (`width` a level) hold. 16 for nodes of
/// sixteen, 32 for nodes of eight.
pub const fn shallow_levels(width: usize) -> usize {
    let single = levels_held(SHALLOW_STACK, width);
    let packets = super::ray_packet::STACK_SIZE / width;
    if single < packets {
        single
    } else {
        packets
    }
}
/// The stack of the fast paths: 1.9 KB. A stack sized for [`MAX_LEVELS`] (6 KB) made
/// every query's frame span two pages, behind a stack probe, and made a query that
/// misses everything about 30 % slower.
pub const SHALLOW_STACK: usize = stack_entries(SHALLOW_LEVELS);
pub const DEEP_STACK: usize = stack_entries(MAX_LEVELS);

/// The most node levels of nodes of `width` children a single-ray stack of `stack`
/// entries holds ([`stack_entries`]'s bound the other way round).
pub const fn levels_held(stack: usize, width: usize) -> usize {
    (stack - 1) / (width - 1)
}

/// Asks for the first cache lines of a child that was pushed on the stack: by the time
/// it is popped, after the nearer subtree, they have arrived (single rays and packets).
/// Four lines, of a node's seven: asking for all seven measured no better.
///
/// # Safety
/// `reference` is a child of the tree `nodes`, `packets`: a node's byte offset or a leaf.
#[inline(always)]
pub(super) unsafe fn prefetch<const W: usize>(nodes: &[WideNode<W>], packets: &[Packet], reference: u32) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        let p = if reference & LEAF == 0 {
            nodes.as_ptr().cast::<i8>().add(reference as usize)
        } else {
            packets.as_ptr().add(leaf_packets(reference).start).cast::<i8>()
        };
        // (`wrapping_add`: a leaf's last packet ends before the fourth line; a prefetch
        // of any address is harmless, but `add` may not leave the allocation.)
        for line in 0..4 {
            _mm_prefetch::<_MM_HINT_T0>(p.wrapping_add(64 * line));
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (nodes, packets, reference);
}

/// The node at byte offset `offset` (see [`super::wide::LEAF`]).
#[inline(always)]
unsafe fn node_at<const W: usize>(nodes: &[WideNode<W>], offset: u32) -> &WideNode<W> {
    debug_assert!((offset as usize) < std::mem::size_of_val(nodes));
    &*nodes.as_ptr().cast::<u8>().add(offset as usize).cast::<WideNode<W>>()
}

/// The packets of leaf reference `reference`.
#[inline(always)]
pub(super) fn leaf_packets(reference: u32) -> std::ops::Range<usize> {
    let first = (reference & FIRST_MASK) as usize;
    let n = ((reference & !LEAF) >> PACKET_SHIFT) as usize + 1;
    first..first + n
}

/// Orders stack entries by decreasing distance (so the nearest is popped first): sorting
/// networks without branches for three and four entries, the common cases, whose
/// order is unpredictable; insertion sort beyond.
#[inline(always)]
fn sort_farthest_first(e: &mut [u64]) {
    #[inline(always)]
    fn order(e: &mut [u64], i: usize, j: usize) {
        let (a, b) = (e[i], e[j]);
        e[i] = a.max(b);
        e[j] = a.min(b);
    }
    match e.len() {
        3 => {
            order(e, 0, 1);
            order(e, 1, 2);
            order(e, 0, 1);
        }
        4 => {
            order(e, 0, 1);
            order(e, 2, 3);
            order(e, 0, 2);
            order(e, 1, 3);
            order(e, 1, 2);
        }
        _ => {
            for i in 1..e.len() {
                let x = e[i];
                let mut j = i;
                while j > 0 && e[j - 1] < x {
                    e[j] = e[j - 1];
                    j -= 1;
                }
                e[j] = x;
            }
        }
    }
}

/// A stack entry: the entry distance in the high half (non-negative floats order like
/// their bits), the node reference in the low half.
#[inline(always)]
fn entry(dist: f32, reference: u32) -> u64 {
    (dist.to_bits() as u64) << 32 | reference as u64
}

/// The entry distance of stack entry `e` ([`entry`]).
#[inline(always)]
fn entry_distance(e: u64) -> f32 {
    f32::from_bits((e >> 32) as u32)
}

/// The closest hit of `r` in the tree, into `best` (the caller's answer, so that the hit
/// is not copied out of a local of this function).
///
/// # Safety
/// The nodes and packets must be one tree built for `prims`, of at most
/// [`levels_held`]`(STACK, W)` node levels, and `T`'s instructions available (and AVX2 and FMA
/// for nodes of eight, which only CPUs with them are given: [`super::Isa::node_width`]).
#[inline(always)]
pub unsafe fn closest<T: BoxTest, const ZERO: bool, P: PrimitiveSet + ?Sized, const STACK: usize, const W: usize>(
    nodes: &[WideNode<W>],
    packets: &[Packet],
    prims: &P,
    r: &PreparedRay,
    rb: &T::Ray,
    best: &mut Option<Hit>,
) {
    *best = None;
    let mut t_max = r.ray.t_max;
    // Boxes are searched a little past the closest hit (ties); kept up to date with it.
    let mut limit = search_limit(t_max);
    let mut stack = [const { MaybeUninit::<u64>::uninit() }; STACK];
    let mut sp = 0usize;
    let mut dist = [0.0f32; W];
    let mut cur = 0u32;
    // Made once a ray, not at every leaf call.
    #[cfg(target_arch = "x86_64")]
    let leaves = LeafQuery { packets, prims, r };
    loop {
        if cur & LEAF == 0 {
            let node = node_at(nodes, cur);
            let mask = T::test::<ZERO, W>(node, rb, limit, &mut dist);
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
                // SAFETY: entries `base..sp` were written just above.
                let pushed = std::slice::from_raw_parts_mut(stack.as_mut_ptr().add(base).cast::<u64>(), sp - base);
                sort_farthest_first(pushed);
                sp -= 1;
                cur = stack.get_unchecked(sp).assume_init() as u32;
                continue;
            }
        } else {
            #[cfg(target_arch = "x86_64")]
            if W == 8 {
                t_max = closest_leaves_avx2(&leaves, cur, t_max, stack.as_ptr().cast(), &mut sp, best);
            } else {
                closest_leaf(packets, prims, r, cur, &mut t_max, best);
            }
            #[cfg(not(target_arch = "x86_64"))]
            closest_leaf(packets, prims, r, cur, &mut t_max, best);
            limit = search_limit(t_max);
        }
        loop {
            if sp == 0 {
                return;
            }
            sp -= 1;
            let e = stack.get_unchecked(sp).assume_init();
            // Keep an entry whose box starts at (or, by rounding, just beyond) the closest
            // hit: it may hold a tie.
            if entry_distance(e) <= limit {
                cur = e as u32;
                break;
            }
        }
    }
}

/// The packets of leaf `reference` tested for a hit closer than `t_max`, into `best`.
#[inline(always)]
unsafe fn closest_leaf<P: PrimitiveSet + ?Sized>(
    packets: &[Packet],
    prims: &P,
    r: &PreparedRay,
    reference: u32,
    t_max: &mut f32,
    best: &mut Option<Hit>,
) {
    for p in leaf_packets(reference) {
        packets.get_unchecked(p).closest(prims, r, t_max, best);
    }
}

/// What a leaf test needs besides the leaf: one reference, so that the out-of-line
/// leaf test takes its arguments in registers.
#[cfg(target_arch = "x86_64")]
struct LeafQuery<'a, P: ?Sized> {
    packets: &'a [Packet],
    prims: &'a P,
    r: &'a PreparedRay,
}

/// [`closest_leaf`] out of line, for the AVX2 trees (nodes of eight), followed by the
/// leaves the traversal would pop next: while the top of the stack (`stack[..sp]`, an
/// entry within the search limit; those beyond it are dropped, as [`closest`] drops
/// them) is a leaf, it is popped and tested here, without a return to the node loop and
/// a call back (a third of the leaves a primary or diffuse ray reaches come straight
/// after another). The node loop then pops the entry left on top, as it would have.
/// Against testing one leaf a call (AMD EPYC, Zen 3, CPU time, paired): the 100k
/// dragon's diffuse rays 1.056 [0.997–1.088], its primary rays 0.997 [0.968–1.154]
/// (12 rounds each); 19 and 28 instructions a ray fewer (callgrind).
///
/// Why out of line: the box test keeps twelve vectors of ray constants, a limit and
/// `t_min`; with the packet test inlined in the same loop, LLVM kept most of them on the
/// stack and reloaded them at every node visit (sixteen vector registers do not hold
/// both). Behind a call, the node loop keeps ten of the twelve in registers and reloads
/// them after a leaf, which a primary ray reaches a third as often as a node (measured
/// on an AMD EPYC, Zen 3, against the inlined form: 1.05× on the 100k dragon's primary
/// rays, the 1.6M dragon's the same; the 100k dragon's diffuse rays, which reach three
/// leaves a ray, 0.965: there the calls cost a little more than the reloads save; the
/// renderer the same within noise). Any-hit queries measured the same either way and
/// stay inline; with AVX-512's thirty-two registers the inlined form keeps them all,
/// and stays.
///
/// # Safety
/// [`closest`]'s conditions; `stack[..*sp]` are entries the traversal pushed.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
#[inline(never)]
unsafe fn closest_leaves_avx2<P: PrimitiveSet + ?Sized>(
    q: &LeafQuery<P>,
    mut reference: u32,
    mut t_max: f32,
    stack: *const u64,
    sp: &mut usize,
    best: &mut Option<Hit>,
) -> f32 {
    loop {
        closest_leaf(q.packets, q.prims, q.r, reference, &mut t_max, best);
        let limit = search_limit(t_max);
        loop {
            if *sp == 0 {
                return t_max;
            }
            let e = *stack.add(*sp - 1);
            if entry_distance(e) > limit {
                *sp -= 1;
                continue;
            }
            if e as u32 & LEAF == 0 {
                return t_max;
            }
            *sp -= 1;
            reference = e as u32;
            break;
        }
    }
}

/// Whether anything in the tree blocks `r` ([`closest`]'s conditions).
#[inline(always)]
pub unsafe fn occluded<T: BoxTest, const ZERO: bool, P: PrimitiveSet + ?Sized, const STACK: usize, const W: usize>(
    nodes: &[WideNode<W>],
    packets: &[Packet],
    prims: &P,
    r: &PreparedRay,
    rb: &T::Ray,
) -> bool {
    let t_max = r.ray.t_max;
    let mut stack = [const { MaybeUninit::<u32>::uninit() }; STACK];
    let mut sp = 0usize;
    let mut dist = [0.0f32; W];
    let mut cur = 0u32;
    loop {
        if cur & LEAF == 0 {
            let node = node_at(nodes, cur);
            let mut mask = T::test::<ZERO, W>(node, rb, search_limit(t_max), &mut dist);
            if mask != 0 {
                // The highest slot next, the others popped in descending order after it
                // (one consistent order; measured 2% faster than lowest first).
                let last = 31 - mask.leading_zeros();
                cur = *node.child.get_unchecked(last as usize);
                mask ^= 1 << last;
                for i in super::packet::Lanes(mask) {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stack_entries_are_sorted_farthest_first_for_every_order() {
        // Every arrangement of up to six entries, ties included (values 0..n with repeats).
        for n in 1..=6usize {
            for code in 0..n.pow(n as u32) {
                let mut e: Vec<u64> = (0..n).map(|k| (code / n.pow(k as u32) % n) as u64).collect();
                let mut expected = e.clone();
                expected.sort_unstable_by(|a, b| b.cmp(a));
                sort_farthest_first(&mut e);
                assert_eq!(e, expected);
            }
        }
    }
}
