//! `lucent check SCENE`: parse and validate without rendering, then print what the scene
//! holds. Errors are reported exactly as `render` reports them.

use std::path::PathBuf;

use clap::Args;
use lucent_core::accel::AccelKind;
use lucent_io::build::warn_if_absurd;
use lucent_io::desc::{LightKind, ProjectionDesc, ShapeKind, SurfaceRecipe};
use lucent_io::resources::input::bytes;
use lucent_io::session::{Session, SessionOptions};

use crate::aov_args::AovSelection;
use crate::output::report;
use crate::picture::{picture_bytes, take_picture_memory, Extras};
use crate::EXIT_BAD_INPUT;

#[derive(Args)]
pub struct CheckArgs {
    /// The scene file (`-`: standard input).
    pub scene: PathBuf,
    /// Treat unknown commands as errors.
    #[arg(long)]
    pub strict: bool,
    /// The memory the scene may take (e.g. 4G, 512M); default: 3/4 of the machine's.
    #[arg(long, value_name = "SIZE", value_parser = crate::render_args::parse_size)]
    pub memory_limit: Option<u64>,
}

pub fn run(args: &CheckArgs) -> u8 {
    // The list needs no build time and reports the same problems as the BVH.
    let options = SessionOptions {
        strict: args.strict,
        accel: AccelKind::List,
        memory_limit: args
            .memory_limit
            .unwrap_or_else(lucent_io::resources::Budget::machine_default),
    };
    // `-`: the scene from standard input, as `render -` reads it.
    let mut session = if args.scene.as_os_str() == "-" {
        let mut text = Vec::new();
        let read = std::io::Read::read_to_end(&mut std::io::Read::take(std::io::stdin(), 1 << 30), &mut text);
        if let Err(e) = read {
            errln!("lucent: error: cannot read the scene from standard input: {e}");
            return EXIT_BAD_INPUT;
        }
        let mut s = Session::parse_text("-", &text, options);
        s.build();
        s
    } else {
        Session::open(&args.scene, options)
    };
    if let Some(built) = &session.built {
        warn_if_absurd(&session.desc, &built.work, &mut session.diags);
    }
    // The picture's memory, as `render` takes it (without `--aov` or `--denoise`).
    let scene_memory = session.res.budget.used();
    let picture_memory = session.built.as_ref().map(|built| {
        let extras = Extras {
            aovs: AovSelection::default(),
            denoiser: None,
            threads: 1,
        };
        let job = built.job();
        let need = picture_bytes(&job, false, &extras);
        let fits = take_picture_memory(&mut session.res.budget, &mut session.diags, &session.desc, &job, need);
        (need, fits)
    });
    report(&session.diags, &session.desc.sources, true);
    let (desc, Some(built), Some((picture_memory, true))) = (&session.desc, &session.built, picture_memory) else {
        return EXIT_BAD_INPUT;
    };

    let count = |f: &dyn Fn(&ShapeKind) -> bool| desc.shapes.iter().filter(|s| f(&s.kind)).count();
    let surfaces = |f: &dyn Fn(&SurfaceRecipe) -> bool| {
        count(&|k| matches!(k, ShapeKind::Surface { index } if f(&desc.surfaces[*index as usize].recipe)))
    };
    let spheres = count(&|k| matches!(k, ShapeKind::Sphere { .. }));
    let tris = count(&|k| matches!(k, ShapeKind::Triangle { .. }));
    let trinormals = count(&|k| matches!(k, ShapeKind::TriNormal { .. }));
    let lights = |f: &dyn Fn(&LightKind) -> bool| desc.lights.iter().filter(|l| f(&l.kind)).count();
    let (w, h) = desc.size.as_ref().map(|s| s.value).unwrap_or_default();
    let c = desc.camera.as_ref().expect("checked by the parser").value;
    let v = |v: lucent_core::math::DVec3| format!("({}, {}, {})", v.x, v.y, v.z);

    outln!("scene:      {}", args.scene.display());
    outln!("size:       {w} x {h}");
    outln!(
        "output:     {}",
        desc.output
            .as_ref()
            .map_or("raytrace.png (default)", |o| o.value.as_str())
    );
    outln!(
        "camera:     eye {} look-at {} up {} {}",
        v(c.eye),
        v(c.center),
        v(c.up),
        match c.projection {
            ProjectionDesc::Perspective { fovy } => format!("fovy {fovy}"),
            ProjectionDesc::Orthographic { height } => format!("orthographic, height {height}"),
        }
    );
    outln!(
        "integrator: {}, maxdepth {}",
        desc.integrator().name(),
        desc.max_depth()
    );
    // The other kinds are named only when the scene has them.
    let others: Vec<String> = [
        ("plane", count(&|k| matches!(k, ShapeKind::Plane { .. }))),
        ("box", count(&|k| matches!(k, ShapeKind::Box { .. }))),
        ("cylinder", count(&|k| matches!(k, ShapeKind::Cylinder { .. }))),
        ("disk", count(&|k| matches!(k, ShapeKind::Disk { .. }))),
        ("cone", count(&|k| matches!(k, ShapeKind::Cone { .. }))),
        ("quadric", count(&|k| matches!(k, ShapeKind::Quadric { .. }))),
        ("nurbs surface", surfaces(&|r| matches!(r, SurfaceRecipe::Nurbs(_)))),
        ("mesh", surfaces(&|r| !matches!(r, SurfaceRecipe::Nurbs(_)))),
        ("object", desc.objects.len()),
        ("instance", count(&|k| matches!(k, ShapeKind::Instance { .. }))),
    ]
    .into_iter()
    .filter(|&(_, n)| n > 0)
    .map(|(name, n)| format!(", {n} {name}{}", if n == 1 { "" } else { "s" }))
    .collect();
    outln!(
        "objects:    {spheres} spheres, {} triangles ({trinormals} with vertex normals){}",
        tris + trinormals,
        others.concat()
    );
    outln!(
        "primitives: {} after build",
        built.scene.geometry.shown_primitive_count()
    );
    outln!(
        "lights:     {} point, {} directional, {} quad",
        lights(&|k| matches!(k, LightKind::Point { .. })),
        lights(&|k| matches!(k, LightKind::Directional { .. })),
        lights(&|k| matches!(k, LightKind::Quad { .. }))
    );
    // The scene's materials and its meshes' MTL materials; not the one the build adds for
    // the surfaces of quad lights.
    let quad_lights = lights(&|k| matches!(k, LightKind::Quad { .. }));
    outln!("materials:  {}", built.scene.materials.len() - quad_lights.min(1));
    let spp = desc.spp.as_ref().map_or(1, |s| s.value);
    let samples = desc.light_samples.as_ref().map_or(1, |s| s.value);
    let stratified = desc.light_stratify.as_ref().is_some_and(|s| s.value);
    let lens = desc.lens.as_ref().map_or(String::new(), |l| {
        format!(", lens aperture {} focus {}", l.value.0, l.value.1)
    });
    outln!(
        "sampling:   spp {spp}, lightsamples {samples}{}{lens}",
        if stratified { " (stratified)" } else { "" }
    );
    let w = &built.work;
    outln!(
        "work:       about {:.1e} rays ({:.0} per pixel, at most {:.0}), reflections up to depth {}",
        w.rays,
        w.rays_per_pixel,
        w.most_rays_per_pixel,
        w.depth
    );
    outln!(
        "memory:     about {} for the scene, {} for the picture (of {})",
        bytes(scene_memory),
        bytes(picture_memory),
        bytes(session.res.budget.limit())
    );
    outln!(
        "textures:   {}{}",
        desc.textures.len(),
        if desc.environment.is_some() {
            ", and an environment map"
        } else {
            ""
        }
    );
    0
}
