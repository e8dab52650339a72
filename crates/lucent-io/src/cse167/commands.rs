//! The command table: every command the parser knows, with the function that reads it.
//! The same table dispatches each line, offers the did-you-mean suggestion for a
//! misspelt name, and lists the commands for the tests and the documentation check.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};
use std::sync::OnceLock;

use super::lexer::Command;
use super::parser::Parser;
use crate::diag::Severity;

type Run = fn(&mut Parser, &Command);

/// Every command, grouped by the file that reads it.
const COMMANDS: &[(&str, Run)] = &[
    // settings.rs: the image and the integrator
    ("size", Parser::size),
    ("output", Parser::output),
    ("maxdepth", Parser::max_depth),
    ("gamma", Parser::gamma),
    ("integrator", Parser::integrator),
    ("spp", Parser::sample_count),
    ("lightsamples", Parser::sample_count),
    ("lightstratify", Parser::switch),
    ("russianroulette", Parser::switch),
    ("nexteventestimation", Parser::next_event_estimation),
    ("importancesampling", Parser::importance_sampling),
    ("sampler", Parser::sampler),
    ("noisethreshold", Parser::noise_threshold),
    // camera.rs
    ("camera", Parser::camera),
    ("orthocamera", Parser::camera),
    ("lens", Parser::lens),
    // transforms.rs
    ("translate", Parser::translate),
    ("rotate", Parser::rotate),
    ("scale", Parser::scale),
    ("pushTransform", Parser::push_transform),
    ("popTransform", Parser::pop_transform),
    // lights.rs
    ("directional", Parser::directional),
    ("point", Parser::point),
    ("attenuation", Parser::attenuation),
    ("quadLight", Parser::quad_light),
    // materials.rs
    ("ambient", Parser::material_color),
    ("diffuse", Parser::material_color),
    ("specular", Parser::material_color),
    ("emission", Parser::material_color),
    ("shininess", Parser::shininess),
    ("transparent", Parser::material_color),
    ("ior", Parser::ior),
    ("glossy", Parser::glossy),
    ("brdf", Parser::brdf),
    ("roughness", Parser::roughness),
    // textures.rs
    ("texture", Parser::texture),
    ("checker", Parser::texture),
    ("diffusemap", Parser::diffuse_map),
    ("bumpmap", Parser::bump_map),
    ("displacementmap", Parser::displacement_map),
    ("envmap", Parser::environment),
    ("include", Parser::include),
    // geometry.rs
    ("sphere", Parser::sphere),
    ("plane", Parser::analytic),
    ("box", Parser::analytic),
    ("cylinder", Parser::analytic),
    ("disk", Parser::analytic),
    ("cone", Parser::analytic),
    ("quadric", Parser::analytic),
    ("maxverts", Parser::max_verts),
    ("maxvertnorms", Parser::max_verts),
    ("vertex", Parser::vertex),
    ("vertexnormal", Parser::vertex_normal),
    ("tri", Parser::triangle),
    ("trinormal", Parser::triangle),
    // surfaces.rs
    ("mesh", Parser::mesh),
    ("subdivmesh", Parser::subdiv_mesh),
    ("bezierpatches", Parser::bezier_patches),
    // nurbs.rs
    ("nurbs", Parser::nurbs_header),
    ("knotsu", Parser::nurbs_part),
    ("knotsv", Parser::nurbs_part),
    ("cpoint", Parser::nurbs_part),
    // objects.rs
    ("objectbegin", Parser::object_begin),
    ("objectend", Parser::object_end),
    ("instance", Parser::instance),
];

/// The name of every command the parser knows.
pub fn command_names() -> impl Iterator<Item = &'static str> {
    COMMANDS.iter().map(|(name, _)| *name)
}

/// The table by name. Looked up once per line, so it hashes with FNV-1a: a handful of
/// instructions for a short name, where the default hasher costs several times that.
fn table() -> &'static HashMap<&'static str, Run, BuildHasherDefault<Fnv>> {
    static TABLE: OnceLock<HashMap<&'static str, Run, BuildHasherDefault<Fnv>>> = OnceLock::new();
    TABLE.get_or_init(|| COMMANDS.iter().copied().collect())
}

#[derive(Default)]
struct Fnv(u64);

impl Hasher for Fnv {
    fn finish(&self) -> u64 {
        self.0
    }

    fn write(&mut self, bytes: &[u8]) {
        let mut h = if self.0 == 0 { 0xcbf2_9ce4_8422_2325 } else { self.0 };
        for &b in bytes {
            h = (h ^ b as u64).wrapping_mul(0x0100_0000_01b3);
        }
        self.0 = h;
    }
}

impl Parser {
    /// Runs command `c`; an unknown name is a warning (an error with `--strict`) with a
    /// suggestion for a near miss.
    pub fn run(&mut self, c: &Command) {
        self.interrupt_nurbs(c);
        match table().get(c.name.text) {
            Some(run) => run(self, c),
            None => {
                let name = c.name.text;
                let severity = if self.options.strict {
                    Severity::Error
                } else {
                    Severity::Warning
                };
                let hint = if self.diags.will_record(severity) {
                    suggestion(name).map_or(String::new(), |s| format!("; did you mean '{s}'?"))
                } else {
                    String::new()
                };
                let loc = self.loc(c.line, &c.name);
                if self.options.strict {
                    self.diags.error(loc, format!("unknown command '{name}'{hint}"));
                } else {
                    self.diags
                        .warning(loc, format!("unknown command '{name}' ignored{hint}"));
                }
            }
        }
    }
}

/// The known command closest to a misspelt one: same letters ignoring case, or at most
/// two edits away. A name much longer than any command is no misspelling (and a
/// ten-megabyte one would cost seconds to compare).
fn suggestion(name: &str) -> Option<&'static str> {
    if name.len() > 32 {
        return None;
    }
    let lower: Vec<char> = name.to_lowercase().chars().collect();
    let mut best: Option<(usize, &'static str)> = None;
    for (known, command) in lowered() {
        // Names whose lengths differ by more than two are more than two edits apart.
        if known.len().abs_diff(lower.len()) > 2 {
            continue;
        }
        let d = edit_distance(&lower, known);
        if d == 0 {
            return Some(command);
        }
        if d <= 2 && best.is_none_or(|(b, _)| d < b) {
            best = Some((d, command));
        }
    }
    best.map(|(_, c)| c)
}

/// Every command's name in lower case (for [`suggestion`]).
fn lowered() -> &'static [(Vec<char>, &'static str)] {
    static LOWERED: OnceLock<Vec<(Vec<char>, &'static str)>> = OnceLock::new();
    LOWERED.get_or_init(|| {
        command_names()
            .map(|c| (c.to_lowercase().chars().collect(), c))
            .collect()
    })
}

/// Levenshtein distance of two names of at most 34 characters (rows on the stack).
fn edit_distance(a: &[char], b: &[char]) -> usize {
    const ROW: usize = 35;
    let n = b.len().min(ROW - 1);
    let mut prev = [0usize; ROW];
    let mut cur = [0usize; ROW];
    for (j, p) in prev.iter_mut().enumerate().take(n + 1) {
        *p = j;
    }
    for (i, &ca) in a.iter().enumerate() {
        cur[0] = i + 1;
        for (j, &cb) in b.iter().take(n).enumerate() {
            cur[j + 1] = (prev[j] + (ca != cb) as usize).min(prev[j + 1] + 1).min(cur[j] + 1);
        }
        std::mem::swap(&mut prev, &mut cur);
    }
    prev[n]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique_and_suggestions_find_near_misses() {
        assert_eq!(table().len(), COMMANDS.len(), "a command is listed twice");
        assert_eq!(suggestion("pushtransform"), Some("pushTransform"));
        assert_eq!(suggestion("sphre"), Some("sphere"));
        assert_eq!(suggestion("xyzzyq"), None);
        assert_eq!(suggestion(&"s".repeat(10_000_000)), None);
    }

    #[test]
    fn every_command_is_documented() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/scene-format.md");
        let docs = std::fs::read_to_string(path).unwrap();
        let missing: Vec<&str> = command_names().filter(|c| !docs.contains(&format!("`{c}`"))).collect();
        assert!(missing.is_empty(), "not in docs/scene-format.md: {missing:?}");
    }
}
