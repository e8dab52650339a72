//! `lucent merge`'s core: states of one render — regions, sample ranges or both — put
//! together into one, refusing states of other renders, overlaps and gaps (found before
//! the merged film is made).

use std::ops::Range;

use lucent_core::film::{AovSum, Film, PixelNoise};
use lucent_core::render::job::PixelRect;

use super::{RenderState, StateHeader};

/// The message for inputs that leave a gap: the first pixel (row by row) that lacks some
/// of `range`'s samples. How many samples cover a pixel changes only at the states' edges,
/// so one pixel of each cell of the grid those edges make stands for the whole cell.
fn gap(states: &[RenderState], union: &PixelRect, range: &Range<u32>) -> String {
    let edges = |ends: &dyn Fn(&PixelRect) -> [u32; 2]| {
        let mut v: Vec<u32> = states.iter().flat_map(|s| ends(&s.header.pixels)).collect();
        v.sort_unstable();
        v.dedup();
        v
    };
    let (xs, ys) = (edges(&|p| [p.x0, p.x1]), edges(&|p| [p.y0, p.y1]));
    for &y in &ys[..ys.len() - 1] {
        for &x in &xs[..xs.len() - 1] {
            let covered: u64 = states
                .iter()
                .filter(|s| {
                    let p = s.header.pixels;
                    (p.x0..p.x1).contains(&x) && (p.y0..p.y1).contains(&y)
                })
                .map(|s| s.header.samples.len() as u64)
                .sum();
            if covered != range.len() as u64 {
                return format!(
                    "a gap: pixel ({x}, {y}) has {covered} of the samples {}..{} that the inputs hold together",
                    range.start,
                    range.end - 1
                );
            }
        }
    }
    // (Not reached: the counts differ, so some cell lacks samples.)
    format!(
        "a gap: the inputs do not hold every sample {}..{} of pixels {}..{} x {}..{}",
        range.start,
        range.end - 1,
        union.x0,
        union.x1,
        union.y0,
        union.y1
    )
}

fn overlap(a: &PixelRect, b: &PixelRect) -> bool {
    a.x0 < b.x1 && b.x0 < a.x1 && a.y0 < b.y1 && b.y0 < a.y1
}

fn describe(h: &StateHeader) -> String {
    let p = h.pixels;
    format!(
        "pixels {}..{} x {}..{}, samples {}..{}",
        p.x0,
        p.x1,
        p.y0,
        p.y1,
        h.samples.start,
        h.samples.end.saturating_sub(1)
    )
}

/// Combines states of one render — regions, sample ranges or both — into one: every pixel
/// of the combined rectangle must be covered by states whose sample ranges do not overlap
/// and together make one range. `names` name the states in messages.
pub fn merge(states: &[RenderState], names: &[String]) -> Result<RenderState, String> {
    let first = states.first().ok_or("nothing to merge")?;
    for (s, name) in states.iter().zip(names).skip(1) {
        if let Some(what) = s.header.difference(&first.header, true) {
            return Err(format!(
                "{name} and {} are renders of a different {what}; they cannot be merged",
                names[0]
            ));
        }
    }
    // Overlaps: two states that share a pixel must share no sample index.
    for i in 0..states.len() {
        for j in i + 1..states.len() {
            let (a, b) = (&states[i].header, &states[j].header);
            if overlap(&a.pixels, &b.pixels) && a.samples.start < b.samples.end && b.samples.start < a.samples.end {
                return Err(format!(
                    "{} ({}) and {} ({}) overlap: both hold some samples of the same pixels",
                    names[i],
                    describe(a),
                    names[j],
                    describe(b)
                ));
            }
        }
    }
    let union = PixelRect {
        x0: states.iter().map(|s| s.header.pixels.x0).min().unwrap(),
        x1: states.iter().map(|s| s.header.pixels.x1).max().unwrap(),
        y0: states.iter().map(|s| s.header.pixels.y0).min().unwrap(),
        y1: states.iter().map(|s| s.header.pixels.y1).max().unwrap(),
    };
    let range = states.iter().map(|s| s.header.samples.start).min().unwrap()
        ..states.iter().map(|s| s.header.samples.end).max().unwrap();
    if first.header.noise_threshold.is_some() {
        for i in 0..states.len() {
            for j in i + 1..states.len() {
                if overlap(&states[i].header.pixels, &states[j].header.pixels) {
                    return Err(format!(
                        "{} and {} hold samples of the same pixels of an adaptive render: sample ranges of adaptive sampling follow from each other, so continue such a render with --resume instead of merging its ranges",
                        names[i], names[j]
                    ));
                }
            }
        }
    }
    // With no overlaps, the inputs hold every sample index of `range` for every pixel of
    // `union` exactly when they hold as many pixel samples as the two span. Checked before
    // the merged film is made, so that two small states at far corners of a large image
    // cannot ask for the film of all of it: once they pass, the film has no more pixels
    // than the inputs together.
    let held: u128 = states
        .iter()
        .map(|s| s.header.pixels.pixels() as u128 * s.header.samples.len() as u128)
        .sum();
    if held != union.pixels() as u128 * range.len() as u128 {
        return Err(gap(states, &union, &range));
    }
    let mut film = Film::with_aovs(union.width(), union.height(), first.header.aovs);
    if first.header.noise_threshold.is_some() {
        film.noise = Some(vec![PixelNoise::default(); film.counts.len()]);
    }
    let w = union.width() as usize;
    for s in states {
        let p = s.header.pixels;
        for y in 0..p.height() {
            for x in 0..p.width() {
                let src = (y * p.width() + x) as usize;
                let dst = (p.y0 - union.y0 + y) as usize * w + (p.x0 - union.x0 + x) as usize;
                let aov = s.film.aovs.as_ref().map_or(AovSum::default(), |a| a[src]);
                film.add(dst, &s.film.sum(src), s.film.counts[src], &aov);
                if let (Some(to), Some(from)) = (&mut film.noise, &s.film.noise) {
                    to[dst] = from[src];
                }
            }
        }
    }
    Ok(RenderState {
        header: StateHeader {
            pixels: union,
            samples: range,
            ..first.header.clone()
        },
        film,
    })
}

#[cfg(test)]
mod tests {
    use super::super::tests::{rect, state};
    use super::*;

    /// The gap's message names the first pixel, row by row, that the states do not hold
    /// every sample of: the same as counting every pixel's samples.
    #[test]
    fn the_gap_found_on_the_states_grid_is_the_first_pixel_short_of_samples() {
        let mut seed = 12345u32;
        let mut next = |n: u32| {
            seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (seed >> 8) % n
        };
        let mut gaps = 0;
        for _ in 0..500 {
            let states: Vec<RenderState> = (0..1 + next(4))
                .map(|_| {
                    let (x0, y0) = (next(7), next(5));
                    let (x1, y1) = (x0 + 1 + next(8 - x0), y0 + 1 + next(6 - y0));
                    let first = next(3);
                    state(rect(x0, x1, y0, y1), first..first + 1 + next(3))
                })
                .collect();
            let union = PixelRect {
                x0: states.iter().map(|s| s.header.pixels.x0).min().unwrap(),
                x1: states.iter().map(|s| s.header.pixels.x1).max().unwrap(),
                y0: states.iter().map(|s| s.header.pixels.y0).min().unwrap(),
                y1: states.iter().map(|s| s.header.pixels.y1).max().unwrap(),
            };
            let range = 0..5;
            let brute = (union.y0..union.y1)
                .flat_map(|y| (union.x0..union.x1).map(move |x| (x, y)))
                .map(|(x, y)| {
                    let n: u64 = states
                        .iter()
                        .filter(|s| {
                            let p = s.header.pixels;
                            p.x0 <= x && x < p.x1 && p.y0 <= y && y < p.y1
                        })
                        .map(|s| s.header.samples.len() as u64)
                        .sum();
                    (x, y, n)
                })
                .find(|&(_, _, n)| n != 5);
            if let Some((x, y, n)) = brute {
                gaps += 1;
                let e = gap(&states, &union, &range);
                assert_eq!(
                    e,
                    format!("a gap: pixel ({x}, {y}) has {n} of the samples 0..4 that the inputs hold together")
                );
            }
        }
        assert!(gaps > 400, "{gaps}");
    }

    #[test]
    fn merging_checks_overlaps_gaps_and_origins() {
        let names: Vec<String> = (0..4).map(|i| format!("s{i}")).collect();
        // Two halves of the sample range over the left half, one range over the right.
        let parts = [
            state(rect(0, 4, 0, 4), 0..8),
            state(rect(0, 4, 0, 4), 8..16),
            state(rect(4, 8, 0, 4), 0..16),
        ];
        let m = merge(&parts, &names).unwrap();
        assert_eq!((m.header.pixels, m.header.samples.clone()), (rect(0, 8, 0, 4), 0..16));
        assert!(m.film.counts.iter().all(|&c| c == 16));
        // Overlap.
        let e = merge(&[state(rect(0, 4, 0, 4), 0..8), state(rect(2, 6, 0, 4), 4..12)], &names).unwrap_err();
        assert!(e.contains("overlap"), "{e}");
        // Gap in the samples of some pixels, and a hole in the rectangle.
        let e = merge(&[state(rect(0, 4, 0, 4), 0..16), state(rect(4, 8, 0, 4), 0..8)], &names).unwrap_err();
        assert!(e.contains("gap: pixel (4, 0)"), "{e}");
        let e = merge(
            &[state(rect(0, 2, 0, 4), 0..16), state(rect(4, 8, 0, 4), 0..16)],
            &names,
        )
        .unwrap_err();
        assert!(e.contains("gap: pixel (2, 0)"), "{e}");
        // An L of two states leaves a corner.
        let e = merge(
            &[state(rect(0, 8, 0, 2), 0..16), state(rect(0, 4, 2, 4), 0..16)],
            &names,
        )
        .unwrap_err();
        assert!(e.contains("gap: pixel (4, 2) has 0 of the samples 0..15"), "{e}");
        // Two pixels at the far corners of a 65535 x 65535 image: a gap, found before the
        // film of the rectangle between them (223 GB) is made.
        let corners: Vec<RenderState> = [rect(0, 1, 0, 1), rect(65534, 65535, 65534, 65535)]
            .into_iter()
            .map(|r| {
                let mut s = state(r, 0..16);
                s.header.resolution = (65535, 65535);
                s
            })
            .collect();
        let e = merge(&corners, &names).unwrap_err();
        assert!(e.contains("gap: pixel (1, 0) has 0 of"), "{e}");
        // Another scene.
        let mut other = state(rect(4, 8, 0, 4), 0..16);
        other.header.scene_hash = 1;
        let e = merge(&[state(rect(0, 4, 0, 4), 0..16), other], &names).unwrap_err();
        assert!(e.contains("different scene"), "{e}");
    }
}
