//! Reading the files a run needs — the scene, meshes, MTL libraries, patch files,
//! textures, environment maps — only if they are regular files of a bounded size: a
//! FIFO would block the run forever, `/dev/zero` or `/dev/urandom` would grow its memory
//! until the machine stops it. A file is opened without blocking (so a FIFO cannot hang
//! the open), then its kind and size are checked on the open handle (so nothing can be
//! swapped in between), and it is read no further than its limit. Every file read is
//! recorded, so that an output can refuse to overwrite one of the run's inputs.

use std::fs::File;
use std::io::Read;
use std::path::{Path, PathBuf};

use super::io_reason;

/// The largest scene file lucent reads.
pub const MAX_SCENE_BYTES: u64 = 1 << 30;
/// The largest mesh file (OBJ or PLY).
pub const MAX_MESH_BYTES: u64 = 4 << 30;
/// The largest MTL library or Bézier patch file.
pub const MAX_SMALL_FILE_BYTES: u64 = 64 << 20;
/// The largest image file (texture or environment map), compressed.
pub const MAX_IMAGE_BYTES: u64 = 1 << 30;

/// Which file a path names: its device and inode, the same for every path (and hard
/// link) to it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FileId {
    dev: u64,
    ino: u64,
}

impl FileId {
    pub fn of(meta: &std::fs::Metadata) -> FileId {
        #[cfg(unix)]
        {
            use std::os::unix::fs::MetadataExt;
            FileId {
                dev: meta.dev(),
                ino: meta.ino(),
            }
        }
        #[cfg(not(unix))]
        {
            let _ = meta;
            FileId { dev: 0, ino: 0 }
        }
    }
}

/// The files a run has read.
#[derive(Clone, Debug, Default)]
pub struct Inputs {
    files: Vec<(FileId, PathBuf)>,
}

impl Inputs {
    pub fn record(&mut self, id: FileId, path: &Path) {
        if !self.files.iter().any(|(f, _)| *f == id) {
            self.files.push((id, path.to_path_buf()));
        }
    }

    /// The path by which the run read the file `id`, if it did.
    pub fn find(&self, id: FileId) -> Option<&Path> {
        self.files.iter().find(|(f, _)| *f == id).map(|(_, p)| p.as_path())
    }

    /// Records every file of `other` too.
    pub fn extend(&mut self, other: &Inputs) {
        for (id, path) in &other.files {
            self.record(*id, path);
        }
    }

    pub fn paths(&self) -> impl Iterator<Item = &Path> {
        self.files.iter().map(|(_, p)| p.as_path())
    }
}

/// Opens `path` for reading if it is a regular file of at most `limit` bytes; records it
/// in `inputs`. Returns the file and its size.
///
/// The path is looked at first, so that nothing but a regular file is ever opened (opening
/// a device can have effects of its own); it is then opened without blocking (a FIFO
/// swapped in meanwhile cannot hang the open) and must still be the same file.
pub fn open_input(path: &Path, limit: u64, inputs: &mut Inputs) -> Result<(File, u64), String> {
    let before = std::fs::metadata(path).map_err(|e| io_reason(&e))?;
    if !before.is_file() {
        return Err(format!("not a regular file ({})", kind(&before)));
    }
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NONBLOCK | libc::O_NOCTTY);
    }
    let file = options.open(path).map_err(|e| io_reason(&e))?;
    let meta = file.metadata().map_err(|e| io_reason(&e))?;
    if !meta.is_file() || FileId::of(&meta) != FileId::of(&before) {
        return Err("the file changed while it was opened".into());
    }
    if meta.len() > limit {
        return Err(format!(
            "the file is {}, more than the {} lucent reads",
            bytes(meta.len()),
            bytes(limit)
        ));
    }
    inputs.record(FileId::of(&meta), path);
    Ok((file, meta.len()))
}

/// The whole of a regular file of at most `limit` bytes (see [`open_input`]); a file
/// that grows while it is read is an error.
pub fn read_input(path: &Path, limit: u64, inputs: &mut Inputs) -> Result<Vec<u8>, String> {
    let (file, size) = open_input(path, limit, inputs)?;
    let mut bytes = Vec::new();
    // (In the `lucent` binary an allocation the system refuses ends the run before this
    // can answer, with exit code 2 and a message of its own: see `lucent`'s `oom.rs`.)
    bytes
        .try_reserve_exact(size as usize)
        .map_err(|_| format!("no memory for the file's {}", self::bytes(size)))?;
    file.take(size + 1).read_to_end(&mut bytes).map_err(|e| io_reason(&e))?;
    if bytes.len() as u64 > size {
        return Err("the file grew while it was read".into());
    }
    Ok(bytes)
}

/// What kind of file system object `meta` describes, in words.
pub fn kind(meta: &std::fs::Metadata) -> &'static str {
    let t = meta.file_type();
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return "a FIFO";
        }
        if t.is_char_device() {
            return "a character device";
        }
        if t.is_block_device() {
            return "a block device";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    if t.is_dir() {
        "a directory"
    } else if t.is_symlink() {
        "a symbolic link"
    } else if t.is_file() {
        "a regular file"
    } else {
        "not a file"
    }
}

/// A byte count for people: "512 kB", "3.2 GB".
pub fn bytes(n: u64) -> String {
    let n = n as f64;
    let (v, unit) = match n {
        _ if n < 1e3 => return format!("{n} bytes"),
        _ if n < 1e6 => (n / 1e3, "kB"),
        _ if n < 1e9 => (n / 1e6, "MB"),
        _ => (n / 1e9, "GB"),
    };
    // Two figures at least: "1.2 kB, more than the 1.0 kB left", not "1 kB … 1 kB".
    if v < 10.0 || unit == "GB" {
        format!("{v:.1} {unit}")
    } else {
        format!("{v:.0} {unit}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_regular_files_within_their_limit_are_read() {
        let test = crate::TestDir::new("input");
        let dir = test.0.clone();
        let mut inputs = Inputs::default();
        let f = dir.join("a.txt");
        std::fs::write(&f, b"hello").unwrap();
        assert_eq!(read_input(&f, 5, &mut inputs).unwrap(), b"hello");
        assert!(read_input(&f, 4, &mut inputs)
            .unwrap_err()
            .contains("more than the 4 bytes"));
        assert!(read_input(&dir, 100, &mut inputs).unwrap_err().contains("a directory"));
        assert!(read_input(Path::new("/dev/zero"), 100, &mut inputs)
            .unwrap_err()
            .contains("character device"));
        assert_eq!(
            read_input(&dir.join("none"), 100, &mut inputs).unwrap_err(),
            "no such file"
        );
        let id = FileId::of(&std::fs::metadata(&f).unwrap());
        assert_eq!(inputs.find(id), Some(f.as_path()));
        #[cfg(unix)]
        {
            // A FIFO with no writer: refused at once instead of waiting forever.
            let fifo = dir.join("fifo");
            let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
            // SAFETY: a valid NUL-terminated path.
            assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
            assert!(read_input(&fifo, 100, &mut inputs).unwrap_err().contains("a FIFO"));
        }
    }
}
