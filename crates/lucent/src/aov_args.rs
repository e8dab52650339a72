//! `--aov albedo,normal,depth,alpha`: which auxiliary passes a render writes beside its
//! colour (as layers of an EXR), and `--denoise`, which needs the albedo and normal ones.

/// The passes asked for.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct AovSelection {
    pub albedo: bool,
    pub normal: bool,
    pub depth: bool,
    pub alpha: bool,
}

/// The names `--aov` takes.
pub const AOV_NAMES: [&str; 4] = ["albedo", "normal", "depth", "alpha"];

impl AovSelection {
    pub fn any(&self) -> bool {
        self.albedo || self.normal || self.depth || self.alpha
    }
}

/// `--aov`: names from [`AOV_NAMES`], separated by commas.
pub fn parse_aovs(s: &str) -> Result<AovSelection, String> {
    let mut sel = AovSelection::default();
    for name in s.split(',').map(str::trim) {
        match name {
            "albedo" => sel.albedo = true,
            "normal" => sel.normal = true,
            "depth" => sel.depth = true,
            "alpha" => sel.alpha = true,
            _ => {
                return Err(format!(
                    "'{name}' is not a pass lucent writes (it writes {})",
                    AOV_NAMES.join(", ")
                ))
            }
        }
    }
    Ok(sel)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn passes_are_named_with_commas() {
        let s = parse_aovs("albedo, depth").unwrap();
        assert!(s.albedo && s.depth && !s.normal && !s.alpha && s.any());
        assert!(parse_aovs("albedo,Z").unwrap_err().contains("'Z'"));
        assert!(!AovSelection::default().any());
    }
}
