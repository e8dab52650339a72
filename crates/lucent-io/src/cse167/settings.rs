//! Global settings: `size`, `output`, `maxdepth`, `gamma`, and the integrator's
//! `integrator`, `spp`, `lightsamples`, `lightstratify`, `nexteventestimation`,
//! `russianroulette`, `importancesampling`, `sampler`, `noisethreshold`. Each is given once (the last one wins, with a
//! warning).

use super::lexer::Command;
use super::parser::Parser;
use super::MAX_PIXELS;
use crate::desc::{DirectionSampling, IntegratorKind, Located, NeeMode, SampleSource, SceneDesc};

impl Parser {
    /// `size width height`.
    pub(super) fn size(&mut self, c: &Command) {
        let Some([w, h]) = self.ints::<2>(c) else {
            return;
        };
        for (k, v) in [w, h].into_iter().enumerate() {
            if v < 1 {
                self.err_arg(c, k, format!("size: width and height must be at least 1, got {v}"));
                return;
            }
        }
        let pixels = (w as i128) * (h as i128);
        if pixels > MAX_PIXELS as i128 || w > u32::MAX as i64 || h > u32::MAX as i64 {
            self.err_span(
                c,
                0,
                2,
                format!("size: {w} x {h} is too large (at most {MAX_PIXELS} pixels)"),
            );
            return;
        }
        if self.seen_command && self.desc.size.is_none() && !self.overriding {
            self.warn_cmd(c, "size: should be the first command of the file");
        }
        let v = Located {
            value: (w as u32, h as u32),
            loc: self.loc(c.line, &c.name),
        };
        self.set_global(c, |d| &mut d.size, v);
    }

    /// `output file`.
    pub(super) fn output(&mut self, c: &Command) {
        if self.expect_count(c, 1, "a file name") {
            let v = Located {
                value: c.args[0].text.to_string(),
                loc: self.loc(c.line, &c.args[0]),
            };
            self.set_global(c, |d| &mut d.output, v);
        }
    }

    /// `maxdepth d`: −1 (unbounded) or a depth ≥ 0.
    pub(super) fn max_depth(&mut self, c: &Command) {
        let Some([d]) = self.ints::<1>(c) else { return };
        if d < -1 || d > i32::MAX as i64 {
            let msg = format!(
                "maxdepth: depth must be -1 (unbounded) or between 0 and {}, got {d}",
                i32::MAX
            );
            self.err_arg(c, 0, msg);
            return;
        }
        let v = Located {
            value: d as i32,
            loc: self.loc(c.line, &c.name),
        };
        self.set_global(c, |d| &mut d.max_depth, v);
    }

    /// `gamma g`, g > 0.
    pub(super) fn gamma(&mut self, c: &Command) {
        if let Some(g) = self.positive(c) {
            let v = Located {
                value: g,
                loc: self.loc(c.line, &c.name),
            };
            self.set_global(c, |d| &mut d.gamma, v);
        }
    }

    /// `integrator raytracer|analyticdirect|direct|pathtracer`.
    pub(super) fn integrator(&mut self, c: &Command) {
        self.keyword_setting(c, &IntegratorKind::ALL, |d| &mut d.integrator);
    }

    /// `spp n` and `lightsamples n`: counts ≥ 1.
    pub(super) fn sample_count(&mut self, c: &Command) {
        let Some([n]) = self.ints::<1>(c) else { return };
        if n < 1 {
            self.err_arg(c, 0, format!("{}: must be at least 1, got {n}", c.name.text));
        } else if n > u32::MAX as i64 {
            self.err_arg(c, 0, format!("{}: {n} is too large", c.name.text));
        } else {
            let v = Located {
                value: n as u32,
                loc: self.loc(c.line, &c.args[0]),
            };
            if c.name.text == "spp" {
                self.set_global(c, |d| &mut d.spp, v);
            } else {
                self.set_global(c, |d| &mut d.light_samples, v);
            }
        }
    }

    /// `lightstratify on|off` and `russianroulette on|off`.
    pub(super) fn switch(&mut self, c: &Command) {
        let on_off = [("on", true), ("off", false)];
        if c.name.text == "lightstratify" {
            self.keyword_setting(c, &on_off, |d| &mut d.light_stratify);
        } else {
            self.keyword_setting(c, &on_off, |d| &mut d.russian_roulette);
        }
    }

    /// `nexteventestimation on|off|mis`.
    pub(super) fn next_event_estimation(&mut self, c: &Command) {
        let modes = [("on", NeeMode::On), ("off", NeeMode::Off), ("mis", NeeMode::Mis)];
        self.keyword_setting(c, &modes, |d| &mut d.next_event_estimation);
    }

    /// `importancesampling hemisphere|cosine|brdf`.
    pub(super) fn importance_sampling(&mut self, c: &Command) {
        let kinds = [
            ("hemisphere", DirectionSampling::Hemisphere),
            ("cosine", DirectionSampling::Cosine),
            ("brdf", DirectionSampling::Brdf),
        ];
        self.keyword_setting(c, &kinds, |d| &mut d.importance_sampling);
    }

    /// `sampler independent|sobol`.
    pub(super) fn sampler(&mut self, c: &Command) {
        let sources = [
            ("independent", SampleSource::Independent),
            ("sobol", SampleSource::Sobol),
        ];
        self.keyword_setting(c, &sources, |d| &mut d.sampler);
    }

    /// `noisethreshold t`: t ≥ 0 (0 turns adaptive sampling off).
    pub(super) fn noise_threshold(&mut self, c: &Command) {
        let Some([t]) = self.nums::<1>(c) else { return };
        if !(t >= 0.0) {
            self.err_arg(c, 0, format!("noisethreshold: must be 0 (off) or positive, got {t}"));
            return;
        }
        let v = Located {
            value: t,
            loc: self.loc(c.line, &c.args[0]),
        };
        self.set_global(c, |d| &mut d.noise_threshold, v);
    }

    /// A global setting given as one of the names in `options`, located at its value.
    fn keyword_setting<T: Copy>(
        &mut self,
        c: &Command,
        options: &[(&str, T)],
        field: impl Fn(&mut SceneDesc) -> &mut Option<Located<T>>,
    ) {
        if let Some(value) = self.keyword(c, options) {
            let loc = self.loc(c.line, &c.args[0]);
            self.set_global(c, field, Located { value, loc });
        }
    }
}
