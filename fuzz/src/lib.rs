//! What the fuzz targets share: the caps that keep one run of a target short, set here
//! in the harness rather than in lucent (which must take any scene).

use lucent_core::accel::AccelKind;
use lucent_io::session::{Session, SessionOptions};

/// Inputs longer than this are skipped.
pub const MAX_INPUT: usize = 8192;

/// The scene in `data` parsed and built with the brute-force list (no structure to
/// build) and a 64 MB memory budget, so that an input asking for a huge tessellation is
/// refused in microseconds; `None` for an input over [`MAX_INPUT`]. Every diagnostic is
/// rendered on the way.
pub fn built_scene(data: &[u8]) -> Option<Session> {
    if data.len() > MAX_INPUT {
        return None;
    }
    let options = SessionOptions {
        strict: false,
        accel: AccelKind::List,
        memory_limit: 64 << 20,
    };
    let mut session = Session::parse_text("fuzz.test", data, options);
    session.build();
    let _ = session.diags.render(&session.desc.sources);
    Some(session)
}
