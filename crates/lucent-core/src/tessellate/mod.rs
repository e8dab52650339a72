//! Floor 4 — surfaces that are rendered as triangle meshes: bicubic Bézier patches
//! (`bezierpatches`), NURBS surfaces (`nurbs`), subdivision surfaces (`subdivmesh`) and
//! displacement (`displacementmap`). Each turns a recipe into a
//! [`crate::geometry::mesh::TriangleMesh`]; the build step (in `lucent-io`) decides when.

pub mod bezier;
pub mod displacement;
pub mod grid;
pub mod nurbs;
pub mod subdivision;
