//! The floors of every crate: each module imports only from its own floor and the floors
//! below it, so the code has no import cycles and a newcomer can read it bottom-up.
//! `docs/architecture.md` draws the same floors.
//!
//! The check reads the sources as text: every `crate::…` path, and every `super::…` path
//! that climbs to the crate root, outside comments, must name a module on the same floor
//! or a lower one. The parser and the scene description may use nothing of `lucent-core`
//! but its math (they record what a file says; the build step makes core objects).

use std::path::{Path, PathBuf};

/// `(module, floor)` for the top-level modules of a crate; `lib.rs`/`main.rs` are above
/// every floor.
type Floors = &'static [(&'static str, u32)];

const CORE: Floors = &[
    ("math", 0),
    ("pow", 0),
    ("huge_pages", 0),
    ("transform", 0),
    ("ray", 0),
    ("aabb", 0),
    ("hit", 0),
    ("spawn", 0),
    ("test_rng", 0),
    ("sampler", 0),
    ("sampling", 0),
    ("shape", 1),
    ("accel", 2),
    ("geometry", 3),
    ("tessellate", 4),
    ("shading", 5),
    ("light", 5),
    ("camera", 5),
    ("scene", 6),
    ("integrator", 7),
    ("render", 8),
    ("film", 8),
    ("image", 8),
];

const IO: Floors = &[
    ("diag", 0),
    ("fnv", 0),
    ("number", 0),
    ("resources", 0),
    ("desc", 1),
    ("cse167", 2),
    ("mesh_file", 3),
    ("obj", 3),
    ("ply", 3),
    ("patches", 3),
    ("texture_file", 3),
    ("image", 3),
    ("denoise", 3),
    ("state", 3),
    ("build", 4),
    ("session", 5),
];

const CLI: Floors = &[
    ("console", 0),
    ("output", 0),
    ("progress", 0),
    ("signals", 0),
    ("oom", 0),
    ("job_args", 0),
    ("settings_args", 0),
    ("aov_args", 0),
    ("targets", 0),
    ("picture", 1),
    ("partial", 2),
    ("plan", 2),
    ("render_args", 2),
    ("passes", 1),
    ("render", 3),
    ("check", 3),
    ("diff", 3),
    ("merge", 3),
    ("bench", 3),
    ("plan_command", 4),
];

/// Modules of `lucent-io` that record what a file says: of `lucent-core` they may use
/// only these modules (math).
const RECORDERS: &[&str] = &["desc", "cse167"];
const RECORDER_CORE: &[&str] = &["math", "transform"];

fn crate_src(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(name).join("src")
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The module path of a source file: `accel/bvh/mod.rs` → `[accel, bvh]`.
fn module_path(src: &Path, file: &Path) -> Vec<String> {
    let rel = file.strip_prefix(src).unwrap();
    let mut parts: Vec<String> = rel.iter().map(|p| p.to_string_lossy().into_owned()).collect();
    let last = parts.pop().unwrap();
    let stem = last.trim_end_matches(".rs");
    if !matches!(stem, "mod" | "lib" | "main") {
        parts.push(stem.to_string());
    }
    parts
}

fn ident_at(s: &str) -> &str {
    let end = s.find(|c: char| !(c.is_alphanumeric() || c == '_')).unwrap_or(s.len());
    &s[..end]
}

/// The first names of the paths after `prefix::` at `rest` (several for `{a, b::c}`).
fn names_after(rest: &str) -> Vec<String> {
    if let Some(group) = rest.strip_prefix('{') {
        let inner = &group[..group.find('}').unwrap_or(group.len())];
        inner.split(',').map(|p| ident_at(p.trim()).to_string()).collect()
    } else {
        vec![ident_at(rest).to_string()]
    }
}

/// Every top-level module of its own crate a line refers to, and every module of
/// another crate `foreign` (e.g. `lucent_core`) it names.
fn references(module: &[String], line: &str, foreign: &str) -> (Vec<String>, Vec<String>) {
    let code = line.split("//").next().unwrap_or("");
    let (mut own, mut other) = (Vec::new(), Vec::new());
    let boundary = |i: usize| i == 0 || !code[..i].ends_with(|c: char| c.is_alphanumeric() || c == '_');
    for (i, _) in code.match_indices("crate::").filter(|&(i, _)| boundary(i)) {
        own.extend(names_after(&code[i + "crate::".len()..]));
    }
    for (i, _) in code.match_indices("super::").filter(|&(i, _)| boundary(i)) {
        if i >= "super::".len() && code[..i].ends_with("super::") {
            continue; // counted from the first `super`
        }
        let mut rest = &code[i..];
        let mut depth = 0;
        while let Some(r) = rest.strip_prefix("super::") {
            rest = r;
            depth += 1;
        }
        // Only a path that climbs to the crate root leaves its own top-level module.
        if depth >= module.len() {
            own.extend(names_after(rest));
        }
    }
    let prefix = format!("{foreign}::");
    for (i, _) in code.match_indices(&prefix).filter(|&(i, _)| boundary(i)) {
        other.extend(names_after(&code[i + prefix.len()..]));
    }
    (own, other)
}

fn check_crate(name: &str, floors: Floors, violations: &mut Vec<String>) {
    let src = crate_src(name);
    let floor = |m: &str| floors.iter().find(|(n, _)| *n == m).map(|(_, f)| *f);
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    files.sort();
    for file in files {
        let module = module_path(&src, &file);
        let Some(top) = module.first() else { continue }; // lib.rs, main.rs
        let Some(own_floor) = floor(top) else {
            violations.push(format!(
                "{}: module '{top}' has no floor in tests/layering.rs",
                file.display()
            ));
            continue;
        };
        let text = std::fs::read_to_string(&file).unwrap();
        for (n, line) in text.lines().enumerate() {
            let (own, core) = references(&module, line, "lucent_core");
            for target in own {
                if let Some(f) = floor(&target) {
                    if f > own_floor {
                        violations.push(format!(
                            "{}:{}: {top} (floor {own_floor}) imports {target} (floor {f})",
                            file.display(),
                            n + 1
                        ));
                    }
                }
            }
            if name == "lucent-io" && RECORDERS.contains(&top.as_str()) {
                for target in core.iter().filter(|t| !RECORDER_CORE.contains(&t.as_str())) {
                    violations.push(format!(
                        "{}:{}: {top} records what a file says, but uses lucent_core::{target}",
                        file.display(),
                        n + 1
                    ));
                }
            }
        }
    }
}

#[test]
fn every_module_imports_only_from_its_floor_or_below() {
    let mut violations = Vec::new();
    check_crate("lucent-core", CORE, &mut violations);
    check_crate("lucent-io", IO, &mut violations);
    check_crate("lucent", CLI, &mut violations);
    assert!(violations.is_empty(), "\n{}", violations.join("\n"));
}

#[test]
fn the_check_sees_upward_imports() {
    let m = |p: &[&str]| p.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    assert_eq!(
        references(&m(&["shape", "sphere"]), "use crate::geometry::mesh::X;", "x").0,
        ["geometry"]
    );
    assert_eq!(references(&m(&["light"]), "use super::scene::Scene;", "x").0, ["scene"]);
    assert!(references(&m(&["accel", "bvh"]), "use super::packet::P;", "x")
        .0
        .is_empty());
    assert_eq!(
        references(&m(&["a", "b"]), "use super::super::{c::D, e};", "x").0,
        ["c", "e"]
    );
    assert!(references(&m(&["a"]), "// see crate::render", "x").0.is_empty());
    assert_eq!(
        references(&m(&["desc"]), "lucent_core::scene::Scene", "lucent_core").1,
        ["scene"]
    );
}
