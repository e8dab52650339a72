//! `lucent merge A.lstate B.lstate … -o OUT.png|OUT.exr|OUT.hdr [--state OUT.lstate]`:
//! the render that states of regions and sample ranges of one scene make together — the
//! bytes of rendering it in one go. Inputs of another scene or other options, overlaps
//! and gaps are refused with a message that names the files.

use std::path::PathBuf;

use clap::Args;
use lucent_io::desc::SceneDesc;
use lucent_io::diag::Diagnostics;
use lucent_io::resources::OutputTarget;
use lucent_io::state::{merge, RenderState};

use crate::output::{choose_output, write_image};
use crate::EXIT_BAD_INPUT;

#[derive(Args)]
pub struct MergeArgs {
    /// State files written by `lucent render --state`.
    #[arg(required = true, value_name = "STATE")]
    pub inputs: Vec<PathBuf>,
    /// The merged image (.png, .exr or .hdr).
    #[arg(short, long, value_name = "OUT.png")]
    pub output: PathBuf,
    /// Also write the merged state (to merge further or resume).
    #[arg(long, value_name = "OUT.lstate")]
    pub state: Option<PathBuf>,
}

pub fn run(args: &MergeArgs) -> u8 {
    let names: Vec<String> = args.inputs.iter().map(|p| p.display().to_string()).collect();
    let mut states = Vec::with_capacity(args.inputs.len());
    for (path, name) in args.inputs.iter().zip(&names) {
        match std::fs::read(path)
            .map_err(|e| e.to_string())
            .and_then(|b| RenderState::decode(&b))
        {
            Ok(s) => states.push(s),
            Err(e) => {
                eprintln!("lucent: error: {name}: {e}");
                return EXIT_BAD_INPUT;
            }
        }
    }
    let merged = match merge(&states, &names) {
        Ok(m) => m,
        Err(e) => {
            eprintln!("lucent: error: {e}");
            return EXIT_BAD_INPUT;
        }
    };
    let mut diags = Diagnostics::default();
    let out = match choose_output(Some(&args.output), &SceneDesc::default(), &mut diags) {
        Ok(o) => o,
        Err(e) => {
            eprintln!("lucent: error: {e}");
            return EXIT_BAD_INPUT;
        }
    };
    if let Err(e) = write_image(&out, &merged.film.resolve(), &crate::output::image_info(&merged.header)) {
        eprintln!("lucent: error: {e}");
        return EXIT_BAD_INPUT;
    }
    if let Some(path) = &args.state {
        let written = OutputTarget::resolve(path).and_then(|t| t.write(&merged.encode()));
        if let Err(e) = written {
            eprintln!("lucent: error: cannot write {}: {e}", path.display());
            return EXIT_BAD_INPUT;
        }
    }
    0
}
