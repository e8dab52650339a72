//! Scene settings from the command line: `-D name=value` (Mitsuba's), `--size`,
//! `--maxdepth` — read as scene lines after the file — and `--quick`, a preview.

/// The settings the command line overrides, as scene lines: `--size`, `--maxdepth`, then
/// every `-D name=value` in order (the last wins).
pub fn overrides(size: Option<&[String]>, maxdepth: Option<&str>, define: &[String]) -> Vec<String> {
    let mut lines = Vec::new();
    if let Some(s) = size {
        lines.push(format!("size {}", s.join(" ")));
    }
    if let Some(d) = maxdepth {
        lines.push(format!("maxdepth {d}"));
    }
    for d in define {
        let (name, value) = d.split_once('=').unwrap_or((d, ""));
        lines.push(format!("{} {}", name.trim(), value.replace(',', " ").trim()));
    }
    lines
}

/// `--quick`: half the image size, at most 4 samples per pixel and 3 scattering events
/// (or mirror bounces).
pub fn quick(desc: &mut lucent_io::desc::SceneDesc) {
    if let Some(size) = &mut desc.size {
        size.value = ((size.value.0 / 2).max(1), (size.value.1 / 2).max(1));
    }
    if let Some(spp) = &mut desc.spp {
        spp.value = spp.value.min(4);
    }
    match &mut desc.max_depth {
        Some(d) if d.value < 0 || d.value > 3 => d.value = 3,
        Some(_) => {}
        None => {
            desc.max_depth = Some(lucent_io::desc::Located {
                value: 3,
                loc: desc.end,
            })
        }
    }
}
