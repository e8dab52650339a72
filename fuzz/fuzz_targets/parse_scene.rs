//! Any bytes as a scene: the parser and the build step must not panic, and every
//! diagnostic must render. Run with `cargo +nightly fuzz run parse_scene` from this
//! folder.
//!
//! Sizes are capped here, in the harness, not in lucent: inputs of at most 8 kB, the
//! build uses the brute-force list (no structure to build) and a 64 MB memory budget,
//! so that an input asking for a huge tessellation is refused in microseconds instead of
//! taking the fuzzer's time.
#![no_main]

use libfuzzer_sys::fuzz_target;
use lucent_core::accel::AccelKind;
use lucent_io::session::{Session, SessionOptions};

fuzz_target!(|data: &[u8]| {
    if data.len() > 8192 {
        return;
    }
    let options = SessionOptions {
        strict: false,
        accel: AccelKind::List,
        memory_limit: 64 << 20,
    };
    let mut session = Session::parse_text("fuzz.test", data, options);
    session.build();
    let _ = session.diags.render(&session.desc.sources);
});
