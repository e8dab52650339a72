//! What the structures' own tests are built over: a deterministic random number
//! generator and a plain soup of triangles. (The cross-checks against brute force on
//! every kind of primitive live on the geometry floor: `crate::geometry`.)

use super::PrimitiveSet;
use crate::aabb::Aabb;
use crate::hit::Hit;
use crate::math::Vec3A;
use crate::ray::PreparedRay;
use crate::shape::triangle;

pub struct Rng(pub u64);
impl Rng {
    pub fn next(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 40) as f32) / (1u64 << 24) as f32
    }
    pub fn range(&mut self, a: f32, b: f32) -> f32 {
        a + (b - a) * self.next()
    }
    pub fn vec(&mut self, s: f32) -> Vec3A {
        Vec3A::new(self.range(-s, s), self.range(-s, s), self.range(-s, s))
    }
}

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
