//! Differential geometry of a surface point: `∂p/∂u` and `∂p/∂v` (what bump mapping
//! differentiates along) for shapes whose texture coordinates are a function of the
//! position, for triangles with texture coordinates, and an orthonormal frame around a
//! normal.

use glam::Vec2;

/// `∂p/∂u` and `∂p/∂v` at the surface point `p` with unit normal `n`, for a shape whose
/// texture coordinates are the function `uv` of the position: the inverse of the
/// Jacobian of `uv` over two tangent directions, by central differences. Differences in
/// u and v are wrapped into (−½, ½], so a longitude seam does not count as a jump. Zero
/// vectors where `uv` does not vary across the surface.
pub fn uv_tangents(p: glam::Vec3A, n: glam::Vec3A, uv: impl Fn(glam::Vec3A) -> Vec2) -> (glam::Vec3A, glam::Vec3A) {
    let (t1, t2) = orthonormal_frame(n);
    let h = 1e-3 * (1.0 + p.abs().max_element());
    let wrap = |d: Vec2| d - d.round();
    let a = wrap(uv(p + t1 * h) - uv(p - t1 * h)) / (2.0 * h);
    let b = wrap(uv(p + t2 * h) - uv(p - t2 * h)) / (2.0 * h);
    let det = a.x * b.y - b.x * a.y;
    if !(det.abs() > 1e-12) || !det.is_finite() {
        return (glam::Vec3A::ZERO, glam::Vec3A::ZERO);
    }
    let dpdu = (t1 * b.y - t2 * a.y) / det;
    let dpdv = (t2 * a.x - t1 * b.x) / det;
    (dpdu, dpdv)
}

/// Two unit vectors completing the unit `n` to an orthonormal, right-handed frame
/// (Duff et al. 2017).
pub fn orthonormal_frame(n: glam::Vec3A) -> (glam::Vec3A, glam::Vec3A) {
    let sign = 1.0f32.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        glam::Vec3A::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        glam::Vec3A::new(b, sign + n.y * n.y * a, -n.y),
    )
}

/// `∂p/∂u`, `∂p/∂v` of a triangle with corners `p` and texture coordinates `uv`.
pub fn triangle_tangents(p: [glam::Vec3A; 3], uv: [Vec2; 3]) -> (glam::Vec3A, glam::Vec3A) {
    let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
    let (d1, d2) = (uv[1] - uv[0], uv[2] - uv[0]);
    let det = d1.x * d2.y - d2.x * d1.y;
    if !(det.abs() > 1e-20) || !det.is_finite() {
        let n = e1.cross(e2).normalize_or_zero();
        return orthonormal_frame(if n == glam::Vec3A::ZERO { glam::Vec3A::Z } else { n });
    }
    ((e1 * d2.y - e2 * d1.y) / det, (e2 * d1.x - e1 * d2.x) / det)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tangents_of_the_sphere_and_a_triangle() {
        // Unit sphere at (1, 0, 0): u = longitude grows along +y by 1/2π per unit of arc;
        // v = acos(z)/π grows toward −z by 1/π per unit.
        let p = glam::Vec3A::X;
        let (dpdu, dpdv) = uv_tangents(p, p, |q| crate::shape::texcoord::sphere(q.normalize()));
        assert!(
            (dpdu - glam::Vec3A::Y * std::f32::consts::TAU).length() < 1e-2,
            "{dpdu}"
        );
        assert!((dpdv + glam::Vec3A::Z * std::f32::consts::PI).length() < 1e-2, "{dpdv}");
        // A triangle whose uv are its x and y coordinates halved.
        let tri = [glam::Vec3A::ZERO, glam::Vec3A::X, glam::Vec3A::Y];
        let uv = [Vec2::ZERO, Vec2::new(0.5, 0.0), Vec2::new(0.0, 0.5)];
        let (du, dv) = triangle_tangents(tri, uv);
        assert!((du - glam::Vec3A::X * 2.0).length() < 1e-6 && (dv - glam::Vec3A::Y * 2.0).length() < 1e-6);
    }
}
