//! Ctrl-C and SIGTERM. The first asks the render to stop: the render loop looks at the
//! flag between pixels and between samples, the run saves the samples of the passes it
//! finished (a partial image and a state beside the output, never over it) and ends with
//! exit code 130 (143 for SIGTERM); should a single sample take longer, the run ends
//! anyway a second later (or once a checkpoint being written and the partial render are
//! saved, at most 30 s). During the write of the final output, and at a second signal,
//! the run ends at once. Every way
//! out removes the temporary file of an output being written, so an existing output is
//! left as it was.

use std::sync::atomic::{AtomicBool, AtomicI32, Ordering};
use std::time::Duration;

use lucent_io::resources::output::remove_temporary_files_and_exit;
use signal_hook::consts::{SIGINT, SIGTERM};

static CANCEL: AtomicBool = AtomicBool::new(false);
static SIGNAL: AtomicI32 = AtomicI32::new(0);
static SAVING: AtomicBool = AtomicBool::new(false);
static WRITING_FINAL: AtomicBool = AtomicBool::new(false);

/// Whether the run is writing its final outputs: a signal then ends it at once (the way
/// out of a write that does not finish, to a FIFO nobody reads). Checkpoints and partial
/// renders are not this: a signal during one lets it finish, and the run saves its
/// samples as after any other signal.
pub fn writing_final(on: bool) {
    WRITING_FINAL.store(on, Ordering::Relaxed);
}

/// Whether the run is saving a partial render after a signal (the one-second limit then
/// waits for it, up to 30 s).
pub fn saving(on: bool) {
    SAVING.store(on, Ordering::Relaxed);
}

/// Set once a signal has asked the run to stop.
pub fn cancel_flag() -> &'static AtomicBool {
    &CANCEL
}

/// The exit code of a run a signal stopped: 128 + the signal's number.
pub fn exit_code() -> u8 {
    (128 + SIGNAL.load(Ordering::Relaxed).clamp(0, 127)) as u8
}

/// Starts listening for SIGINT and SIGTERM (once per process).
pub fn install() {
    let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM]) else {
        return; // Without the handler the default applies: the signal ends the run.
    };
    std::thread::spawn(move || {
        for (count, sig) in signals.forever().enumerate() {
            SIGNAL.store(sig, Ordering::Relaxed);
            CANCEL.store(true, Ordering::Relaxed);
            if count > 0 || WRITING_FINAL.load(Ordering::Relaxed) {
                stop_now();
            }
            // The run stops cleanly within a second (or once its partial render is
            // saved), or it is stopped.
            std::thread::spawn(|| {
                let start = std::time::Instant::now();
                loop {
                    std::thread::sleep(Duration::from_millis(50));
                    let waited = start.elapsed();
                    if (waited >= Duration::from_secs(1) && !SAVING.load(Ordering::Relaxed))
                        || waited >= Duration::from_secs(30)
                    {
                        stop_now();
                    }
                }
            });
        }
    });
}

/// Ends the run: the message (written directly: a stalled or closed stderr must not
/// keep the run alive), then the temporary files, then the process.
fn stop_now() -> ! {
    let msg = b"\nlucent: interrupted; nothing written\n";
    // SAFETY: writing a static buffer to standard error; the result does not matter.
    unsafe {
        libc::write(2, msg.as_ptr().cast(), msg.len());
    }
    remove_temporary_files_and_exit(exit_code() as i32)
}
