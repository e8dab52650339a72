//! Scene commands: `integrator raytracer` (the default) and `maxdepth d` — the classic
//! recursive ray tracer of CSE167 homework 3 (docs/scene-format.md, "How a pixel is
//! computed"):
//!
//! ```text
//! I = A + E + Σ_lights V · (C / att) · (D · max(N·L, 0) + S · max(N·H, 0)^s)
//!           + [depth < maxdepth] · S · I(reflected ray)
//! ```
//!
//! with `H = normalize(L − d)`, `V` the shadow-ray visibility (a point light's shadow
//! ray stops ε short of the light, so objects beyond it cast no shadow) and the mirror
//! direction `R = d − 2 (d·N) N`. Normals are not flipped toward the viewer, and the
//! specular term is not gated by `N·L`.
//!
//! lucent's extensions:
//! - a `quadLight` adds, for each of its `lightsamples` points (stratified with
//!   `lightstratify on`), the same Blinn–Phong terms as a point light with `C` the
//!   light's radiance times that point's share of the light's solid angle; its geometry
//!   shows the radiance from the emitting side and black from behind;
//! - a `transparent` material (Kt ≠ 0) splits the recursion by the Fresnel reflectance F
//!   of its `ior`: `S · F · I(reflected) + Kt · (1 − F) · I(refracted)`, total internal
//!   reflection making F = 1; the ray knows it is inside when it meets the surface from
//!   the side the normal points away from;
//! - a `glossy exponent samples` material replaces the mirror ray by `samples` rays from
//!   a Phong lobe around it (one ray below the first bounce, so that the count does not
//!   grow geometrically), each weighted `S / samples`; rays that would leave below the
//!   surface count as black.
//!
//! Secondary rays leave the hit point offset past its rounding error (`crate::spawn`).
//! Where an interpolated or bumped normal would mirror a ray into the true surface (or
//! refract it out on the viewer's side), the ray is turned back to just past the surface
//! (`lift_above`); glossy rays below the true surface count as black.
//!
//! The ray tree is walked with an explicit stack, in the order of the recursion it
//! stands for, so that no scene can overflow the thread's stack; a branch whose weight
//! can no longer show is not traced (adaptive depth control, [`super::depth`]), and one
//! camera sample traces at most [`MAX_TREE_RAYS`] rays of its tree ([`tree_size`]).
//!
//! The renderer hands the ray tracer 64 camera samples at a time: their first hits'
//! shadow rays toward point and directional lights are traced together
//! ([`camera_batch`]); where each light term goes until then is [`light_terms`]'s.

mod camera_batch;
mod light_terms;
mod tree_size;

use super::depth::DepthControl;
use super::shadow_batch::ShadowBatch;
use super::{CameraHit, Integrator, TraceCounts};
use crate::hit::{Hit, SurfacePoint, BACKGROUND};
use crate::light::Light;
use crate::math::{Color, Vec3A};
use crate::pow;
use crate::ray::Ray;
use crate::sampler::{stratified, Sampler};
use crate::scene::Scene;
use crate::shading::optics::{fresnel_dielectric, lift_above, phong_lobe, reflect_above, refract, side_of};
use crate::shading::surface;
use light_terms::{Immediate, LightTerms};
pub use tree_size::MAX_TREE_RAYS;

/// Branches of the ray tree whose weight falls below this add less than a tenth of an
/// 8-bit step: they are not traced.
const MIN_WEIGHT: f32 = 1.0 / 2048.0;

/// What one camera sample's ray tree shares.
struct Tracing<'a> {
    scene: &'a Scene,
    /// The camera ray's closest hit, if the renderer traced it already.
    camera: CameraHit,
    sampler: &'a mut Sampler,
    counts: &'a mut TraceCounts,
    /// What left-out branches could have added (adaptive depth control's spending).
    dropped: f32,
    /// The rays of the tree traced so far (shadow rays not counted).
    traced: u32,
}

/// Branches of one ray tree waiting to be traced, at most this many at once (4 MB a
/// thread); a branch beyond is cut and counted. Each level of a tree adds at most two, so
/// only trees deeper than 32,768 bounces get here — where mirrors or glass reflect
/// everything (no adaptive depth control) and `maxdepth` is larger than that.
pub const MAX_PENDING: usize = 1 << 16;

/// Scenes with at most this many lights have the shadow rays of a batch of camera
/// samples' first hits traced together ([`camera_batch`]): 64 samples' worth take at most
/// 600 KB a thread (about 140 bytes a ray, with its term and its sorted copy).
const MAX_BATCH_LIGHTS: usize = 64;

/// A branch of the ray tree waiting to be traced. The tree is walked depth first with an
/// explicit stack — never by recursion, whose depth the scene would control — in the
/// order a recursive tracer takes, so that every sample and every sum comes in the same
/// order.
enum Branch {
    /// A ray (and the mirror chain after it, followed in a loop).
    Ray { ray: Ray, depth: u32, weight: Color },
    /// Glossy rays still to draw, `left` of them, around the mirror direction `mirror`,
    /// leaving `from`, each of weight `weight`, on the side `side` of the true surface.
    Glossy {
        from: SurfacePoint,
        mirror: Vec3A,
        side: Vec3A,
        exponent: f32,
        left: u32,
        depth: u32,
        weight: Color,
    },
}

#[derive(Clone, Copy, Debug)]
pub struct Whitted {
    /// Bounces allowed after the primary hit.
    pub max_depth: u32,
    /// `lightsamples`: shadow rays per quad light per shading point.
    pub light_samples: u32,
    /// `lightstratify`: the light samples on a jittered √N × √N grid.
    pub light_stratify: bool,
    /// When a branch's weight can no longer show ([`DepthControl::for_scene`]).
    pub depth: DepthControl,
    /// The rays one camera sample's tree may trace ([`MAX_TREE_RAYS`]); the branches
    /// past them are cut and counted.
    pub max_tree_rays: u32,
}

impl Whitted {
    /// The local terms at `hit`, the closest hit of `ray` (ambient, emission, lights),
    /// into `terms`, and the hit's surface point (with the shading normal).
    fn shade(&self, t: &mut Tracing, ray: &Ray, hit: &Hit, terms: &mut impl LightTerms) -> SurfacePoint {
        let scene = t.scene;
        let mut sp = scene.surface_point(hit, ray);
        if let Some(light) = sp.light {
            terms.start(scene.lights[light as usize].radiance_seen(ray.dir, sp.normal));
            return sp;
        }
        let m = &scene.materials[sp.material as usize];
        let shaded = surface::shade(m, &scene.textures, &sp, || scene.tangents(hit, ray));
        sp.normal = shaded.normal;
        let diffuse = shaded.diffuse;
        let n = sp.normal;
        let view = -ray.dir;
        terms.start(m.ambient + m.emission);
        for light in &scene.lights {
            if let Light::Quad(q) = light {
                let count = self.light_samples.max(1);
                let mut shadows = ShadowBatch::new();
                // Up to sixteen samples at a time, so that their highlights are one
                // vector computation (`crate::pow`).
                let mut first = 0;
                while first < count {
                    let lanes = (count - first).min(pow::LANES as u32) as usize;
                    let mut incs = [const { None }; pow::LANES];
                    let mut cos_h = [0.0f32; pow::LANES];
                    for (j, slot) in incs[..lanes].iter_mut().enumerate() {
                        let (u, v) = t.sampler.uniform2();
                        let (u, v) = if self.light_stratify {
                            stratified(first + j as u32, count, u, v)
                        } else {
                            (u, v)
                        };
                        let inc = q.incidence(sp.point, q.point(u, v));
                        cos_h[j] = n.dot((inc.dir + view).normalize()).max(0.0);
                        *slot = Some(inc);
                    }
                    // A material without a highlight needs no powers (each would be
                    // multiplied by zero).
                    let highlight = if m.specular == Color::ZERO {
                        [0.0; pow::LANES]
                    } else {
                        pow::pow_lanes(&cos_h, m.shininess)
                    };
                    for (inc, &h) in incs[..lanes].iter().flatten().zip(&highlight) {
                        let reflected = diffuse * n.dot(inc.dir).max(0.0) + m.specular * h;
                        if reflected != Color::ZERO && inc.intensity != Color::ZERO {
                            // Aimed at a point on the light: stops just before it.
                            let shadow = sp.spawn_segment(inc.dir, inc.distance);
                            shadows.add(scene, shadow, inc.intensity * reflected, t.counts);
                        }
                    }
                    first += lanes as u32;
                }
                terms.add(shadows.sum(scene) / count as f32);
                continue;
            }
            let inc = light.incidence(sp.point);
            let n_dot_l = n.dot(inc.dir).max(0.0);
            let n_dot_h = n.dot((inc.dir + view).normalize()).max(0.0);
            // One power: libm's `powf` (short polynomials on tables) is faster here than
            // `pow`'s long dependency chain, which only pays sixteen lanes at a time.
            let reflected = diffuse * n_dot_l + m.specular * n_dot_h.powf(m.shininess);
            // A light that could add nothing needs no shadow ray.
            if reflected == Color::ZERO || inc.intensity == Color::ZERO {
                continue;
            }
            t.counts.rays += 1;
            terms.add_unless_blocked(sp.spawn_segment(inc.dir, inc.distance), inc.intensity * reflected);
        }
        sp
    }

    /// Adds `weight · I(ray)` to `total`. The mirror chain `I0 + S0 (I1 + S1 (…))` runs
    /// as a loop (the product of the specular colours so far weighs each hit's local
    /// terms); where a hit branches — a refracted ray, glossy rays — the branches go on
    /// the stack `pending`, the one to trace first on top.
    fn follow(
        &self,
        t: &mut Tracing,
        ray: Ray,
        depth: u32,
        weight: Color,
        total: &mut Color,
        pending: &mut Vec<Branch>,
    ) {
        let scene = t.scene;
        let (mut ray, mut depth, mut weight) = (ray, depth, weight);
        loop {
            if self.leave_out(t, weight, pending) {
                return;
            }
            if t.traced >= self.max_tree_rays {
                t.counts.cut_branches += 1;
                return;
            }
            t.traced += 1;
            let mut found = None;
            t.camera.take_into(scene, &ray, t.counts, &mut found);
            let Some(hit) = &found else {
                if let Some(env) = &scene.environment {
                    *total += weight * env.radiance(ray.dir);
                }
                return;
            };
            let mut local = Immediate {
                scene,
                color: Color::ZERO,
            };
            let sp = self.shade(t, &ray, &hit, &mut local);
            *total += weight * local.color;
            match self.next(t, &ray, &sp, depth, weight, pending) {
                Some(next) => (ray, depth, weight) = next,
                None => return,
            }
        }
    }

    /// What comes after the hit `sp` of `ray` (at `depth`, of weight `weight`): the
    /// mirror ray that goes on with the chain, or `None` — where the tree ends there, or
    /// where it branches (a refracted ray, glossy rays), the branches then put on
    /// `pending`.
    fn next(
        &self,
        t: &mut Tracing,
        ray: &Ray,
        sp: &SurfacePoint,
        depth: u32,
        weight: Color,
        pending: &mut Vec<Branch>,
    ) -> Option<(Ray, u32, Color)> {
        // A light's surface reflects nothing.
        if sp.light.is_some() || depth >= self.max_depth {
            return None;
        }
        let m = &t.scene.materials[sp.material as usize];
        let (d, n) = (ray.dir, sp.normal);
        // The side of the true surface the ray came from: reflected rays must leave on it
        // and refracted rays on the other, whatever the shading normal says.
        let viewer = side_of(-d, sp.geometric_normal);
        let mut mirror = m.specular;
        let mut refracted = None;
        if m.transparent != Color::ZERO {
            // Entering when the ray meets the side the normal points to.
            let entering = d.dot(n) < 0.0;
            let (facing, n_i, n_t) = if entering { (n, 1.0, m.ior) } else { (-n, m.ior, 1.0) };
            let f = fresnel_dielectric(-d.dot(facing), n_i, n_t);
            let through = weight * m.transparent * (1.0 - f);
            if f < 1.0 && through.max_element() > MIN_WEIGHT {
                if let Some(dir) = refract(d, facing, n_i / n_t) {
                    let dir = if dir.dot(viewer) < 0.0 {
                        dir
                    } else {
                        lift_above(dir, -viewer, 0.01)
                    };
                    refracted = Some(Branch::Ray {
                        ray: sp.spawn(dir),
                        depth: depth + 1,
                        weight: through,
                    });
                }
            }
            mirror *= f;
        }
        // (Opaque mirrors are never pruned here: the course images depend on every bounce
        // up to `maxdepth`, and adaptive depth control stops them where they cannot show.)
        let negligible = m.transparent != Color::ZERO && (weight * mirror).max_element() <= MIN_WEIGHT;
        let reflected = if mirror == Color::ZERO || negligible {
            None
        } else {
            let r = reflect_above(-d, n, viewer);
            Some(match m.glossy {
                Some(g) => {
                    let count = if depth == 0 { g.samples.max(1) } else { 1 };
                    Branch::Glossy {
                        from: *sp,
                        mirror: r,
                        side: viewer,
                        exponent: g.exponent,
                        left: count,
                        depth: depth + 1,
                        weight: weight * mirror / count as f32,
                    }
                }
                None => Branch::Ray {
                    ray: sp.spawn(r),
                    depth: depth + 1,
                    weight: weight * mirror,
                },
            })
        };
        match (refracted, reflected) {
            // The mirror chain goes on.
            (None, Some(Branch::Ray { ray, depth, weight })) => Some((ray, depth, weight)),
            (None, None) => None,
            // The refracted branch is traced first, then the reflected one.
            (refracted, reflected) => {
                for b in [reflected, refracted].into_iter().flatten() {
                    push(pending, b, t.counts);
                }
                None
            }
        }
    }

    /// Traces the branches left on `pending` (and those they add), into `total`.
    fn finish_tree(&self, t: &mut Tracing, total: &mut Color, pending: &mut Vec<Branch>) {
        while let Some(b) = pending.pop() {
            match b {
                Branch::Ray { ray, depth, weight } => self.follow(t, ray, depth, weight, total, pending),
                glossy => self.next_glossy(t, glossy, pending),
            }
        }
    }

    /// Whether a branch of weight `w` is left out (adaptive depth control): what it could
    /// add must fit in what is left of the sample's budget, and where the scene draws
    /// random numbers after the camera ray, nothing may wait to be traced after it.
    fn leave_out(&self, t: &mut Tracing, w: Color, pending: &[Branch]) -> bool {
        if self.depth.tails_only && !pending.is_empty() {
            return false;
        }
        let cost = self.depth.cost(w);
        if t.dropped + cost <= self.depth.budget {
            t.dropped += cost;
            true
        } else {
            false
        }
    }

    /// Draws the next of a hit's glossy rays (`left` > 0 of them) and puts it on the
    /// stack, above the rays still to draw, so that it is traced before they are drawn.
    fn next_glossy(&self, t: &mut Tracing, glossy: Branch, pending: &mut Vec<Branch>) {
        let Branch::Glossy {
            from,
            mirror,
            side,
            exponent,
            left,
            depth,
            weight,
        } = glossy
        else {
            unreachable!("only glossy branches draw")
        };
        let (u, v) = t.sampler.uniform2();
        let dir = phong_lobe(mirror, exponent, u, v);
        if left > 1 {
            let rest = Branch::Glossy {
                from,
                mirror,
                side,
                exponent,
                left: left - 1,
                depth,
                weight,
            };
            push(pending, rest, t.counts);
        }
        if dir.dot(side) > 0.0 {
            let ray = Branch::Ray {
                ray: from.spawn(dir),
                depth,
                weight,
            };
            push(pending, ray, t.counts);
        }
    }
}

/// Puts a branch on the stack, unless the stack is full ([`MAX_PENDING`]).
fn push(pending: &mut Vec<Branch>, b: Branch, counts: &mut TraceCounts) {
    if pending.len() < MAX_PENDING {
        pending.push(b);
    } else {
        counts.cut_branches += 1;
    }
}

impl Integrator for Whitted {
    fn radiance(
        &self,
        scene: &Scene,
        ray: &Ray,
        camera: CameraHit,
        sampler: &mut Sampler,
        counts: &mut TraceCounts,
    ) -> Color {
        let mut total = BACKGROUND;
        let mut t = Tracing {
            scene,
            camera,
            sampler,
            counts,
            dropped: 0.0,
            traced: 0,
        };
        // Only a tree that branches allocates.
        let mut pending = Vec::new();
        self.follow(&mut t, *ray, 0, Color::ONE, &mut total, &mut pending);
        self.finish_tree(&mut t, &mut total, &mut pending);
        total
    }

    fn radiances(
        &self,
        scene: &Scene,
        rays: &[Ray],
        hits: &[Option<Hit>],
        samplers: &mut [Sampler],
        counts: &mut TraceCounts,
        out: &mut [Color],
    ) {
        // A batch keeps every shadow ray of its first hits, as many as samples × lights:
        // with more lights than this the samples go one at a time, in constant memory.
        if scene.lights.len() > MAX_BATCH_LIGHTS {
            super::one_at_a_time(self, scene, rays, hits, samplers, counts, out);
        } else {
            self.batch(scene, rays, hits, samplers, counts, out);
        }
    }
}
