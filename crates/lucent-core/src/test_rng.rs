//! A small deterministic random number generator for the tests of every floor (a
//! 64-bit linear congruential generator; its high bits are uniform enough for
//! choosing test geometry, and a fixed seed gives every run the same cases).

use crate::math::Vec3A;

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
