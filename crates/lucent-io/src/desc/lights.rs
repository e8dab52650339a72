//! Lights as the file gives them: `directional`, `point` (with the `attenuation` current
//! at its command) and `quadLight`, each with the transform current at its command.

use glam::DVec3;

use crate::diag::Loc;

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LightKind {
    /// `dir` points toward the light.
    Directional { dir: DVec3, color: DVec3 },
    Point {
        position: DVec3,
        color: DVec3,
        attenuation: DVec3,
    },
    Quad {
        a: DVec3,
        ab: DVec3,
        ac: DVec3,
        color: DVec3,
    },
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightDesc {
    pub kind: LightKind,
    /// Index into the description's transforms.
    pub transform: u32,
    pub loc: Loc,
}
