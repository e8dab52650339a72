//! The render in passes of sample indices: every pass takes the next few samples of every
//! pixel of the job, and its sums join the film's (exact sums: the result is the bytes of
//! one pass over all samples). So at any moment the film holds a complete picture of the
//! first k samples — what an interrupted render saves, and what `--checkpoint` writes —
//! and a stop loses at most the pass under way.
//!
//! The first pass is one sample; later ones are sized from the time a sample took, to
//! last about an eighth of the time spent so far (at least 2 s, at most the checkpoint
//! interval or a minute). Adaptive sampling carries each pixel's estimate from pass to
//! pass in the film, so its decisions are those of one pass too.
//!
//! Without a film to resume, the first pass's film becomes the render's, or, since it
//! keeps one sample per pixel (a quarter of the memory of sums), the second pass's film
//! takes it in and becomes the render's; every later pass renders into the film of the
//! pass before it (whose samples were added), so that a picture's worth of fresh memory
//! is faulted in once or twice, not once per pass.

use std::ops::Range;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use lucent_core::film::Film;
use lucent_core::render::job::RenderJob;
use lucent_core::render::RenderStats;
use lucent_io::build::Built;
use lucent_io::session::Renderer;

/// How the passes ended.
pub enum Outcome {
    /// Every sample: the film and what the render counted.
    Done(Film, RenderStats),
    /// Stopped by a signal, with the film of the samples `done` of every pixel if any
    /// pass finished.
    Interrupted(Option<(Film, Range<u32>)>),
}

/// Renders `job` in passes, adding to `start` (the film of earlier samples of the same
/// pixels, when resuming: its samples begin at `first`). After a pass, when
/// `checkpoint` has passed since the last save, `save` gets the film so far and the
/// samples it holds.
#[allow(clippy::too_many_arguments)]
pub fn render_in_passes(
    renderer: &Renderer,
    built: &Built,
    job: &RenderJob,
    start: Option<Film>,
    first: u32,
    progress: &(dyn Fn(u64) + Sync),
    cancel: &AtomicBool,
    checkpoint: Option<Duration>,
    save: &mut dyn FnMut(&Film, &Range<u32>),
) -> Outcome {
    // The samples so far (none yet without `start`: the first pass's film becomes it), and
    // the film of the pass before, whose memory the next pass uses again.
    let mut film = start;
    let mut spare: Option<Film> = None;
    let mut stats: Option<RenderStats> = None;
    let began = Instant::now();
    let mut last_save = Instant::now();
    let mut done = job.samples.start;
    let mut size = 1;
    while done < job.samples.end {
        let pass = done..done.saturating_add(size).min(job.samples.end);
        let pass_job = RenderJob {
            samples: pass.clone(),
            ..job.clone()
        };
        let t = Instant::now();
        // (A pass that returns is whole, even if a signal came as it ended: it is kept.)
        let Some((f, s)) = renderer.render_after(built, &pass_job, film.as_ref(), spare.take(), progress, cancel)
        else {
            break;
        };
        let took = t.elapsed().as_secs_f64();
        // (Exact sums: the first pass's film is what adding it to an empty one gives.)
        let so_far = match film.take() {
            // The first pass kept one sample per pixel; the second pass's film of sums
            // takes them in and becomes the render's (a two-pass render faults in one
            // film of sums, not two; a third pass renders into a film of its own, which
            // later passes use again).
            Some(first) if first.holds_one_sample() && !f.holds_one_sample() => {
                let mut f = f;
                f.add_earlier(&first);
                film.insert(f)
            }
            Some(mut so_far) => {
                so_far.add_film(&f);
                spare = Some(f);
                film.insert(so_far)
            }
            None => film.insert(f),
        };
        match &mut stats {
            Some(total) => total.add(&s),
            None => stats = Some(s),
        }
        done = pass.end;
        if cancel.load(Ordering::Relaxed) {
            break;
        }
        if let Some(every) = checkpoint {
            if last_save.elapsed() >= every && done < job.samples.end {
                save(so_far, &(first..done));
                last_save = Instant::now();
            }
        }
        // The next pass: about an eighth of the time so far, 2 s to a minute (or the
        // checkpoint interval), in whole samples.
        let per_sample = took / pass.len() as f64;
        let cap = checkpoint.map_or(60.0, |c| c.as_secs_f64().clamp(0.5, 60.0));
        let target = (began.elapsed().as_secs_f64() / 8.0).clamp(2.0_f64.min(cap), cap);
        size = ((target / per_sample.max(1e-9)) as u64).clamp(1, u32::MAX as u64) as u32;
    }
    match (stats, film) {
        (Some(s), Some(film)) if done == job.samples.end => Outcome::Done(film, s),
        (_, Some(film)) if done > job.samples.start || first < job.samples.start => {
            Outcome::Interrupted(Some((film, first..done)))
        }
        _ => Outcome::Interrupted(None),
    }
}
