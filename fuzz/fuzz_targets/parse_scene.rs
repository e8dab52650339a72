//! Any bytes: the CSE167 parser and the build step must not panic, and every diagnostic
//! must render. Run with `cargo +nightly fuzz run parse_scene` from this folder.
#![no_main]

use libfuzzer_sys::fuzz_target;
use lucent_io::session::{Session, SessionOptions};

fuzz_target!(|data: &[u8]| {
    let mut session = Session::parse_text("fuzz.test", data, SessionOptions::default());
    if let Some((w, h)) = session.desc.size.as_ref().map(|s| s.value) {
        // Building is linear in the scene; rendering is not exercised here.
        if (w as u64) * (h as u64) <= 1 << 20 {
            session.build();
        }
    }
    let _ = session.diags.render(&session.desc.sources);
});
