//! `include file`: another file's commands where the command stands, relative paths,
//! diagnostics located in the included file, cycles refused with their chain.

mod common;

use common::{render_scene, TempDir};

use lucent_core::accel::AccelKind;

#[test]
fn included_commands_act_where_the_include_stands() {
    let dir = TempDir::new("include");
    std::fs::create_dir_all(dir.0.join("parts")).unwrap();
    // The material and transform carry into the included file and back out of it.
    dir.write("parts/ball.test", "sphere 0 0 0 1\ninclude ../lamp.test\n");
    dir.write("lamp.test", "point 0 0 5 1 1 1\n");
    let head = "size 9 9\ncamera 0 0 5 0 0 0 0 1 0 30\nambient 0 0 0\ndiffuse 0.5 0.25 0.125\n";
    let included = render_scene(
        &dir.scene(),
        &format!("{head}translate 0.2 0 0\ninclude parts/ball.test\n"),
        AccelKind::Bvh,
        1,
    )
    .0;
    let inline = render_scene(
        &dir.scene(),
        &format!("{head}translate 0.2 0 0\nsphere 0 0 0 1\npoint 0 0 5 1 1 1\n"),
        AccelKind::Bvh,
        1,
    )
    .0;
    assert_eq!(included.pixels, inline.pixels);
    assert!(included.pixels[40].x > 0.1, "the lit sphere is there");
}

#[test]
fn include_errors_point_into_the_right_file_and_name_the_cycle() {
    let dir = TempDir::new("include-errors");
    dir.write("a.test", "include b.test\n");
    dir.write("b.test", "sphere 0 0\ninclude a.test\n");
    let head = "size 8 8\ncamera 0 0 5 0 0 0 0 1 0 45\n";
    let text = format!("{head}include a.test\ninclude missing.test\n");
    let session = lucent_io::session::Session::parse_text(&dir.scene(), text.as_bytes(), Default::default());
    let d = session.diags.render(&session.desc.sources);
    let b = dir.path("b.test");
    let s = dir.scene();
    assert!(d.contains(&format!("{b}:1:11: error: sphere:")), "{d}");
    assert!(
        d.contains(&format!(
            "{b}:2:9: error: include: a cycle: a.test includes b.test includes a.test"
        )),
        "{d}"
    );
    assert!(
        d.contains(&format!("{s}:4:9: error: include: ")) && d.contains("missing.test"),
        "{d}"
    );
}

/// 31 files of 22 bytes, each including the next twice, would include 2³¹ files (before
/// the cap, `check` ran 11 minutes into 6.5 GB): the inclusions stop at 10,000, at once.
#[test]
fn inclusions_that_double_at_every_level_stop_at_the_cap() {
    let dir = TempDir::new("include-doubling");
    for i in 1..=31 {
        dir.write(&format!("{i}"), &format!("include {}\ninclude {}\n", i + 1, i + 1));
    }
    dir.write("32", "");
    let text = "size 8 8\ncamera 0 0 5 0 0 0 0 1 0 45\ninclude 1\n";
    let session = lucent_io::session::Session::parse_text(&dir.scene(), text.as_bytes(), Default::default());
    let d = session.diags.render(&session.desc.sources);
    assert!(d.contains("error: include: more than 10000 inclusions in all"), "{d}");
    assert!(session.desc.included.len() <= 10_000);
}
