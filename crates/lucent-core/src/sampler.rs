//! Deterministic random numbers for everything that samples: pixel positions
//! (`spp`), lens positions (`lens`), points on area lights (`quadLight`) and glossy
//! directions (`glossy`).
//!
//! Every number is a hash of (seed, pixel, sample index, dimension): a pixel's samples do
//! not depend on which thread renders it or in what order, so the picture is the same
//! bytes for any thread count. The seed belongs to the render job; seed 0 is the default.

/// The random numbers of one sample of one pixel, drawn in a fixed order.
#[derive(Clone, Debug)]
pub struct Sampler {
    key: u64,
    dimension: u64,
}

/// SplitMix64's finaliser: a bijection of u64 with good avalanche.
#[inline(always)]
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

impl Sampler {
    pub fn new(seed: u64, x: u32, y: u32, sample: u32) -> Sampler {
        let pixel = (y as u64) << 32 | x as u64;
        Sampler {
            // `mix(0) = 0`: seed 0 leaves the key of the unseeded sequence.
            key: mix(mix(pixel) ^ (sample as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15)) ^ mix(seed),
            dimension: 0,
        }
    }

    /// The next number, uniform in [0, 1).
    #[inline]
    pub fn uniform(&mut self) -> f32 {
        self.dimension += 1;
        let bits = mix(self.key ^ self.dimension.wrapping_mul(0xd1b5_4a32_d192_ed03));
        // 24 random bits: every value is exactly representable and below 1.
        (bits >> 40) as f32 * (1.0 / (1u64 << 24) as f32)
    }

    pub fn uniform2(&mut self) -> (f32, f32) {
        (self.uniform(), self.uniform())
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
