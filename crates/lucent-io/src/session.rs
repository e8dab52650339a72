//! The start-up sequence every entry point runs — the `render`, `check` and `bench`
//! commands and the tests: parse a scene file, build it, and render a job of it on a
//! pool of worker threads with a progress callback and a cancel flag.

use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

use lucent_core::accel::AccelKind;
use lucent_core::film::Film;
use lucent_core::render::job::RenderJob;
use lucent_core::render::{render_after, RenderControl, RenderStats};

use crate::build::{build, BuildOptions, Built};
use crate::cse167::{parse_bytes_with, parse_file_with, ParseOptions};
use crate::desc::SceneDesc;
use crate::diag::Diagnostics;
use crate::resources::{Budget, Resources};

#[derive(Clone, Copy, Debug)]
pub struct SessionOptions {
    /// Unknown commands are errors instead of warnings.
    pub strict: bool,
    pub accel: AccelKind,
    /// The memory budget in bytes ([`crate::resources::budget`]).
    pub memory_limit: u64,
}

impl Default for SessionOptions {
    fn default() -> Self {
        SessionOptions {
            strict: false,
            accel: AccelKind::Bvh,
            memory_limit: Budget::machine_default(),
        }
    }
}

/// A scene on its way to being rendered: what the file said, everything reported about
/// it so far, and — once built without errors — the scene itself.
pub struct Session {
    pub desc: SceneDesc,
    pub diags: Diagnostics,
    pub built: Option<Built>,
    /// Every file read so far (the scene file, then what the build read) and the memory
    /// budget.
    pub res: Resources,
    pub parse_seconds: f64,
    pub build_seconds: f64,
    options: SessionOptions,
}

impl Session {
    /// Parses a scene file; nothing is built yet ([`Session::build`]).
    pub fn parse_file(path: &Path, options: SessionOptions) -> Session {
        Session::parse_file_with(path, options, &[])
    }

    /// Parses a scene file, then `overrides` (scene settings from the command line, as
    /// lines: `spp 64`), which replace what the file says.
    pub fn parse_file_with(path: &Path, options: SessionOptions, overrides: &[String]) -> Session {
        let mut res = Resources::new(options.memory_limit);
        let mut s = Session::parse_with(options, || {
            parse_file_with(path, ParseOptions { strict: options.strict }, &mut res, overrides)
        });
        s.res = res;
        s
    }

    /// Parses scene text; `name` is what diagnostics call it, and the files it names are
    /// found beside it.
    pub fn parse_text(name: &str, text: &[u8], options: SessionOptions) -> Session {
        Session::parse_text_with(name, text, options, &[])
    }

    /// [`Session::parse_text`] with command-line overrides ([`Session::parse_file_with`]).
    pub fn parse_text_with(name: &str, text: &[u8], options: SessionOptions, overrides: &[String]) -> Session {
        Session::parse_with(options, || {
            parse_bytes_with(name, text, ParseOptions { strict: options.strict }, overrides)
        })
    }

    fn parse_with(options: SessionOptions, parse: impl FnOnce() -> (SceneDesc, Diagnostics)) -> Session {
        let start = Instant::now();
        let (desc, diags) = parse();
        Session {
            desc,
            diags,
            built: None,
            res: Resources::new(options.memory_limit),
            parse_seconds: start.elapsed().as_secs_f64(),
            build_seconds: 0.0,
            options,
        }
    }

    /// Parses and builds a scene file.
    pub fn open(path: &Path, options: SessionOptions) -> Session {
        let mut s = Session::parse_file(path, options);
        s.build();
        s
    }

    /// Builds what was parsed, unless the parse found errors; whether the scene is ready.
    pub fn build(&mut self) -> bool {
        if self.built.is_none() && !self.diags.has_errors() {
            let start = Instant::now();
            let options = BuildOptions {
                accel: self.options.accel,
            };
            self.built = build(&self.desc, &options, &mut self.res, &mut self.diags);
            self.build_seconds = start.elapsed().as_secs_f64();
        }
        self.built.is_some()
    }
}

thread_local! {
    /// A pool of one thread that is this thread itself (rayon's `use_current_thread`),
    /// made the first time it is asked for on a thread that is in no pool yet, and kept
    /// for the thread's life: rayon makes the thread that pool's worker for good (its
    /// registry outlives any handle), so there is one per thread, never dropped before it.
    /// `None` where rayon cannot make it (the thread is in another pool already).
    static CALLING_THREAD_POOL: Option<std::sync::Arc<rayon::ThreadPool>> = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .use_current_thread()
        .build()
        .ok()
        .map(std::sync::Arc::new);
}

/// The most worker threads a run starts (`--threads`, `RAYON_NUM_THREADS`).
pub const MAX_THREADS: usize = 4096;

/// Worker threads that render jobs.
pub struct Renderer {
    pool: rayon::ThreadPool,
}

impl Renderer {
    /// `threads` workers, or one per core.
    /// `threads` workers; by default rayon's choice (every core, or `RAYON_NUM_THREADS`),
    /// held to [`MAX_THREADS`] as `--threads` is.
    pub fn new(threads: Option<usize>) -> Result<Renderer, String> {
        let from_env = || {
            std::env::var("RAYON_NUM_THREADS")
                .ok()
                .and_then(|v| v.trim().parse::<usize>().ok())
                .map_or(0, |n| n.min(MAX_THREADS))
        };
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads.unwrap_or_else(from_env).min(MAX_THREADS))
            .build()
            .map(|pool| Renderer { pool })
            .map_err(|e| format!("cannot start worker threads: {e}"))
    }

    pub fn threads(&self) -> usize {
        self.pool.current_num_threads()
    }

    /// Runs a scene's build (`work`: its BVH, its meshes, whatever it does in parallel)
    /// within the render's thread count. With one worker it runs on the calling thread,
    /// which would only wait for it otherwise: a one-thread run uses one core, and its
    /// worker's CPU time is the render's alone (what a side-by-side comparison that times
    /// the sampling by the worker threads' CPU time takes it to be). With more, on the
    /// workers.
    pub fn build<R: Send>(&self, work: impl FnOnce() -> R + Send) -> R {
        if self.threads() == 1 {
            // (A later build on this thread finds it in that pool already: `install` runs
            // the work in place.)
            if let Some(pool) = CALLING_THREAD_POOL.with(|p| p.clone()) {
                return pool.install(work);
            }
        }
        self.pool.install(work)
    }

    /// Renders `job` of a built scene; `progress` hears of every finished tile's pixels,
    /// and setting `cancel` stops the render (`None`).
    pub fn render(
        &self,
        built: &Built,
        job: &RenderJob,
        progress: &(dyn Fn(u64) + Sync),
        cancel: &AtomicBool,
    ) -> Option<(Film, RenderStats)> {
        self.render_after(built, job, None, None, progress, cancel)
    }

    /// [`Renderer::render`], continuing `earlier`: the film of the job's pixels' samples
    /// before `job.samples`; the result goes into `spare` when that is a film of an
    /// earlier pass that is no longer needed ([`render_after`]).
    pub fn render_after(
        &self,
        built: &Built,
        job: &RenderJob,
        earlier: Option<&Film>,
        spare: Option<Film>,
        progress: &(dyn Fn(u64) + Sync),
        cancel: &AtomicBool,
    ) -> Option<(Film, RenderStats)> {
        let control = RenderControl { progress, cancel };
        self.pool
            .install(|| render_after(&built.scene, built.integrator.as_ref(), job, earlier, spare, &control))
    }
}

#[cfg(test)]
mod tests {
    use super::Renderer;
    use std::thread::{current, ThreadId};

    /// The threads both halves of a parallel join ran on, and the pool's width there.
    fn joined() -> (ThreadId, ThreadId, usize) {
        let (a, b) = rayon::join(|| current().id(), || current().id());
        (a, b, rayon::current_num_threads())
    }

    #[test]
    fn a_one_thread_build_runs_on_the_calling_thread_and_a_wider_one_on_the_workers() {
        let here = current().id();
        let one = Renderer::new(Some(1)).unwrap();
        // Twice: the second time the thread is in its one-thread pool already.
        for _ in 0..2 {
            assert_eq!(one.build(joined), (here, here, 1));
        }
        let two = Renderer::new(Some(2)).unwrap();
        let (a, b, width) = two.build(joined);
        assert_eq!(width, 2);
        assert!(a != here && b != here);
        // And the one-thread build still finds this thread after a wider one.
        assert_eq!(one.build(joined), (here, here, 1));
    }
}
