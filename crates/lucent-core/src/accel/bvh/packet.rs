//! Leaf data of the wide BVH: primitives in packets of four, triangles stored as
//! structure-of-arrays so that one SSE instruction works on four of them.
//!
//! The packet test is the scalar watertight test of [`crate::shape::triangle::intersect`]
//! done four lanes at a time with the same operations in the same order (no fused
//! multiply–add), so it returns the same `t`, `b1`, `b2` to the bit — which is what lets
//! the BVH agree exactly with the brute-force list. Lanes whose edge functions round to
//! zero take the scalar path (and its f64 fallback). Non-triangle primitives (spheres)
//! sit in a packet as a flagged index with NaN corners and are tested by the scalar
//! primitive code; unused lanes hold NaN corners, which no test accepts. Large
//! triangles ([`triangle::checks_t_error`]) are flagged too but keep their corners: the
//! SIMD test computes their `t` as for any triangle, and only a hit it accepts goes to
//! the scalar test, which checks it against the bound on the error of `t` (the SIMD test
//! leaves that bound out: on a fine mesh it would never change an answer). A miss there
//! is a miss of the scalar test too, which accepts only what the SIMD test accepts and
//! passes the bound.

use crate::accel::PrimitiveSet;
use crate::hit::Hit;
use crate::ray::PreparedRay;
use crate::shape::triangle;

pub const LANES: usize = 4;
/// Marks a lane whose primitive is not a triangle (its corners are NaN), or a triangle
/// that [`triangle::checks_t_error`] (its corners are stored).
const OTHER: u32 = 1 << 31;
/// An unused lane (no high bit, so it is skipped by the `OTHER` check for free).
const UNUSED: u32 = OTHER - 1;

/// 160 bytes, aligned to 32 so that a packet spans three cache lines, never four.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
pub struct Packet {
    /// `p[corner][axis][lane]`.
    p: [[[f32; LANES]; 3]; 3],
    /// Primitive index per lane; `OTHER` set for non-triangles and checked triangles,
    /// `UNUSED` for empty lanes.
    ids: [u32; LANES],
}

impl Packet {
    /// Packs up to four primitives.
    pub fn new<P: PrimitiveSet + ?Sized>(prims: &P, ids: &[u32]) -> Packet {
        debug_assert!(!ids.is_empty() && ids.len() <= LANES);
        let mut pk = Packet {
            p: [[[f32::NAN; LANES]; 3]; 3],
            ids: [UNUSED; LANES],
        };
        for (lane, &id) in ids.iter().enumerate() {
            match prims.triangle(id) {
                Some(p) => {
                    for (corner, v) in p.iter().enumerate() {
                        for axis in 0..3 {
                            pk.p[corner][axis][lane] = v[axis];
                        }
                    }
                    // A triangle whose hits are checked against the bound on the error of
                    // `t`: the scalar test decides the hits the SIMD test accepts.
                    let checked = triangle::checks_t_error(p[0], p[1], p[2]);
                    pk.ids[lane] = if checked { id | OTHER } else { id };
                }
                None => pk.ids[lane] = id | OTHER,
            }
        }
        pk
    }

    /// What lane `lane` holds. Used lanes come first: after the first unused one, all are.
    #[inline(always)]
    pub fn lane_kind(&self, lane: usize) -> LaneKind {
        match self.ids[lane] {
            UNUSED => LaneKind::Unused,
            id if id & OTHER != 0 && self.p[0][0][lane].is_nan() => LaneKind::Other(id & !OTHER),
            id => LaneKind::Triangle {
                id: id & !OTHER,
                checked: id & OTHER != 0,
            },
        }
    }

    /// Coordinate `axis` of corner `c` of the triangle in `lane`.
    #[inline(always)]
    pub fn corner(&self, c: usize, axis: usize, lane: usize) -> f32 {
        self.p[c][axis][lane]
    }

    /// Scene index of the primitive in `lane`, if the lane is used.
    #[cfg(test)]
    pub fn prim(&self, lane: usize) -> Option<u32> {
        (self.ids[lane] != UNUSED).then_some(self.ids[lane] & !OTHER)
    }

    /// Updates `best` (and `t_max`, the distance limit) with the closest hit in this packet.
    #[inline(always)]
    pub fn closest<P: PrimitiveSet + ?Sized>(
        &self,
        prims: &P,
        r: &PreparedRay,
        t_max: &mut f32,
        best: &mut Option<Hit>,
    ) {
        let lanes = self.triangle_lanes(r, *t_max);
        for lane in Lanes(lanes.mask) {
            let (t, b1, b2) = (
                lanes.t[lane],
                lanes.v[lane] * lanes.inv_det[lane],
                lanes.w[lane] * lanes.inv_det[lane],
            );
            Self::record(prims, Hit::new(t, self.ids[lane], b1, b2), t_max, best);
        }
        if lanes.scalar != 0 {
            self.closest_scalar(prims, r, lanes.scalar, t_max, best);
        }
    }

    /// The lanes the SIMD test leaves to scalar code: other primitives, large triangles'
    /// hits and edge cases. Out of line: inlined, this rarely run code took registers from
    /// the traversal loop around it; out of line, the loop ran 3–6 % faster on fine meshes.
    #[cold]
    #[inline(never)]
    fn closest_scalar<P: PrimitiveSet + ?Sized>(
        &self,
        prims: &P,
        r: &PreparedRay,
        scalar: u32,
        t_max: &mut f32,
        best: &mut Option<Hit>,
    ) {
        for lane in Lanes(scalar) {
            let hit = match self.lane_kind(lane) {
                LaneKind::Other(id) => prims.intersect(id, r, *t_max),
                LaneKind::Triangle { id, .. } => self
                    .scalar_triangle(r, lane, *t_max)
                    .map(|(t, b1, b2)| Hit::new(t, id, b1, b2)),
                LaneKind::Unused => None,
            };
            if let Some(hit) = hit {
                Self::record(prims, hit, t_max, best);
            }
        }
    }

    /// Whether anything in this packet lies within `(t_min, t_max]`.
    #[inline(always)]
    pub fn any_hit<P: PrimitiveSet + ?Sized>(&self, prims: &P, r: &PreparedRay, t_max: f32) -> bool {
        let lanes = self.triangle_lanes(r, t_max);
        if lanes.mask != 0 {
            return true;
        }
        lanes.scalar != 0 && self.any_hit_scalar(prims, r, lanes.scalar, t_max)
    }

    /// [`Self::closest_scalar`] for any-hit queries.
    #[cold]
    #[inline(never)]
    fn any_hit_scalar<P: PrimitiveSet + ?Sized>(&self, prims: &P, r: &PreparedRay, scalar: u32, t_max: f32) -> bool {
        Lanes(scalar).any(|lane| match self.lane_kind(lane) {
            LaneKind::Other(id) => prims.occludes(id, r, t_max),
            LaneKind::Triangle { .. } => self.scalar_triangle(r, lane, t_max).is_some(),
            LaneKind::Unused => false,
        })
    }

    #[inline(always)]
    fn record<P: PrimitiveSet + ?Sized>(prims: &P, hit: Hit, t_max: &mut f32, best: &mut Option<Hit>) {
        if Hit::is_closer_than(hit.t, hit.prim, best) {
            prims.prefetch(hit.prim);
            *best = Some(hit);
            *t_max = hit.t;
        }
    }

    /// The scalar test (with its f64 fallback) of the triangle in `lane`.
    #[cold]
    pub(super) fn scalar_triangle(&self, r: &PreparedRay, lane: usize, t_max: f32) -> Option<(f32, f32, f32)> {
        let corner = |c: usize| crate::math::Vec3A::new(self.p[c][0][lane], self.p[c][1][lane], self.p[c][2][lane]);
        triangle::intersect(r, corner(0), corner(1), corner(2), t_max).map(|h| (h.t, h.b1, h.b2))
    }

    /// The SIMD part: accepted triangle lanes with their `t` and unnormalised
    /// barycentrics, plus the lanes that need the scalar code.
    #[inline(always)]
    fn triangle_lanes(&self, r: &PreparedRay, t_max: f32) -> LaneHits {
        #[cfg(target_arch = "x86_64")]
        {
            // SAFETY: SSE and SSE2 are part of the x86-64 baseline.
            unsafe { self.triangle_lanes_sse(r, t_max) }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            self.triangle_lanes_portable(r, t_max)
        }
    }

    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    unsafe fn triangle_lanes_sse(&self, r: &PreparedRay, t_max: f32) -> LaneHits {
        use std::arch::x86_64::*;
        let (kx, ky, kz) = (r.kx.index(), r.ky.index(), r.kz.index());
        let [ox, oy, oz] = r.origin_k.map(|c| _mm_set1_ps(c));
        let (sx, sy, sz) = (_mm_set1_ps(r.sx), _mm_set1_ps(r.sy), _mm_set1_ps(r.sz));
        let ld = |c: usize, axis: usize| _mm_load_ps(self.p[c][axis].as_ptr());
        // Translate to the ray origin and shear (the same operations as the scalar test).
        let project = |c: usize| {
            let dx = _mm_sub_ps(ld(c, kx), ox);
            let dy = _mm_sub_ps(ld(c, ky), oy);
            let dz = _mm_sub_ps(ld(c, kz), oz);
            (
                _mm_sub_ps(dx, _mm_mul_ps(sx, dz)),
                _mm_sub_ps(dy, _mm_mul_ps(sy, dz)),
                dz,
            )
        };
        let (ax, ay, az) = project(0);
        let (bx, by, bz) = project(1);
        let (cx, cy, cz) = project(2);
        let u = _mm_sub_ps(_mm_mul_ps(cx, by), _mm_mul_ps(cy, bx));
        let v = _mm_sub_ps(_mm_mul_ps(ax, cy), _mm_mul_ps(ay, cx));
        let w = _mm_sub_ps(_mm_mul_ps(bx, ay), _mm_mul_ps(by, ax));
        let zero = _mm_setzero_ps();
        let any_zero = _mm_or_ps(
            _mm_or_ps(_mm_cmpeq_ps(u, zero), _mm_cmpeq_ps(v, zero)),
            _mm_cmpeq_ps(w, zero),
        );
        // Lanes whose edge functions rounded to zero: the scalar code decides them.
        let any_zero = _mm_movemask_ps(any_zero) as u32;
        // With no zero among them, the three edge functions agree in sign exactly when
        // the sign bits of `u ^ v` and `u ^ w` are clear. (Unused lanes and non-triangles
        // hold NaN, whose sign is arbitrary; their distance is NaN and fails the range test.)
        let mixed = _mm_movemask_ps(_mm_or_ps(_mm_xor_ps(u, v), _mm_xor_ps(u, w))) as u32;
        let inside = !mixed & !any_zero & 0xF;
        let other = _mm_movemask_ps(_mm_castsi128_ps(_mm_load_si128(self.ids.as_ptr().cast()))) as u32;
        // No lane inside its triangle and none to leave to the scalar code but those whose
        // edge functions rounded to zero: the distance would decide nothing. (918 → 880
        // instructions a ray on the 100k dragon's primary rays.)
        if inside | other == 0 {
            return LaneHits::none(any_zero);
        }
        let det = _mm_add_ps(_mm_add_ps(u, v), w);
        let t_scaled = _mm_add_ps(
            _mm_add_ps(_mm_mul_ps(u, _mm_mul_ps(sz, az)), _mm_mul_ps(v, _mm_mul_ps(sz, bz))),
            _mm_mul_ps(w, _mm_mul_ps(sz, cz)),
        );
        let inv_det = _mm_div_ps(_mm_set1_ps(1.0), det);
        let t = _mm_mul_ps(t_scaled, inv_det);
        let accept = _mm_and_ps(
            _mm_cmpneq_ps(det, zero),
            _mm_and_ps(
                _mm_cmpgt_ps(t, _mm_set1_ps(r.ray.t_min)),
                _mm_cmple_ps(t, _mm_set1_ps(t_max)),
            ),
        );
        let accepted = _mm_movemask_ps(accept) as u32 & inside;
        // Flagged lanes: non-triangles (NaN corners, so NaN edge functions) always go to the
        // scalar code, checked triangles only with a hit the SIMD test accepted.
        let scalar = if other == 0 {
            any_zero
        } else {
            let nan = _mm_movemask_ps(_mm_cmpunord_ps(det, det)) as u32;
            any_zero | other & (nan | accepted)
        };
        let mask = accepted & !other;
        let mut hits = LaneHits::none(scalar);
        hits.mask = mask;
        if mask != 0 {
            _mm_storeu_ps(hits.t.as_mut_ptr(), t);
            _mm_storeu_ps(hits.v.as_mut_ptr(), v);
            _mm_storeu_ps(hits.w.as_mut_ptr(), w);
            _mm_storeu_ps(hits.inv_det.as_mut_ptr(), inv_det);
        }
        hits
    }

    #[cfg(not(target_arch = "x86_64"))]
    fn triangle_lanes_portable(&self, r: &PreparedRay, t_max: f32) -> LaneHits {
        // No SIMD here: every used lane goes through the scalar code.
        let mut scalar = 0;
        for lane in 0..LANES {
            if self.ids[lane] != UNUSED {
                scalar |= 1 << lane;
            }
        }
        let _ = (r, t_max);
        LaneHits::none(scalar)
    }
}

/// The primitive a packet lane holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LaneKind {
    /// A triangle; `checked`: its hits must also pass the bound on the error of `t`
    /// ([`triangle::checks_t_error`]), which the scalar test applies.
    Triangle {
        id: u32,
        checked: bool,
    },
    /// A primitive that is not a triangle: tested by the primitive's own code.
    Other(u32),
    Unused,
}

struct LaneHits {
    /// Lanes whose triangle the SIMD test accepted.
    mask: u32,
    /// Lanes that must be tested by the scalar code.
    scalar: u32,
    t: [f32; LANES],
    v: [f32; LANES],
    w: [f32; LANES],
    inv_det: [f32; LANES],
}

impl LaneHits {
    #[inline(always)]
    fn none(scalar: u32) -> LaneHits {
        LaneHits {
            mask: 0,
            scalar,
            t: [0.0; LANES],
            v: [0.0; LANES],
            w: [0.0; LANES],
            inv_det: [0.0; LANES],
        }
    }
}

/// The set bits of a mask, lowest first.
pub struct Lanes(pub u32);

impl Iterator for Lanes {
    type Item = usize;
    #[inline(always)]
    fn next(&mut self) -> Option<usize> {
        if self.0 == 0 {
            return None;
        }
        let i = self.0.trailing_zeros() as usize;
        self.0 &= self.0 - 1;
        Some(i)
    }
}
