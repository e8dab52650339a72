//! Piecewise-constant distributions, drawn by inverting their cumulative sums: over n
//! equal intervals of [0, 1) ([`Distribution1D`], also a discrete choice among n items)
//! and over a grid of cells of the unit square ([`Distribution2D`]: a row by the marginal
//! distribution, then a column by the row's own). The environment light draws texels
//! with them. [`AliasTable`] is a discrete choice in constant time (Walker's alias
//! method): the emissive surfaces draw one of possibly millions of primitives with it,
//! where a binary search over a table that does not fit in the cache would cost a cache
//! miss per step.
//!
//! Sums are kept in f64: a 100,000-item distribution summed in f32 would lose the
//! smallest items to rounding.
//!
//! Inverting the cumulative sums is a search, and a binary search is a chain of
//! dependent loads (an environment map's rows of a thousand cells: ten of them per draw,
//! a fifth of a sky-lit path tracer's time). A guide table (Chen and Asau's index table)
//! says, for each of n equal parts of [0, 1), the last item whose sum starts at or before
//! the part's start, so that the search only covers the items that start within the
//! part: one or two for a smooth distribution. The item found is the binary search's,
//! always (a check falls back to the whole search where rounding might have put the part
//! off by one).

use super::ONE_BELOW;

/// A density proportional to `weights[i]` on `[i/n, (i+1)/n)`.
#[derive(Clone, Debug)]
pub struct Distribution1D {
    /// `cdf[i]` = (weights[0] + … + weights[i−1]) / total; `cdf[n]` = 1.
    cdf: Vec<f64>,
    /// `guide[k]`: the last i with `cdf[i] ≤ k / n`, for k in 0..n (see the module).
    guide: Vec<u32>,
    weights: Vec<f32>,
    total: f64,
}

impl Distribution1D {
    /// `None` when there is nothing to draw: no weights, or all of them zero. Negative
    /// and non-finite weights count as zero.
    pub fn new(weights: Vec<f32>) -> Option<Distribution1D> {
        let weights: Vec<f32> = weights
            .into_iter()
            .map(|w| if w.is_finite() && w > 0.0 { w } else { 0.0 })
            .collect();
        let mut cdf = Vec::with_capacity(weights.len() + 1);
        let mut sum = 0f64;
        cdf.push(0.0);
        for &w in &weights {
            sum += w as f64;
            cdf.push(sum);
        }
        if !(sum > 0.0 && sum.is_finite()) {
            return None;
        }
        for c in &mut cdf {
            *c /= sum;
        }
        *cdf.last_mut().unwrap() = 1.0;
        // (Distributions of more items than a u32 counts go without the table.)
        let n = weights.len();
        let parts = if n <= u32::MAX as usize { n } else { 0 };
        let mut guide = Vec::with_capacity(parts);
        let mut i = 0;
        for k in 0..parts {
            let start = k as f64 / n as f64;
            while i + 1 < cdf.len() && cdf[i + 1] <= start {
                i += 1;
            }
            guide.push(i as u32);
        }
        Some(Distribution1D {
            cdf,
            guide,
            weights,
            total: sum,
        })
    }

    pub fn len(&self) -> usize {
        self.weights.len()
    }

    pub fn is_empty(&self) -> bool {
        self.weights.is_empty()
    }

    /// The sum of the weights.
    pub fn total(&self) -> f64 {
        self.total
    }

    /// The item `u` ∈ [0, 1) falls in: never one of weight zero.
    #[inline]
    fn find(&self, u: f32) -> usize {
        // The last i with cdf[i] ≤ u; items of weight zero have cdf[i] = cdf[i+1] and
        // are skipped because the search takes the last such i.
        let i = self.last_at_or_below(u as f64);
        let mut i = i.min(self.weights.len() - 1);
        // u rounding to 1 lands past the end: step back to an item that has weight.
        while self.weights[i] == 0.0 && i > 0 {
            i -= 1;
        }
        i
    }

    /// The last i with `cdf[i] ≤ u` (0 when there is none): the binary search
    /// `cdf.partition_point(|c| c <= u) − 1`, narrowed by the guide table.
    #[inline]
    fn last_at_or_below(&self, u: f64) -> usize {
        let whole = || self.cdf.partition_point(|&c| c <= u).saturating_sub(1);
        let m = self.guide.len();
        if m == 0 {
            return whole();
        }
        // The part u falls in (NaN and negative u: the first; u ≥ 1: the last).
        let k = ((u * m as f64) as usize).min(m - 1);
        let lo = self.guide[k] as usize;
        let hi = match self.guide.get(k + 1) {
            Some(&g) => g as usize + 1,
            None => self.cdf.len(),
        };
        // The answer is in lo..hi when cdf[lo] ≤ u < cdf[hi]; rounding of u·m (or a NaN)
        // can break that, and then the whole search answers.
        if self.cdf[lo] <= u && self.cdf.get(hi).is_none_or(|&c| c > u) {
            lo + self.cdf[lo..hi].partition_point(|&c| c <= u) - 1
        } else {
            whole()
        }
    }

    /// A discrete choice: item i with probability weights[i] / total, and `u` rescaled
    /// to [0, 1) within the item (so it can be used again).
    #[inline]
    pub fn sample_discrete(&self, u: f32) -> (usize, f32, f32) {
        let i = self.find(u);
        let (lo, hi) = (self.cdf[i], self.cdf[i + 1]);
        let rest = (((u as f64 - lo) / (hi - lo)) as f32).clamp(0.0, ONE_BELOW);
        (i, self.probability(i), rest)
    }

    /// The probability of item i in [`Distribution1D::sample_discrete`].
    #[inline]
    pub fn probability(&self, i: usize) -> f32 {
        (self.weights[i] as f64 / self.total) as f32
    }

    /// A point of [0, 1) drawn with the piecewise-constant density, with that density
    /// and the interval it is in.
    #[inline]
    pub fn sample_continuous(&self, u: f32) -> (f32, f32, usize) {
        let (i, _, rest) = self.sample_discrete(u);
        let x = ((i as f32 + rest) / self.len() as f32).min(ONE_BELOW);
        (x, self.density(i), i)
    }

    /// The density on interval i: weights[i] · n / total.
    #[inline]
    pub fn density(&self, i: usize) -> f32 {
        (self.weights[i] as f64 * self.len() as f64 / self.total) as f32
    }

    /// The density at `x` ∈ [0, 1].
    #[inline]
    pub fn density_at(&self, x: f32) -> f32 {
        let i = ((x * self.len() as f32) as usize).min(self.len() - 1);
        self.density(i)
    }
}

/// A density on the unit square proportional to `weights[row · width + column]` on each
/// cell of a `width × height` grid; `(u, v)` with u along a row, v down the rows.
#[derive(Clone, Debug)]
pub struct Distribution2D {
    rows: Vec<Option<Distribution1D>>,
    marginal: Distribution1D,
}

impl Distribution2D {
    /// `None` when every weight is zero.
    pub fn new(width: usize, height: usize, weights: &[f32]) -> Option<Distribution2D> {
        assert_eq!(weights.len(), width * height);
        let rows: Vec<Option<Distribution1D>> = weights
            .chunks(width)
            .map(|row| Distribution1D::new(row.to_vec()))
            .collect();
        let marginal = Distribution1D::new(
            rows.iter()
                .map(|r| r.as_ref().map_or(0.0, |r| r.total() as f32))
                .collect(),
        )?;
        Some(Distribution2D { rows, marginal })
    }

    /// A point `(u, v)` of the unit square and its density.
    #[inline]
    pub fn sample(&self, a: f32, b: f32) -> ((f32, f32), f32) {
        let (v, pv, row) = self.marginal.sample_continuous(b);
        let r = self.rows[row].as_ref().expect("a row the marginal can draw has weight");
        let (u, pu, _) = r.sample_continuous(a);
        ((u, v), pu * pv)
    }

    /// The density of the point `(u, v)`.
    #[inline]
    pub fn density(&self, u: f32, v: f32) -> f32 {
        let row = ((v * self.rows.len() as f32) as usize).min(self.rows.len() - 1);
        match &self.rows[row] {
            Some(r) => self.marginal.density(row) * r.density_at(u),
            None => 0.0,
        }
    }
}

/// A discrete choice among n items with probabilities ∝ weights, in constant time: item
/// ⌊u·n⌋ is kept with probability `keep`, otherwise its `alias` is taken (Vose's
/// construction, in f64). 8 bytes an item.
#[derive(Clone, Debug)]
pub struct AliasTable {
    entries: Vec<AliasEntry>,
}

#[derive(Clone, Copy, Debug)]
struct AliasEntry {
    keep: f32,
    alias: u32,
}

impl AliasTable {
    /// `None` when every weight is zero (negative and non-finite weights count as zero).
    pub fn new(weights: &[f32]) -> Option<AliasTable> {
        let clean = |w: f32| if w.is_finite() && w > 0.0 { w as f64 } else { 0.0 };
        let total: f64 = weights.iter().map(|&w| clean(w)).sum();
        if !(total > 0.0 && total.is_finite()) {
            return None;
        }
        let n = weights.len();
        // Each item's weight in units of the mean: the table fills n cells of size 1.
        let mut scaled: Vec<f64> = weights.iter().map(|&w| clean(w) * n as f64 / total).collect();
        let mut entries = vec![AliasEntry { keep: 1.0, alias: 0 }; n];
        let (mut small, mut large): (Vec<usize>, Vec<usize>) = (0..n).partition(|&i| scaled[i] < 1.0);
        while let (Some(&s), Some(&l)) = (small.last(), large.last()) {
            small.pop();
            entries[s] = AliasEntry {
                keep: scaled[s] as f32,
                alias: l as u32,
            };
            scaled[l] -= 1.0 - scaled[s];
            if scaled[l] < 1.0 {
                large.pop();
                small.push(l);
            }
        }
        // What is left is 1 up to rounding: kept whole.
        for i in small.into_iter().chain(large) {
            entries[i] = AliasEntry {
                keep: 1.0,
                alias: i as u32,
            };
        }
        Some(AliasTable { entries })
    }

    /// The item `u` ∈ [0, 1) picks.
    #[inline]
    pub fn sample(&self, u: f32) -> usize {
        let n = self.entries.len();
        let x = u * n as f32;
        let i = (x as usize).min(n - 1);
        let e = self.entries[i];
        if x - (i as f32) < e.keep {
            i
        } else {
            e.alias as usize
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::Sampler;
    use crate::sampling::chi2::{pearson, SIGNIFICANCE};

    #[test]
    fn the_guide_table_finds_what_the_binary_search_finds() {
        // Smooth, peaked (one item with nearly all the weight, the rest crowded into a
        // few parts), with runs of zeros (leading, inside, trailing), and tiny ones.
        let mut sampler = Sampler::new(7, 3, 0, 0);
        let mut sets: Vec<Vec<f32>> = vec![
            vec![1.0],
            vec![0.0, 0.0, 1.0],
            vec![1.0, 0.0, 0.0],
            vec![0.0, 2.0, 0.0, 0.0, 3.0, 0.0],
            (0..1000).map(|i| if i == 500 { 1e6 } else { 1.0 }).collect(),
            (0..1000)
                .map(|i| if i % 7 == 0 { 0.0 } else { (i % 13) as f32 })
                .collect(),
            (0..300).map(|i| 1e-30 * i as f32).collect(),
        ];
        for n in [2, 3, 17, 64, 1025] {
            sets.push((0..n).map(|_| sampler.uniform().powi(4)).collect());
        }
        for weights in sets {
            let d = Distribution1D::new(weights).expect("some weight");
            let n = d.len();
            // Every sum and every part's start, each with its neighbouring doubles, and
            // random points, NaN, below 0 and from 1 on.
            let mut us: Vec<f64> = vec![f64::NAN, -1.0, -0.0, 0.0, 1.0, 1.5, f64::INFINITY];
            for x in d.cdf.iter().copied().chain((0..=n).map(|k| k as f64 / n as f64)) {
                us.extend([x, x.next_up(), x.next_down()]);
            }
            us.extend((0..2000).map(|_| sampler.uniform() as f64));
            for u in us {
                let want = d.cdf.partition_point(|&c| c <= u).saturating_sub(1);
                assert_eq!(d.last_at_or_below(u), want, "u = {u:e}, {n} items");
            }
        }
    }

    #[test]
    fn discrete_choices_follow_their_weights_and_skip_empty_items() {
        let d = Distribution1D::new(vec![1.0, 0.0, 3.0, 0.0, 4.0, 0.0]).unwrap();
        assert_eq!(d.probability(2), 3.0 / 8.0);
        let mut counts = [0f64; 6];
        let n = 200_000;
        for i in 0..n {
            let u = Sampler::new(7, i, 0, 0).uniform();
            let (k, p, rest) = d.sample_discrete(u);
            assert!((0.0..1.0).contains(&rest));
            assert_eq!(p, d.probability(k));
            counts[k] += 1.0;
        }
        assert_eq!((counts[1], counts[3], counts[5]), (0.0, 0.0, 0.0));
        let expected: Vec<f64> = [1.0, 3.0, 4.0].iter().map(|w| w / 8.0 * n as f64).collect();
        let observed = [counts[0], counts[2], counts[4]];
        let r = pearson(&observed, &expected).unwrap();
        assert!(r.p_value >= SIGNIFICANCE, "{r:?}");
        // The ends of [0, 1) land on items that have weight.
        assert_eq!(d.sample_discrete(0.0).0, 0);
        assert_eq!(d.sample_discrete(ONE_BELOW).0, 4);
        assert!(Distribution1D::new(vec![0.0, f32::NAN, -1.0]).is_none());
    }

    #[test]
    fn alias_tables_choose_in_proportion_to_the_weights() {
        let weights = [1.0, 0.0, 3.0, 0.5, 7.0, 0.0, 2.5, 1e-3];
        let table = AliasTable::new(&weights).unwrap();
        let total: f32 = weights.iter().sum();
        let mut counts = [0f64; 8];
        let n = 400_000;
        for i in 0..n {
            counts[table.sample(Sampler::new(4, i, 0, 0).uniform())] += 1.0;
        }
        assert_eq!(
            (counts[1], counts[5]),
            (0.0, 0.0),
            "items of weight zero are never drawn"
        );
        let keep: Vec<usize> = (0..8).filter(|&k| weights[k] > 0.0).collect();
        let observed: Vec<f64> = keep.iter().map(|&k| counts[k]).collect();
        let expected: Vec<f64> = keep.iter().map(|&k| (weights[k] / total) as f64 * n as f64).collect();
        let r = pearson(&observed, &expected).unwrap();
        assert!(r.p_value >= SIGNIFICANCE, "{r:?}");
        assert!(AliasTable::new(&[0.0, -1.0]).is_none());
        assert_eq!(AliasTable::new(&[2.0]).unwrap().sample(0.999), 0);
    }

    #[test]
    fn continuous_samples_follow_the_piecewise_constant_density() {
        let d = Distribution1D::new(vec![2.0, 0.0, 1.0, 5.0]).unwrap();
        assert_eq!(d.density_at(0.1), 2.0 * 4.0 / 8.0);
        assert_eq!(d.density_at(0.3), 0.0);
        // 64 bins, 16 per interval: uniform within each interval.
        let mut observed = vec![0f64; 64];
        let n = 256_000;
        for i in 0..n {
            let (x, p, k) = d.sample_continuous(Sampler::new(9, i, 0, 0).uniform());
            assert!((0.0..1.0).contains(&x));
            assert_eq!(k, (x * 4.0) as usize);
            assert_eq!(p, d.density_at(x));
            observed[(x * 64.0) as usize] += 1.0;
        }
        let expected: Vec<f64> = (0..64)
            .map(|b| d.density_at((b as f32 + 0.5) / 64.0) as f64 / 64.0 * n as f64)
            .collect();
        let r = pearson(&observed, &expected).unwrap();
        assert!(r.p_value >= SIGNIFICANCE, "{r:?}");
    }

    #[test]
    fn two_dimensional_samples_follow_their_density_and_integrate_to_one() {
        let (w, h) = (5, 3);
        let weights = [
            1.0, 2.0, 0.0, 0.0, 3.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.5, 0.5, 7.0, 1.0, 0.0,
        ];
        let d = Distribution2D::new(w, h, &weights).unwrap();
        let total: f32 = weights.iter().sum();
        let mut integral = 0.0;
        for (k, &wt) in weights.iter().enumerate() {
            let (u, v) = (((k % w) as f32 + 0.5) / w as f32, ((k / w) as f32 + 0.5) / h as f32);
            let p = d.density(u, v);
            assert!((p - wt / total * (w * h) as f32).abs() < 1e-5, "{k}: {p}");
            integral += p / (w * h) as f32;
        }
        assert!((integral - 1.0).abs() < 1e-5);
        let mut observed = vec![0f64; w * h];
        let n = 300_000;
        for i in 0..n {
            let (a, b) = Sampler::new(3, i, 0, 0).uniform2();
            let ((u, v), p) = d.sample(a, b);
            assert_eq!(p, d.density(u, v));
            observed[(v * h as f32) as usize * w + (u * w as f32) as usize] += 1.0;
        }
        let (mut obs, mut exp) = (Vec::new(), Vec::new());
        for k in 0..w * h {
            if weights[k] == 0.0 {
                assert_eq!(observed[k], 0.0, "cell {k}");
            } else {
                obs.push(observed[k]);
                exp.push(weights[k] as f64 / total as f64 * n as f64);
            }
        }
        let r = pearson(&obs, &exp).unwrap();
        assert!(r.p_value >= SIGNIFICANCE, "{r:?}");
        assert!(Distribution2D::new(2, 1, &[0.0, 0.0]).is_none());
    }
}
