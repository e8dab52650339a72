//! `lucent bench`: speed is measured here, never asserted in tests. Each benchmark ends
//! with one `key=value` line that scripts (and docs/performance.md) read.

mod rays;
mod scene;

use clap::Subcommand;

#[derive(Subcommand)]
pub enum BenchCommand {
    /// Render a scene several times and report the median time and Mrays/s.
    Scene(scene::SceneBenchArgs),
    /// Trace a ray file against an OBJ mesh: the kernel benchmark beside Embree.
    Rays(rays::RaysBenchArgs),
}

pub fn run(cmd: &BenchCommand) -> u8 {
    match cmd {
        BenchCommand::Scene(a) => scene::run(a),
        BenchCommand::Rays(a) => rays::run(a),
    }
}

/// Median of a non-empty list of timings.
fn median(mut times: Vec<f64>) -> f64 {
    times.sort_by(f64::total_cmp);
    times[times.len() / 2]
}
