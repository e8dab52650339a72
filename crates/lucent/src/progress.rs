//! The progress bar: elapsed time and ETA on a terminal, nothing otherwise.

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
                "{elapsed_precise} [{wide_bar}] {percent:>3}%  {human_pos}/{human_len} samples  ETA {eta_precise}",
            )
            .expect("valid template")
            .progress_chars("=> ");
            bar.set_style(style);
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
