//! Cutting a render into independent tasks (`lucent plan`, `lucent render --task I/N`):
//! bands of rows, ranges of sample indices, or both. Each task is a job of its own — its
//! pixels and samples — whose state files merge into the one-go render. The cut depends
//! only on the job and on a cost per row that every task computes alike (a count of
//! rays, never a time), so every task of a cluster finds the same plan.

use std::ops::Range;

use super::job::{PixelRect, RenderJob};

/// How to cut (`--by`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Cut {
    /// Bands of rows, balanced by the cost of their rows.
    Tiles,
    /// Ranges of sample indices over the whole picture.
    Samples,
    /// For the Monte Carlo integrators, sample ranges — up to [`MAX_AUTO_RANGES`] of
    /// them, and no more than there are samples — times bands for the rest; bands for
    /// the ray tracer and adaptive sampling.
    Auto,
}

impl Cut {
    pub const NAMES: [&'static str; 3] = ["auto", "tiles", "samples"];

    pub fn parse(s: &str) -> Option<Cut> {
        match s {
            "auto" => Some(Cut::Auto),
            "tiles" => Some(Cut::Tiles),
            "samples" => Some(Cut::Samples),
            _ => None,
        }
    }
}

/// The most sample ranges `auto` cuts into. Sample ranges balance perfectly (every sample
/// index costs the same on average), but each one's state holds the whole picture: with N
/// ranges the merge reads N pictures' worth of state (N × 52 bytes per pixel: 431 MB for
/// a 3840 × 2160 frame). Bands of rows hold their own rows only, so past 8 ranges the
/// cut goes on in bands, and the states of any plan add up to at most 8 pictures.
pub const MAX_AUTO_RANGES: u32 = 8;

/// One task: the pixels and the sample indices it renders, and its estimated cost (in
/// the units of the row costs, times samples).
#[derive(Clone, Debug, PartialEq)]
pub struct Task {
    pub pixels: PixelRect,
    pub samples: Range<u32>,
    pub cost: f64,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    /// `tiles`, `samples` or `tiles x samples`.
    pub by: &'static str,
    pub tasks: Vec<Task>,
}

impl Plan {
    /// The most expensive task's cost over the mean (1: perfectly balanced).
    pub fn imbalance(&self) -> f64 {
        let mean = self.tasks.iter().map(|t| t.cost).sum::<f64>() / self.tasks.len() as f64;
        let max = self.tasks.iter().map(|t| t.cost).fold(0.0, f64::max);
        if mean > 0.0 {
            max / mean
        } else {
            1.0
        }
    }
}

/// What the job allows to cut.
#[derive(Clone, Copy, Debug)]
pub struct Cuttable {
    /// Its sample indices can be rendered in separate ranges (not with adaptive
    /// sampling, whose later samples depend on the earlier ones).
    pub samples: bool,
    /// It is a Monte Carlo render (the ray tracer is cut in tiles unless asked).
    pub monte_carlo: bool,
}

/// Cuts `job` into `tasks` tasks. `row_cost[i]` is the cost of one sample in every pixel
/// of row `job.pixels.y0 + i`.
pub fn plan(job: &RenderJob, tasks: u32, cut: Cut, what: Cuttable, row_cost: &[f64]) -> Result<Plan, String> {
    let rows = job.pixels.height();
    let samples = job.samples.len() as u32;
    assert_eq!(row_cost.len(), rows as usize, "plan: a cost for every row");
    if tasks == 0 {
        return Err("a plan needs at least one task".into());
    }
    let (bands, ranges) = match cut {
        Cut::Tiles => (tasks, 1),
        Cut::Samples => {
            if !what.samples {
                return Err("adaptive sampling cannot be cut into sample ranges (each pixel's later samples depend on its earlier ones): cut it --by tiles".into());
            }
            if samples < tasks {
                return Err(format!(
                    "{tasks} sample ranges need at least {tasks} samples per pixel, and the render takes {samples}: cut it --by tiles or --by auto"
                ));
            }
            (1, tasks)
        }
        Cut::Auto if what.samples && what.monte_carlo && samples > 1 => {
            // As many ranges as divide the tasks and the samples (and the limit) allow,
            // bands for the rest.
            let most = samples.min(tasks).min(MAX_AUTO_RANGES);
            let r = (1..=most).rev().find(|r| tasks % r == 0).unwrap_or(1);
            (tasks / r, r)
        }
        Cut::Auto => (tasks, 1),
    };
    if bands > rows {
        return Err(format!(
            "{bands} bands of rows need at least {bands} rows, and the render has {rows}: ask for fewer tasks"
        ));
    }
    let by = match (bands, ranges) {
        (_, 1) => "tiles",
        (1, _) => "samples",
        _ => "tiles x samples",
    };
    let cuts = balanced_bands(row_cost, bands);
    let p = job.pixels;
    let mut out = Vec::with_capacity(tasks as usize);
    for b in 0..bands as usize {
        let (r0, r1) = (cuts[b], cuts[b + 1]);
        let band_cost: f64 = row_cost[r0 as usize..r1 as usize].iter().sum();
        for r in 0..ranges {
            let range = split(&job.samples, ranges, r);
            out.push(Task {
                pixels: PixelRect {
                    x0: p.x0,
                    x1: p.x1,
                    y0: p.y0 + r0,
                    y1: p.y0 + r1,
                },
                cost: band_cost * range.len() as f64,
                samples: range,
            });
        }
    }
    Ok(Plan { by, tasks: out })
}

/// Part `k` of `n` nearly equal parts of `range` (the first ones one longer).
fn split(range: &Range<u32>, n: u32, k: u32) -> Range<u32> {
    let len = range.len() as u32;
    let (base, extra) = (len / n, len % n);
    let start = range.start + k * base + k.min(extra);
    start..start + base + u32::from(k < extra)
}

/// The row boundaries `0 = c₀ < c₁ < … < c_bands = rows` that split the rows into `bands`
/// bands of nearly equal total cost, each at least one row.
fn balanced_bands(row_cost: &[f64], bands: u32) -> Vec<u32> {
    let rows = row_cost.len();
    let mut prefix = vec![0.0; rows + 1];
    for (i, c) in row_cost.iter().enumerate() {
        prefix[i + 1] = prefix[i] + c.max(0.0);
    }
    let total = prefix[rows];
    let mut cuts = vec![0u32];
    for k in 1..bands as usize {
        let prev = *cuts.last().unwrap() as usize;
        // Room for the bands still to come, one row each.
        let last = rows - (bands as usize - k);
        let target = total * k as f64 / bands as f64;
        // The first boundary at or past the target, or the one just before it if that
        // is closer.
        let mut i = (prev + 1..=last).find(|&i| prefix[i] >= target).unwrap_or(last);
        if i > prev + 1 && target - prefix[i - 1] < prefix[i] - target {
            i -= 1;
        }
        cuts.push(i as u32);
    }
    cuts.push(rows as u32);
    cuts
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::Resolution;

    fn job(w: u32, h: u32, spp: u32) -> RenderJob {
        RenderJob::whole(Resolution { width: w, height: h }, spp)
    }

    const MC: Cuttable = Cuttable {
        samples: true,
        monte_carlo: true,
    };

    /// Every pixel's samples covered exactly once.
    fn covers(j: &RenderJob, p: &Plan) {
        let (w, h) = (j.pixels.width() as usize, j.pixels.height() as usize);
        let mut seen = vec![0u32; w * h];
        for t in &p.tasks {
            for y in t.pixels.y0..t.pixels.y1 {
                for x in t.pixels.x0..t.pixels.x1 {
                    seen[y as usize * w + x as usize] += t.samples.len() as u32;
                }
            }
        }
        assert!(seen.iter().all(|&n| n == j.samples.len() as u32), "{p:?}");
    }

    #[test]
    fn monte_carlo_renders_are_cut_in_sample_ranges_and_others_in_balanced_bands() {
        let j = job(8, 10, 64);
        let flat = vec![1.0; 10];
        let p = plan(&j, 8, Cut::Auto, MC, &flat).unwrap();
        assert_eq!(p.by, "samples");
        assert!(p.tasks.iter().all(|t| t.samples.len() == 8));
        covers(&j, &p);
        // Too few samples for 8 ranges: 2 ranges × 4 bands.
        let few = job(8, 10, 2);
        let p = plan(&few, 8, Cut::Auto, MC, &flat).unwrap();
        assert_eq!((p.by, p.tasks.len()), ("tiles x samples", 8));
        covers(&few, &p);
        // The ray tracer, or adaptive sampling: bands, balanced by cost — the costly
        // rows (the last two, 9 times the others) get bands of their own.
        let mut cost = vec![1.0; 10];
        cost[8] = 9.0;
        cost[9] = 9.0;
        let whitted = Cuttable {
            samples: true,
            monte_carlo: false,
        };
        let p = plan(&j, 3, Cut::Auto, whitted, &cost).unwrap();
        assert_eq!(p.by, "tiles");
        let bands: Vec<(u32, u32)> = p.tasks.iter().map(|t| (t.pixels.y0, t.pixels.y1)).collect();
        assert_eq!(bands, [(0, 8), (8, 9), (9, 10)]);
        covers(&j, &p);
        assert!(p.imbalance() < 1.2, "{}", p.imbalance());
        let adaptive = Cuttable {
            samples: false,
            monte_carlo: true,
        };
        assert!(plan(&j, 4, Cut::Samples, adaptive, &flat)
            .unwrap_err()
            .contains("--by tiles"));
        // Many tasks: 8 ranges at most, bands for the rest.
        let big = job(8, 100, 4096);
        let p = plan(&big, 64, Cut::Auto, MC, &vec![1.0; 100]).unwrap();
        assert_eq!(
            (p.by, p.tasks.iter().filter(|t| t.pixels.y0 == 0).count()),
            ("tiles x samples", 8)
        );
        covers(&big, &p);
        assert_eq!(plan(&j, 4, Cut::Auto, adaptive, &flat).unwrap().by, "tiles");
    }

    #[test]
    fn uneven_cuts_still_cover_everything_once() {
        for (h, spp, n) in [(7, 5, 3), (10, 1, 10), (3, 9, 6), (50, 7, 7), (4, 3, 12)] {
            let j = job(5, h, spp);
            let cost: Vec<f64> = (0..h).map(|i| (i * i % 7) as f64).collect();
            for cut in [Cut::Auto, Cut::Tiles, Cut::Samples] {
                if let Ok(p) = plan(&j, n, cut, MC, &cost) {
                    assert_eq!(p.tasks.len(), n as usize);
                    assert!(p.tasks.iter().all(|t| t.pixels.height() > 0 && !t.samples.is_empty()));
                    covers(&j, &p);
                }
            }
        }
        assert!(plan(&job(5, 3, 2), 4, Cut::Tiles, MC, &[1.0; 3])
            .unwrap_err()
            .contains("rows"));
        assert!(plan(&job(5, 3, 2), 4, Cut::Samples, MC, &[1.0; 3])
            .unwrap_err()
            .contains("samples per pixel"));
    }
}
