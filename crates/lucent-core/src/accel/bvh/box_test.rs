//! The box test of a BVH node visit: one ray against a node's child boxes (sixteen, or
//! eight in the AVX2 trees), eight at a time with AVX-512 VL (compared into mask
//! registers) or AVX when the CPU has them (detected at run time), else four at a time
//! with SSE (the tests are written once over the lanes of [`super::lanes`]), giving which
//! boxes it enters and at what distance.
//!
//! Every box test is conservative: it never rejects a box the exact slab test enters.
//! * The SSE and scalar tests are the slab test of [`crate::aabb::Aabb::intersect`],
//!   `(plane - origin) · (1/d)`, with the far distance widened by `1 + 2γ(3)` (folded
//!   into a per-ray far reciprocal: the same roundings in another order).
//! * With AVX2 and FMA (and AVX-512), each plane costs one fused multiply–add,
//!   `plane · (1/d) − o/d`, which is shorter on the path from loading a node to choosing
//!   the next one. Its error is not relative to the result (`o/d` may dwarf the
//!   difference), so the ray carries two offsets, `o/d ± c` with `c = 2⁻¹⁸·|o/d|`, and a
//!   far reciprocal widened by `1 + 2⁻¹⁹`: [`FmaOffsets`] states the bound (the same
//!   for every lane width). Rays whose constants may overflow (single rays: `|o/d|` or
//!   `|1/d|` at least half the largest float; packets: any constant infinite), a
//!   negative `t_min` or an axis they do not move along take the plain AVX test.
//!
//! Axes along which the ray does not move are decided by where the origin lies (a
//! separate instantiation, since such rays are rare).

use std::marker::PhantomData;

use super::lanes::{FusedLanes, Lanes};
use super::wide::WideNode;
#[cfg(test)]
use super::wide::MAX_WIDTH as WIDTH;
use crate::math::{gamma, Vec3A};
use crate::ray::PreparedRay;

pub(super) const FAR_WIDENING: f32 = 1.0 + 2.0 * gamma(3);

/// The bytes of one row of a node's bounds.
const fn row_bytes<const W: usize>() -> usize {
    std::mem::size_of::<[f32; W]>()
}

/// Row `offset` (bytes) of a node's bounds, from lane `lane`.
#[inline(always)]
unsafe fn row_ptr<const W: usize>(node: &WideNode<W>, offset: usize, lane: usize) -> *const f32 {
    debug_assert!(offset < 6 * row_bytes::<W>() && lane < W);
    (node as *const WideNode<W>)
        .cast::<u8>()
        .add(offset)
        .cast::<f32>()
        .add(lane)
}

/// What the box test needs of a ray, per axis.
#[derive(Clone, Copy)]
pub struct RayBoxes {
    // Kept as vectors, not arrays: the per-axis broadcasts are then made in registers.
    // Through arrays, each went to memory and back, and one 8-byte load spanned two of
    // the stores that made it, which cannot be forwarded (a stall on every query).
    origin: Vec3A,
    inv_dir: Vec3A,
    /// `inv_dir` times the far widening (left alone where that overflows).
    inv_far: Vec3A,
    /// The rows of a [`WideNode`]'s `bounds` holding the planes the ray enters and leaves
    /// by (made byte offsets for the node width by [`PlaneLanes`]).
    near_row: [usize; 3],
    far_row: [usize; 3],
    zero: [bool; 3],
    t_min: f32,
}

impl RayBoxes {
    #[inline(always)]
    pub fn new(r: &PreparedRay) -> RayBoxes {
        // Worked on as whole vectors, never read one component at a time from the
        // ray: the caller has just stored it with 16-byte stores, and an 8-byte load of
        // two of its components waited for that store (7 % of a shadow query).
        let widened = r.inv_dir * FAR_WIDENING;
        let inv_far = Vec3A::select(widened.is_finite_mask(), widened, r.inv_dir);
        let positive = r.inv_dir.cmpge(Vec3A::ZERO).bitmask();
        RayBoxes {
            origin: r.ray.origin,
            inv_dir: r.inv_dir,
            inv_far,
            near_row: [0, 1, 2].map(|a| if positive >> a & 1 != 0 { a } else { a + 3 }),
            far_row: [0, 1, 2].map(|a| if positive >> a & 1 != 0 { a + 3 } else { a }),
            zero: [r.zero_axes.test(0), r.zero_axes.test(1), r.zero_axes.test(2)],
            t_min: r.ray.t_min,
        }
    }
}

/// The per-ray constants of the fused box test: a plane `b` gives the near distance
/// `fma(b, inv, −near)` and the far distance `fma(b, inv_far, −far)`.
///
/// Why this is conservative (u = 2⁻²⁴, `X = b/d`, `P = o/d`, exact `t = X − P`): the
/// computed `1/d`, `o·(1/d)`, the offset and the fused result each round once. `near`
/// is `P + c` with `c ≥ 63u|P|`, which outweighs the ≤ 3u|P| rounding of `P`, so the
/// near distance is at most `t(1 + 2.01u)` (or negative). For the far distance: when
/// `X ≥ 0` the widening adds ≥ 30u·X; when `X < 0` then `|X| ≤ |P|` (if `t ≥ 0`) and the
/// offset's surplus covers the widening's loss; either way the far distance is at least
/// `t(1 + 23u)`. Hence whenever the exact test enters a box at `t ≥ t_min ≥ 0`, the
/// computed near ≤ computed far, and near ≤ `search_limit(t_max)`. The test at the end
/// of this file checks every box test against f64 arithmetic on grazing rays.
#[derive(Clone, Copy)]
pub struct FmaOffsets {
    pub(super) near: Vec3A,
    pub(super) far: Vec3A,
    pub(super) inv_far: Vec3A,
}

impl FmaOffsets {
    pub(super) const OFFSET: f32 = 1.0 / (1u32 << 18) as f32;
    pub(super) const WIDENING: f32 = 1.0 + 1.0 / (1u32 << 19) as f32;
    /// The largest `|o/d|` and `|1/d|` the constants are made for.
    const LIMIT: f32 = f32::MAX / 2.0;

    /// The constants, or `None` for rays that must take the plain test — every ray that
    /// is not a line among them ([`crate::ray::Ray::is_line`]; the callers' plain paths
    /// answer those with nothing).
    #[inline(always)]
    pub fn new(r: &PreparedRay) -> Option<FmaOffsets> {
        if r.zero_axes.any() || !(r.ray.t_min >= 0.0) {
            return None;
        }
        // As whole vectors (see `RayBoxes::new`): the same operations lane by lane.
        let inv = r.inv_dir;
        let p = r.ray.origin * inv;
        let p_abs = p.abs();
        let c = p_abs * Self::OFFSET;
        let (near, far, inv_far) = (p + c, p - c, inv * Self::WIDENING);
        // Below half the largest float, `o/d` and `1/d` stay finite with their offset and
        // widening (each grows by less than 2⁻¹⁷); a NaN fails the comparison. Two
        // comparisons instead of four finiteness tests, and a third that `1/d` is not
        // zero. So no ray that is not a line passes: an infinite direction component
        // makes `1/d = 0` (and NaN distances, `inf · 0`), a NaN one `1/d = ±f32::MAX`
        // (`PreparedRay::new`), an infinite or NaN origin component `o/d` infinite or NaN.
        let inv_abs = inv.abs();
        let small = p_abs.cmplt(Vec3A::splat(Self::LIMIT))
            & inv_abs.cmplt(Vec3A::splat(Self::LIMIT))
            & inv_abs.cmpgt(Vec3A::ZERO);
        small.all().then_some(FmaOffsets { near, far, inv_far })
    }
}

/// Which child boxes a ray enters before `t_max`, and where: one group of `L::N` boxes at
/// a time.
pub trait BoxTest {
    /// The ray in the form the test wants it (lanes of broadcast constants), made once
    /// per ray by the type's own `prepare`.
    type Ray;
    type Lanes: Lanes;

    /// The boxes in slots `first .. first + N`: their entry distances, and which of them
    /// the ray enters. `ZERO`: the ray has direction components that are zero. `node`
    /// must lie in the node array the ray was prepared for.
    unsafe fn group<const ZERO: bool, const W: usize>(
        node: &WideNode<W>,
        r: &Self::Ray,
        t_max: f32,
        first: usize,
    ) -> (Self::Lanes, <Self::Lanes as Lanes>::Mask);

    /// All of the node's boxes: the entry distances are stored in `dist`, the entered
    /// boxes are the returned mask's bits.
    #[inline(always)]
    unsafe fn test<const ZERO: bool, const W: usize>(
        node: &WideNode<W>,
        r: &Self::Ray,
        t_max: f32,
        dist: &mut [f32; W],
    ) -> u32 {
        debug_assert!(W.is_multiple_of(Self::Lanes::N));
        let mut mask = 0;
        for first in (0..W).step_by(Self::Lanes::N) {
            let (near, enters) = Self::group::<ZERO, W>(node, r, t_max, first);
            near.store(dist.as_mut_ptr().add(first));
            mask |= Self::Lanes::bits(enters) << first;
        }
        mask
    }
}

/// The lanes of row `offset` (bytes, see [`RayBoxes`]) of a node, from slot `first`.
#[inline(always)]
unsafe fn row<L: Lanes, const W: usize>(node: &WideNode<W>, offset: usize, first: usize) -> L {
    L::load(row_ptr(node, offset, first))
}

/// A ray's box-test constants as lanes of broadcasts: per axis, the multiplier and the
/// offset that turn a near plane and a far plane into distances.
#[derive(Clone, Copy)]
pub struct PlaneLanes<L> {
    near_mul: [L; 3],
    near_off: [L; 3],
    far_mul: [L; 3],
    far_off: [L; 3],
    t_min: L,
    /// The rows of the planes the ray enters and leaves by (see [`RayBoxes`]) as
    /// addresses in the first node of the tree's array: a node's row is that address
    /// plus the node's byte offset. The usual node address plus row offset puts an
    /// addition between loading a child's reference and loading its planes, on the
    /// path every node visit waits on (measured: 0.6–2 % on the dragons' rays).
    near_row: [*const u8; 3],
    far_row: [*const u8; 3],
    /// The start of the tree's node array, which every node tested lies in.
    nodes: *const u8,
    /// The ray's zero axes (see [`RayBoxes`]).
    zero: [bool; 3],
}

impl<L: Lanes> PlaneLanes<L> {
    #[inline(always)]
    unsafe fn new<const W: usize>(
        r: &RayBoxes,
        [near_mul, near_off, far_mul, far_off]: [Vec3A; 4],
        nodes: &[WideNode<W>],
    ) -> PlaneLanes<L> {
        let splat = |v: Vec3A| [L::splat(v.x), L::splat(v.y), L::splat(v.z)];
        let nodes = nodes.as_ptr().cast::<u8>();
        PlaneLanes {
            near_mul: splat(near_mul),
            near_off: splat(near_off),
            far_mul: splat(far_mul),
            far_off: splat(far_off),
            t_min: L::splat(r.t_min),
            near_row: r.near_row.map(|row| nodes.wrapping_add(row * row_bytes::<W>())),
            far_row: r.far_row.map(|row| nodes.wrapping_add(row * row_bytes::<W>())),
            nodes,
            zero: r.zero,
        }
    }
}

/// The slab test over lanes `L`, with planes made into distances by `D`: the entry
/// distance is the largest near-plane distance (and `t_min`), the exit distance the
/// smallest far-plane distance (and the search limit); axes the ray does not move along
/// are decided by where the origin lies.
pub struct Planes<L, D>(PhantomData<(L, D)>);

/// How a plane coordinate becomes a distance along the ray, given the axis's multiplier
/// and offset ([`PlaneLanes`]).
pub trait Distance<L: Lanes> {
    unsafe fn distance(plane: L, mul: L, off: L) -> L;
}

/// `(plane − origin) · (1/d)`: the far reciprocal widened by `1 + 2γ(3)`.
pub struct Subtract;

impl<L: Lanes> Distance<L> for Subtract {
    #[inline(always)]
    unsafe fn distance(plane: L, mul: L, off: L) -> L {
        plane.sub(off).mul(mul)
    }
}

/// `plane · (1/d) − o/d` in one fused multiply–subtract, with the offsets and widening of
/// [`FmaOffsets`]; only for rays that have them (no zero axes).
pub struct MulSub;

impl<L: FusedLanes> Distance<L> for MulSub {
    #[inline(always)]
    unsafe fn distance(plane: L, mul: L, off: L) -> L {
        plane.mul_sub(mul, off)
    }
}

/// The plain slab test.
pub type Slab<L> = Planes<L, Subtract>;
/// The fused slab test.
pub type Fused<L> = Planes<L, MulSub>;

impl<L: Lanes> Slab<L> {
    /// The prepared ray tests nodes of `nodes` only.
    #[inline(always)]
    pub unsafe fn prepare<const W: usize>(r: &RayBoxes, nodes: &[WideNode<W>]) -> PlaneLanes<L> {
        PlaneLanes::new(r, [r.inv_dir, r.origin, r.inv_far, r.origin], nodes)
    }
}

impl<L: FusedLanes> Fused<L> {
    /// `offsets` must come from the same ray; the prepared ray tests nodes of `nodes` only.
    #[inline(always)]
    pub unsafe fn prepare<const W: usize>(r: &RayBoxes, offsets: &FmaOffsets, nodes: &[WideNode<W>]) -> PlaneLanes<L> {
        PlaneLanes::new(r, [r.inv_dir, offsets.near, offsets.inv_far, offsets.far], nodes)
    }
}

impl<L: Lanes, D: Distance<L>> BoxTest for Planes<L, D> {
    type Ray = PlaneLanes<L>;
    type Lanes = L;
    #[inline(always)]
    unsafe fn group<const ZERO: bool, const W: usize>(
        node: &WideNode<W>,
        r: &PlaneLanes<L>,
        t_max: f32,
        first: usize,
    ) -> (L, L::Mask) {
        // The node's byte offset in the array, and the lanes' within a row.
        let at = (node as *const WideNode<W> as usize).wrapping_sub(r.nodes as usize) + first * 4;
        let mut near = r.t_min;
        let mut far = L::splat(t_max);
        let mut inside = L::all();
        for a in 0..3 {
            if ZERO && r.zero[a] {
                // The plain test's offset is the origin.
                let o = r.near_off[a];
                let lo = row::<L, W>(node, a * row_bytes::<W>(), first);
                let hi = row::<L, W>(node, (a + 3) * row_bytes::<W>(), first);
                inside = L::and(inside, L::and(lo.le(o), o.le(hi)));
            } else {
                let n = D::distance(
                    L::load(r.near_row[a].wrapping_add(at).cast()),
                    r.near_mul[a],
                    r.near_off[a],
                );
                let f = D::distance(
                    L::load(r.far_row[a].wrapping_add(at).cast()),
                    r.far_mul[a],
                    r.far_off[a],
                );
                near = n.max(near);
                far = f.min(far);
            }
        }
        (near, L::and(near.le(far), inside))
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::accel::search_limit;
    use crate::accel::test_sets::Rng;
    use crate::math::Vec3A;
    use crate::ray::Ray;

    /// The slab test in f64 with a true division: within 1e-16 of exact, far inside the
    /// slack every f32 test is allowed. Returns the entry distance when entered.
    pub(in crate::accel::bvh) fn exact_entry(lo: [f32; 3], hi: [f32; 3], r: &Ray, t_max: f32) -> Option<f64> {
        let (mut near, mut far) = (r.t_min as f64, t_max as f64);
        for a in 0..3 {
            let (o, d) = (r.origin[a] as f64, r.dir[a] as f64);
            if d == 0.0 {
                if o < lo[a] as f64 || o > hi[a] as f64 {
                    return None;
                }
                continue;
            }
            let (t0, t1) = ((lo[a] as f64 - o) / d, (hi[a] as f64 - o) / d);
            near = near.max(t0.min(t1));
            far = far.min(t0.max(t1));
        }
        (near <= far).then_some(near)
    }

    /// A node full of boxes, and rays from near and far that graze their corners, edges and faces.
    fn cases(rng: &mut Rng) -> impl Iterator<Item = (WideNode, Ray)> + '_ {
        (0..20_000).map(move |_| {
            let mut node = WideNode::EMPTY;
            let scale = [1e-3, 1.0, 1e3][(rng.next() * 3.0) as usize % 3];
            let mut boxes = Vec::new();
            for slot in 0..WIDTH {
                let c = rng.vec(scale);
                let e = Vec3A::new(rng.next(), rng.next(), rng.next()) * scale * 0.3;
                let (lo, hi) = (c - e, c + e);
                for a in 0..3 {
                    node.bounds[a][slot] = lo[a];
                    node.bounds[a + 3][slot] = hi[a];
                }
                boxes.push((lo, hi));
            }
            // Aim at a corner, an edge or a face point of one box, from near or far away.
            let (lo, hi) = boxes[(rng.next() * WIDTH as f32) as usize % WIDTH];
            let pick = |rng: &mut Rng, a: usize| match (rng.next() * 3.0) as u32 {
                0 => lo[a],
                1 => hi[a],
                _ => lo[a] + (hi[a] - lo[a]) * rng.next(),
            };
            let target = Vec3A::new(pick(rng, 0), pick(rng, 1), pick(rng, 2));
            let distance = scale * [0.01, 1.0, 100.0, 1e4][(rng.next() * 4.0) as usize % 4];
            let origin = target + rng.vec(1.0).normalize_or(Vec3A::X) * distance + rng.vec(scale * 1e3);
            let mut dir = (target - origin).normalize_or(Vec3A::X);
            if rng.next() < 0.05 {
                dir[(rng.next() * 3.0) as usize % 3] = 0.0; // an axis-parallel ray
            }
            let t_min = [0.0, 1e-4][(rng.next() * 2.0) as usize % 2];
            (node, Ray::segment(origin, dir, t_min, f32::INFINITY))
        })
    }

    fn check<T: BoxTest>(name: &str, node: &WideNode, r: &Ray, rb: &T::Ray, zero: bool) {
        for t_max in [f32::INFINITY, 1e3] {
            let mut dist = [0.0; WIDTH];
            // SAFETY: callers only pass tests this CPU can run.
            let mask = unsafe {
                if zero {
                    T::test::<true, WIDTH>(node, rb, search_limit(t_max), &mut dist)
                } else {
                    T::test::<false, WIDTH>(node, rb, search_limit(t_max), &mut dist)
                }
            };
            for (slot, &entry) in dist.iter().enumerate() {
                let lo = [0, 1, 2].map(|a| node.bounds[a][slot]);
                let hi = [0, 1, 2].map(|a| node.bounds[a + 3][slot]);
                if let Some(near) = exact_entry(lo, hi, r, t_max) {
                    assert!(mask & 1 << slot != 0, "{name} rejects box {lo:?}..{hi:?} for {r:?}");
                    // The entry distance must not exceed the true one by more than the
                    // slack `search_limit` leaves when popping.
                    assert!(
                        entry as f64 <= near + near.abs() * 1e-5,
                        "{name}: entry {entry} beyond {near} for {r:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn box_tests_never_reject_a_box_the_exact_slab_test_enters() {
        let mut rng = Rng(41);
        let mut fused = 0;
        for (node, r) in cases(&mut rng) {
            let pr = PreparedRay::new(r);
            let rb = RayBoxes::new(&pr);
            let zero = pr.zero_axes.any();
            let one = std::slice::from_ref(&node);
            // SAFETY: plain f32 runs anywhere; SSE2 is part of x86-64; AVX2 and FMA are
            // checked first.
            unsafe {
                check::<Slab<f32>>("scalar", &node, &r, &Slab::prepare(&rb, one), zero);
                #[cfg(target_arch = "x86_64")]
                {
                    use super::super::lanes::{Avx, Sse};
                    check::<Slab<Sse>>("sse", &node, &r, &Slab::prepare(&rb, one), zero);
                    if super::super::Isa::detect().has_avx2() {
                        check::<Slab<Avx>>("avx", &node, &r, &Slab::prepare(&rb, one), zero);
                        if let Some(offsets) = FmaOffsets::new(&pr) {
                            check::<Fused<Avx>>("avx+fma", &node, &r, &Fused::prepare(&rb, &offsets, one), false);
                            if super::super::Isa::detect() == super::super::Isa::Avx512 {
                                // The same operations, compared into a mask register:
                                // the same bound.
                                check::<Fused<super::super::lanes::Avx512Vl8>>(
                                    "avx512vl8+fma",
                                    &node,
                                    &r,
                                    &Fused::prepare(&rb, &offsets, one),
                                    false,
                                );
                            }
                            fused += 1;
                        }
                    }
                }
            }
        }
        if super::super::Isa::detect().has_avx2() {
            assert!(fused > 15_000, "{fused}");
        } else {
            eprintln!("note: no AVX2 and FMA here, the fused box test was not checked");
        }
    }
}
