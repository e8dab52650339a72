//! Affine transforms as the scene format builds them: `translate`, `rotate` and `scale`
//! right-multiply the current matrix (OpenGL semantics), so the transform written last
//! is applied to an object first.
//!
//! Transforms are kept in `f64` while a scene is set up; `to_f32` rounds once for the
//! render. Normals are carried by the inverse transpose of the linear part.

use crate::math::{Affine3A, DAffine3, DMat3, DVec3, Mat3A};

/// An affine transform with its inverse.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    pub m: DAffine3,
    pub inv: DAffine3,
}

impl Default for Transform {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Transform {
    pub const IDENTITY: Transform = Transform {
        m: DAffine3::IDENTITY,
        inv: DAffine3::IDENTITY,
    };

    /// Wraps a matrix; `None` when it is singular (or too close to singular to invert).
    pub fn new(m: DAffine3) -> Option<Transform> {
        let det = m.matrix3.determinant();
        if !det.is_finite() || det.abs() < 1e-300 {
            return None;
        }
        let inv = m.inverse();
        if !inv.is_finite() {
            return None;
        }
        Some(Transform { m, inv })
    }

    pub fn translate(t: DVec3) -> Transform {
        Transform {
            m: DAffine3::from_translation(t),
            inv: DAffine3::from_translation(-t),
        }
    }

    /// `None` if a factor is zero (a singular transform).
    pub fn scale(s: DVec3) -> Option<Transform> {
        if s.x == 0.0 || s.y == 0.0 || s.z == 0.0 {
            return None;
        }
        Some(Transform {
            m: DAffine3::from_scale(s),
            inv: DAffine3::from_scale(s.recip()),
        })
    }

    /// Counter-clockwise rotation by `degrees` about `axis` (normalised first), as
    /// `glRotate`: `R = c·I + (1 − c)·a aᵀ + s·[a]×`. `None` for a zero axis.
    pub fn rotate(axis: DVec3, degrees: f64) -> Option<Transform> {
        let len = axis.length();
        if !(len > 0.0) || !len.is_finite() {
            return None;
        }
        let a = axis / len;
        let (s, c) = degrees.to_radians().sin_cos();
        let outer = DMat3::from_cols(a * a.x, a * a.y, a * a.z);
        let cross = DMat3::from_cols(
            DVec3::new(0.0, a.z, -a.y),
            DVec3::new(-a.z, 0.0, a.x),
            DVec3::new(a.y, -a.x, 0.0),
        );
        let r = DMat3::IDENTITY * c + outer * (1.0 - c) + cross * s;
        // A rotation's inverse is its transpose.
        Some(Transform {
            m: DAffine3::from_mat3(r),
            inv: DAffine3::from_mat3(r.transpose()),
        })
    }

    /// `self · other`: `other` is applied first.
    pub fn then_apply(&self, other: &Transform) -> Transform {
        Transform {
            m: self.m * other.m,
            inv: other.inv * self.inv,
        }
    }

    pub fn is_identity(&self) -> bool {
        self.m == DAffine3::IDENTITY
    }

    pub fn point(&self, p: DVec3) -> DVec3 {
        self.m.transform_point3(p)
    }

    pub fn vector(&self, v: DVec3) -> DVec3 {
        self.m.transform_vector3(v)
    }

    /// A normal carried by the inverse transpose of the linear part (not normalised).
    pub fn normal(&self, n: DVec3) -> DVec3 {
        self.inv.matrix3.transpose() * n
    }

    /// The determinant of the linear part (negative for a mirroring transform).
    pub fn determinant(&self) -> f64 {
        self.m.matrix3.determinant()
    }

    pub fn to_f32(m: &DAffine3) -> Affine3A {
        Affine3A::from_cols_array(&m.to_cols_array().map(|x| x as f32))
    }

    /// The inverse transpose of the linear part, in `f32`, for normals.
    pub fn normal_matrix_f32(&self) -> Mat3A {
        Mat3A::from_cols_array(&self.inv.matrix3.transpose().to_cols_array().map(|x| x as f32))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: DVec3, b: DVec3) -> bool {
        (a - b).length() < 1e-12
    }

    #[test]
    fn rotation_is_counter_clockwise_in_degrees() {
        let r = Transform::rotate(DVec3::new(0.0, 0.0, 2.0), 90.0).unwrap();
        assert!(close(r.vector(DVec3::X), DVec3::Y));
        assert!(close(r.inv.transform_vector3(DVec3::Y), DVec3::X));
    }

    #[test]
    fn right_multiplication_applies_the_last_transform_first() {
        // translate then scale in the file: the point is scaled first.
        let t = Transform::translate(DVec3::new(1.0, 0.0, 0.0));
        let s = Transform::scale(DVec3::splat(2.0)).unwrap();
        let m = t.then_apply(&s);
        assert!(close(m.point(DVec3::new(1.0, 0.0, 0.0)), DVec3::new(3.0, 0.0, 0.0)));
        assert!(close(m.inv.transform_point3(DVec3::new(3.0, 0.0, 0.0)), DVec3::X));
    }

    #[test]
    fn normals_use_the_inverse_transpose() {
        // Squash y: a 45° surface's normal tilts toward y.
        let s = Transform::scale(DVec3::new(1.0, 0.5, 1.0)).unwrap();
        let tangent = s.vector(DVec3::new(1.0, -1.0, 0.0));
        let n = s.normal(DVec3::new(1.0, 1.0, 0.0));
        assert!(tangent.dot(n).abs() < 1e-12);
    }

    #[test]
    fn singular_and_degenerate_transforms_are_refused() {
        assert!(Transform::scale(DVec3::new(1.0, 0.0, 1.0)).is_none());
        assert!(Transform::rotate(DVec3::ZERO, 30.0).is_none());
    }
}
