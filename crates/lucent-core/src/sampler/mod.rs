//! Deterministic random numbers for everything that samples: pixel positions
//! (`spp`), lens positions (`lens`), points on area lights (`quadLight`), glossy
//! directions (`glossy`) and the bounces of the Monte Carlo integrators.
//!
//! Every number depends only on (seed, pixel, sample index, dimension): a pixel's samples
//! do not depend on which thread renders it, in what order, or how many samples the
//! render asks for in all, so the picture is the same bytes for any thread count and
//! more samples can be added later. Two sources (the `sampler` command):
//!
//! - `independent`: every number is a hash of the four.
//! - `sobol`: an Owen-scrambled Sobol sequence per pixel ([`sobol`]), *padded*: each draw
//!   of one or two numbers is its own 1-D or 2-D Sobol sequence over the pixel's sample
//!   indices, scrambled and shuffled by a hash of (seed, pixel, draw). Any 2ᵏ consecutive
//!   samples of a pixel then cover every 2-D draw (pixel position, lens, light point,
//!   bounce direction) evenly, while different draws stay independent of each other, so
//!   paths of any length can draw as many numbers as they need. The seed 0 is the
//!   default.

pub mod sobol;
pub mod sobol_block;

use sobol_block::{Block, BLOCK};

/// Where a sampler's numbers come from (`sampler independent|sobol`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SamplerKind {
    Independent,
    Sobol,
}

impl SamplerKind {
    /// The names the scene file and the command line use.
    pub const ALL: [(&'static str, SamplerKind); 2] =
        [("independent", SamplerKind::Independent), ("sobol", SamplerKind::Sobol)];

    pub fn name(self) -> &'static str {
        match self {
            SamplerKind::Independent => "independent",
            SamplerKind::Sobol => "sobol",
        }
    }
}

/// The random numbers of one sample of one pixel, drawn in a fixed order.
#[derive(Clone, Debug)]
pub struct Sampler {
    /// Independent: the hash of (seed, pixel, sample). Sobol: the hash of (seed, pixel)
    /// that seeds every draw's scramble.
    key: u64,
    /// How many draws came before this one.
    dimension: u64,
    /// Sobol: the sample's index in the pixel's sequences, its bits reversed (the order
    /// the scrambles work in); `None` for independent numbers.
    sobol_index: Option<u32>,
    /// Sobol: the numbers of the block of [`BLOCK`] draws that the last draw belongs to,
    /// made together when its first draw was asked for ([`sobol_block`]).
    block: Block,
}

/// SplitMix64's finaliser: a bijection of u64 with good avalanche.
#[inline(always)]
fn mix(mut z: u64) -> u64 {
    let [m1, m2] = MIX_MULTIPLIERS;
    z = (z ^ (z >> 30)).wrapping_mul(m1);
    z = (z ^ (z >> 27)).wrapping_mul(m2);
    z ^ (z >> 31)
}

/// [`mix`]'s multipliers (shared with the vector code of [`sobol_block`]).
const MIX_MULTIPLIERS: [u64; 2] = [0xbf58_476d_1ce4_e5b9, 0x94d0_49bb_1331_11eb];

impl Sampler {
    /// Sample `sample` of pixel (x, y), with numbers of the given kind.
    pub fn start(kind: SamplerKind, seed: u64, x: u32, y: u32, sample: u32) -> Sampler {
        match kind {
            SamplerKind::Independent => Sampler::new(seed, x, y, sample),
            SamplerKind::Sobol => {
                let pixel = (y as u64) << 32 | x as u64;
                let index = sample.reverse_bits();
                Sampler {
                    key: mix(pixel ^ 0x5851_f42d_4c95_7f2d) ^ mix(seed),
                    dimension: 0,
                    sobol_index: Some(index),
                    block: Block::default(),
                }
            }
        }
    }

    /// Sample `sample` of pixel (x, y), with independent numbers.
    pub fn new(seed: u64, x: u32, y: u32, sample: u32) -> Sampler {
        let pixel = (y as u64) << 32 | x as u64;
        Sampler {
            // `mix(0) = 0`: seed 0 leaves the key of the unseeded sequence.
            key: mix(mix(pixel) ^ (sample as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15)) ^ mix(seed),
            dimension: 0,
            sobol_index: None,
            block: Block::default(),
        }
    }

    /// The hash that picks the next draw's numbers.
    #[inline]
    fn next_draw(&mut self) -> u64 {
        self.dimension += 1;
        sobol_block::draw_hash(self.key, self.dimension)
    }

    /// The next number, uniform in [0, 1).
    #[inline(always)]
    pub fn uniform(&mut self) -> f32 {
        match self.sobol_index {
            // A draw of one number is the first of a two-number draw's.
            Some(_) => self.uniform2().0,
            // 24 random bits: every value is exactly representable and below 1.
            None => (self.next_draw() >> 40) as f32 * (1.0 / (1u64 << 24) as f32),
        }
    }

    /// The next two numbers, uniform in the unit square (with Sobol numbers, the first two
    /// dimensions of one scrambled sequence: a (0, 2)-sequence over the pixel's samples).
    #[inline(always)]
    pub fn uniform2(&mut self) -> (f32, f32) {
        match self.sobol_index {
            // Draws come in blocks made together (their numbers do not depend on the
            // path, so they can be made before it asks for them).
            Some(i) => {
                let slot = (self.dimension % BLOCK as u64) as usize;
                if slot == 0 {
                    self.block = sobol_block::draws(self.key, self.dimension + 1, i);
                }
                self.dimension += 1;
                (self.block.x[slot], self.block.y[slot])
            }
            None => (self.uniform(), self.uniform()),
        }
    }
}

/// Sample `i` of `n` in the unit square: on a jittered √n × √n grid when `n` is a
/// square (one sample per cell, at a random point of it), uniform otherwise. `(u, v)` are
/// the sample's two random numbers.
pub fn stratified(i: u32, n: u32, u: f32, v: f32) -> (f32, f32) {
    let k = (n as f64).sqrt().round() as u32;
    // (In u64: the root of a count near 2³² squares past u32.)
    if k as u64 * k as u64 == n as u64 && n > 1 {
        let (cx, cy) = (i % k, i / k);
        ((cx as f32 + u) / k as f32, (cy as f32 + v) / k as f32)
    } else {
        (u, v)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_depend_only_on_pixel_sample_and_dimension() {
        let draw = |seed: u64, x: u32, y: u32| -> Vec<f32> {
            let mut s = Sampler::new(seed, x, y, 5);
            (0..8).map(|_| s.uniform()).collect()
        };
        let a = draw(0, 3, 4);
        assert_eq!(a, draw(0, 3, 4));
        assert_ne!(a[0], draw(0, 4, 3)[0]);
        let seeded = draw(7, 3, 4);
        assert!(
            a.iter().zip(&seeded).all(|(x, y)| x != y),
            "another seed, other numbers"
        );
        assert!(a.iter().all(|&x| (0.0..1.0).contains(&x)));
    }

    #[test]
    fn numbers_are_uniform() {
        // 64 bins over 64k draws from many pixels: every bin near 1/64.
        let mut bins = [0u32; 64];
        for p in 0..1024u32 {
            let mut s = Sampler::new(0, p % 37, p / 37, p % 5);
            for _ in 0..64 {
                bins[(s.uniform() * 64.0) as usize] += 1;
            }
        }
        assert!(bins.iter().all(|&b| (850..1200).contains(&b)), "{bins:?}");
    }

    #[test]
    fn a_pixels_sobol_samples_cover_every_draw_evenly() {
        // Samples 16..32 of a pixel: for each of the first five draws (of one or two
        // numbers), one number in each sixteenth of [0, 1), or one point in each cell of
        // a 4 × 4 grid.
        let draws = |x: u32| -> Vec<Vec<(f32, f32)>> {
            (16..32)
                .map(|i| {
                    let mut s = Sampler::start(SamplerKind::Sobol, 0, x, 9, i);
                    vec![
                        s.uniform2(),
                        (s.uniform(), 0.0),
                        s.uniform2(),
                        s.uniform2(),
                        (s.uniform(), 0.0),
                    ]
                })
                .collect()
        };
        let samples = draws(4);
        for d in 0..5 {
            let mut cells = [false; 16];
            for sample in &samples {
                let (u, v) = sample[d];
                let c = if d == 1 || d == 4 {
                    (u * 16.0) as usize
                } else {
                    (v * 4.0) as usize * 4 + (u * 4.0) as usize
                };
                assert!(
                    !std::mem::replace(&mut cells[c], true),
                    "draw {d}: two samples in cell {c}"
                );
            }
        }
        // Each pixel its own scramble; each draw its own sequence.
        assert_ne!(samples[0], draws(5)[0]);
        assert_ne!(samples[0][0], samples[0][2]);
        // The independent kind is the hashed numbers.
        let (mut a, mut b) = (
            Sampler::start(SamplerKind::Independent, 3, 1, 2, 7),
            Sampler::new(3, 1, 2, 7),
        );
        assert_eq!(a.uniform2(), b.uniform2());
    }

    #[test]
    fn sobol_draws_made_in_blocks_are_each_dimensions_own() {
        // Draw d of a sample is point `sample` of sequence d (its first number, for a
        // draw of one), whatever was drawn before it: the numbers made in blocks are the
        // ones a sampler computing each dimension when asked gives.
        for sample in [0u32, 1, 7, 300] {
            let mut s = Sampler::start(SamplerKind::Sobol, 5, 3, 4, sample);
            let mut direct = s.clone();
            let i = sample.reverse_bits();
            for d in 0..3 * BLOCK + 3 {
                let want = sobol::sample2(i, sobol_block::seeds(direct.next_draw()));
                if d % 3 == 1 {
                    assert_eq!(s.uniform(), want.0, "sample {sample}, draw {d}");
                } else {
                    assert_eq!(s.uniform2(), want, "sample {sample}, draw {d}");
                }
            }
        }
    }

    #[test]
    fn square_counts_put_one_sample_in_each_cell() {
        let mut cells = [false; 16];
        let mut s = Sampler::new(0, 0, 0, 0);
        for i in 0..16 {
            let (x, y) = stratified(i, 16, s.uniform(), s.uniform());
            let c = (y * 4.0) as usize * 4 + (x * 4.0) as usize;
            assert!(!cells[c]);
            cells[c] = true;
        }
        assert_eq!(stratified(2, 3, 0.25, 0.75), (0.25, 0.75));
        // The largest count: not a square, and no overflow finding that out.
        assert_eq!(stratified(7, u32::MAX, 0.5, 0.5), (0.5, 0.5));
    }
}
