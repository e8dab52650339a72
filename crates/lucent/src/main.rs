//! `lucent`: the command line. `render` makes a picture of a scene, `check` validates one
//! and says what it holds, `diff` compares two images, `merge` puts render states
//! together, `plan` cuts a render into tasks, `bench` measures speed.

// First: its macros are for every module below.
#[macro_use]
mod console;

mod aov_args;
mod bench;
mod check;
mod diff;
mod job_args;
mod merge;
mod oom;
mod output;
mod partial;
mod passes;
mod picture;
mod plan;
mod plan_command;
mod progress;
mod render;
mod render_args;
mod settings_args;
mod signals;
mod targets;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// Exit code for bad input, missing files, unwritable output and lack of memory.
pub const EXIT_BAD_INPUT: u8 = 2;

#[global_allocator]
static ALLOCATOR: oom::ExitOnFailure = oom::ExitOnFailure;

#[derive(Parser)]
#[command(
    name = "lucent",
    version,
    about = "A CPU ray tracer for the CSE167/CSE168 scene format"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene to an image.
    Render(Box<render_args::RenderArgs>),
    /// Parse and validate a scene without rendering it, and print what it holds.
    Check(check::CheckArgs),
    /// Compare two images (PNG or JPEG) pixel by pixel.
    Diff(diff::DiffArgs),
    /// Combine render state files (regions, sample ranges) into one image.
    Merge(merge::MergeArgs),
    /// Cut a render into independent tasks (for a job array), and print how.
    // (It plans one scene: the render options it shares take several.)
    #[command(mut_arg("scenes", |a| a.num_args(1).action(clap::ArgAction::Set)))]
    Plan(Box<plan_command::PlanArgs>),
    /// Benchmarks (figures for docs/performance.md).
    #[command(subcommand)]
    Bench(bench::BenchCommand),
}

fn main() -> ExitCode {
    // A file-size limit (`ulimit -f`, common on batch nodes) makes a write that passes it
    // fail with "file too large", which every output reports and cleans up after,
    // instead of a SIGXFSZ that would end the run with its temporary files left behind.
    // SAFETY: setting a signal's disposition before any thread is started.
    #[cfg(unix)]
    unsafe {
        libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
    }
    let cli = Cli::parse();
    let code = match cli.command {
        Command::Render(a) => render::run(&a),
        Command::Check(a) => check::run(&a),
        Command::Diff(a) => diff::run(&a),
        Command::Merge(a) => merge::run(&a),
        Command::Plan(a) => plan_command::run(&a),
        Command::Bench(c) => bench::run(&c),
    };
    ExitCode::from(code)
}
