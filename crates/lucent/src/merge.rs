//! `lucent merge A.lstate B.lstate … -o OUT.png|OUT.exr|OUT.hdr [--state OUT.lstate] [--aov …] [--denoise] [--threads N]`:
//! the render that states of regions and sample ranges of one scene make together — the
//! bytes of rendering it in one go. Inputs of another scene or other options, overlaps
//! and gaps are refused with a message that names the files.

use std::path::PathBuf;

use clap::Args;
use lucent_io::desc::SceneDesc;
use lucent_io::diag::Diagnostics;
use lucent_io::resources::OutputTarget;
use lucent_io::state::{merge, RenderState};

use crate::aov_args::{parse_aovs, AovSelection};
use crate::output::choose_output;
use crate::picture::{aov_file, write_picture, Extras};
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
    /// Write these auxiliary passes too (the states must keep them: rendered with --aov
    /// or --denoise), as `lucent render --aov`.
    #[arg(long, value_name = "albedo,normal,depth,alpha", value_parser = parse_aovs)]
    pub aov: Option<AovSelection>,
    /// Denoise the merged colour with Intel Open Image Denoise (the states must keep the
    /// passes), as `lucent render --denoise`.
    #[arg(long)]
    pub denoise: bool,
    /// Threads for the denoiser (default: all cores).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub threads: Option<u32>,
}

pub fn run(args: &MergeArgs) -> u8 {
    let denoiser = match args.denoise.then(lucent_io::denoise::Denoiser::load).transpose() {
        Ok(d) => d,
        Err(e) => {
            eprintln!("lucent: error: {e}");
            return EXIT_BAD_INPUT;
        }
    };
    let extras = Extras {
        aovs: args.aov.unwrap_or_default(),
        denoiser: denoiser.as_ref(),
        threads: args.threads.map_or_else(
            || std::thread::available_parallelism().map_or(1, |n| n.get()),
            |n| n as usize,
        ),
    };
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
    if extras.need_aovs() && !merged.header.aovs {
        eprintln!("lucent: error: --aov and --denoise need the auxiliary passes, and these states keep none: render them with --aov or --denoise");
        return EXIT_BAD_INPUT;
    }
    if let Err(e) = aov_file(&out, extras.aovs) {
        eprintln!("lucent: error: {e}");
        return EXIT_BAD_INPUT;
    }
    if let Err(e) = write_picture(&out, &merged.film, &merged.header, &extras) {
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
