//! Any bytes: the CSE167 parser and the build step must not panic, and every diagnostic
//! must render. Run with `cargo +nightly fuzz run parse_scene` from this folder.
#![no_main]

use libfuzzer_sys::fuzz_target;
use lucent_io::build::{build, BuildOptions};
use lucent_io::cse167::{parse_bytes, ParseOptions};

fuzz_target!(|data: &[u8]| {
    let (desc, mut diags) = parse_bytes("fuzz.test", data, ParseOptions::default());
    if !diags.has_errors() {
        if let Some((w, h)) = desc.size.as_ref().map(|s| s.value) {
            // Building is linear in the scene; rendering is not exercised here.
            if (w as u64) * (h as u64) <= 1 << 20 {
                let _ = build(&desc, &BuildOptions::default(), &mut diags);
            }
        }
    }
    let _ = diags.render(&desc.sources);
});
