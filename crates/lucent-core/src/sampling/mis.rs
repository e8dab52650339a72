//! Multiple importance sampling (Veach 1997): weights that combine two estimators of the
//! same integral — light sampling and BSDF sampling — so that each counts where its
//! density is the better one.

/// The power heuristic with exponent 2 for a sample drawn with density `pa` by one of
/// two strategies, the other having density `pb` for the same sample:
/// `pa² / (pa² + pb²)`. 0 when both densities are 0; with an infinite `pa` (a delta
/// distribution the other cannot draw) it is 1.
#[inline]
pub fn power_heuristic(pa: f32, pb: f32) -> f32 {
    if pa.is_infinite() {
        return 1.0;
    }
    // In f64: the squares of large f32 densities would overflow.
    let (a, b) = ((pa as f64).powi(2), (pb as f64).powi(2));
    if a + b > 0.0 {
        (a / (a + b)) as f32
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_of_the_two_strategies_sum_to_one() {
        for (a, b) in [(1.0, 1.0), (0.3, 7.0), (1e-20, 5.0), (2e19, 3e19), (0.0, 2.0)] {
            let w = power_heuristic(a, b) + power_heuristic(b, a);
            assert!((w - 1.0).abs() < 1e-6, "{a} {b}: {w}");
        }
        assert_eq!(power_heuristic(1.0, 1.0), 0.5);
        assert!((power_heuristic(1.0, 2.0) - 0.2).abs() < 1e-7);
        assert_eq!(power_heuristic(0.0, 0.0), 0.0);
        assert_eq!(power_heuristic(f32::INFINITY, 3.0), 1.0);
        assert_eq!(power_heuristic(3.0, f32::INFINITY), 0.0);
    }
}
