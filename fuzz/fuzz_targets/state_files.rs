//! Any bytes as a render state file (`--resume`, `lucent merge`): decoding must return a
//! state or an error, never panic; a state that decodes must encode and decode back to
//! itself, merge with itself cut into two sample ranges (or say why not), and resolve to
//! an image that every output format encodes (or refuses) without a panic.
//! Run with `cargo +nightly fuzz run state_files` from this folder.
//!
//! The harness writes the right checksum over whatever follows the `data` line, so that
//! the fuzzer reaches the pixels instead of stopping at the checksum.
#![no_main]

use libfuzzer_sys::fuzz_target;
use lucent_io::fnv::{fnv1a, START};
use lucent_io::image::{encode_exr, encode_hdr, encode_png, ImageInfo};
use lucent_io::state::{describe_render, merge, RenderState};

/// Pictures larger than this many pixels are not resolved (the fuzzer's time is better
/// spent elsewhere; their decoding was checked all the same).
const MAX_PIXELS: usize = 1 << 16;

fuzz_target!(|data: &[u8]| {
    let mut bytes = data.to_vec();
    let marker = b"\ndata\n";
    if let Some(at) = bytes.windows(marker.len()).position(|w| w == marker) {
        let body = at + marker.len();
        if bytes.len() >= body + 8 {
            let end = bytes.len() - 8;
            let sum = fnv1a(&bytes[body..end], START).to_le_bytes();
            bytes[end..].copy_from_slice(&sum);
        }
    }
    let Ok(state) = RenderState::decode(&bytes) else {
        return;
    };
    let encoded = state.encode();
    let again = RenderState::decode(&encoded).expect("a state's own encoding decodes");
    assert!(again.encode() == encoded, "a state encodes to the same bytes twice");
    let names = ["a".to_string(), "b".to_string()];
    let _ = merge(std::slice::from_ref(&state), &names);
    let h = &state.header;
    if h.samples.len() >= 2 {
        // The same pixels, their samples in two ranges: a merge of the two halves'
        // headers (with the whole film in the first) must not panic.
        let mid = h.samples.start + h.samples.len() as u32 / 2;
        let mut a = state.clone();
        a.header.samples = h.samples.start..mid;
        let mut b = state.clone();
        b.header.samples = mid..h.samples.end;
        let _ = merge(&[a, b], &names);
    }
    if state.film.counts.len() > MAX_PIXELS {
        return;
    }
    let image = state.film.resolve();
    let _ = state.film.resolve_aovs();
    let info = ImageInfo {
        gamma: h.gamma,
        text: vec![
            ("Source".into(), h.scene_name.clone()),
            ("Comment".into(), describe_render(h)),
        ],
        origin: (h.pixels.x0, h.pixels.y0),
        full: h.resolution,
    };
    let (w, ht) = (image.width, image.height);
    let _ = encode_png(w, ht, &image.to_rgb8(h.gamma), &info);
    let _ = encode_exr(w, ht, &image.to_rgb_f32(), &info);
    let _ = encode_hdr(w, ht, &image.to_rgb_f32());
});
