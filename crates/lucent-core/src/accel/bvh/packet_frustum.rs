//! A packet's rays bounded by intervals, and the node test that culls a node's children
//! for the whole packet at once (interval arithmetic, as in Wald, Boulos and
//! Shirley, "Ray Tracing Deformable Scenes Using Dynamic Bounding Volume Hierarchies",
//! 2007). When every ray of a packet moves the same way along each axis, all their
//! origins lie in `[O_lo, O_hi]` and all their reciprocal directions in `[R_lo, R_hi]`
//! (one sign) per axis; a child box that no ray in those intervals can enter is dropped
//! with eight-wide tests (two for a node of sixteen, one for a node of eight), before
//! [`super::ray_packet`] tests the boxes left ray by ray. Coherent packets (camera rays of
//! a tile) enter one or two of a node's children, so most per-ray box tests are never
//! made.
//!
//! **Conservative.** For ray `i` and a plane `b` along an axis its exact slab distance is
//! `t = (b − oᵢ)/dᵢ`, and its lane holds `rᵢ = fl(1/dᵢ) = (1/dᵢ)(1 + δ)`, `|δ| ≤ u`
//! (u = 2⁻²⁴). For rays moving up the axis, `(b − oᵢ)·rᵢ ≥ (b − O_hi)·rᵢ`, which is at
//! least the smaller of `(b − O_hi)·R_lo` and `(b − O_hi)·R_hi` (a product linear in
//! `r`); for rays moving down, `O_lo` takes `O_hi`'s place; the far bound is the same
//! with the larger product and the other end of the origins. The subtraction and the
//! product each round once, and `t` differs from `(b − oᵢ)·rᵢ` by the factor `1/(1 + δ)`:
//! within 3u of the bound in all. Widening `[R_lo, R_hi]` outward by 2⁻²⁰ of each end
//! (16u; itself rounded once, and the interval keeps its sign) scales every product's
//! magnitude up or down by at least that much in the direction that loosens the bound,
//! so the near bound is at most every ray's near distance and the far bound at least
//! every ray's far distance (for results in the normal range). So whenever the
//! exact slab test has some ray enter a child within `[t_min, t_max]` (`t_min ≥ 0`),
//! the interval test keeps that child: near ≤ far, near ≤ the packet's largest search
//! limit, far ≥ 0. An empty slot (`+∞` minima, `−∞` maxima) gives near `+∞` and far
//! `−∞`, and is dropped.

use super::lanes::{Avx, Lanes};
use super::ray_lanes::RayLanes;
use super::wide::WideNode;
#[cfg(test)]
use super::wide::MAX_WIDTH as WIDTH;

/// The relative widening of the reciprocal directions' interval (see the module docs).
const MARGIN: f32 = 1.0 / (1u32 << 20) as f32;

/// A packet's rays as intervals, per axis, broadcast over eight of a node's children.
#[derive(Clone, Copy)]
pub(super) struct Frustum {
    /// Rows of a node's bounds: the planes the rays enter and leave by.
    rows: [(usize, usize); 3],
    /// The origin coordinate that gives the smallest near distance, and the one that
    /// gives the largest far distance.
    near_origin: [Avx; 3],
    far_origin: [Avx; 3],
    /// The smallest and largest reciprocal direction.
    inv_lo: [Avx; 3],
    inv_hi: [Avx; 3],
}

impl Frustum {
    /// The intervals of the rays in `rays` (not empty), whose origins and reciprocal
    /// directions are `origin` and `inv` lane by lane, and which all enter and leave by
    /// `rows` (as [`super::ray_packet`] chose them).
    #[inline(always)]
    pub(super) unsafe fn new<L: RayLanes>(
        origin: &[L; 3],
        inv: &[L; 3],
        rows: [(usize, usize); 3],
        rays: u32,
    ) -> Frustum {
        let mut f = Frustum {
            rows,
            near_origin: [Avx::splat(0.0); 3],
            far_origin: [Avx::splat(0.0); 3],
            inv_lo: [Avx::splat(0.0); 3],
            inv_hi: [Avx::splat(0.0); 3],
        };
        for a in 0..3 {
            let (o_lo, o_hi) = (origin[a].min_of(rays), origin[a].max_of(rays));
            let up = rows[a].0 == a;
            f.near_origin[a] = Avx::splat(if up { o_hi } else { o_lo });
            f.far_origin[a] = Avx::splat(if up { o_lo } else { o_hi });
            let (r_lo, r_hi) = (inv[a].min_of(rays), inv[a].max_of(rays));
            f.inv_lo[a] = Avx::splat(r_lo - r_lo.abs() * MARGIN);
            f.inv_hi[a] = Avx::splat(r_hi + r_hi.abs() * MARGIN);
        }
        f
    }

    /// The child slots of `node` that some ray of the packet may enter before `limit`
    /// (bit `c` for slot `c`): a superset of the slots the rays' own box tests enter.
    /// Their near bounds go to `bound` (eight slots at a time).
    #[inline(always)]
    pub(super) unsafe fn children<const W: usize>(&self, node: &WideNode<W>, limit: f32, bound: &mut [f32; W]) -> u32 {
        let mut mask = 0;
        for first in (0..W).step_by(Avx::N) {
            let mut near = Avx::splat(f32::NEG_INFINITY);
            let mut far = Avx::splat(f32::INFINITY);
            for a in 0..3 {
                let (near_row, far_row) = self.rows[a];
                let dn = Avx::load(node.bounds[near_row].as_ptr().add(first)).sub(self.near_origin[a]);
                let df = Avx::load(node.bounds[far_row].as_ptr().add(first)).sub(self.far_origin[a]);
                near = near.max(dn.mul(self.inv_lo[a]).min(dn.mul(self.inv_hi[a])));
                far = far.min(df.mul(self.inv_lo[a]).max(df.mul(self.inv_hi[a])));
            }
            let enters = Avx::and(near.le(far), near.le(Avx::splat(limit)));
            mask |= Avx::bits(Avx::and(enters, Avx::splat(0.0).le(far))) << first;
            near.store(bound.as_mut_ptr().add(first));
        }
        mask
    }
}

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use super::super::box_test::tests::exact_entry;
    use super::super::ray_lanes::{Rays16, Rays8};
    use super::*;
    use crate::accel::search_limit;
    use crate::accel::test_sets::Rng;
    use crate::math::Vec3A;
    use crate::ray::Ray;

    /// A node of random boxes and a packet of up to eight rays that all move the
    /// same way along each axis, from origins spread over `spread`, aimed at the corners,
    /// edges and faces of the boxes (grazing them).
    fn case(rng: &mut Rng) -> (WideNode, Vec<Ray>) {
        let mut node = WideNode::EMPTY;
        let scale = [1e-3, 1.0, 1e3][(rng.next() * 3.0) as usize % 3];
        let mut boxes = Vec::new();
        // Some slots stay empty.
        for slot in 0..WIDTH - (rng.next() * 3.0) as usize {
            let c = rng.vec(scale);
            let e = Vec3A::new(rng.next(), rng.next(), rng.next()) * scale * 0.3;
            for a in 0..3 {
                node.bounds[a][slot] = c[a] - e[a];
                node.bounds[a + 3][slot] = c[a] + e[a];
            }
            boxes.push((c - e, c + e));
        }
        let distance = scale * [0.01, 1.0, 100.0, 1e4][(rng.next() * 4.0) as usize % 4];
        let eye = rng.vec(1.0).normalize_or(Vec3A::X) * distance + rng.vec(scale * 3.0);
        let spread = scale * [0.0, 1e-3, 0.1, 1.0][(rng.next() * 4.0) as usize % 4];
        let t_min = [0.0, 1e-4][(rng.next() * 2.0) as usize % 2];
        let mut rays: Vec<Ray> = Vec::new();
        while rays.len() < 8 {
            let (lo, hi) = boxes[(rng.next() * boxes.len() as f32) as usize % boxes.len()];
            let pick = |rng: &mut Rng, a: usize| match (rng.next() * 3.0) as u32 {
                0 => lo[a],
                1 => hi[a],
                _ => lo[a] + (hi[a] - lo[a]) * rng.next(),
            };
            let target = Vec3A::new(pick(rng, 0), pick(rng, 1), pick(rng, 2));
            let origin = eye + rng.vec(spread);
            let dir = (target - origin).normalize_or(Vec3A::X);
            let same_signs = rays
                .first()
                .is_none_or(|r| (0..3).all(|a| (r.dir[a] < 0.0) == (dir[a] < 0.0)));
            if (0..3).all(|a| dir[a] != 0.0) && same_signs {
                rays.push(Ray::segment(origin, dir, t_min, f32::INFINITY));
            } else if rays.is_empty() {
                continue;
            } else {
                break;
            }
        }
        (node, rays)
    }

    /// The slots the interval test keeps for `rays` (at most eight) and their near
    /// bounds, with the rays' fields in lanes of `L`.
    ///
    /// # Safety
    /// The CPU must run `L`'s instructions.
    unsafe fn interval_test<L: RayLanes>(node: &WideNode, rays: &[Ray], limit: f32) -> (u32, [f32; WIDTH]) {
        let lane = |f: &dyn Fn(&Ray) -> f32| {
            let mut v = [0f32; 16];
            for (i, r) in rays.iter().enumerate() {
                v[i] = f(r);
            }
            L::load(v.as_ptr())
        };
        let origin = [0, 1, 2].map(|a| lane(&|r: &Ray| r.origin[a]));
        let inv = [0, 1, 2].map(|a| lane(&|r: &Ray| 1.0 / r.dir[a]));
        let rows = [0, 1, 2].map(|a| if rays[0].dir[a] > 0.0 { (a, a + 3) } else { (a + 3, a) });
        let f = Frustum::new(&origin, &inv, rows, (1 << rays.len()) - 1);
        let mut bound = [0f32; WIDTH];
        let mask = f.children(node, limit, &mut bound);
        (mask, bound)
    }

    #[test]
    fn the_interval_test_keeps_every_box_a_ray_of_the_packet_enters() {
        if !super::super::Isa::detect().has_avx2() {
            eprintln!("note: no AVX2 and FMA here, the interval test was not checked");
            return;
        }
        let avx512 = super::super::Isa::detect() == super::super::Isa::Avx512;
        let mut rng = Rng(97);
        let (mut entered, mut dropped) = (0u32, 0u32);
        for _ in 0..20_000 {
            let (node, rays) = case(&mut rng);
            for t_max in [f32::INFINITY, 1e3 * rng.next()] {
                // SAFETY: AVX2 checked above, AVX-512 where it is used.
                let (mask, near) = unsafe { interval_test::<Rays8>(&node, &rays, search_limit(t_max)) };
                if avx512 {
                    // The sixteen-lane packets' reductions find the same intervals.
                    let wide = unsafe { interval_test::<Rays16>(&node, &rays, search_limit(t_max)) };
                    assert_eq!((mask, near), wide);
                }
                for slot in 0..WIDTH {
                    let lo = [0, 1, 2].map(|a| node.bounds[a][slot]);
                    let hi = [0, 1, 2].map(|a| node.bounds[a + 3][slot]);
                    if lo[0] > hi[0] {
                        assert!(mask >> slot & 1 == 0, "empty slot {slot} kept");
                        continue;
                    }
                    let entries: Vec<f64> = rays.iter().filter_map(|r| exact_entry(lo, hi, r, t_max)).collect();
                    if entries.is_empty() {
                        dropped += (mask >> slot & 1 == 0) as u32;
                        continue;
                    }
                    entered += 1;
                    assert!(mask >> slot & 1 != 0, "slot {slot} dropped, {rays:?}, {node:?}");
                    // Its near bound is no farther than any ray's entry (it is the key
                    // that drops rays which have found a nearer hit).
                    for e in entries {
                        assert!(near[slot] as f64 <= e, "near {} beyond an entry at {e}", near[slot]);
                    }
                }
            }
        }
        // The cases reach both sides: boxes entered, and boxes the test drops.
        assert!(
            entered > 50_000 && dropped > 50_000,
            "{entered} entered, {dropped} dropped"
        );
    }
}
