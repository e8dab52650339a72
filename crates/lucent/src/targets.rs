//! The files a run writes, checked together before any work is done and again before
//! they are written: none may be one of the run's inputs (by any path: links, hard
//! links, `/proc`), no two may be the same file (`-o x.png --state x.png` would keep
//! only one of them), and at most one may go to standard output. Devices such as
//! `/dev/null` take any number.

use std::ffi::OsString;
use std::path::{Path, PathBuf};

use lucent_io::resources::input::FileId;
use lucent_io::resources::{Inputs, OutputTarget};

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
        (OutputTarget::File(p), OutputTarget::File(q)) => {
            if let (Ok(m), Ok(n)) = (std::fs::metadata(p), std::fs::metadata(q)) {
                return FileId::of(&m) == FileId::of(&n);
            }
            matches!((place(p), place(q)), (Some(x), Some(y)) if x == y)
        }
        _ => false,
    }
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
