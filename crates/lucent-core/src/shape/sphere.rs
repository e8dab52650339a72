//! Scene command: `sphere cx cy cz r` — a sphere of radius r at (cx, cy, cz) under the
//! current transform; non-uniform scales make it an ellipsoid.
//!
//! A sphere is stored as the transform that maps the unit sphere at the origin to it.
//! The world ray is carried into object space with the inverse (origin as a point,
//! direction as a vector, **not renormalised**), so the ray parameter `t` is the same in
//! both spaces and hits on different objects compare directly (SCENE_FORMAT.md §4.2).
//!
//! Two textbook methods are implemented; they must agree. The geometric one is used for
//! rendering because it measures the ray's closest approach to the centre directly and
//! so loses less precision for small or distant spheres.

use crate::math::Vec3A;

/// The algebraic method: solve `|o + t d|² = 1` as a quadratic in `t`, with the
/// numerically stable form of the roots. Returns the smallest root in `(t_min, t_max]`.
pub fn intersect_unit_algebraic(o: Vec3A, d: Vec3A, t_min: f32, t_max: f32) -> Option<f32> {
    let a = d.dot(d);
    let half_b = o.dot(d);
    let c = o.dot(o) - 1.0;
    let disc = half_b * half_b - a * c;
    if disc < 0.0 || a == 0.0 {
        return None;
    }
    // q = -(b + sign(b)·sqrt(disc)) / 2 avoids cancellation; roots q/a and c/q.
    let q = -(half_b + disc.sqrt().copysign(half_b));
    let (mut t0, mut t1) = (q / a, if q != 0.0 { c / q } else { q / a });
    if t0 > t1 {
        std::mem::swap(&mut t0, &mut t1);
    }
    nearest_root(t0, t1, t_min, t_max)
}

/// The geometric method: find the parameter of the ray's closest approach to the centre,
/// then step back and forth by the half chord from Pythagoras.
#[inline]
pub fn intersect_unit_geometric(o: Vec3A, d: Vec3A, t_min: f32, t_max: f32) -> Option<f32> {
    let dd = d.dot(d);
    if dd == 0.0 {
        return None;
    }
    let t_closest = -o.dot(d) / dd;
    let closest = o + d * t_closest;
    let dist2 = closest.dot(closest);
    if dist2 > 1.0 {
        return None;
    }
    let half_chord = ((1.0 - dist2) / dd).sqrt();
    nearest_root(t_closest - half_chord, t_closest + half_chord, t_min, t_max)
}

#[inline(always)]
fn nearest_root(t0: f32, t1: f32, t_min: f32, t_max: f32) -> Option<f32> {
    if t0 > t_min && t0 <= t_max {
        Some(t0)
    } else if t1 > t_min && t1 <= t_max {
        Some(t1)
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    type Method = fn(Vec3A, Vec3A, f32, f32) -> Option<f32>;
    const BOTH: [Method; 2] = [intersect_unit_algebraic, intersect_unit_geometric];

    #[test]
    fn head_on_hit_is_at_distance_minus_radius() {
        for f in BOTH {
            let t = f(Vec3A::new(0.0, 0.0, 5.0), -Vec3A::Z, 1e-4, f32::INFINITY).unwrap();
            assert!((t - 4.0).abs() < 1e-6);
        }
    }

    #[test]
    fn off_centre_hit_matches_pythagoras() {
        // Offset 0.6 from the axis: the chord's half length is 0.8.
        for f in BOTH {
            let t = f(Vec3A::new(0.6, 0.0, 5.0), -Vec3A::Z, 1e-4, f32::INFINITY).unwrap();
            assert!((t - 4.2).abs() < 1e-6, "{t}");
        }
    }

    #[test]
    fn inside_the_sphere_hits_the_far_side() {
        for f in BOTH {
            let t = f(Vec3A::ZERO, Vec3A::X, 1e-4, f32::INFINITY).unwrap();
            assert!((t - 1.0).abs() < 1e-6);
        }
    }

    #[test]
    fn misses_behind_and_beside() {
        for f in BOTH {
            assert!(f(Vec3A::new(0.0, 0.0, 5.0), Vec3A::Z, 1e-4, f32::INFINITY).is_none());
            assert!(f(Vec3A::new(1.01, 0.0, 5.0), -Vec3A::Z, 1e-4, f32::INFINITY).is_none());
            assert!(f(Vec3A::new(0.0, 0.0, 5.0), -Vec3A::Z, 1e-4, 3.9).is_none());
        }
    }

    #[test]
    fn unnormalised_directions_keep_world_t() {
        // Direction of length 2: t halves.
        for f in BOTH {
            let t = f(
                Vec3A::new(0.0, 0.0, 5.0),
                Vec3A::new(0.0, 0.0, -2.0),
                1e-4,
                f32::INFINITY,
            )
            .unwrap();
            assert!((t - 2.0).abs() < 1e-6);
        }
    }

    #[test]
    fn leaving_the_surface_does_not_hit_it_again() {
        // Start on the surface, going out: no hit beyond epsilon.
        for f in BOTH {
            assert!(f(Vec3A::new(0.0, 0.0, 1.0), Vec3A::Z, 1e-4, f32::INFINITY).is_none());
        }
    }

    #[test]
    fn both_methods_agree_on_many_rays() {
        // A deterministic scatter of rays from around the sphere toward it.
        let mut seed = 0x9e3779b9u32;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 17;
            seed ^= seed << 5;
            seed as f32 / u32::MAX as f32 * 2.0 - 1.0
        };
        let mut hits = 0;
        for _ in 0..20_000 {
            let o = Vec3A::new(next(), next(), next()) * 4.0;
            let target = Vec3A::new(next(), next(), next()) * 1.2;
            let d = (target - o).normalize() * (0.5 + next().abs());
            let a = intersect_unit_algebraic(o, d, 1e-4, f32::INFINITY);
            let g = intersect_unit_geometric(o, d, 1e-4, f32::INFINITY);
            match (a, g) {
                (Some(a), Some(g)) => {
                    hits += 1;
                    assert!((a - g).abs() <= 1e-4 * a.abs().max(1.0), "{a} vs {g}");
                }
                (None, None) => {}
                // Only grazing rays may disagree: their closest approach is ~ the radius.
                _ => {
                    let tc = -o.dot(d) / d.dot(d);
                    let r = (o + d * tc).length();
                    assert!((r - 1.0).abs() < 1e-3, "disagreement away from the rim: r = {r}");
                }
            }
        }
        assert!(hits > 5_000);
    }
}
