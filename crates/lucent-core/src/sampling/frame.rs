//! An orthonormal frame `(t1, t2, n)` around a unit vector: the local coordinates in
//! which hemisphere and lobe directions are drawn (z along `n`).

use crate::math::Vec3A;

#[derive(Clone, Copy, Debug)]
pub struct Frame {
    pub t1: Vec3A,
    pub t2: Vec3A,
    pub n: Vec3A,
}

impl Frame {
    /// A frame whose third axis is the unit vector `n`, without a branch on a
    /// near-zero component (Duff et al., "Building an orthonormal basis, revisited", 2017).
    #[inline]
    pub fn around(n: Vec3A) -> Frame {
        let sign = 1.0f32.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        Frame {
            t1: Vec3A::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
            t2: Vec3A::new(b, sign + n.y * n.y * a, -n.y),
            n,
        }
    }

    /// The world direction of local coordinates `(x, y, z)`.
    #[inline]
    pub fn to_world(&self, v: Vec3A) -> Vec3A {
        self.t1 * v.x + self.t2 * v.y + self.n * v.z
    }

    /// The local coordinates of a world direction.
    #[inline]
    pub fn to_local(&self, v: Vec3A) -> Vec3A {
        Vec3A::new(v.dot(self.t1), v.dot(self.t2), v.dot(self.n))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_are_orthonormal_and_right_handed_for_every_normal() {
        let normals = [
            Vec3A::Z,
            -Vec3A::Z,
            Vec3A::X,
            Vec3A::new(0.0, 0.0, -1.0 + 1e-7).normalize(),
            Vec3A::new(1e-8, -1e-8, -1.0).normalize(),
            Vec3A::new(0.3, -0.5, 0.8).normalize(),
        ];
        for n in normals {
            let f = Frame::around(n);
            for (a, b) in [(f.t1, f.t2), (f.t1, f.n), (f.t2, f.n)] {
                assert!(a.dot(b).abs() < 1e-6, "{n}");
            }
            for v in [f.t1, f.t2] {
                assert!((v.length() - 1.0).abs() < 1e-6, "{n}");
            }
            assert!((f.t1.cross(f.t2) - n).length() < 1e-5, "{n}");
            let w = Vec3A::new(0.2, -0.7, 0.4);
            assert!((f.to_world(f.to_local(w)) - w).length() < 1e-6);
        }
    }
}
