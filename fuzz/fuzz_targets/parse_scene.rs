//! Any bytes as a scene: the parser and the build step must not panic, and every
//! diagnostic must render (with the harness's caps, `lucent_fuzz::built_scene`). Run
//! with `cargo +nightly fuzz run parse_scene` from this folder.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = lucent_fuzz::built_scene(data);
});
