//! The files a run writes, checked together before any work is done and again before
//! they are written: none may be one of the run's inputs (by any path: links, hard
//! links, `/proc`), no two may be the same file (`-o x.png --state x.png` would keep
//! only one of them), and at most one may go to standard output (by any name: `-`,
//! `/dev/fd/1`, the file it was sent to). Devices such as
//! `/dev/null` take any number. A run of several scenes keeps what its earlier scenes
//! read and wrote ([`RunFiles`]): a later scene may replace neither (an earlier scene's
//! output may be a later scene's input: one scene makes the texture the next one reads).

use std::ffi::OsString;
use std::path::{Path, PathBuf};

use lucent_io::resources::input::FileId;
use lucent_io::resources::output::standard_output;
use lucent_io::resources::{Inputs, OutputTarget};

/// What the scenes rendered so far in this run read and were to write.
#[derive(Default)]
pub struct RunFiles {
    pub inputs: Inputs,
    pub outputs: Vec<(PathBuf, OutputTarget)>,
}

impl RunFiles {
    /// Checks a later scene's `targets`: none may be a file the earlier scenes read or
    /// wrote.
    pub fn check(&self, targets: &[(&Path, &OutputTarget)]) -> Result<(), String> {
        for (name, target) in targets {
            target
                .check_not_input(&self.inputs)
                .map_err(|e| format!("cannot write {}: {e}", name.display()))?;
            if let Some((earlier, _)) = self.outputs.iter().find(|(_, t)| same_file(t, target)) {
                return Err(format!(
                    "cannot write {}: an earlier scene of the run wrote it ({}); give each scene an output of its own",
                    name.display(),
                    earlier.display()
                ));
            }
        }
        Ok(())
    }

    /// Records what a scene reads and may write.
    pub fn add(&mut self, inputs: &Inputs, targets: &[(&Path, &OutputTarget)]) {
        self.inputs.extend(inputs);
        self.outputs
            .extend(targets.iter().map(|(n, t)| (n.to_path_buf(), (*t).clone())));
    }
}

/// Checks `targets` (each with the name it was given) against `inputs` and each other.
pub fn check_targets(targets: &[(&Path, &OutputTarget)], inputs: &Inputs) -> Result<(), String> {
    for (name, target) in targets {
        target
            .check_not_input(inputs)
            .map_err(|e| format!("cannot write {}: {e}", name.display()))?;
    }
    for (j, (b, tb)) in targets.iter().enumerate() {
        if let Some((a, _)) = targets[..j].iter().find(|(_, ta)| same_file(ta, tb)) {
            return Err(format!(
                "cannot write both {} and {}: they are the same file (name one of them otherwise)",
                a.display(),
                b.display()
            ));
        }
    }
    Ok(())
}

fn same_file(a: &OutputTarget, b: &OutputTarget) -> bool {
    match (a, b) {
        (OutputTarget::Stdout, OutputTarget::Stdout) => true,
        // `-` beside `/dev/fd/1`, or beside the file standard output was sent to; devices
        // (`/dev/null`) still take any number.
        (OutputTarget::Stdout, OutputTarget::File(p) | OutputTarget::Device(p))
        | (OutputTarget::File(p) | OutputTarget::Device(p), OutputTarget::Stdout) => {
            match (standard_output(), std::fs::metadata(p)) {
                (Some(out), Ok(m)) => !is_char_device(&m) && FileId::of(&out) == FileId::of(&m),
                _ => false,
            }
        }
        (OutputTarget::File(p), OutputTarget::File(q)) => {
            if let (Ok(m), Ok(n)) = (std::fs::metadata(p), std::fs::metadata(q)) {
                return FileId::of(&m) == FileId::of(&n);
            }
            matches!((place(p), place(q)), (Some(x), Some(y)) if x == y)
        }
        _ => false,
    }
}

fn is_char_device(m: &std::fs::Metadata) -> bool {
    use std::os::unix::fs::FileTypeExt;
    m.file_type().is_char_device()
}

/// Where a file is or will be: its folder, absolute with links followed, and its name.
fn place(p: &Path) -> Option<(PathBuf, OsString)> {
    let dir = match p.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    Some((std::fs::canonicalize(dir).ok()?, p.file_name()?.to_os_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_same_file_by_two_names_is_refused_and_devices_are_not() {
        let dir = std::env::temp_dir().join(format!("lucent-targets-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("sub")).unwrap();
        std::fs::write(dir.join("old.png"), b"x").unwrap();
        std::fs::hard_link(dir.join("old.png"), dir.join("link.png")).unwrap();
        let t = |p: PathBuf| (p.clone(), OutputTarget::resolve(&p).unwrap());
        let check = |list: &[(PathBuf, OutputTarget)]| {
            let v: Vec<(&Path, &OutputTarget)> = list.iter().map(|(p, t)| (p.as_path(), t)).collect();
            check_targets(&v, &Inputs::default())
        };
        let new = t(dir.join("new.png"));
        let again = t(dir.join("sub/../new.png"));
        assert!(check(&[new.clone(), again]).unwrap_err().contains("the same file"));
        assert!(check(&[t(dir.join("old.png")), t(dir.join("link.png"))]).is_err());
        assert!(check(&[new.clone(), t(dir.join("new.lstate"))]).is_ok());
        let stdout = (PathBuf::from("-"), OutputTarget::Stdout);
        assert!(check(&[stdout.clone(), new, stdout]).is_err());
        assert!(check(&[t("/dev/null".into()), t("/dev/null".into())]).is_ok());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
