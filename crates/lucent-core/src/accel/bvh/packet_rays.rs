//! A packet's rays side by side in SIMD lanes, for [`super::ray_packet`]: the constants of
//! each ray's box test and triangle test, made in lanes with the operations
//! [`PreparedRay::new`] and [`FmaOffsets::new`] apply ray by ray (so the same bits), the
//! packet's rays as intervals when they all move the same way ([`Frustum`]), and the
//! test of one child box against every ray of the packet.

use super::box_test::FmaOffsets;
use super::packet_frustum::Frustum;
use super::ray_lanes::RayLanes;
use super::ray_triangle::ShearedRays;
use super::wide::WideNode;
#[cfg(doc)]
use crate::ray::PreparedRay;
use crate::ray::Ray;
use std::mem::offset_of;

/// The rays' box-test constants, one lane each: the fused test of [`FmaOffsets`] (whose
/// bound holds lane by lane), a plane `b` giving the near distance `b · inv − near_off`
/// and the far distance `b · inv_far − far_off`.
pub(super) struct BoxLanes<L> {
    pub(super) inv: [L; 3],
    pub(super) near_off: [L; 3],
    pub(super) inv_far: [L; 3],
    pub(super) far_off: [L; 3],
    pub(super) t_min: L,
    /// Per axis, the rows of a node's bounds holding the planes every ray of the packet
    /// enters and leaves by, when they all move the same way along every axis.
    pub(super) rows: Option<[(usize, usize); 3]>,
}

/// A packet's rays as lanes: what the box test and the triangle test need.
pub(super) struct PacketLanes<L> {
    pub(super) boxes: BoxLanes<L>,
    /// For the triangle test, when the rays share their axis permutation.
    pub(super) sheared: Option<ShearedRays<L>>,
    /// The rays as intervals, when they all move the same way along every axis.
    pub(super) frustum: Option<Frustum>,
    /// The rays that can travel in the packet: those with the fused box test's
    /// constants (no axis they do not move along, a finite origin and direction, every
    /// constant finite, `0 ≤ t_min ≤ t_max`). The others are traced alone.
    pub(super) ok: u32,
}

/// Makes the lanes of 1 to `L::N` rays, computing in lanes what [`PreparedRay::new`] and
/// [`FmaOffsets::new`] compute ray by ray (the same operations, so the same bits).
#[inline(always)]
pub(super) unsafe fn packet_lanes<L: RayLanes>(rays: &[Ray]) -> PacketLanes<L> {
    debug_assert!(!rays.is_empty() && rays.len() <= L::N);
    let (zero, inf) = (L::splat(0.0), L::splat(f32::INFINITY));
    let t_min = L::gather_field(rays, offset_of!(Ray, t_min));
    // A NaN far limit would make the packet's largest search limit NaN, and its interval
    // test drop every child for all the packet's rays; rays with an empty interval find
    // nothing anyway. Both are traced alone.
    let t_max = L::gather_field(rays, offset_of!(Ray, t_max));
    let mut ok = L::ALL >> (L::N - rays.len()) & zero.le(t_min) & t_min.le(t_max);
    let (mut o, mut d, mut inv) = ([zero; 3], [zero; 3], [zero; 3]);
    let (mut near_off, mut far_off, mut inv_far) = ([zero; 3], [zero; 3], [zero; 3]);
    let mut negative = [0u32; 3];
    for a in 0..3 {
        // (A vector's components lie 4 bytes apart, x first.)
        o[a] = L::gather_field(rays, offset_of!(Ray, origin) + 4 * a);
        d[a] = L::gather_field(rays, offset_of!(Ray, dir) + 4 * a);
        inv[a] = L::splat(1.0).div(d[a]);
        let p = o[a].mul(inv[a]);
        let c = p.abs().mul(L::splat(FmaOffsets::OFFSET));
        near_off[a] = p.add(c);
        far_off[a] = p.sub(c);
        inv_far[a] = inv[a].mul(L::splat(FmaOffsets::WIDENING));
        ok &= !d[a].eq(zero);
        for x in [o[a], d[a], inv[a], near_off[a], far_off[a], inv_far[a]] {
            ok &= inf.gt(x.abs());
        }
        negative[a] = zero.gt(d[a]);
    }
    let same = |m: u32| m & ok == 0 || m & ok == ok;
    let rows = negative
        .iter()
        .all(|&m| same(m))
        .then(|| [0, 1, 2].map(|a| if negative[a] & ok == 0 { (a, a + 3) } else { (a + 3, a) }));
    // The dominant axis, as `max_abs_axis` picks it (ties to the later axis).
    let [ax, ay, az] = [d[0].abs(), d[1].abs(), d[2].abs()];
    let x_wins = ax.gt(ay) & ax.gt(az);
    let y_wins = !ax.gt(ay) & ay.gt(az);
    let kz = [x_wins, y_wins, !(x_wins | y_wins)].iter().position(|&m| m & ok == ok);
    let sheared = match kz {
        Some(kz) if ok != 0 && same(negative[kz]) => {
            let (mut kx, mut ky) = ((kz + 1) % 3, (kz + 2) % 3);
            // Keep the winding of the projected triangle: swap when looking down −kz.
            if negative[kz] & ok != 0 {
                std::mem::swap(&mut kx, &mut ky);
            }
            let sz = inv[kz];
            Some(ShearedRays {
                k: [kx, ky, kz],
                origin_k: [o[kx], o[ky], o[kz]],
                shear: [d[kx].mul(sz), d[ky].mul(sz), sz],
                t_min,
            })
        }
        _ => None,
    };
    let frustum = rows.filter(|_| ok != 0).map(|rows| Frustum::new(&o, &inv, rows, ok));
    PacketLanes {
        frustum,
        boxes: BoxLanes {
            inv,
            near_off,
            inv_far,
            far_off,
            t_min,
            rows,
        },
        sheared,
        ok,
    }
}

impl<L: RayLanes> BoxLanes<L> {
    /// Which rays enter child `c` of `node`, given each ray's search limit, and their
    /// entry distances. `ROWS`: `self.rows` is known (each axis costs two fused
    /// operations instead of four and a `min`/`max`).
    #[inline(always)]
    pub(super) unsafe fn enters<const ROWS: bool, const W: usize>(
        &self,
        node: &WideNode<W>,
        c: usize,
        limit: L,
    ) -> (u32, L) {
        let mut near = self.t_min;
        let mut far = limit;
        for a in 0..3 {
            let (n, f) = if ROWS {
                let (near_row, far_row) = self.rows.unwrap_unchecked()[a];
                (
                    L::splat(node.bounds[near_row][c]).mul_sub(self.inv[a], self.near_off[a]),
                    L::splat(node.bounds[far_row][c]).mul_sub(self.inv_far[a], self.far_off[a]),
                )
            } else {
                let (lo, hi) = (L::splat(node.bounds[a][c]), L::splat(node.bounds[a + 3][c]));
                (
                    lo.mul_sub(self.inv[a], self.near_off[a])
                        .min(hi.mul_sub(self.inv[a], self.near_off[a])),
                    lo.mul_sub(self.inv_far[a], self.far_off[a])
                        .max(hi.mul_sub(self.inv_far[a], self.far_off[a])),
                )
            };
            near = n.max(near);
            far = f.min(far);
        }
        (near.le(far), near)
    }
}
