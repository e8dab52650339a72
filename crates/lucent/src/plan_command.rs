//! `lucent plan SCENE --tasks N [--by auto|tiles|samples] [--json PLAN.json] [render options]`:
//! prints how `lucent render SCENE --task I/N` cuts the render ([`crate::plan`]).

use std::path::PathBuf;

use clap::Args;

use crate::plan::PlanRequest;
use crate::render::run_one;
use crate::render_args::RenderArgs;
use crate::EXIT_BAD_INPUT;

#[derive(Args)]
pub struct PlanArgs {
    /// How many tasks to cut the render into.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    pub tasks: u32,
    /// Also write the plan as JSON (for `lucent render --task I/N --plan PLAN.json`).
    #[arg(long, value_name = "PLAN.json")]
    pub json: Option<PathBuf>,
    /// Balance the bands of rows by the measured time of a probe rather than its ray
    /// counts (better where rays differ in cost); the tasks then need --plan PLAN.json,
    /// since a time is not the same on every machine.
    #[arg(long, requires = "json")]
    pub measure: bool,
    /// The render's options, as `lucent render` takes them: the plan is of that render.
    #[command(flatten)]
    pub render: RenderArgs,
}

pub fn run(args: &PlanArgs) -> u8 {
    if args.render.scenes.len() != 1 {
        errln!("lucent: error: plan one scene at a time");
        return EXIT_BAD_INPUT;
    }
    let request = PlanRequest {
        tasks: args.tasks,
        json: args.json.clone(),
        measure: args.measure,
    };
    run_one(
        &args.render,
        &args.render.scenes[0],
        false,
        &mut crate::targets::RunFiles::default(),
        Some(&request),
    )
}
