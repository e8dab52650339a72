//! Any bytes as an OBJ or PLY file (the first byte picks the format): the mesh loaders,
//! the polygon loaders and subdivision must return a mesh or an error, never panic.
//! Run with `cargo +nightly fuzz run mesh_files` from this folder.
//!
//! The file goes to /dev/shm where there is one (no disk on the fuzzer's path); meshes
//! of more than 64 faces are not subdivided.
#![no_main]

use libfuzzer_sys::fuzz_target;
use lucent_core::tessellate::subdivision::{subdivide, Scheme};
use lucent_io::mesh_file::{load_mesh, load_polygons};
use lucent_io::resources::Resources;

fuzz_target!(|data: &[u8]| {
    let Some((&kind, body)) = data.split_first() else {
        return;
    };
    let ext = if kind & 1 == 0 { "obj" } else { "ply" };
    let dir = if std::path::Path::new("/dev/shm").is_dir() {
        std::path::PathBuf::from("/dev/shm")
    } else {
        std::env::temp_dir()
    };
    let path = dir.join(format!("lucent-fuzz-{}.{ext}", std::process::id()));
    std::fs::write(&path, body).expect("temp file");
    let mut res = Resources::new(64 << 20);
    let _ = load_mesh(&path, &mut res);
    if let Ok(control) = load_polygons(&path, &mut res) {
        if control.faces.len() < 64 {
            let scheme = if kind & 2 == 0 { Scheme::Loop } else { Scheme::CatmullClark };
            let _ = subdivide(&control, scheme, 2);
        }
    }
});
