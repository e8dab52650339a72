//! One triangle against every ray of a packet, one lane per ray: how a leaf is tested
//! when many rays of a coherent packet reach it together (camera rays of a tile, shadow
//! rays toward one light).
//!
//! It is the watertight test of [`crate::shape::triangle::intersect`] with the same
//! operations in the same order (no fused multiply–add), as the four-triangle test of
//! [`super::packet`] is, so every lane's `t`, `v`, `w` and `1/det` are the bits the
//! scalar test computes for its ray. It needs every ray of the packet to share the axis
//! permutation `kx, ky, kz` (the dominant axis of the direction): then a triangle's
//! corners are the same three broadcasts for all lanes. Packets that do not share it
//! test their leaves ray by ray. Lanes whose edge functions round to zero are returned
//! for the scalar test and its f64 fallback, exactly as in the four-triangle test.

use super::packet::Packet;
use super::ray_lanes::RayLanes;
#[cfg(doc)]
use crate::ray::PreparedRay;

/// What the triangle test needs of a packet's rays: origins along `kx, ky, kz` and the
/// shear constants, one lane per ray, each the bits [`PreparedRay::new`] computes.
#[derive(Clone, Copy)]
pub struct ShearedRays<L> {
    /// The shared axis permutation `[kx, ky, kz]`.
    pub k: [usize; 3],
    pub origin_k: [L; 3],
    /// `[sx, sy, sz]`.
    pub shear: [L; 3],
    pub t_min: L,
}

/// The answer for one triangle, lane by lane.
pub struct TriangleLanes<L> {
    /// Rays the test accepted (within `(t_min, t_max]`, inside all three edges).
    pub accept: u32,
    /// Rays the scalar test must decide (an edge function rounded to zero).
    pub scalar: u32,
    pub t: L,
    /// Unnormalised barycentrics: `b1 = v · inv_det`, `b2 = w · inv_det`.
    pub v: L,
    pub w: L,
    pub inv_det: L,
}

/// Tests the triangle in lane `lane` of `packet` (a triangle, not another primitive)
/// against the rays `active` of `rays`, each against its own `t_max`. Only the returned
/// masks are meaningful for rays outside `active`.
#[inline(always)]
pub unsafe fn test<L: RayLanes>(
    packet: &Packet,
    lane: usize,
    rays: &ShearedRays<L>,
    t_max: L,
    active: u32,
) -> TriangleLanes<L> {
    let (ax, ay, az) = project(packet, 0, lane, rays);
    let (bx, by, bz) = project(packet, 1, lane, rays);
    let (cx, cy, cz) = project(packet, 2, lane, rays);
    let u = cx.mul(by).sub(cy.mul(bx));
    let v = ax.mul(cy).sub(ay.mul(cx));
    let w = bx.mul(ay).sub(by.mul(ax));
    let zero = L::splat(0.0);
    let scalar = (u.eq(zero) | v.eq(zero) | w.eq(zero)) & active;
    // With no zero among them, the edge functions agree in sign exactly when the sign
    // bits of `u ^ v` and `u ^ w` are clear.
    let inside = !u.xor(v).or(u.xor(w)).sign_bits() & !scalar & active;
    if inside == 0 {
        // Most rays that reach a leaf miss most of its triangles: no division for them.
        return TriangleLanes {
            accept: 0,
            scalar,
            t: zero,
            v,
            w,
            inv_det: zero,
        };
    }
    let det = u.add(v).add(w);
    let sz = rays.shear[2];
    let t_scaled = u.mul(sz.mul(az)).add(v.mul(sz.mul(bz))).add(w.mul(sz.mul(cz)));
    let inv_det = L::splat(1.0).div(det);
    let t = t_scaled.mul(inv_det);
    let accept = !det.eq(zero) & t.gt(rays.t_min) & t.le(t_max) & inside;
    TriangleLanes {
        accept,
        scalar,
        t,
        v,
        w,
        inv_det,
    }
}

/// Corner `c` translated to each ray's origin and sheared (the scalar test's operations).
#[inline(always)]
unsafe fn project<L: RayLanes>(packet: &Packet, c: usize, lane: usize, rays: &ShearedRays<L>) -> (L, L, L) {
    let [kx, ky, kz] = rays.k;
    let [ox, oy, oz] = rays.origin_k;
    let [sx, sy, _] = rays.shear;
    let dx = L::splat(packet.corner(c, kx, lane)).sub(ox);
    let dy = L::splat(packet.corner(c, ky, lane)).sub(oy);
    let dz = L::splat(packet.corner(c, kz, lane)).sub(oz);
    (dx.sub(sx.mul(dz)), dy.sub(sy.mul(dz)), dz)
}
