//! Which primitives a cell holds: the exact triangle–box overlap test (separating axis
//! theorem, Akenine-Möller 2001) and triangle clipping to a box (the bounds of the part
//! of a triangle inside a kd-tree node: "perfect splits", Havran 2000).
//!
//! Both work in f64 on cells padded by [`cell_padding`], so rounding can only put a
//! primitive into a cell it merely touches, never leave it out of one it overlaps: a
//! structure that leaves a primitive out of a cell the ray crosses would miss its hit.

use super::PrimitiveSet;
use crate::aabb::Aabb;
use crate::math::{DVec3, Vec3A};

/// How much a box grows before primitives are assigned to it: a hundred-thousandth of
/// its size and a millionth of its largest coordinate (eight to sixteen units in the
/// last place of an `f32` there), far above the rounding of its planes and far below
/// the box.
///
/// The kd-tree and the octree pad each cell by its own: their walks decide which cells
/// a ray enters with a margin of their own for the rounding of the ray's distances,
/// which grows with the distance (the kd-tree a relative 2⁻¹² at each plane, the octree
/// the conservative slab test of each octant). With the scene's padding, a small detail
/// far from the scene's largest coordinate — 50,000 triangles 0.01 wide in a unit cube,
/// with one more triangle 10⁴ away — was padded by 0.12, so every triangle fell into the
/// cells on both sides of every plane near it. The grid pads its cells by the box it
/// is built over (the scene's, or a crowded cell's part for a grid of its own); its
/// walk allows for the rounding itself (`grid::Grid::walk_from`).
pub fn cell_padding(b: &Aabb) -> f32 {
    let e = b.extent().max_element();
    let m = b.min.abs().max(b.max.abs()).max_element();
    1e-5 * e + 1e-6 * m + f32::MIN_POSITIVE
}

pub fn padded(b: &Aabb, pad: f32) -> Aabb {
    Aabb {
        min: b.min - Vec3A::splat(pad),
        max: b.max + Vec3A::splat(pad),
    }
}

fn d(v: Vec3A) -> DVec3 {
    DVec3::new(v.x as f64, v.y as f64, v.z as f64)
}

/// Whether a primitive overlaps box `b` (faces included). Exact for triangles; other
/// shapes are represented by their bounding box.
pub fn overlaps<P: PrimitiveSet + ?Sized>(prims: &P, i: u32, b: &Aabb) -> bool {
    match prims.triangle(i) {
        Some(p) => triangle_overlaps_box(&p, b),
        None => boxes_overlap(&prims.bounds(i), b),
    }
}

pub fn boxes_overlap(a: &Aabb, b: &Aabb) -> bool {
    a.min.cmple(b.max).all() && b.min.cmple(a.max).all()
}

/// Separating axis test: the triangle and the box are disjoint exactly when one of 13
/// axes separates them — the box's three face normals, the triangle's normal, and the
/// nine cross products of box edges with triangle edges.
pub fn triangle_overlaps_box(p: &[Vec3A; 3], b: &Aabb) -> bool {
    let c = (d(b.min) + d(b.max)) * 0.5;
    let h = (d(b.max) - d(b.min)) * 0.5;
    let v = [d(p[0]) - c, d(p[1]) - c, d(p[2]) - c];
    // Box face normals: compare the triangle's bounds with the box.
    for a in 0..3 {
        let lo = v[0][a].min(v[1][a]).min(v[2][a]);
        let hi = v[0][a].max(v[1][a]).max(v[2][a]);
        if lo > h[a] || hi < -h[a] {
            return false;
        }
    }
    let e = [v[1] - v[0], v[2] - v[1], v[0] - v[2]];
    let separates = |axis: DVec3| {
        if axis == DVec3::ZERO {
            return false; // parallel edges: covered by the other axes
        }
        let (p0, p1, p2) = (axis.dot(v[0]), axis.dot(v[1]), axis.dot(v[2]));
        let r = h.x * axis.x.abs() + h.y * axis.y.abs() + h.z * axis.z.abs();
        p0.min(p1).min(p2) > r || p0.max(p1).max(p2) < -r
    };
    if separates(e[0].cross(e[1])) {
        return false;
    }
    for edge in e {
        for unit in [DVec3::X, DVec3::Y, DVec3::Z] {
            if separates(unit.cross(edge)) {
                return false;
            }
        }
    }
    true
}

/// The part of a primitive inside a box, as a kd-tree's build prices it.
#[derive(Clone, Copy, Debug)]
pub struct Clipped {
    pub bounds: Aabb,
    /// The part is a segment or a point (no area beside the box's faces: [`NO_AREA`]): the triangle
    /// only touches the box, along an edge or at a corner, as a mesh's neighbour does
    /// across the plane that made the box. Never set for other shapes.
    pub touches_only: bool,
}

/// The part of the primitive inside `b`, or `None` if it does not overlap.
/// Triangles are clipped (Sutherland–Hodgman against the six planes); other shapes
/// use their bounding box cut to `b`.
pub fn clipped_bounds<P: PrimitiveSet + ?Sized>(prims: &P, i: u32, b: &Aabb) -> Option<Clipped> {
    match prims.triangle(i) {
        Some(p) => clip_triangle(&p, b),
        None => {
            let pb = prims.bounds(i);
            boxes_overlap(&pb, b).then(|| Clipped {
                bounds: Aabb {
                    min: pb.min.max(b.min),
                    max: pb.max.min(b.max),
                },
                touches_only: false,
            })
        }
    }
}

/// Twice the vector area of a polygon (Newell's sum): its length is twice the area.
fn vector_area(poly: &[DVec3]) -> DVec3 {
    let mut n = DVec3::ZERO;
    for (i, a) in poly.iter().enumerate() {
        n += a.cross(poly[(i + 1) % poly.len()]);
    }
    n
}

/// A clipped part this much smaller (in area) than the box's largest face counts as no
/// area: the part of a triangle that touches the box is made of copies of its corners
/// and points on its edges, whose rounding leaves far less; a sliver this thin is seldom
/// hit. (Measured against the box, not the triangle: a large triangle crossing a small
/// box has a part small beside the triangle, but not beside the box.)
const NO_AREA: f64 = 1e-9;

/// The corners a clipped triangle may have: each plane adds at most one corner to a
/// convex polygon, nine in all, with room for a few more (rounding can make the polygon
/// slightly non-convex; past this, the triangle's bounds are used, see below). Kept on
/// the stack: the kd-tree's build clips every primitive a plane straddles, and an
/// allocation a pass took a third of its time.
const MAX_CLIPPED: usize = 16;

fn clip_triangle(p: &[Vec3A; 3], b: &Aabb) -> Option<Clipped> {
    let (mut a, mut c) = ([DVec3::ZERO; MAX_CLIPPED], [DVec3::ZERO; MAX_CLIPPED]);
    // (The two buffers change roles by reference: swapping the arrays themselves
    // copied them, at every pass.)
    let (mut poly, mut out) = (&mut a, &mut c);
    for (q, &v) in poly.iter_mut().zip(p) {
        *q = d(v);
    }
    let mut len = 3;
    let (lo, hi) = (d(b.min), d(b.max));
    for axis in 0..3 {
        for (plane, keep_above) in [(lo[axis], true), (hi[axis], false)] {
            let inside = |q: &DVec3| if keep_above { q[axis] >= plane } else { q[axis] <= plane };
            let mut n = 0;
            for i in 0..len {
                let (a, c) = (poly[i], poly[(i + 1) % len]);
                if n + 2 > MAX_CLIPPED {
                    // Only a polygon bent by rounding gets here: the triangle's own
                    // bounds within the box hold its clipped part.
                    let whole = Aabb::from_points(p);
                    return Some(Clipped {
                        bounds: Aabb {
                            min: whole.min.max(b.min),
                            max: whole.max.min(b.max),
                        },
                        touches_only: false,
                    });
                }
                if inside(&a) {
                    out[n] = a;
                    n += 1;
                }
                if inside(&a) != inside(&c) {
                    let t = (plane - a[axis]) / (c[axis] - a[axis]);
                    let mut q = a + (c - a) * t;
                    q[axis] = plane;
                    out[n] = q;
                    n += 1;
                }
            }
            std::mem::swap(&mut poly, &mut out);
            len = n;
            if len == 0 {
                return None;
            }
        }
    }
    // The clipped bounds only place candidate split planes (which cell a primitive goes
    // to is decided by `overlaps`), so rounding to nearest is fine; never beyond the box.
    let mut r = Aabb::EMPTY;
    for q in &poly[..len] {
        let q = Vec3A::new(q.x as f32, q.y as f32, q.z as f32);
        r = r.grow(q);
    }
    let e = hi - lo;
    let largest_face = (e.x * e.y).max(e.y * e.z).max(e.z * e.x);
    Some(Clipped {
        bounds: Aabb {
            min: r.min.max(b.min),
            max: r.max.min(b.max),
        },
        touches_only: 0.5 * vector_area(&poly[..len]).length() <= NO_AREA * largest_face,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::test_sets::Rng;

    #[test]
    fn clipping_and_the_separating_axis_test_agree() {
        let mut rng = Rng(3);
        let b = Aabb::new(Vec3A::splat(-1.0), Vec3A::splat(1.0));
        let (mut inside, mut outside) = (0, 0);
        for _ in 0..20_000 {
            let c = rng.vec(2.5);
            let p = [c + rng.vec(1.5), c + rng.vec(1.5), c + rng.vec(1.5)];
            let sat = triangle_overlaps_box(&p, &b);
            let clip = clip_triangle(&p, &b);
            // Clipping can lose a sliver that only touches the box within rounding.
            assert!(clip.is_none() || sat, "{p:?}");
            if let Some(Clipped { bounds: cb, .. }) = clip {
                assert!(cb.min.cmpge(b.min).all() && cb.max.cmple(b.max).all());
                inside += 1;
            } else if !sat {
                outside += 1;
            }
            // Brute force: sample the triangle; any sample in the box means overlap.
            for k in 0..50 {
                let (u, v) = (rng.next(), rng.next());
                let (u, v) = if u + v > 1.0 { (1.0 - u, 1.0 - v) } else { (u, v) };
                let q = p[0] + (p[1] - p[0]) * u + (p[2] - p[0]) * v;
                if q.cmpge(b.min).all() && q.cmple(b.max).all() {
                    assert!(sat, "sample {k} of {p:?} is in the box but SAT says disjoint");
                    assert!(
                        clip.is_some_and(|c| c.bounds.min.cmple(q + 1e-5).all() && c.bounds.max.cmpge(q - 1e-5).all())
                    );
                    break;
                }
            }
        }
        assert!(inside > 2000 && outside > 2000, "{inside} {outside}");
    }

    #[test]
    fn a_triangle_near_a_box_corner_is_separated_by_an_edge_axis() {
        // Its bounding box overlaps the unit box, but the triangle passes by the corner.
        let b = Aabb::new(Vec3A::ZERO, Vec3A::ONE);
        let p = [
            Vec3A::new(2.0, 0.5, 0.5),
            Vec3A::new(0.5, 2.0, 0.5),
            Vec3A::new(2.0, 2.0, 0.5),
        ];
        assert!(!triangle_overlaps_box(&p, &b));
        assert!(clip_triangle(&p, &b).is_none());
        let touching = [
            Vec3A::new(2.0, 0.0, 0.5),
            Vec3A::new(0.0, 2.0, 0.5),
            Vec3A::new(2.0, 2.0, 0.5),
        ];
        assert!(triangle_overlaps_box(&touching, &b));
    }
}
