//! Scene commands: `camera ex ey ez cx cy cz ux uy uz fovy` — a pinhole camera at E
//! looking at C, with up hint U and the full vertical field of view in degrees
//! (SCENE_FORMAT.md §3.2); `orthocamera … height` — parallel rays over a view `height`
//! world units tall; `lens aperture focus` — a thin lens of radius `aperture` focused at
//! distance `focus` (depth of field) for the perspective camera. The frame is
//! `w = normalize(E − C)`, `u = normalize(U × w)`, `v = w × u`; row 0 of the image is the
//! top.
//!
//! The camera does not know the image's size: a [`Resolution`] comes with every ray
//! request, from the render job, so a crop or a different size is a setting of the
//! render, not of the scene.

use crate::math::{DVec3, Vec3A};
use crate::ray::Ray;

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// Full vertical field of view in degrees.
    Perspective { fovy: f64 },
    /// World-space height of the view.
    Orthographic { height: f64 },
}

/// The size of the whole image in pixels: the camera's view is divided into this many
/// square pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Resolution {
    pub width: u32,
    pub height: u32,
}

impl Resolution {
    pub fn pixels(self) -> u64 {
        self.width as u64 * self.height as u64
    }
}

#[derive(Clone, Copy, Debug)]
pub struct Camera {
    eye: DVec3,
    u: DVec3,
    v: DVec3,
    w: DVec3,
    /// Half the view's height: at unit distance (perspective) or in world units
    /// (orthographic).
    half_height: f64,
    orthographic: bool,
    /// Thin lens: radius and focus distance.
    lens: Option<(f64, f64)>,
}

/// Why a camera cannot be built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CameraError {
    FovOutOfRange,
    /// An orthographic view height that is not positive.
    HeightNotPositive,
    EyeAtTarget,
    UpParallelToView,
}

impl Camera {
    /// A pinhole camera.
    pub fn look_at(eye: DVec3, center: DVec3, up: DVec3, fovy_degrees: f64) -> Result<Camera, CameraError> {
        Camera::new(eye, center, up, Projection::Perspective { fovy: fovy_degrees })
    }

    pub fn new(eye: DVec3, center: DVec3, up: DVec3, projection: Projection) -> Result<Camera, CameraError> {
        let (half_height, orthographic) = match projection {
            Projection::Perspective { fovy } => {
                if !(fovy > 0.0 && fovy < 180.0) {
                    return Err(CameraError::FovOutOfRange);
                }
                ((fovy.to_radians() * 0.5).tan(), false)
            }
            Projection::Orthographic { height } => {
                if !(height > 0.0 && height.is_finite()) {
                    return Err(CameraError::HeightNotPositive);
                }
                (0.5 * height, true)
            }
        };
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
            half_height,
            orthographic,
            lens: None,
        })
    }

    /// Adds a thin lens of radius `aperture` focused at distance `focus` (perspective
    /// cameras only; an aperture of 0 is the pinhole).
    pub fn with_lens(mut self, aperture: f64, focus: f64) -> Camera {
        debug_assert!(!self.orthographic && aperture >= 0.0 && focus > 0.0);
        self.lens = (aperture > 0.0).then_some((aperture, focus));
        self
    }

    /// Whether rays need lens samples (see [`Camera::ray`]).
    pub fn has_lens(&self) -> bool {
        self.lens.is_some()
    }

    /// The ray through the point (`x`, `y`), in pixel units, of an image of `resolution`:
    /// column `j` and row `i` have their centre at `(j + 0.5, i + 0.5)`. `lens` is a point
    /// of the unit square that picks the point of the lens the ray leaves from (ignored
    /// without a lens).
    pub fn ray(&self, resolution: Resolution, x: f64, y: f64, lens: (f32, f32)) -> Ray {
        let (width, height) = (resolution.width as f64, resolution.height as f64);
        let a = self.half_height * (width / height) * (2.0 * x / width - 1.0);
        let b = self.half_height * (1.0 - 2.0 * y / height);
        let (origin, dir) = if self.orthographic {
            (self.eye + self.u * a + self.v * b, -self.w)
        } else {
            let d = (self.u * a + self.v * b - self.w).normalize();
            match self.lens {
                None => (self.eye, d),
                Some((aperture, focus)) => {
                    // Every ray through the lens meets the pinhole ray on the plane of focus.
                    let focal_point = self.eye + d * (focus / d.dot(-self.w));
                    let (lx, ly) = concentric_disk(lens.0 as f64, lens.1 as f64);
                    let origin = self.eye + (self.u * lx + self.v * ly) * aperture;
                    (origin, (focal_point - origin).normalize())
                }
            }
        };
        Ray::new(
            Vec3A::new(origin.x as f32, origin.y as f32, origin.z as f32),
            Vec3A::new(dir.x as f32, dir.y as f32, dir.z as f32),
        )
    }
}

/// Shirley and Chiu's concentric map from the unit square to the unit disk: uniform, and
/// strata of the square stay compact on the disk.
pub fn concentric_disk(u: f64, v: f64) -> (f64, f64) {
    let (a, b) = (2.0 * u - 1.0, 2.0 * v - 1.0);
    if a == 0.0 && b == 0.0 {
        return (0.0, 0.0);
    }
    let (r, phi) = if a.abs() > b.abs() {
        (a, std::f64::consts::FRAC_PI_4 * (b / a))
    } else {
        (b, std::f64::consts::FRAC_PI_2 - std::f64::consts::FRAC_PI_4 * (a / b))
    };
    (r * phi.cos(), r * phi.sin())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centre_ray_looks_at_the_target_and_corners_span_the_fov() {
        let c = Camera::look_at(DVec3::new(0.0, 0.0, 5.0), DVec3::ZERO, DVec3::Y, 90.0).unwrap();
        let res = Resolution {
            width: 200,
            height: 100,
        };
        let r = c.ray(res, 100.0, 50.0, (0.5, 0.5));
        assert!((r.dir - Vec3A::new(0.0, 0.0, -1.0)).length() < 1e-7);
        // Top edge at 45°; right edge at atan(2) because tan(fovx/2) = tan(fovy/2)·W/H.
        let top = c.ray(res, 100.0, 0.0, (0.5, 0.5)).dir;
        assert!((top.y / -top.z - 1.0).abs() < 1e-6);
        let right = c.ray(res, 200.0, 50.0, (0.5, 0.5)).dir;
        assert!((right.x / -right.z - 2.0).abs() < 1e-6);
    }

    #[test]
    fn up_hint_need_not_be_perpendicular() {
        let c = Camera::look_at(
            DVec3::new(0.0, -4.0, 4.0),
            DVec3::new(0.0, -1.0, 0.0),
            DVec3::new(0.0, 1.0, 1.0),
            45.0,
        )
        .unwrap();
        let res = Resolution { width: 64, height: 48 };
        let up = c.ray(res, 32.0, 0.0, (0.5, 0.5)).dir - c.ray(res, 32.0, 48.0, (0.5, 0.5)).dir;
        assert!(up.y > 0.0 && up.z > 0.0);
    }

    #[test]
    fn orthographic_rays_are_parallel_and_span_the_height() {
        let ortho = Projection::Orthographic { height: 4.0 };
        let c = Camera::new(DVec3::new(0.0, 0.0, 5.0), DVec3::ZERO, DVec3::Y, ortho).unwrap();
        let res = Resolution {
            width: 200,
            height: 100,
        };
        let top = c.ray(res, 100.0, 0.0, (0.5, 0.5));
        let corner = c.ray(res, 200.0, 100.0, (0.5, 0.5));
        assert_eq!(top.dir, Vec3A::new(0.0, 0.0, -1.0));
        assert_eq!(corner.dir, top.dir);
        assert!((top.origin - Vec3A::new(0.0, 2.0, 5.0)).length() < 1e-6);
        assert!((corner.origin - Vec3A::new(4.0, -2.0, 5.0)).length() < 1e-6);
    }

    #[test]
    fn lens_rays_meet_on_the_plane_of_focus() {
        let c = Camera::look_at(DVec3::new(0.0, 0.0, 5.0), DVec3::ZERO, DVec3::Y, 60.0)
            .unwrap()
            .with_lens(0.5, 4.0);
        let pinhole = Camera::look_at(DVec3::new(0.0, 0.0, 5.0), DVec3::ZERO, DVec3::Y, 60.0).unwrap();
        let res = Resolution { width: 64, height: 48 };
        let p = pinhole.ray(res, 10.0, 7.0, (0.5, 0.5));
        let focus = p.at(4.0 / -p.dir.z);
        for lens in [(0.0, 0.0), (0.9, 0.2), (0.3, 0.99)] {
            let r = c.ray(res, 10.0, 7.0, lens);
            assert!((r.origin.z - 5.0).abs() < 1e-6 && r.origin.truncate().length() <= 0.5 + 1e-6);
            let at = r.at((focus.z - r.origin.z) / r.dir.z);
            assert!((at - focus).length() < 1e-4, "{at} vs {focus}");
        }
        // Uniform on the disk: the mean radius² of a grid of samples is 1/2.
        let mut sum = 0.0;
        for i in 0..100 {
            let (x, y) = concentric_disk((i % 10) as f64 / 10.0 + 0.05, (i / 10) as f64 / 10.0 + 0.05);
            sum += x * x + y * y;
        }
        assert!((sum / 100.0 - 0.5).abs() < 0.01, "{}", sum / 100.0);
    }

    #[test]
    fn degenerate_cameras_are_refused() {
        let bad = |e: DVec3, c: DVec3, u: DVec3, f: f64| Camera::look_at(e, c, u, f).unwrap_err();
        assert_eq!(bad(DVec3::Z, DVec3::ZERO, DVec3::Y, 0.0), CameraError::FovOutOfRange);
        assert_eq!(bad(DVec3::Z, DVec3::ZERO, DVec3::Y, 180.0), CameraError::FovOutOfRange);
        assert_eq!(bad(DVec3::Z, DVec3::Z, DVec3::Y, 45.0), CameraError::EyeAtTarget);
        assert_eq!(
            bad(DVec3::Z, DVec3::ZERO, DVec3::new(0.0, 0.0, 3.0), 45.0),
            CameraError::UpParallelToView
        );
    }
}
