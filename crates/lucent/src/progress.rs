//! The progress bar: the phase (building, rendering, writing), elapsed time and ETA on a
//! terminal, nothing otherwise.

use std::io::IsTerminal;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

pub struct Progress {
    bar: ProgressBar,
}

impl Progress {
    /// A bar over `total` samples (pixels × samples per pixel); hidden with `quiet` or when stderr is not a terminal.
    pub fn new(total: u64, quiet: bool) -> Progress {
        let bar = if quiet || !std::io::stderr().is_terminal() {
            ProgressBar::hidden()
        } else {
            let bar = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr_with_hz(10));
            let style = ProgressStyle::with_template(
                "rendering {elapsed_precise} [{wide_bar}] {percent:>3}%  {human_pos}/{human_len} samples  ETA {eta_precise}",
            )
            .expect("valid template")
            .progress_chars("=> ");
            bar.set_style(style);
            bar
        };
        Progress { bar }
    }

    /// A spinner naming a phase that has no count (`building`, `writing`), until
    /// [`Progress::finish`].
    pub fn phase(name: &str, quiet: bool) -> Progress {
        let bar = if quiet || !std::io::stderr().is_terminal() {
            ProgressBar::hidden()
        } else {
            let bar = ProgressBar::new_spinner();
            bar.set_style(ProgressStyle::with_template("{msg} {elapsed_precise} {spinner}").expect("valid template"));
            bar.set_message(name.to_string());
            bar.enable_steady_tick(std::time::Duration::from_millis(200));
            bar
        };
        Progress { bar }
    }

    pub fn advance(&self, samples: u64) {
        self.bar.inc(samples);
    }

    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

/// Clears a phase's spinner when the phase ends, however it ends.
pub struct Finish<'a>(pub &'a Progress);

impl Drop for Finish<'_> {
    fn drop(&mut self) {
        self.0.finish();
    }
}
