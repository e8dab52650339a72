//! What the structures' own tests are built over: a deterministic random number
//! generator (from [`crate::test_rng`]) and a plain soup of triangles. (The cross-checks
//! against brute force on every kind of primitive live on the geometry floor:
//! `crate::geometry`.)

use super::PrimitiveSet;
use crate::aabb::Aabb;
use crate::hit::Hit;
use crate::math::Vec3A;
use crate::ray::PreparedRay;
use crate::shape::triangle;

pub use crate::test_rng::Rng;

/// Triangles given by their corners.
pub struct Triangles(pub Vec<[Vec3A; 3]>);

impl Triangles {
    /// `n` random triangles of size about 1.5 scattered over a cube of side 20.
    pub fn random(seed: u64, n: usize) -> Triangles {
        let mut rng = Rng(seed);
        Triangles(
            (0..n)
                .map(|_| {
                    let c = rng.vec(10.0);
                    [c + rng.vec(1.5), c + rng.vec(1.5), c + rng.vec(1.5)]
                })
                .collect(),
        )
    }

    /// A "teapot in a stadium": `n` random triangles about 0.01 wide in the unit cube, and
    /// one more 10⁴ away, so that the scene is a million times the detail's size.
    pub fn detail_in_a_stadium(seed: u64, n: usize) -> Triangles {
        let mut rng = Rng(seed);
        let mut tris: Vec<[Vec3A; 3]> = (0..n)
            .map(|_| {
                let c = rng.vec(0.5) + Vec3A::splat(0.5);
                [c + rng.vec(0.01), c + rng.vec(0.01), c + rng.vec(0.01)]
            })
            .collect();
        let far = Vec3A::splat(1e4);
        tris.push([far, far + Vec3A::X, far + Vec3A::Y]);
        Triangles(tris)
    }
}

impl PrimitiveSet for Triangles {
    fn count(&self) -> usize {
        self.0.len()
    }

    fn bounds(&self, i: u32) -> Aabb {
        Aabb::from_points(&self.0[i as usize])
    }

    fn triangle(&self, i: u32) -> Option<[Vec3A; 3]> {
        Some(self.0[i as usize])
    }

    fn intersect(&self, i: u32, ray: &PreparedRay, t_max: f32) -> Option<Hit> {
        let [a, b, c] = self.0[i as usize];
        triangle::intersect(ray, a, b, c, t_max).map(|h| Hit::new(h.t, i, h.b1, h.b2))
    }
}
