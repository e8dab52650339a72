//! Roots of `a t² + b t + c = 0` for the quadric shapes (cylinder, cone, general
//! quadric), in f64, in the cancellation-free form: `q = −(b + sign(b)·√Δ)/2`,
//! roots `q/a` and `c/q`.

/// The real roots in increasing order (`None` when there are none). A degenerate
/// quadratic (`a = 0`) has the one root `−c/b`.
pub fn solve(a: f64, b: f64, c: f64) -> Option<(f64, f64)> {
    if a == 0.0 {
        if b == 0.0 {
            return None;
        }
        let t = -c / b;
        return Some((t, t));
    }
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 {
        return None;
    }
    let q = -0.5 * (b + disc.sqrt().copysign(b));
    let (t0, t1) = if q == 0.0 { (0.0, 0.0) } else { (q / a, c / q) };
    Some(if t0 <= t1 { (t0, t1) } else { (t1, t0) })
}

/// The first root in `(t_min, t_max]` (nearest first) for which `accept(t)` holds.
pub fn first_root(
    roots: Option<(f64, f64)>,
    t_min: f32,
    t_max: f32,
    mut accept: impl FnMut(f64) -> bool,
) -> Option<f32> {
    let (t0, t1) = roots?;
    [t0, t1].into_iter().find_map(|t| {
        let tf = t as f32;
        (tf > t_min && tf <= t_max && accept(t)).then_some(tf)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn roots_are_accurate_and_ordered() {
        assert_eq!(solve(1.0, -3.0, 2.0), Some((1.0, 2.0)));
        assert_eq!(solve(-1.0, 3.0, -2.0), Some((1.0, 2.0)));
        assert_eq!(solve(1.0, 0.0, 1.0), None);
        assert_eq!(solve(0.0, 2.0, -4.0), Some((2.0, 2.0)));
        assert_eq!(solve(0.0, 0.0, 1.0), None);
        // Widely separated roots: the small one is not lost to cancellation.
        let (t0, t1) = solve(1.0, -1e8, 1.0).unwrap();
        assert!((t0 - 1e-8).abs() < 1e-20 && (t1 - 1e8).abs() < 1e-4);
    }
}
