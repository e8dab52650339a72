//! The progress bar: the phase (building, rendering, writing), elapsed time and ETA on a
//! terminal, nothing otherwise.

use std::io::IsTerminal;
use std::time::Duration;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressState, ProgressStyle};

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
                "rendering {elapsed_precise} [{wide_bar}] {percent:>3}%  {human_pos}/{human_len} samples  ETA {remaining}",
            )
            .expect("valid template")
            .with_key("remaining", |state: &ProgressState, w: &mut dyn std::fmt::Write| {
                let _ = match remaining(state.pos(), state.len(), state.elapsed()) {
                    Some(left) => {
                        let s = left.as_secs();
                        write!(w, "{:02}:{:02}:{:02}", s / 3600, s / 60 % 60, s % 60)
                    }
                    None => write!(w, "--:--:--"),
                };
            })
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

/// The time a render has left at its mean rate since it began (as pbrt and Blender
/// estimate it), once it has run for a second; before that the rate says little (the
/// first pass, of one sample per pixel, runs at a rate of its own, and the first tiles
/// pay for cold caches and fresh pages: the bar's own estimate, a moving average, put a
/// 3-second render at nearly 3 minutes), and there is none.
fn remaining(done: u64, total: Option<u64>, elapsed: Duration) -> Option<Duration> {
    let total = total?;
    if elapsed < Duration::from_secs(1) || done == 0 {
        return None;
    }
    let left = total.saturating_sub(done) as f64;
    Some(Duration::from_secs_f64(elapsed.as_secs_f64() * left / done as f64))
}

/// Clears a phase's spinner when the phase ends, however it ends.
pub struct Finish<'a>(pub &'a Progress);

impl Drop for Finish<'_> {
    fn drop(&mut self) {
        self.0.finish();
    }
}

#[cfg(test)]
mod tests {
    use super::remaining;
    use std::time::Duration;

    #[test]
    fn the_time_left_is_the_mean_rate_after_the_first_second() {
        let s = Duration::from_secs;
        // A quarter done in 3 s: 9 s left; all done: none left.
        assert_eq!(remaining(250, Some(1000), s(3)), Some(s(9)));
        assert_eq!(remaining(1000, Some(1000), s(3)), Some(s(0)));
        // Too early, nothing done yet, or no total: no estimate.
        assert_eq!(remaining(10, Some(1000), Duration::from_millis(900)), None);
        assert_eq!(remaining(0, Some(1000), s(5)), None);
        assert_eq!(remaining(10, None, s(5)), None);
    }
}
