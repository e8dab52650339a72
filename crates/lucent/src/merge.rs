//! `lucent merge A.lstate B.lstate … -o OUT.png|OUT.exr|OUT.hdr [--state OUT.lstate] [--aov …] [--denoise] [--threads N] [--memory-limit SIZE]`:
//! the render that states of regions and sample ranges of one scene make together — the
//! bytes of rendering it in one go. Inputs of another scene or other options, overlaps
//! and gaps are refused with a message that names the files. The states are read as
//! every input is (regular files only), their films and the picture come out of a
//! memory budget, and no output may replace one of the inputs.

use std::path::{Path, PathBuf};

use clap::Args;
use lucent_io::desc::SceneDesc;
use lucent_io::diag::Diagnostics;
use lucent_io::resources::{Budget, Inputs, OutputTarget};
use lucent_io::state::{merge, read_state};

use crate::aov_args::{parse_aovs, AovSelection};
use crate::output::{choose_output, write_all, Encoded};
use crate::picture::{aov_file, encode_picture, image_bytes, Extras};
use crate::render_args::parse_size;
use crate::targets::check_targets;
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
    /// The memory the merge may take (e.g. 4G, 512M); default: 3/4 of the machine's.
    #[arg(long, value_name = "SIZE", value_parser = parse_size)]
    pub memory_limit: Option<u64>,
}

pub fn run(args: &MergeArgs) -> u8 {
    let denoiser = match args.denoise.then(lucent_io::denoise::Denoiser::load).transpose() {
        Ok(d) => d,
        Err(e) => {
            errln!("lucent: error: {e}");
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
    let mut budget = Budget::new(args.memory_limit.unwrap_or_else(Budget::machine_default));
    let mut inputs = Inputs::default();
    let mut states = Vec::with_capacity(args.inputs.len());
    for (path, name) in args.inputs.iter().zip(&names) {
        match read_state(path, &mut budget, &mut inputs) {
            Ok(s) => states.push(s),
            Err(e) => {
                errln!("lucent: error: {name}: {e}");
                return EXIT_BAD_INPUT;
            }
        }
    }
    // The merged film has no more pixels than the inputs together (merge checks that
    // they leave no gap before making it), so it is taken before it is made.
    let pixels: u64 = states.iter().map(|s| s.header.pixels.pixels()).sum();
    let aovs = states[0].header.aovs;
    let picture = states.iter().map(|s| s.film_bytes()).sum::<u64>() + image_bytes(pixels, aovs, &extras);
    if let Err(e) = budget.take(picture, "the merged picture") {
        errln!("lucent: error: {e}");
        return EXIT_BAD_INPUT;
    }
    let merged = match merge(&states, &names) {
        Ok(m) => m,
        Err(e) => {
            errln!("lucent: error: {e}");
            return EXIT_BAD_INPUT;
        }
    };
    drop(states);
    let mut diags = Diagnostics::default();
    let out = match choose_output(Some(&args.output), &SceneDesc::default(), &mut diags) {
        Ok(o) => o,
        Err(e) => {
            errln!("lucent: error: {e}");
            return EXIT_BAD_INPUT;
        }
    };
    if extras.need_aovs() && !merged.header.aovs {
        errln!("lucent: error: --aov and --denoise need the auxiliary passes, and these states keep none: render them with --aov or --denoise");
        return EXIT_BAD_INPUT;
    }
    let aov_side = match aov_file(&out, extras.aovs) {
        Ok(a) => a,
        Err(e) => {
            errln!("lucent: error: {e}");
            return EXIT_BAD_INPUT;
        }
    };
    let state_out = match args.state.as_deref().map(OutputTarget::resolve).transpose() {
        Ok(t) => t,
        Err(e) => {
            let name = args.state.as_ref().map_or(String::new(), |p| p.display().to_string());
            errln!("lucent: error: cannot write {name}: {e}");
            return EXIT_BAD_INPUT;
        }
    };
    // No output may replace an input: the states stay as they were, so that a merge of
    // the wrong list can be made again.
    let mut targets: Vec<(&Path, &OutputTarget)> = vec![(&out.name, &out.target)];
    targets.extend(aov_side.iter().map(|a| (a.name.as_path(), &a.target)));
    targets.extend(args.state.iter().map(|p| p.as_path()).zip(&state_out));
    if let Err(e) = check_targets(&targets, &inputs) {
        errln!("lucent: error: {e}");
        return EXIT_BAD_INPUT;
    }
    // Every output or none.
    let written = encode_picture(&out, &merged.film, &merged.header, &extras).and_then(|mut files| {
        if let (Some(path), Some(target)) = (&args.state, &state_out) {
            files.push(Encoded {
                name: path.clone(),
                target: target.clone(),
                bytes: merged.encode(),
            });
        }
        write_all(&files)
    });
    if let Err(e) = written {
        errln!("lucent: error: {e}");
        return EXIT_BAD_INPUT;
    }
    0
}
