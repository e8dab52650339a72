//! Writing an output without destroying anything: a regular file is written to a
//! temporary file beside it and renamed over it (readers see the old file or the whole
//! new one), a symbolic link is written through (the link stays), a character device or
//! FIFO (`/dev/null`, a pipe) is written directly and never replaced, standard output
//! (`-`) is written as a stream; anything else — a directory, a socket — and every file
//! the run read as an input are refused.
//!
//! Temporary files are registered while they exist, so that every way out of the
//! program — an error, a panic, Ctrl-C, a failed allocation — removes them
//! ([`remove_temporary_files`]).

use std::ffi::CString;
use std::fs::{self, File};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use super::input::{kind, FileId, Inputs};
use super::io_reason;

/// Where an output goes, and how it is written.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum OutputTarget {
    /// A regular file (there or not yet), replaced atomically. Symbolic links have been
    /// followed: this is the file they lead to.
    File(PathBuf),
    /// A character device or FIFO, or a path through `/proc` or `/dev/fd`: written
    /// directly, never replaced.
    Device(PathBuf),
    /// Standard output (`-`, `/dev/stdout`).
    Stdout,
}

/// What standard output is open on (a file, a pipe, a terminal), if it can be asked.
pub fn standard_output() -> Option<fs::Metadata> {
    #[cfg(unix)]
    {
        use std::os::fd::AsFd;
        // A second descriptor of it, closed again when the file is dropped.
        let fd = std::io::stdout().as_fd().try_clone_to_owned().ok()?;
        File::from(fd).metadata().ok()
    }
    #[cfg(not(unix))]
    None
}

/// Symbolic links followed before giving up (as the kernel does).
const MAX_LINKS: usize = 40;
/// The longest file name most file systems take.
const NAME_MAX: usize = 255;

impl OutputTarget {
    /// How `path` would be written, or why it cannot be: checked before any work is
    /// done, so a run that could not write its result does not start.
    pub fn resolve(path: &Path) -> Result<OutputTarget, String> {
        if path.as_os_str() == "-" || path == Path::new("/dev/stdout") {
            return Ok(OutputTarget::Stdout);
        }
        if path.as_os_str().is_empty() || path.file_name().is_none() {
            return Err("not a file name".into());
        }
        let mut p = path.to_path_buf();
        for _ in 0..MAX_LINKS {
            let meta = match fs::symlink_metadata(&p) {
                Ok(m) => m,
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => return new_file(p),
                Err(e) => return Err(io_reason(&e)),
            };
            if meta.file_type().is_symlink() {
                // Links into /proc and /dev/fd name open files, not paths: written there.
                if p.starts_with("/proc") || p.starts_with("/dev/fd") {
                    return Ok(OutputTarget::Device(p));
                }
                let target = fs::read_link(&p).map_err(|e| io_reason(&e))?;
                p = p.parent().unwrap_or(Path::new("")).join(target);
                continue;
            }
            if meta.is_file() {
                return new_file(p);
            }
            return match kind(&meta) {
                "a character device" | "a FIFO" => Ok(OutputTarget::Device(p)),
                other => Err(format!("it is {other}")),
            };
        }
        Err("too many levels of symbolic links".into())
    }

    /// An error if writing would overwrite one of the run's inputs (through a link into
    /// `/proc` too).
    /// Standard output too, when it was sent to an input file (`>> texture.png`).
    pub fn check_not_input(&self, inputs: &Inputs) -> Result<(), String> {
        let meta = match self {
            OutputTarget::File(path) | OutputTarget::Device(path) => fs::metadata(path),
            OutputTarget::Stdout => match standard_output() {
                Some(m) if m.is_file() => Ok(m),
                _ => return Ok(()),
            },
        };
        match meta {
            Ok(meta) => match inputs.find(FileId::of(&meta)) {
                Some(input) => Err(format!(
                    "it is one of this run's inputs ({}); choose another output",
                    input.display()
                )),
                None => Ok(()),
            },
            Err(_) => Ok(()),
        }
    }

    /// Writes `bytes`; on any failure the target is as it was.
    pub fn write(&self, bytes: &[u8]) -> Result<(), String> {
        match self {
            OutputTarget::File(path) => write_atomically(path, bytes),
            OutputTarget::Device(path) => write_device(path, bytes),
            OutputTarget::Stdout => {
                let mut out = std::io::stdout().lock();
                out.write_all(bytes)
                    .and_then(|_| out.flush())
                    .map_err(|e| io_reason(&e))
            }
        }
    }

    /// Standard output that is a terminal: writing an image there would fill the screen
    /// with bytes.
    pub fn is_terminal(&self) -> bool {
        use std::io::IsTerminal;
        matches!(self, OutputTarget::Stdout) && std::io::stdout().is_terminal()
    }
}

/// Writes the outputs of one run together, so that a failure leaves every file as it
/// was: devices and standard output first (they cannot be taken back, and a FIFO nobody
/// reads or a full device fails there), then every file to a temporary beside it; only
/// once all are written are the temporaries renamed over their targets. The error names
/// the output that failed (its index).
pub fn write_together(outputs: &[(&OutputTarget, &[u8])]) -> Result<(), (usize, String)> {
    for (i, (target, bytes)) in outputs.iter().enumerate() {
        if !matches!(target, OutputTarget::File(_)) {
            target.write(bytes).map_err(|e| (i, e))?;
        }
    }
    let mut staged = Vec::new();
    for (i, (target, bytes)) in outputs.iter().enumerate() {
        if let OutputTarget::File(path) = target {
            let tmp = TemporaryFile::create(path).map_err(|e| (i, e))?;
            let mut file = tmp.file.as_ref().expect("just created");
            file.write_all(bytes)
                .and_then(|_| file.sync_all())
                .map_err(|e| (i, io_reason(&e)))?;
            staged.push((i, path, tmp));
        }
    }
    for (i, path, tmp) in staged {
        tmp.rename_over(path).map_err(|e| (i, e))?;
    }
    Ok(())
}

/// A regular file to be (re)written: its folder must take a new file.
fn new_file(path: PathBuf) -> Result<OutputTarget, String> {
    // A missing folder is named as such (the temporary file's error would say "no such
    // file" of the file being made).
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    match fs::metadata(dir) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Err(format!("no such folder: {}", dir.display())),
        Ok(m) if !m.is_dir() => return Err(format!("{} is not a folder", dir.display())),
        _ => {}
    }
    let tmp = TemporaryFile::create(&path)?;
    drop(tmp);
    Ok(OutputTarget::File(path))
}

fn write_device(path: &Path, bytes: &[u8]) -> Result<(), String> {
    let mut options = fs::OpenOptions::new();
    options.write(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        // A FIFO nobody reads would block the open forever: fail instead (ENXIO).
        options.custom_flags(libc::O_NONBLOCK);
    }
    let mut file = options.open(path).map_err(|e| match e.raw_os_error() {
        #[cfg(unix)]
        Some(libc::ENXIO) => "nothing reads from it".to_string(),
        _ => io_reason(&e),
    })?;
    #[cfg(unix)]
    {
        use std::os::fd::AsRawFd;
        // Writes may block once the reader is there.
        // SAFETY: fcntl on a descriptor this function owns.
        unsafe {
            let fd = file.as_raw_fd();
            let flags = libc::fcntl(fd, libc::F_GETFL);
            if flags >= 0 {
                libc::fcntl(fd, libc::F_SETFL, flags & !libc::O_NONBLOCK);
            }
        }
    }
    // A link into /proc may lead to a regular file (standard output sent to one): it is
    // written from its start, and only what is written remains, as `>` would.
    if file.metadata().is_ok_and(|m| m.is_file()) {
        file.set_len(0).map_err(|e| io_reason(&e))?;
    }
    file.write_all(bytes)
        .and_then(|_| file.flush())
        .map_err(|e| io_reason(&e))
}

/// Writes `bytes` to a temporary file beside `path`, syncs it and renames it over
/// `path`.
fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), String> {
    let tmp = TemporaryFile::create(path)?;
    let mut file = tmp.file.as_ref().expect("just created");
    file.write_all(bytes).map_err(|e| io_reason(&e))?;
    file.sync_all().map_err(|e| io_reason(&e))?;
    tmp.rename_over(path)
}

/// The temporary files that exist now, as C strings made when they were created, so that
/// removing them needs no allocation (the allocation-failure path uses it).
static TEMPORARY: Mutex<Vec<CString>> = Mutex::new(Vec::new());

/// Removes every temporary file this process has not renamed yet, for the last words of
/// a failed allocation: never allocates, and gives up if another thread holds the list
/// (it may be this one).
pub fn remove_temporary_files() {
    if let Ok(list) = TEMPORARY.try_lock() {
        unlink_all(&list);
    }
}

/// Removes every temporary file and ends the process with `code`, holding the list so
/// that no temporary file can be made meanwhile (for the signal handler).
pub fn remove_temporary_files_and_exit(code: i32) -> ! {
    let list = TEMPORARY.lock().unwrap_or_else(|e| e.into_inner());
    unlink_all(&list);
    // SAFETY: ends the process at once, without running exit handlers that the main
    // thread may be running too.
    unsafe { libc::_exit(code) }
}

fn unlink_all(list: &[CString]) {
    for c in list {
        #[cfg(unix)]
        // SAFETY: a valid NUL-terminated path.
        unsafe {
            libc::unlink(c.as_ptr());
        }
        #[cfg(not(unix))]
        let _ = c;
    }
}

/// A temporary file beside its target, removed unless it is renamed over it.
struct TemporaryFile {
    path: PathBuf,
    file: Option<File>,
    registered: Option<CString>,
    /// Renamed over its target: nothing to remove.
    renamed: bool,
}

impl TemporaryFile {
    /// `.NAME.PID.lucent-tmp` beside `target` (`.NAME.PID.N.lucent-tmp` if that exists
    /// already: another process's file is never touched), or `.lucent-PID.N.tmp` when
    /// that name would be longer than a file name may be. Made and registered under the
    /// list's lock, so that the signal handler sees every one.
    fn create(target: &Path) -> Result<TemporaryFile, String> {
        let name = target
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let pid = std::process::id();
        let mut list = TEMPORARY.lock().unwrap_or_else(|e| e.into_inner());
        // Room first: an allocation failing after the file exists could not remove it.
        list.reserve(1);
        for attempt in 0..100u32 {
            let n = if attempt == 0 {
                String::new()
            } else {
                format!(".{attempt}")
            };
            let long = format!(".{name}.{pid}{n}.lucent-tmp");
            let tmp_name = if long.len() <= NAME_MAX {
                long
            } else {
                format!(".lucent-{pid}{n}.tmp")
            };
            let path = target.with_file_name(tmp_name);
            let registered = path_cstring(&path);
            // The list's copy is made before the file exists, for the same reason.
            let listed = registered.clone();
            match fs::OpenOptions::new().write(true).create_new(true).open(&path) {
                Ok(file) => {
                    if let Some(c) = listed {
                        list.push(c); // into the room reserved above: no allocation
                    }
                    return Ok(TemporaryFile {
                        path,
                        file: Some(file),
                        registered,
                        renamed: false,
                    });
                }
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
                Err(e) => return Err(io_reason(&e)),
            }
        }
        Err("cannot find a free name for a temporary file beside it".into())
    }

    fn rename_over(mut self, target: &Path) -> Result<(), String> {
        self.file = None;
        fs::rename(&self.path, target).map_err(|e| io_reason(&e))?;
        self.renamed = true;
        self.unregister();
        Ok(())
    }

    fn unregister(&mut self) {
        if let Some(c) = self.registered.take() {
            let mut list = TEMPORARY.lock().unwrap_or_else(|e| e.into_inner());
            if let Some(i) = list.iter().position(|x| *x == c) {
                list.swap_remove(i);
            }
        }
    }
}

impl Drop for TemporaryFile {
    fn drop(&mut self) {
        if !self.renamed {
            self.file = None;
            let _ = fs::remove_file(&self.path);
            self.unregister();
        }
    }
}

fn path_cstring(path: &Path) -> Option<CString> {
    #[cfg(unix)]
    {
        use std::os::unix::ffi::OsStrExt;
        CString::new(path.as_os_str().as_bytes()).ok()
    }
    #[cfg(not(unix))]
    {
        CString::new(path.to_string_lossy().as_bytes()).ok()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn files_are_replaced_whole_and_links_and_devices_are_kept() {
        let test = crate::TestDir::new("out-kinds");
        let d = test.0.clone();
        let file = d.join("a.png");
        let target = OutputTarget::resolve(&file).unwrap();
        assert_eq!(target, OutputTarget::File(file.clone()));
        target.write(b"one").unwrap();
        target.write(b"two").unwrap();
        assert_eq!(fs::read(&file).unwrap(), b"two");
        // Through a link: the file it leads to is written, the link stays.
        #[cfg(unix)]
        {
            let link = d.join("link.png");
            std::os::unix::fs::symlink("a.png", &link).unwrap();
            let t = OutputTarget::resolve(&link).unwrap();
            assert_eq!(t, OutputTarget::File(d.join("a.png")));
            t.write(b"three").unwrap();
            assert!(fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
            assert_eq!(fs::read(&file).unwrap(), b"three");
            let null = OutputTarget::resolve(Path::new("/dev/null")).unwrap();
            assert_eq!(null, OutputTarget::Device("/dev/null".into()));
            null.write(b"x").unwrap();
            let full = OutputTarget::resolve(Path::new("/dev/full")).unwrap();
            assert_eq!(full.write(b"x").unwrap_err(), "no space left on device");
        }
        assert!(OutputTarget::resolve(&d).unwrap_err().contains("a directory"));
        // Nothing is left beside the file.
        let names: Vec<_> = fs::read_dir(&d).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert!(
            names.iter().all(|n| !n.to_string_lossy().contains("lucent-tmp")),
            "{names:?}"
        );
    }

    #[test]
    fn a_name_near_the_limit_gets_a_short_temporary_name() {
        let test = crate::TestDir::new("out-long");
        let d = test.0.clone();
        let file = d.join(format!("{}.png", "x".repeat(NAME_MAX - 4)));
        let t = OutputTarget::resolve(&file).unwrap();
        t.write(b"ok").unwrap();
        assert_eq!(fs::read(&file).unwrap(), b"ok");
    }

    #[test]
    fn inputs_are_not_overwritten() {
        let test = crate::TestDir::new("out-inputs");
        let d = test.0.clone();
        let scene = d.join("s.test");
        fs::write(&scene, "size 1 1").unwrap();
        let mut inputs = Inputs::default();
        super::super::input::read_input(&scene, 100, &mut inputs).unwrap();
        let t = OutputTarget::resolve(&scene).unwrap();
        assert!(t
            .check_not_input(&inputs)
            .unwrap_err()
            .contains("one of this run's inputs"));
        assert!(OutputTarget::resolve(&d.join("new.png"))
            .unwrap()
            .check_not_input(&inputs)
            .is_ok());
    }
}
