//! The camera: `camera eye center up fovy`, `orthocamera eye center up height` (either is
//! the scene's camera; the last one given wins) and `lens aperture focusdistance`. The
//! build checks that they make a camera.

use glam::DVec3;

use super::lexer::Command;
use super::parser::Parser;
use crate::desc::{CameraDesc, CameraSpans, Located, ProjectionDesc};

impl Parser {
    /// `camera … fovy` and `orthocamera … height`.
    pub(super) fn camera(&mut self, c: &Command) {
        let Some(v) = self.nums::<10>(c) else { return };
        let projection = if c.name.text == "orthocamera" {
            ProjectionDesc::Orthographic { height: v[9] }
        } else {
            ProjectionDesc::Perspective { fovy: v[9] }
        };
        let camera = CameraDesc {
            eye: DVec3::new(v[0], v[1], v[2]),
            center: DVec3::new(v[3], v[4], v[5]),
            up: DVec3::new(v[6], v[7], v[8]),
            projection,
            spans: CameraSpans {
                eye_center: self.span(c, 0, 6),
                up: self.span(c, 6, 3),
                angle: self.span(c, 9, 1),
            },
        };
        let v = Located {
            value: camera,
            loc: self.loc(c.line, &c.name),
        };
        self.set_global(c, |d| &mut d.camera, v);
    }

    /// `lens aperture focusdistance`: aperture ≥ 0 (0 is the pinhole), focus > 0.
    pub(super) fn lens(&mut self, c: &Command) {
        let Some([aperture, focus]) = self.nums::<2>(c) else {
            return;
        };
        if aperture < 0.0 {
            self.err_arg(
                c,
                0,
                format!("lens: the aperture must not be negative, got {}", c.args[0].text),
            );
            return;
        }
        if !(focus > 0.0) {
            self.err_arg(
                c,
                1,
                format!("lens: the focus distance must be positive, got {}", c.args[1].text),
            );
            return;
        }
        let v = Located {
            value: (aperture, focus),
            loc: self.loc(c.line, &c.name),
        };
        self.set_global(c, |d| &mut d.lens, v);
    }
}
