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
