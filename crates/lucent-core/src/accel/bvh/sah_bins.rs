//! The binned surface area heuristic of the BVH build ([`super::binary`]): a node's
//! references sorted into `N` bins by centroid along each axis at once, and the cheapest
//! plane between bins priced by `A_l·P(N_l) + A_r·P(N_r)`, where `P(n) = ⌈n/4⌉` counts
//! the four-wide packets a leaf of `n` primitives needs. Only the planes between
//! occupied bins are priced (the choice pricing every plane makes, for less).

use super::build_ref::BuildRef;
use super::packet::LANES;
use crate::aabb::Aabb;
use crate::math::Vec3A;

/// Bins of nodes over at most [`FEW_BINS_UP_TO`] references, and of larger ones. 32
/// bins everywhere made primary rays 2.4 % faster and the build 27 % slower, most of it
/// clearing and pricing the larger bins of the many small nodes; 32 above 64 references
/// keeps most of the gain (1.5 %) at no measurable cost. (Also measured: 32 above 16
/// references, and 64 above 64: no faster, the build slower.)
pub(super) const FEW_BINS: usize = 16;
pub(super) const MANY_BINS: usize = 32;
pub(super) const FEW_BINS_UP_TO: usize = 64;
const _: () = assert!(
    FEW_BINS.is_power_of_two() && MANY_BINS.is_power_of_two() && MANY_BINS <= 256,
    "bin indices are masked with N - 1 and kept in 8 bits"
);
/// Nodes over more references than this bin them on the pool's threads, in chunks whose
/// bins are then merged (exactly: minima, maxima and counts).
pub(super) const PARALLEL_BINNING: usize = 1 << 16;

/// Truncates three non-negative bin coordinates at once (one SIMD conversion on x86-64).
#[inline(always)]
fn bin_indices(v: Vec3A) -> [u32; 4] {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: SSE2 is part of x86-64; the values are in [0, N) or NaN (→ 0x80000000,
    // masked to a valid bin by the caller).
    unsafe {
        use std::arch::x86_64::*;
        let i = _mm_cvttps_epi32(v.into());
        std::mem::transmute::<__m128i, [u32; 4]>(i)
    }
    #[cfg(not(target_arch = "x86_64"))]
    [v.x as u32, v.y as u32, v.z as u32, 0]
}

#[inline(always)]
pub(super) fn packets(n: usize) -> f32 {
    n.div_ceil(LANES) as f32
}

#[derive(Clone, Copy)]
pub(super) struct Bin {
    pub(super) lo: Vec3A,
    pub(super) hi: Vec3A,
    pub(super) count: u32,
}

pub(super) const EMPTY_BIN: Bin = Bin {
    lo: Vec3A::INFINITY,
    hi: Vec3A::NEG_INFINITY,
    count: 0,
};

pub(super) fn area(lo: Vec3A, hi: Vec3A) -> f32 {
    let e = (hi - lo).max(Vec3A::ZERO);
    e.x * e.y + e.y * e.z + e.z * e.x
}

pub(super) type Bins<const N: usize> = [[Bin; N]; 3];

/// Sorts the references' centroids into bins along the three axes (and notes each
/// one's bins in it).
fn bin_refs<const N: usize>(refs: &mut [BuildRef], lo: Vec3A, scale: Vec3A) -> Bins<N> {
    if refs.len() < TWO_BIN_SETS {
        let mut bins = [[EMPTY_BIN; N]; 3];
        for r in refs.iter_mut() {
            bin_ref(&mut bins, r, lo, scale);
        }
        return bins;
    }
    // Neighbouring references mostly fall into the same bins, and each bin update waits
    // for the one before it (load, min, store): alternating between two sets of bins
    // halves that chain. Merging them is exact (minima, maxima, counts).
    let (mut even, mut odd) = ([[EMPTY_BIN; N]; 3], [[EMPTY_BIN; N]; 3]);
    let mut pairs = refs.chunks_exact_mut(2);
    for pair in &mut pairs {
        let [a, b] = pair else { unreachable!("pairs") };
        bin_ref(&mut even, a, lo, scale);
        bin_ref(&mut odd, b, lo, scale);
    }
    for r in pairs.into_remainder() {
        bin_ref(&mut even, r, lo, scale);
    }
    merge_bins(even, odd)
}

/// Nodes over at least this many references bin them into two sets of bins.
const TWO_BIN_SETS: usize = 64;

/// Adds one reference to `bins` and notes its bins in it.
#[inline(always)]
fn bin_ref<const N: usize>(bins: &mut Bins<N>, r: &mut BuildRef, lo: Vec3A, scale: Vec3A) {
    let max_bin = Vec3A::splat((N - 1) as f32);
    // Both halves are read once, before `bins` is written (a 16-byte load of the half
    // that holds a 4-byte store still in flight waits for it).
    let (rlo, rhi) = (r.lo(), r.hi());
    let b = bin_indices(((rlo + rhi - lo) * scale).min(max_bin)).map(|i| i as usize & (N - 1));
    for (axis, bin_axis) in bins.iter_mut().enumerate() {
        let bin = &mut bin_axis[b[axis]];
        bin.lo = bin.lo.min(rlo);
        bin.hi = bin.hi.max(rhi);
        bin.count += 1;
    }
    r.set_bins([b[0], b[1], b[2]]);
}

/// The bins of two groups of references together.
fn merge_bins<const N: usize>(mut a: Bins<N>, b: Bins<N>) -> Bins<N> {
    for (axis_a, axis_b) in a.iter_mut().zip(&b) {
        for (x, y) in axis_a.iter_mut().zip(axis_b) {
            x.lo = x.lo.min(y.lo);
            x.hi = x.hi.max(y.hi);
            x.count += y.count;
        }
    }
    a
}

/// Sorts `refs` into bins between the bounds `cb` of their doubled centroids (on the
/// pool's threads when there are many), and the scale from centroid to bin per axis.
pub(super) fn bin_node<const N: usize>(refs: &mut [BuildRef], cb: &Aabb) -> (Bins<N>, Vec3A) {
    let extent = cb.max - cb.min;
    let lo = cb.min;
    // Axes with no extent get scale 0: everything lands in bin 0 and no plane is priced.
    let scale = Vec3A::select(
        extent.cmpgt(Vec3A::ZERO),
        Vec3A::splat(N as f32 * (1.0 - 1e-6)) / extent,
        Vec3A::ZERO,
    );
    let bins = if refs.len() > PARALLEL_BINNING {
        use rayon::prelude::*;
        refs.par_chunks_mut(PARALLEL_BINNING / 4)
            .map(|chunk| bin_refs(chunk, lo, scale))
            .reduce(|| [[EMPTY_BIN; N]; 3], merge_bins)
    } else {
        bin_refs(refs, lo, scale)
    };
    (bins, scale)
}

/// The boxes of the two sides of the plane before bin `split_bin` along `axis`: the
/// unions of their bins' boxes (minima and maxima are exact: the same bits as scanning
/// the references again).
pub(super) fn side_bounds<const N: usize>(bins: &Bins<N>, axis: usize, split_bin: usize) -> (Aabb, Aabb) {
    let union = |bins: &[Bin]| {
        bins.iter().fold(
            Aabb {
                min: Vec3A::INFINITY,
                max: Vec3A::NEG_INFINITY,
            },
            |b, bin| Aabb {
                min: b.min.min(bin.lo),
                max: b.max.max(bin.hi),
            },
        )
    };
    let bins = &bins[axis];
    (union(&bins[..split_bin]), union(&bins[split_bin..]))
}

/// No plane chosen (see [`cheapest_plane`]).
const NO_PLANE: u32 = u32::MAX;

/// The cheapest plane of `bins` by the SAH, as (cost, axis, first bin on the right);
/// `None` when no plane has references on both sides. Axes of `scale` 0 are not split.
pub(super) fn cheapest_plane<const N: usize>(bins: &Bins<N>, scale: Vec3A) -> Option<(f32, usize, usize)> {
    // The cheapest plane so far, as its cost and `axis << 8 | first bin on the right`
    // (none yet: cost ∞), chosen without branches: which candidate wins is data, and a
    // mispredicted branch per win cost more than the pricing.
    let (mut best_cost, mut best_plane) = (f32::INFINITY, NO_PLANE);
    for axis in 0..3 {
        if scale[axis] == 0.0 {
            continue;
        }
        let bins = &bins[axis];
        // Only planes between two occupied bins can split, and all planes in one gap
        // between them make the same two sides at the same cost: pricing the lowest plane
        // of each gap, in order, finds the split that pricing every plane finds (its
        // folds skip only empty bins, which change no bit), at the cost of the occupied
        // bins alone — few in the many small nodes near the leaves.
        let mut occupied = [0u8; N];
        let mut m = 0;
        for (k, bin) in bins.iter().enumerate() {
            occupied[m] = k as u8;
            m += (bin.count > 0) as usize;
        }
        let occupied = &occupied[..m];
        // right_cost[t]: the bins occupied[t..] on the right.
        let mut right_cost = [0.0f32; N];
        let (mut rlo, mut rhi, mut n) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY, 0usize);
        for t in (1..m).rev() {
            let bin = &bins[occupied[t] as usize];
            rlo = rlo.min(bin.lo);
            rhi = rhi.max(bin.hi);
            n += bin.count as usize;
            right_cost[t] = area(rlo, rhi) * packets(n);
        }
        let (mut llo, mut lhi, mut n) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY, 0usize);
        for t in 1..m {
            let bin = &bins[occupied[t - 1] as usize];
            llo = llo.min(bin.lo);
            lhi = lhi.max(bin.hi);
            n += bin.count as usize;
            let cost = area(llo, lhi) * packets(n) + right_cost[t];
            // (A NaN or infinite cost, from areas past f32's range, never wins.)
            let better = cost < best_cost;
            best_cost = if better { cost } else { best_cost };
            let plane = (axis as u32) << 8 | (occupied[t - 1] as u32 + 1);
            best_plane = if better { plane } else { best_plane };
        }
    }
    (best_plane != NO_PLANE).then_some((best_cost, (best_plane >> 8) as usize, (best_plane & 0xff) as usize))
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    const BINS: usize = FEW_BINS;

    /// Boxes of random sizes scattered over a 100-unit cube, the same for every run.
    pub(in crate::accel::bvh) fn boxes(n: u32) -> Vec<(u32, Aabb)> {
        let mut x = 0x9e37_79b9u32;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            x as f32 / u32::MAX as f32
        };
        (0..n)
            .map(|i| {
                let c = Vec3A::new(next(), next(), next()) * 100.0;
                let e = Vec3A::new(next(), next(), next());
                (i, Aabb { min: c - e, max: c + e })
            })
            .collect()
    }

    fn centroid_bounds(refs: &[BuildRef]) -> Aabb {
        refs.iter().fold(
            Aabb {
                min: Vec3A::INFINITY,
                max: Vec3A::NEG_INFINITY,
            },
            |b, r| Aabb {
                min: b.min.min(r.centroid2()),
                max: b.max.max(r.centroid2()),
            },
        )
    }

    /// Every one of the 15 planes per axis priced, empty bins folded in (the plain
    /// binned SAH), the first cheapest one kept.
    fn cheapest_of_every_plane(bins: &Bins<BINS>, scale: Vec3A) -> Option<(f32, usize, usize)> {
        let mut best: Option<(f32, usize, usize)> = None;
        for axis in (0..3).filter(|&a| scale[a] != 0.0) {
            let bins = &bins[axis];
            for k in 1..BINS {
                let side = |range: &[Bin]| {
                    range
                        .iter()
                        .fold((Vec3A::INFINITY, Vec3A::NEG_INFINITY, 0usize), |(lo, hi, n), b| {
                            (lo.min(b.lo), hi.max(b.hi), n + b.count as usize)
                        })
                };
                let (llo, lhi, nl) = side(&bins[..k]);
                let (rlo, rhi, nr) = side(&bins[k..]);
                let cost = area(llo, lhi) * packets(nl) + area(rlo, rhi) * packets(nr);
                if nl > 0 && nr > 0 && best.is_none_or(|(c, _, _)| cost < c) {
                    best = Some((cost, axis, k));
                }
            }
        }
        best
    }

    #[test]
    fn pricing_only_occupied_gaps_finds_the_plane_every_plane_finds() {
        for n in [2, 3, 5, 8, 13, 17, 40, 100, 300] {
            for seed in 0..20 {
                // Boxes clustered on a few spots, so many bins stay empty and many
                // planes tie.
                let mut refs: Vec<BuildRef> = boxes(n + seed * 7)
                    .into_iter()
                    .skip(seed as usize * 7)
                    .map(|(i, b)| {
                        let snapped = Aabb {
                            min: (b.min / 25.0).round() * 25.0,
                            max: (b.min / 25.0).round() * 25.0 + (b.max - b.min),
                        };
                        BuildRef::new(if seed % 2 == 0 { &snapped } else { &b }, i)
                    })
                    .collect();
                let cb = centroid_bounds(&refs);
                let extent = cb.max - cb.min;
                let scale = Vec3A::select(
                    extent.cmpgt(Vec3A::ZERO),
                    Vec3A::splat(BINS as f32 * (1.0 - 1e-6)) / extent,
                    Vec3A::ZERO,
                );
                let bins = bin_refs::<BINS>(&mut refs, cb.min, scale);
                let fast = cheapest_plane(&bins, scale).map(|(c, a, k)| (c.to_bits(), a, k));
                let every = cheapest_of_every_plane(&bins, scale).map(|(c, a, k)| (c.to_bits(), a, k));
                assert_eq!(fast, every, "{n} boxes, seed {seed}");
            }
        }
    }

    #[test]
    fn two_sets_of_bins_bin_as_one() {
        let mut refs: Vec<BuildRef> = boxes(1000).iter().map(|(i, b)| BuildRef::new(b, *i)).collect();
        let cb = centroid_bounds(&refs);
        let scale = Vec3A::splat(BINS as f32 * (1.0 - 1e-6)) / (cb.max - cb.min);
        let mut one = [[EMPTY_BIN; BINS]; 3];
        for r in refs.iter_mut() {
            bin_ref(&mut one, r, cb.min, scale);
        }
        let two = bin_refs::<BINS>(&mut refs, cb.min, scale);
        assert!(refs.len() >= TWO_BIN_SETS);
        for (a, b) in one.iter().flatten().zip(two.iter().flatten()) {
            assert_eq!(
                (a.lo.to_array(), a.hi.to_array(), a.count),
                (b.lo.to_array(), b.hi.to_array(), b.count)
            );
        }
    }
}
