//! Scene command: `camera ex ey ez cx cy cz ux uy uz fovy` — a pinhole camera at E
//! looking at C, with up hint U and the full vertical field of view in degrees
//! (SCENE_FORMAT.md §3.2). The frame is `w = normalize(E − C)`, `u = normalize(U × w)`,
//! `v = w × u`; row 0 of the image is the top.

use crate::math::{DVec3, Vec3A};
use crate::ray::Ray;

#[derive(Clone, Copy, Debug)]
pub struct Camera {
    eye: DVec3,
    u: DVec3,
    v: DVec3,
    w: DVec3,
    tan_half_fovy: f64,
    width: f64,
    height: f64,
}

/// Why a camera cannot be built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CameraError {
    FovOutOfRange,
    EyeAtTarget,
    UpParallelToView,
}

impl Camera {
    pub fn look_at(
        eye: DVec3,
        center: DVec3,
        up: DVec3,
        fovy_degrees: f64,
        width: u32,
        height: u32,
    ) -> Result<Camera, CameraError> {
        if !(fovy_degrees > 0.0 && fovy_degrees < 180.0) {
            return Err(CameraError::FovOutOfRange);
        }
        let view = eye - center;
        if view.length() == 0.0 {
            return Err(CameraError::EyeAtTarget);
        }
        let w = view.normalize();
        let side = up.cross(w);
        if side.length() <= 1e-12 * up.length().max(1e-300) {
            return Err(CameraError::UpParallelToView);
        }
        let u = side.normalize();
        let v = w.cross(u);
        Ok(Camera {
            eye,
            u,
            v,
            w,
            tan_half_fovy: (fovy_degrees.to_radians() * 0.5).tan(),
            width: width as f64,
            height: height as f64,
        })
    }

    /// The ray through the image point (`x`, `y`) in pixel units: column `j` and row `i`
    /// have their centre at `(j + 0.5, i + 0.5)`.
    pub fn ray(&self, x: f64, y: f64) -> Ray {
        let a = self.tan_half_fovy * (self.width / self.height) * (2.0 * x / self.width - 1.0);
        let b = self.tan_half_fovy * (1.0 - 2.0 * y / self.height);
        let d = (self.u * a + self.v * b - self.w).normalize();
        Ray::new(
            Vec3A::new(self.eye.x as f32, self.eye.y as f32, self.eye.z as f32),
            Vec3A::new(d.x as f32, d.y as f32, d.z as f32),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centre_ray_looks_at_the_target_and_corners_span_the_fov() {
        let c = Camera::look_at(DVec3::new(0.0, 0.0, 5.0), DVec3::ZERO, DVec3::Y, 90.0, 200, 100).unwrap();
        let r = c.ray(100.0, 50.0);
        assert!((r.dir - Vec3A::new(0.0, 0.0, -1.0)).length() < 1e-7);
        // Top edge at 45°; right edge at atan(2) because tan(fovx/2) = tan(fovy/2)·W/H.
        let top = c.ray(100.0, 0.0).dir;
        assert!((top.y / -top.z - 1.0).abs() < 1e-6);
        let right = c.ray(200.0, 50.0).dir;
        assert!((right.x / -right.z - 2.0).abs() < 1e-6);
    }

    #[test]
    fn up_hint_need_not_be_perpendicular() {
        let c = Camera::look_at(
            DVec3::new(0.0, -4.0, 4.0),
            DVec3::new(0.0, -1.0, 0.0),
            DVec3::new(0.0, 1.0, 1.0),
            45.0,
            64,
            48,
        )
        .unwrap();
        let up = c.ray(32.0, 0.0).dir - c.ray(32.0, 48.0).dir;
        assert!(up.y > 0.0 && up.z > 0.0);
    }

    #[test]
    fn degenerate_cameras_are_refused() {
        let bad = |e: DVec3, c: DVec3, u: DVec3, f: f64| Camera::look_at(e, c, u, f, 10, 10).unwrap_err();
        assert_eq!(bad(DVec3::Z, DVec3::ZERO, DVec3::Y, 0.0), CameraError::FovOutOfRange);
        assert_eq!(bad(DVec3::Z, DVec3::ZERO, DVec3::Y, 180.0), CameraError::FovOutOfRange);
        assert_eq!(bad(DVec3::Z, DVec3::Z, DVec3::Y, 45.0), CameraError::EyeAtTarget);
        assert_eq!(
            bad(DVec3::Z, DVec3::ZERO, DVec3::new(0.0, 0.0, 3.0), 45.0),
            CameraError::UpParallelToView
        );
    }
}
