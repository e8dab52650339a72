//! Any bytes as an image file: a texture or environment map (PNG, JPEG, Radiance HDR,
//! OpenEXR; the first bytes pick the decoder) and the images `lucent diff` compares must
//! load or give an error, never panic, and never take more memory than the budget.
//! Run with `cargo +nightly fuzz run image_files` from this folder.
//!
//! The file goes to /dev/shm where there is one (no disk on the fuzzer's path).
#![no_main]

use libfuzzer_sys::fuzz_target;
use lucent_io::image::{read_rgb8, read_rgb_f32};
use lucent_io::resources::Resources;
use lucent_io::texture_file::load_image;

fuzz_target!(|data: &[u8]| {
    let dir = if std::path::Path::new("/dev/shm").is_dir() {
        std::path::PathBuf::from("/dev/shm")
    } else {
        std::env::temp_dir()
    };
    let path = dir.join(format!("lucent-fuzz-image-{}", std::process::id()));
    std::fs::write(&path, data).expect("temp file");
    let mut res = Resources::new(64 << 20);
    if let Ok(image) = load_image(&path, &mut res) {
        assert!(image.max_channel().is_finite());
    }
    // `lucent diff` reads whole files with the decoders' own limits.
    let _ = read_rgb8(&path);
    let _ = read_rgb_f32(&path);
});
