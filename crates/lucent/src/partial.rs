//! Where a render's partial results go — checkpoints, and what an interrupt leaves —
//! beside the outputs, never over them: `OUT.partial.EXT`, and the state beside
//! `--state` (`STATE.partial.lstate`: a task killed by Slurm leaves no `STATE` that a
//! resubmission would take for done) or, without it, `OUT.partial.lstate`.

use std::path::PathBuf;

use lucent_core::film::Film;
use lucent_io::resources::OutputTarget;
use lucent_io::state::{RenderState, StateHeader};

use crate::output::{write_all, Encoded, Output};
use crate::picture::Extras;

/// Where a partial render goes: `OUT.partial.EXT` beside the output (nothing for standard
/// output or a device) and the state beside `--state`, else `OUT.partial.lstate`.
pub struct Partial {
    image: Option<Output>,
    state: PathBuf,
}

impl Partial {
    pub fn beside(out: &Output, state: &Option<PathBuf>, desc: &lucent_io::desc::SceneDesc) -> Partial {
        let is_file = matches!(out.target, OutputTarget::File(_));
        // Beside a file; in the current folder for standard output or a device.
        let with = |ext: &str| match is_file {
            true => {
                let stem = out
                    .name
                    .file_stem()
                    .map_or("render".into(), |s| s.to_string_lossy().into_owned());
                out.name.with_file_name(format!("{stem}.partial.{ext}"))
            }
            false => PathBuf::from(format!("lucent.partial.{ext}")),
        };
        let ext = out
            .name
            .extension()
            .map_or("png".into(), |e| e.to_string_lossy().into_owned());
        let mut quiet = lucent_io::diag::Diagnostics::default();
        let image = is_file
            .then(|| crate::output::choose_output(Some(&with(&ext)), desc, &mut quiet).ok())
            .flatten();
        let state = match state {
            Some(p) => {
                let stem = p
                    .file_stem()
                    .map_or("state".into(), |s| s.to_string_lossy().into_owned());
                p.with_file_name(format!("{stem}.partial.lstate"))
            }
            None => with("lstate"),
        };
        Partial { image, state }
    }

    /// Where the partial results would go (the names that can be written).
    pub fn targets(&self) -> Vec<(PathBuf, OutputTarget)> {
        let state = OutputTarget::resolve(&self.state).ok().map(|t| (self.state.clone(), t));
        let image = self.image.as_ref().map(|o| (o.name.clone(), o.target.clone()));
        image.into_iter().chain(state).collect()
    }

    pub fn image_name(&self) -> String {
        self.image
            .as_ref()
            .map_or("no image".into(), |o| o.name.display().to_string())
    }

    pub fn state_name(&self) -> String {
        self.state.display().to_string()
    }

    /// Writes the partial image (with the passes and denoising of `extras`) and the
    /// state (each atomically).
    pub fn write(&self, film: &Film, header: StateHeader, extras: &Extras) -> Result<(), String> {
        let mut files = match &self.image {
            Some(img) => crate::picture::encode_picture(img, film, &header, extras)?,
            None => Vec::new(),
        };
        let target =
            OutputTarget::resolve(&self.state).map_err(|e| format!("cannot write {}: {e}", self.state.display()))?;
        let state = RenderState {
            header,
            film: film.clone(),
        };
        files.push(Encoded {
            name: self.state.clone(),
            target,
            bytes: state.encode(),
        });
        write_all(&files)
    }

    /// Removes what checkpoints wrote, once the render is complete (the final state at
    /// `--state` stays).
    pub fn remove(&self, extras: &Extras) {
        if let Some(img) = &self.image {
            let _ = std::fs::remove_file(&img.name);
            if let Ok(Some(side)) = crate::picture::aov_file(img, extras.aovs) {
                let _ = std::fs::remove_file(&side.name);
            }
        }
        let _ = std::fs::remove_file(&self.state);
    }
}
