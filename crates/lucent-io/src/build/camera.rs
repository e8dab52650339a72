//! The camera: `camera` or `orthocamera` made into a core camera (the frame must exist:
//! the eye apart from the look-at point, the up vector not along the view, a field of
//! view or view height in range), with the thin `lens` for perspective cameras.

use lucent_core::camera::{Camera, CameraError, Projection};

use crate::desc::{ProjectionDesc, SceneDesc};
use crate::diag::Diagnostics;

/// The scene's camera, or `None` after an error (or when the parser found none).
pub fn camera(desc: &SceneDesc, diags: &mut Diagnostics) -> Option<Camera> {
    let c = &desc.camera.as_ref()?.value;
    let (name, projection) = match c.projection {
        ProjectionDesc::Perspective { fovy } => ("camera", Projection::Perspective { fovy }),
        ProjectionDesc::Orthographic { height } => ("orthocamera", Projection::Orthographic { height }),
    };
    let camera = match Camera::new(c.eye, c.center, c.up, projection) {
        Ok(camera) => camera,
        Err(e) => {
            let (loc, msg) = match (e, c.projection) {
                (CameraError::FovOutOfRange, ProjectionDesc::Perspective { fovy }) => (
                    c.spans.angle,
                    format!("camera: field of view must be between 0 and 180 degrees, got {fovy}"),
                ),
                (CameraError::HeightNotPositive, ProjectionDesc::Orthographic { height }) => (
                    c.spans.angle,
                    format!("orthocamera: the view height must be positive, got {height}"),
                ),
                (CameraError::EyeAtTarget, _) => (
                    c.spans.eye_center,
                    format!("{name}: the eye and the look-at point are the same"),
                ),
                (CameraError::UpParallelToView, _) => (
                    c.spans.up,
                    format!("{name}: the up vector is parallel to the viewing direction"),
                ),
                (e, _) => (c.spans.angle, format!("{name}: {e:?}")),
            };
            diags.error(loc, msg);
            return None;
        }
    };
    let Some(lens) = &desc.lens else {
        return Some(camera);
    };
    let (aperture, focus) = lens.value;
    if name == "orthocamera" {
        diags.error(
            lens.loc,
            "lens: depth of field needs the perspective camera (this scene uses orthocamera)",
        );
        return None;
    }
    Some(camera.with_lens(aperture, focus))
}
