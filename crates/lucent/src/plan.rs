//! `lucent plan SCENE --tasks N [--by auto|tiles|samples] [--json PLAN.json]` and
//! `lucent render SCENE --task I/N --state TASK.lstate`: a render cut into N independent
//! tasks ([`lucent_core::render::plan`]) — for a Slurm job array (`scripts/slurm/`), or
//! any scheduler that starts N indexed tasks — whose states `lucent merge` puts together
//! into the one-go render.
//!
//! The cost of each row comes from a probe: the scene rendered at a fraction of its size
//! with a few samples. By default the probe counts rays per row — counts, not times, so
//! that every task derives the same plan wherever it runs. `lucent plan --measure`
//! times the probe's rows instead (rays that meet a 100,000-triangle dragon cost more
//! than rays into the sky), and the tasks then read that plan from its JSON
//! (`--plan PLAN.json`). Sample ranges do not depend on costs at all.

use std::fmt::Write as _;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

use lucent_core::camera::Resolution;
use lucent_core::render::job::{PixelRect, RenderJob};
use lucent_core::render::plan::{plan, Cut, Cuttable, Plan};
use lucent_io::build::Built;
use lucent_io::session::Renderer;

/// What `lucent plan` asks of the render it plans.
pub struct PlanRequest {
    pub tasks: u32,
    /// Where to write the JSON, if anywhere.
    pub json: Option<PathBuf>,
    /// Balance bands by the probe's measured time rather than its ray counts.
    pub measure: bool,
}

/// `--task I/N`: task I (from 0) of N.
pub fn parse_task(s: &str) -> Result<(u32, u32), String> {
    let (i, n) = s
        .split_once('/')
        .ok_or_else(|| format!("'{s}' is not I/N (task I, counted from 0, of N)"))?;
    let num = |v: &str| {
        v.trim()
            .parse::<u32>()
            .map_err(|_| format!("'{v}' in '{s}' is not a whole number"))
    };
    let (i, n) = (num(i)?, num(n)?);
    if n == 0 || i >= n {
        return Err(format!(
            "task {i} of {n}: tasks are numbered 0..{}",
            n.saturating_sub(1)
        ));
    }
    Ok((i, n))
}

/// What the plan part of `lucent render` / `lucent plan` decided.
pub enum Planned {
    /// `job` now holds the task's pixels and samples (or nothing was asked).
    Render,
    /// `lucent plan`: the plan was printed (and written); nothing is rendered.
    Printed,
}

/// For `--task I/N` points `job` at task I — read from `plan_file` when given, else the
/// plan derived here; for `lucent plan` (`planning`) prints the plan and writes its JSON.
#[allow(clippy::too_many_arguments)]
pub fn apply(
    renderer: &Renderer,
    built: &Built,
    job: &mut RenderJob,
    task: Option<(u32, u32)>,
    plan_file: Option<&std::path::Path>,
    planning: Option<&PlanRequest>,
    cut: Cut,
    monte_carlo: bool,
    scene: &str,
) -> Result<Planned, String> {
    let task = task.or(planning.map(|p| (0, p.tasks)));
    let Some((i, n)) = task else {
        return Ok(Planned::Render);
    };
    if let (Some(path), None) = (plan_file, planning) {
        // Read as every input is: a regular file of a bounded size.
        let limit = lucent_io::resources::input::MAX_SMALL_FILE_BYTES;
        let text = lucent_io::resources::read_input(path, limit, &mut lucent_io::resources::Inputs::default())
            .and_then(|b| String::from_utf8(b).map_err(|_| "not a plan (not text)".to_string()))
            .map_err(|e| format!("--plan {}: {e}", path.display()))?;
        let (pixels, samples) =
            task_from_json(&text, job, i, n).map_err(|e| format!("--plan {}: {e}", path.display()))?;
        job.pixels = pixels;
        job.samples = samples;
        return Ok(Planned::Render);
    }
    let measure = planning.is_some_and(|p| p.measure);
    let plan = make(renderer, built, job, n, cut, monte_carlo, measure)?;
    if let Some(request) = planning {
        use lucent_io::resources::OutputTarget;
        let target = match &request.json {
            Some(path) => {
                Some(OutputTarget::resolve(path).map_err(|e| format!("cannot write {}: {e}", path.display()))?)
            }
            None => None,
        };
        // `--json -`: standard output holds the JSON alone (a program reads it), the
        // table goes to standard error.
        match target {
            Some(OutputTarget::Stdout) => err!("{}", describe(scene, job, &plan)),
            _ => out!("{}", describe(scene, job, &plan)),
        }
        if let (Some(path), Some(t)) = (&request.json, target) {
            t.write(json(scene, job, &plan).as_bytes())
                .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
        }
        return Ok(Planned::Printed);
    }
    let t = &plan.tasks[i as usize];
    job.pixels = t.pixels;
    job.samples = t.samples.clone();
    Ok(Planned::Render)
}

/// The plan of `job` (the whole image) in `tasks` tasks, its bands balanced by the
/// probe's ray counts or (`measure`) its time.
fn make(
    renderer: &Renderer,
    built: &Built,
    job: &RenderJob,
    tasks: u32,
    cut: Cut,
    monte_carlo: bool,
    measure: bool,
) -> Result<Plan, String> {
    let what = Cuttable {
        samples: job.noise_threshold.is_none(),
        monte_carlo,
    };
    plan(job, tasks, cut, what, &row_costs(renderer, built, job, measure))
}

/// The cost of one sample in every pixel of each row of `job.pixels`, from the probe:
/// rays per sample (and one for the sample itself) times the row's width, or the time
/// the probe's row took, scaled to the row.
fn row_costs(renderer: &Renderer, built: &Built, job: &RenderJob, measure: bool) -> Vec<f64> {
    let (w, h) = (job.resolution.width, job.resolution.height);
    // Counting: a quarter of the size and 2 samples are plenty. Timing: half the size and
    // 4 samples, so that each row's render (about a millisecond) dwarfs the fixed cost
    // of starting one.
    let (divisor, take) = if measure { (2, 4) } else { (4, 2) };
    let probe = Resolution {
        width: w.div_ceil(divisor),
        height: h.div_ceil(divisor),
    };
    let samples = job.samples.start..job.samples.end.min(job.samples.start + take);
    let never = AtomicBool::new(false);
    let per_sample: Vec<f64> = (0..probe.height)
        .map(|y| {
            let row = RenderJob {
                resolution: probe,
                pixels: PixelRect {
                    x0: 0,
                    x1: probe.width,
                    y0: y,
                    y1: y + 1,
                },
                samples: samples.clone(),
                noise_threshold: None,
                aovs: false,
                ..job.clone()
            };
            let t = Instant::now();
            let (_, stats) = renderer
                .render(built, &row, &|_| {}, &never)
                .expect("the probe is not cancelled");
            let per = stats.samples.max(1) as f64;
            match measure {
                true => t.elapsed().as_secs_f64() / per,
                false => stats.rays as f64 / per + 1.0,
            }
        })
        .collect();
    (job.pixels.y0..job.pixels.y1)
        .map(|y| {
            let py = (y as u64 * probe.height as u64 / h as u64) as usize;
            per_sample[py] * job.pixels.width() as f64
        })
        .collect()
}

/// Task `i` of the plan a `lucent plan --json` file holds, checked against `job` (the
/// same image and samples) and `tasks`.
pub fn task_from_json(
    text: &str,
    job: &RenderJob,
    i: u32,
    tasks: u32,
) -> Result<(PixelRect, std::ops::Range<u32>), String> {
    let numbers = |line: &str, key: &str| -> Option<Vec<u64>> {
        let rest = &line[line.find(&format!("\"{key}\""))? + key.len() + 2..];
        let rest = rest.trim_start().strip_prefix(':')?.trim_start();
        let inner = match rest.strip_prefix('[') {
            Some(r) => &r[..r.find(']')?],
            None => rest.split(|c: char| c == ',' || c == '}').next()?,
        };
        inner.split(',').map(|v| v.trim().parse::<u64>().ok()).collect()
    };
    // (The keys are looked for in the text, not line by line: a plan reformatted by
    // another tool, or onto one line, reads the same.)
    let resolution = numbers(text, "resolution").ok_or("it has no \"resolution\": not a plan lucent wrote")?;
    let spp = numbers(text, "spp").ok_or("it has no \"spp\": not a plan lucent wrote")?;
    if resolution.len() != 2 || spp.len() != 1 {
        return Err(
            "its \"resolution\" is not [width, height] or its \"spp\" not one number: not a plan lucent wrote".into(),
        );
    }
    if resolution != [job.resolution.width as u64, job.resolution.height as u64] || spp != [job.spp as u64] {
        return Err(format!(
            "it is a plan of a {} x {} render at {} samples per pixel, and this render is {} x {} at {}",
            resolution.first().unwrap_or(&0),
            resolution.get(1).unwrap_or(&0),
            spp[0],
            job.resolution.width,
            job.resolution.height,
            job.spp
        ));
    }
    let listed: Vec<&str> = text.split("\"index\"").skip(1).collect();
    if listed.len() != tasks as usize {
        return Err(format!("it has {} tasks, not {tasks}", listed.len()));
    }
    for (k, chunk) in listed.iter().enumerate() {
        let index = chunk
            .trim_start()
            .strip_prefix(':')
            .and_then(|r| r.trim_start().split(|c: char| !c.is_ascii_digit()).next())
            .and_then(|n| n.parse::<usize>().ok());
        if index != Some(k) {
            return Err(format!(
                "its tasks are not numbered 0 to {} in order (the task at place {k} is not \"index\": {k})",
                tasks - 1
            ));
        }
    }
    let task = listed[i as usize];
    let (p, s) = match (numbers(task, "pixels"), numbers(task, "samples")) {
        (Some(p), Some(s)) if p.len() == 4 && s.len() == 2 && p.iter().chain(&s).all(|&v| v <= u32::MAX as u64) => {
            (p, s)
        }
        _ => {
            return Err(format!(
                "its task {i} is not pixels [x0, x1, y0, y1] and samples [first, last]"
            ))
        }
    };
    let pixels = PixelRect {
        x0: p[0] as u32,
        x1: p[1] as u32,
        y0: p[2] as u32,
        y1: p[3] as u32,
    };
    let samples = s[0] as u32..(s[1] as u32).saturating_add(1);
    let task = RenderJob {
        pixels,
        samples: samples.clone(),
        ..job.clone()
    };
    task.check().map_err(|e| format!("its task {i}: {e}"))?;
    Ok((pixels, samples))
}

/// Each task's share of the plan's whole cost.
fn shares(plan: &Plan) -> Vec<f64> {
    let total: f64 = plan.tasks.iter().map(|t| t.cost).sum();
    plan.tasks
        .iter()
        .map(|t| t.cost / total.max(f64::MIN_POSITIVE))
        .collect()
}

/// The plan as a table for people.
pub fn describe(scene: &str, job: &RenderJob, plan: &Plan) -> String {
    let mut out = format!(
        "{scene}: {} x {}, samples {}..{} per pixel, {} tasks by {} (the costliest task is {:.2} x the mean)\n",
        job.resolution.width,
        job.resolution.height,
        job.samples.start,
        job.samples.end - 1,
        plan.tasks.len(),
        plan.by,
        plan.imbalance()
    );
    out.push_str("task  pixels x0..x1, y0..y1   samples     share of the cost\n");
    for (i, (t, share)) in plan.tasks.iter().zip(shares(plan)).enumerate() {
        let p = t.pixels;
        let _ = writeln!(
            out,
            "{i:<5} {:>5}..{:<5} {:>5}..{:<5}  {:>5}..{:<5}  {:.3}",
            p.x0,
            p.x1,
            p.y0,
            p.y1,
            t.samples.start,
            t.samples.end - 1,
            share
        );
    }
    out
}

/// The plan as JSON (pixels `[x0, x1, y0, y1]` with exclusive ends, samples
/// `[first, last]` inclusive as `--samples` takes them, cost as a share of the whole).
pub fn json(scene: &str, job: &RenderJob, plan: &Plan) -> String {
    let escaped: String = scene
        .chars()
        .flat_map(|c| match c {
            '"' | '\\' => vec!['\\', c],
            c if c.is_control() => format!("\\u{:04x}", c as u32).chars().collect(),
            c => vec![c],
        })
        .collect();
    let mut out = format!(
        "{{\n  \"scene\": \"{escaped}\",\n  \"resolution\": [{}, {}],\n  \"spp\": {},\n  \"by\": \"{}\",\n  \"imbalance\": {:.4},\n  \"tasks\": [\n",
        job.resolution.width,
        job.resolution.height,
        job.spp,
        plan.by,
        plan.imbalance()
    );
    for (i, (t, share)) in plan.tasks.iter().zip(shares(plan)).enumerate() {
        let p = t.pixels;
        let _ = write!(
            out,
            "    {{\"index\": {i}, \"pixels\": [{}, {}, {}, {}], \"samples\": [{}, {}], \"cost\": {:.6}}}{}\n",
            p.x0,
            p.x1,
            p.y0,
            p.y1,
            t.samples.start,
            t.samples.end - 1,
            share,
            if i + 1 < plan.tasks.len() { "," } else { "" }
        );
    }
    out.push_str("  ]\n}\n");
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_plan_written_as_json_is_read_back() {
        let job = RenderJob::whole(Resolution { width: 40, height: 30 }, 16);
        let plan = Plan {
            by: "tiles",
            tasks: vec![
                lucent_core::render::plan::Task {
                    pixels: PixelRect {
                        x0: 0,
                        x1: 40,
                        y0: 0,
                        y1: 12,
                    },
                    samples: 0..16,
                    cost: 2.0,
                },
                lucent_core::render::plan::Task {
                    pixels: PixelRect {
                        x0: 0,
                        x1: 40,
                        y0: 12,
                        y1: 30,
                    },
                    samples: 0..16,
                    cost: 2.0,
                },
            ],
        };
        let text = json("a \"scene\".test", &job, &plan);
        assert_eq!(task_from_json(&text, &job, 1, 2), Ok((plan.tasks[1].pixels, 0..16)));
        assert!(task_from_json(&text, &job, 1, 3).unwrap_err().contains("2 tasks"));
        let other = RenderJob::whole(Resolution { width: 40, height: 30 }, 8);
        assert!(task_from_json(&text, &other, 0, 2)
            .unwrap_err()
            .contains("16 samples per pixel"));
        assert!(task_from_json("{}", &job, 0, 2).is_err());
        let swapped = text.replacen("\"index\": 0", "\"index\": 1", 1);
        assert!(task_from_json(&swapped, &job, 1, 2)
            .unwrap_err()
            .contains("not numbered 0 to 1"));
        // Ranges are quoted inclusive, as the plan and --samples give them.
        let beyond = text.replace("\"samples\": [0, 15]", "\"samples\": [0, 20]");
        assert!(task_from_json(&beyond, &job, 1, 2)
            .unwrap_err()
            .contains("samples 0..20 are not within the 16 samples per pixel (0..15)"));
        // Reformatted onto one line (as `jq -c` writes it): the same tasks.
        let one_line: String = text.lines().map(str::trim).collect();
        assert_eq!(task_from_json(&one_line, &job, 1, 2), Ok((plan.tasks[1].pixels, 0..16)));
        let three = text.replace("[40, 30]", "[40, 30, 1]");
        assert!(task_from_json(&three, &job, 0, 2)
            .unwrap_err()
            .contains("not [width, height]"));
    }

    #[test]
    fn tasks_are_i_of_n() {
        assert_eq!(parse_task("3/8"), Ok((3, 8)));
        assert!(parse_task("8/8").unwrap_err().contains("0..7"));
        assert!(parse_task("3").unwrap_err().contains("I/N"));
        assert!(parse_task("0/0").is_err());
    }
}
