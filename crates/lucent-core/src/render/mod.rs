//! The render loop: the job's pixels are cut into square tiles (on a grid fixed by the
//! whole image), rayon spreads the tiles over the threads of the current pool, and each
//! pixel's value depends only on the pixel and the job, never on which thread or in which
//! order its tile ran — so the output is the same bytes for any thread count, and a crop
//! is exactly that part of the whole image.
//!
//! The path of one pixel: [`render`] → `render_tile` → for each sample, a point of the
//! pixel ([`PixelSampling`]) → [`Camera::ray`] → [`Integrator::radiance`] → the sum of
//! its samples on the film. With a noise threshold (`noisethreshold`, adaptive sampling)
//! a pixel may stop before its last sample, on the evidence of its own samples alone.
//!
//! [`Camera::ray`]: crate::camera::Camera::ray

pub mod aov;
pub mod job;
pub mod plan;

use std::sync::atomic::{AtomicBool, Ordering};

use rayon::prelude::*;

use crate::film::{AovSum, ExactSum, Film, PixelNoise};
use crate::integrator::{CameraHit, Integrator, PixelSampling, TraceCounts};
use crate::math::Color;
use crate::ray::Ray;
use crate::sampler::{stratified, Sampler};
use crate::scene::Scene;
use job::{PixelRect, RenderJob, MIN_ADAPTIVE_SAMPLES};

/// The side of a render's tiles, the pixels one thread renders at a time.
pub const TILE_SIZE: u32 = 16;
/// The smallest tiles, for pictures and regions too small to give every thread some
/// tiles of [`TILE_SIZE`] (a block of camera rays, [`BLOCK`]², fills them).
const MIN_TILE_SIZE: u32 = 4;
/// The most samples per pixel whose lens positions are stratified (a table of this many
/// entries per pixel, 256 kB).
const MAX_LENS_STRATA: u32 = 1 << 16;
/// Samples of one pixel between two looks at the cancel flag (so that even a pixel of a
/// billion samples stops at once).
const CANCEL_EVERY: u32 = 64;

/// What the render loop reports.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RenderStats {
    /// Every ray traced: camera, shadow and reflection rays.
    pub rays: u64,
    /// Samples that came out NaN or infinite and were replaced by black.
    pub bad_samples: u64,
    /// The first pixels (in reading order, `(x, y)`) where that happened, up to four.
    pub bad_pixels: BadPixels,
    /// Branches of ray trees cut: past a camera sample's
    /// [`crate::integrator::whitted::MAX_TREE_RAYS`] rays, or because too many were
    /// waiting at once ([`crate::integrator::whitted::MAX_PENDING`]).
    pub cut_branches: u64,
    /// Samples taken in all, and the fewest and most that one pixel took (they differ
    /// with adaptive sampling).
    pub samples: u64,
    pub min_pixel_samples: u32,
    pub max_pixel_samples: u32,
}

impl RenderStats {
    pub fn add(&mut self, other: &RenderStats) {
        self.rays += other.rays;
        self.bad_samples += other.bad_samples;
        for &p in other.bad_pixels.list() {
            self.bad_pixels.note(p);
        }
        self.cut_branches += other.cut_branches;
        self.samples += other.samples;
        self.min_pixel_samples = self.min_pixel_samples.min(other.min_pixel_samples);
        self.max_pixel_samples = self.max_pixel_samples.max(other.max_pixel_samples);
    }
}

/// The first few pixels, in reading order (row by row), that had a NaN or infinite
/// sample: the same whichever thread found them first.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BadPixels {
    pixels: [(u32, u32); 4],
    len: usize,
}

impl BadPixels {
    /// Keeps `(x, y)` if it is among the first four in reading order.
    pub fn note(&mut self, p: (u32, u32)) {
        let key = |q: &(u32, u32)| (q.1, q.0);
        if self.list().contains(&p) {
            return;
        }
        if self.len < 4 {
            self.pixels[self.len] = p;
            self.len += 1;
        } else if let Some(last) = self.pixels.iter_mut().max_by_key(|q| key(q)) {
            if key(&p) < key(last) {
                *last = p;
            }
        }
        self.pixels[..self.len].sort_by_key(key);
    }

    pub fn list(&self) -> &[(u32, u32)] {
        &self.pixels[..self.len]
    }
}

/// Hooks for the caller: `progress` is called after each tile with the number of samples
/// it took (pixels × samples per pixel); when `cancel` becomes true the remaining tiles
/// are skipped.
pub struct RenderControl<'a> {
    pub progress: &'a (dyn Fn(u64) + Sync),
    pub cancel: &'a AtomicBool,
}

/// What a pixel's samples add to the film.
struct PixelResult {
    sum: ExactSum,
    taken: u32,
    /// The last sample (the only one when `taken` is 1: what a film of one sample per
    /// pixel keeps).
    last: Color,
}

/// The side of the tiles `rect` is cut into for `threads` threads: [`TILE_SIZE`], or
/// smaller where that would give fewer than four tiles a thread, so that a small picture
/// or region of an expensive scene keeps every thread busy to the end and its progress
/// moves. Where a pixel lands and what it sums do not depend on the tiles.
fn tile_side(rect: PixelRect, threads: usize) -> u32 {
    let tiles = |side: u32| {
        let across = rect.x1.div_ceil(side) - rect.x0 / side;
        let down = rect.y1.div_ceil(side) - rect.y0 / side;
        across as usize * down as usize
    };
    let mut side = TILE_SIZE;
    while side > MIN_TILE_SIZE && tiles(side) < 4 * threads {
        side /= 2;
    }
    side
}

/// What a tile's pixels add to the film, row by row: their sums, and only where the job
/// asks for them (empty otherwise: 150 bytes a pixel that every tile would clear and
/// copy) the sums of their auxiliary passes and adaptive sampling's estimates.
struct TilePixels {
    results: Vec<PixelResult>,
    aovs: Vec<AovSum>,
    noise: Vec<PixelNoise>,
}

struct Tile {
    x0: u32,
    y0: u32,
    x1: u32,
    y1: u32,
}

/// Renders the job's pixels of `scene` with `integrator` on the current rayon pool: a film
/// the size of `job.pixels`. `None` if cancelled.
///
/// # Panics
/// If the job is not valid ([`RenderJob::check`]).
pub fn render(
    scene: &Scene,
    integrator: &dyn Integrator,
    job: &RenderJob,
    control: &RenderControl,
) -> Option<(Film, RenderStats)> {
    render_after(scene, integrator, job, None, None, control)
}

/// [`render`], continuing `earlier`, the film of the same pixels' samples before
/// `job.samples` (adaptive sampling goes on from its estimates: a pixel that stopped
/// there takes no sample here). The result goes into `spare`, cleared, when that is a
/// film of the job's pixels and passes that is no longer needed (an earlier pass's,
/// whose samples were added elsewhere): a picture's worth of fresh memory costs page
/// faults on every pass (a few percent of a path-traced render in passes of a couple of
/// seconds).
///
/// # Panics
/// If the job is not valid, or `earlier` is not a film of its pixels.
pub fn render_after(
    scene: &Scene,
    integrator: &dyn Integrator,
    job: &RenderJob,
    earlier: Option<&Film>,
    spare: Option<Film>,
    control: &RenderControl,
) -> Option<(Film, RenderStats)> {
    if let Err(e) = job.check() {
        panic!("render: {e}");
    }
    if let Some(f) = earlier {
        assert_eq!(
            (f.width, f.height),
            (job.pixels.width(), job.pixels.height()),
            "render: an earlier film of other pixels"
        );
    }
    let rect = job.pixels;
    // Tiles of the whole image's grid, clipped to the rectangle.
    let side = tile_side(rect, rayon::current_num_threads());
    let tiles: Vec<Tile> = (rect.y0 / side..rect.y1.div_ceil(side))
        .flat_map(|ty| {
            (rect.x0 / side..rect.x1.div_ceil(side)).map(move |tx| Tile {
                x0: (tx * side).max(rect.x0),
                y0: (ty * side).max(rect.y0),
                x1: ((tx + 1) * side).min(rect.x1),
                y1: ((ty + 1) * side).min(rect.y1),
            })
        })
        .collect();

    // The tiles are taken in an order drawn once (the same for every render), so that
    // any stretch of the render is a fair sample of the picture's cost and the ETA that
    // the progress callback's rate gives is honest from the first tiles on; where a
    // tile's pixels land does not depend on it.
    let order = shuffled_strata(0x711e, 0, 0, tiles.len() as u32, Vec::new());
    let w = rect.width() as usize;
    // A pass of one sample per pixel (a ray tracer's whole render, a Monte Carlo render's
    // first pass) keeps the samples themselves: a quarter of the fresh memory.
    let one = job.samples.len() == 1;
    let mut film = match spare {
        Some(mut f)
            if (f.width, f.height, f.aovs.is_some()) == (rect.width(), rect.height(), job.aovs)
                && (one || !f.holds_one_sample()) =>
        {
            f.clear();
            f
        }
        _ if one => Film::one_sample(rect.width(), rect.height(), job.aovs),
        _ => Film::with_aovs(rect.width(), rect.height(), job.aovs),
    };
    if job.noise_threshold.is_some() {
        film.noise = Some(vec![PixelNoise::default(); film.counts.len()]);
    }
    let stats = RenderStats {
        min_pixel_samples: u32::MAX,
        ..RenderStats::default()
    };
    // Each finished tile is added to the film at once (exact sums, and counts that add
    // up: the same film in any order), rather than kept until the end: a picture's worth
    // of per-pixel sums would be fresh memory, paid for in page faults every render.
    let shared = std::sync::Mutex::new((film, stats));
    let finished = order
        .par_iter()
        .map(|&t| {
            if control.cancel.load(Ordering::Relaxed) {
                return false;
            }
            let tile = &tiles[t as usize];
            let Some((pixels, s)) = render_tile(scene, integrator, job, earlier, tile, control.cancel) else {
                return false;
            };
            {
                let mut guard = shared.lock().unwrap_or_else(|e| e.into_inner());
                let (film, stats) = &mut *guard;
                stats.add(&s);
                let tw = (tile.x1 - tile.x0) as usize;
                let no_aov = AovSum::default();
                for (row, chunk) in pixels.results.chunks(tw).enumerate() {
                    let start = (tile.y0 - rect.y0) as usize * w + row * w + (tile.x0 - rect.x0) as usize;
                    for (i, p) in chunk.iter().enumerate() {
                        let k = row * tw + i;
                        let aov = pixels.aovs.get(k).unwrap_or(&no_aov);
                        film.add_pixel(start + i, &p.sum, p.taken, p.last, aov);
                        if let Some(noise) = &mut film.noise {
                            noise[start + i] = pixels.noise[k];
                        }
                    }
                }
            }
            (control.progress)(pixels.results.len() as u64 * job.samples.len() as u64);
            true
        })
        .reduce(|| true, |a, b| a & b);
    if !finished {
        return None;
    }
    let (film, stats) = shared.into_inner().unwrap_or_else(|e| e.into_inner());
    Some((film, stats))
}

/// Camera samples made ahead and finished together: up to this many, in the order the
/// tile's pixels are visited ([`block_order`]), have their camera rays traced at once (in
/// packets, [`Scene::closest_hits`]).
const CAMERA_BATCH: usize = 64;

/// The side of the square blocks a tile's pixels are visited in (see [`block_order`]).
const BLOCK: u32 = 4;

/// The pixels of `tile` block by block: blocks of [`BLOCK`] × [`BLOCK`] pixels in reading
/// order, and each block's pixels in reading order. A packet of camera rays (16 with
/// AVX-512, 8 with AVX2) then covers a square of pixels at one sample per pixel, not a
/// strip of a row: fewer boxes and leaves for the packet (scene7's render phase 1.045×
/// [1.031–1.111], 20 paired rounds, AMD EPYC). Each pixel's samples are the same
/// whatever the order (its sampler depends on the pixel and the sample index only), and
/// a pixel's sums do not depend on when its samples are added.
fn block_order(tile: &Tile) -> impl Iterator<Item = (u32, u32)> + '_ {
    (tile.y0..tile.y1).step_by(BLOCK as usize).flat_map(move |by| {
        (tile.x0..tile.x1).step_by(BLOCK as usize).flat_map(move |bx| {
            (by..(by + BLOCK).min(tile.y1)).flat_map(move |y| (bx..(bx + BLOCK).min(tile.x1)).map(move |x| (x, y)))
        })
    })
}

/// A camera sample made, waiting for its ray's closest hit (its ray and its sampler,
/// past the numbers the camera drew, wait beside it).
struct CameraSample {
    /// The pixel's index in the tile (reading order).
    pixel: usize,
    x: u32,
    y: u32,
}

/// The sums of the samples of one tile's pixels and how many each took; `None` as soon
/// as `cancel` is set (it is looked at between pixels and every [`CANCEL_EVERY`] samples).
fn render_tile(
    scene: &Scene,
    integrator: &dyn Integrator,
    job: &RenderJob,
    earlier: Option<&Film>,
    tile: &Tile,
    cancel: &AtomicBool,
) -> Option<(TilePixels, RenderStats)> {
    let mut counts = TraceCounts::default();
    let mut bad_samples = 0;
    let mut bad_pixels = BadPixels::default();
    let n = job.spp.max(1);
    let sampling = integrator.pixel_sampling();
    // Shuffled lens strata need a table of `spp` entries: beyond MAX_LENS_STRATA samples
    // per pixel (where stratifying them no longer matters) lens samples are independent.
    let shuffle_lens = scene.camera.has_lens() && n <= MAX_LENS_STRATA;
    let mut lens_strata: Vec<u32> = Vec::new();
    // Each pixel's sums; adaptive sampling goes on from the earlier samples' estimate.
    let count = ((tile.x1 - tile.x0) * (tile.y1 - tile.y0)) as usize;
    let adaptive = job.noise_threshold.is_some();
    let mut pixels = TilePixels {
        results: Vec::with_capacity(count),
        aovs: if job.aovs {
            vec![AovSum::default(); count]
        } else {
            Vec::new()
        },
        noise: Vec::with_capacity(if adaptive { count } else { 0 }),
    };
    // Samples taken before (adaptive sampling counts them).
    let mut before = Vec::with_capacity(if adaptive { count } else { 0 });
    for y in tile.y0..tile.y1 {
        for x in tile.x0..tile.x1 {
            pixels.results.push(PixelResult {
                sum: ExactSum::default(),
                taken: 0,
                last: Color::ZERO,
            });
            if adaptive {
                let (noise, b) = match earlier {
                    Some(f) => {
                        let k =
                            (y - job.pixels.y0) as usize * job.pixels.width() as usize + (x - job.pixels.x0) as usize;
                        (f.noise.as_ref().map_or(PixelNoise::default(), |n| n[k]), f.counts[k])
                    }
                    None => (PixelNoise::default(), 0),
                };
                pixels.noise.push(noise);
                before.push(b);
            }
        }
    }
    // Samples are made pixel by pixel (in `block_order`), and finished in the same
    // order, so every pixel's sums and stopping point are what one sample at a time
    // gives. Adaptive sampling decides after each sample whether its pixel takes the
    // next: one at a time there.
    let batch = if job.noise_threshold.is_some() { 1 } else { CAMERA_BATCH };
    let mut made: Vec<CameraSample> = Vec::with_capacity(batch);
    let mut rays: Vec<Ray> = Vec::with_capacity(batch);
    let mut samplers: Vec<Sampler> = Vec::with_capacity(batch);
    let mut hits = vec![None; batch];
    let mut colors = vec![Color::ZERO; batch];
    let mut finish = |made: &mut Vec<CameraSample>,
                      rays: &mut Vec<Ray>,
                      samplers: &mut Vec<Sampler>,
                      pixels: &mut TilePixels| {
        let colors = &mut colors[..rays.len()];
        if batch > 1 {
            let hits = &mut hits[..rays.len()];
            scene.closest_hits(rays, hits);
            integrator.radiances(scene, rays, hits, samplers, &mut counts, colors);
        } else {
            for ((ray, sampler), c) in rays.iter().zip(samplers.iter_mut()).zip(colors.iter_mut()) {
                *c = integrator.radiance(scene, ray, CameraHit::Untraced, sampler, &mut counts);
            }
        }
        for ((s, ray), &c) in made.drain(..).zip(rays.drain(..)).zip(colors.iter()) {
            if job.aovs {
                pixels.aovs[s.pixel].add_sample(&aov::first_surface(scene, &ray, &mut counts));
            }
            let p = &mut pixels.results[s.pixel];
            let c = if c.is_finite() {
                c
            } else {
                bad_samples += 1;
                bad_pixels.note((s.x, s.y));
                Color::ZERO
            };
            // The box filter: every sample of the pixel counts the same.
            p.sum.add_sample(c);
            p.taken += 1;
            p.last = c;
            if let Some(threshold) = job.noise_threshold {
                let noise = &mut pixels.noise[s.pixel];
                noise.add(c);
                // Looked at every 8 samples: a stop then leaves whole 8-point nets of
                // the Sobol sequences, which cover the pixel evenly.
                let all = before[s.pixel] + p.taken;
                if all >= MIN_ADAPTIVE_SAMPLES.min(n) && all % 8 == 0 && noise.relative_error(all) < threshold as f64 {
                    noise.stopped = true;
                }
            }
        }
        samplers.clear();
    };
    for (x, y) in block_order(tile) {
        let pixel = ((y - tile.y0) * (tile.x1 - tile.x0) + (x - tile.x0)) as usize;
        if shuffle_lens {
            lens_strata = shuffled_strata(job.seed, x, y, n, lens_strata);
        }
        for i in job.samples.clone() {
            if (i - job.samples.start) % CANCEL_EVERY == 0 && cancel.load(Ordering::Relaxed) {
                return None;
            }
            if pixels.noise.get(pixel).is_some_and(|p| p.stopped) {
                break;
            }
            let mut sampler = Sampler::start(job.sampler, job.seed, x, y, i);
            let (dx, dy) = match sampling {
                // One sample goes through the pixel centre; more are jittered over
                // the pixel (one per cell of a √n × √n grid when n is a square).
                PixelSampling::Stratified if n == 1 => (0.5, 0.5),
                PixelSampling::Stratified => {
                    let (u, v) = sampler.uniform2();
                    stratified(i, n, u, v)
                }
                // A single sample through the centre, more anywhere in the pixel; the
                // two numbers are drawn either way, so that the integrator's numbers
                // are the same dimensions for every sample.
                PixelSampling::Uniform => {
                    let (u, v) = sampler.uniform2();
                    if n == 1 {
                        (0.5, 0.5)
                    } else {
                        (u, v)
                    }
                }
            };
            let lens = if shuffle_lens {
                // The lens strata in another order than the pixel's, so that where a
                // sample falls in the pixel says nothing about where it leaves the lens.
                let (u, v) = sampler.uniform2();
                stratified(lens_strata[i as usize], n, u, v)
            } else if scene.camera.has_lens() {
                sampler.uniform2()
            } else {
                (0.5, 0.5)
            };
            rays.push(
                scene
                    .camera
                    .ray(job.resolution, x as f64 + dx as f64, y as f64 + dy as f64, lens),
            );
            made.push(CameraSample { pixel, x, y });
            samplers.push(sampler);
            if made.len() == batch {
                finish(&mut made, &mut rays, &mut samplers, &mut pixels);
            }
        }
    }
    finish(&mut made, &mut rays, &mut samplers, &mut pixels);
    let (mut taken_min, mut taken_max, mut taken_all) = (u32::MAX, 0u32, 0u64);
    for p in &pixels.results {
        taken_min = taken_min.min(p.taken);
        taken_max = taken_max.max(p.taken);
        taken_all += p.taken as u64;
    }
    let stats = RenderStats {
        rays: counts.rays,
        bad_samples,
        bad_pixels,
        cut_branches: counts.cut_branches,
        samples: taken_all,
        min_pixel_samples: taken_min,
        max_pixel_samples: taken_max,
    };
    Some((pixels, stats))
}

/// `0..n` in an order drawn from the pixel alone (Fisher–Yates), reusing `out`'s storage.
fn shuffled_strata(seed: u64, x: u32, y: u32, n: u32, mut out: Vec<u32>) -> Vec<u32> {
    out.clear();
    out.extend(0..n);
    let mut rng = Sampler::new(seed, x, y, u32::MAX);
    for i in (1..n as usize).rev() {
        let j = ((rng.uniform() * (i + 1) as f32) as usize).min(i);
        out.swap(i, j);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_pictures_are_cut_into_smaller_tiles_so_that_every_thread_has_some() {
        let rect = |x0, y0, x1, y1| PixelRect { x0, y0, x1, y1 };
        assert_eq!(tile_side(rect(0, 0, 640, 480), 2), 16);
        assert_eq!(tile_side(rect(0, 0, 640, 480), 64), 16);
        // 16 × 12 is one tile of 16: four of 8 for one thread, twelve of 4 for two.
        assert_eq!(tile_side(rect(0, 0, 16, 12), 1), 8);
        assert_eq!(tile_side(rect(0, 0, 16, 12), 2), 4);
        // A region counts the tiles of the image's grid it touches: four pixels at the
        // corner of four tiles are four tiles already, enough for one thread.
        assert_eq!(tile_side(rect(15, 15, 17, 17), 1), 16);
        assert_eq!(tile_side(rect(15, 15, 17, 17), 2), 4);
        assert_eq!(tile_side(rect(0, 0, 1, 1), 8), MIN_TILE_SIZE);
    }

    #[test]
    fn block_order_visits_every_pixel_of_a_tile_once_in_square_blocks() {
        // A whole tile, and tiles cut by the image's edge or a crop (sides not multiples of 4).
        for (x0, y0, x1, y1) in [(0, 0, 16, 16), (32, 16, 45, 23), (5, 3, 6, 4), (0, 0, 3, 9)] {
            let tile = Tile { x0, y0, x1, y1 };
            let order: Vec<(u32, u32)> = block_order(&tile).collect();
            let mut sorted = order.clone();
            sorted.sort_unstable_by_key(|&(x, y)| (y, x));
            sorted.dedup();
            let all: Vec<(u32, u32)> = (y0..y1).flat_map(|y| (x0..x1).map(move |x| (x, y))).collect();
            assert_eq!(sorted, all, "{x0} {y0} {x1} {y1}");
            assert_eq!(order.len(), all.len());
        }
        // In a whole tile every run of 16 pixels is a 4 × 4 square.
        let tile = Tile {
            x0: 0,
            y0: 0,
            x1: 16,
            y1: 16,
        };
        let order: Vec<(u32, u32)> = block_order(&tile).collect();
        for run in order.chunks(16) {
            let (x, y) = run[0];
            assert_eq!(
                run,
                (y..y + 4)
                    .flat_map(|y| (x..x + 4).map(move |x| (x, y)))
                    .collect::<Vec<_>>()
            );
        }
    }

    #[test]
    fn lens_strata_are_a_permutation_fixed_by_the_pixel() {
        let a = shuffled_strata(0, 3, 7, 16, Vec::new());
        let mut sorted = a.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, (0..16).collect::<Vec<_>>());
        assert_eq!(a, shuffled_strata(0, 3, 7, 16, vec![9; 40]));
        assert_ne!(a, (0..16).collect::<Vec<_>>(), "not the pixel strata's order");
        assert_ne!(a, shuffled_strata(0, 4, 7, 16, Vec::new()));
    }
}

#[cfg(test)]
mod bad_pixel_tests {
    use super::BadPixels;

    #[test]
    fn the_first_bad_pixels_in_reading_order_are_kept_whatever_the_order_found() {
        let found = [(5, 2), (1, 0), (9, 9), (3, 2), (0, 1), (1, 0), (7, 0)];
        let mut a = BadPixels::default();
        found.iter().for_each(|&p| a.note(p));
        let mut b = BadPixels::default();
        found.iter().rev().for_each(|&p| b.note(p));
        assert_eq!(a.list(), [(1, 0), (7, 0), (0, 1), (3, 2)]);
        assert_eq!(a, b);
    }
}
