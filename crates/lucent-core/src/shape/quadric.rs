//! Scene command: `quadric a b c d e f g h i j x0 y0 z0 x1 y1 z1` — the implicit surface
//! `a x² + b y² + c z² + d xy + e xz + f yz + g x + h y + i z + j = 0` clipped to the
//! object-space box `[x0, x1] × [y0, y1] × [z0, z1]`.

use super::quadratic::{first_root, solve};
use crate::aabb::Aabb;
use crate::math::Vec3A;

/// The ten coefficients in the order of the scene command.
pub type Coefficients = [f32; 10];

pub fn intersect(q: &Coefficients, clip: &Aabb, o: Vec3A, d: Vec3A, t_min: f32, t_max: f32) -> Option<f32> {
    let [a, b, c, dd, e, f, g, h, i, j] = q.map(|x| x as f64);
    let (ox, oy, oz) = (o.x as f64, o.y as f64, o.z as f64);
    let (dx, dy, dz) = (d.x as f64, d.y as f64, d.z as f64);
    let qa = a * dx * dx + b * dy * dy + c * dz * dz + dd * dx * dy + e * dx * dz + f * dy * dz;
    let qb = 2.0 * (a * ox * dx + b * oy * dy + c * oz * dz)
        + dd * (ox * dy + oy * dx)
        + e * (ox * dz + oz * dx)
        + f * (oy * dz + oz * dy)
        + g * dx
        + h * dy
        + i * dz;
    let qc = a * ox * ox
        + b * oy * oy
        + c * oz * oz
        + dd * ox * oy
        + e * ox * oz
        + f * oy * oz
        + g * ox
        + h * oy
        + i * oz
        + j;
    let (lo, hi) = (clip.min.as_dvec3(), clip.max.as_dvec3());
    first_root(solve(qa, qb, qc), t_min, t_max, |t| {
        let p = [ox + t * dx, oy + t * dy, oz + t * dz];
        (0..3).all(|k| p[k] >= lo[k] && p[k] <= hi[k])
    })
}

/// The gradient at `p`: the normal, pointing to where the polynomial grows.
pub fn normal(q: &Coefficients, p: Vec3A) -> Vec3A {
    let [a, b, c, d, e, f, g, h, i, _] = *q;
    Vec3A::new(
        2.0 * a * p.x + d * p.y + e * p.z + g,
        2.0 * b * p.y + d * p.x + f * p.z + h,
        2.0 * c * p.z + e * p.x + f * p.y + i,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    const BIG: Aabb = Aabb {
        min: Vec3A::splat(-10.0),
        max: Vec3A::splat(10.0),
    };

    #[test]
    fn a_unit_sphere_as_a_quadric() {
        let s: Coefficients = [1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0];
        assert_eq!(
            intersect(&s, &BIG, Vec3A::new(0.0, 0.0, 5.0), -Vec3A::Z, 1e-4, f32::INFINITY),
            Some(4.0)
        );
        // From inside: the far side; leaving outward: nothing.
        assert_eq!(
            intersect(&s, &BIG, Vec3A::ZERO, Vec3A::X, 1e-4, f32::INFINITY),
            Some(1.0)
        );
        assert_eq!(intersect(&s, &BIG, Vec3A::X, Vec3A::X, 1e-4, f32::INFINITY), None);
        let t = intersect(&s, &BIG, Vec3A::X, -Vec3A::X, 1e-4, f32::INFINITY).unwrap();
        assert!((t - 2.0).abs() < 1e-6);
        // Tangent ray: the double root.
        assert_eq!(
            intersect(&s, &BIG, Vec3A::new(1.0, -3.0, 0.0), Vec3A::Y, 1e-4, f32::INFINITY),
            Some(3.0)
        );
        assert_eq!(normal(&s, Vec3A::new(0.0, 0.0, 1.0)), Vec3A::new(0.0, 0.0, 2.0));
    }

    #[test]
    fn clipping_and_degenerate_quadrics() {
        // A hyperbolic paraboloid z = x² − y² clipped to |x|, |y| ≤ 1.
        let saddle: Coefficients = [1.0, -1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0];
        let clip = Aabb::new(Vec3A::new(-1.0, -1.0, -5.0), Vec3A::new(1.0, 1.0, 5.0));
        let t = intersect(
            &saddle,
            &clip,
            Vec3A::new(0.5, 0.0, 5.0),
            -Vec3A::Z,
            1e-4,
            f32::INFINITY,
        )
        .unwrap();
        assert!((t - 4.75).abs() < 1e-6, "{t}");
        assert_eq!(
            intersect(
                &saddle,
                &clip,
                Vec3A::new(1.5, 0.0, 5.0),
                -Vec3A::Z,
                1e-4,
                f32::INFINITY
            ),
            None
        );
        // A plane as a quadric (only linear terms): the equation is linear in t.
        let plane: Coefficients = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, -2.0];
        assert_eq!(
            intersect(&plane, &BIG, Vec3A::ZERO, Vec3A::Z, 1e-4, f32::INFINITY),
            Some(2.0)
        );
        assert_eq!(
            intersect(&plane, &BIG, Vec3A::ZERO, Vec3A::X, 1e-4, f32::INFINITY),
            None
        );
    }
}
