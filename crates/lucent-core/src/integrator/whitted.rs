//! Scene commands: `integrator raytracer` (the default) and `maxdepth d` — the classic
//! recursive ray tracer of CSE167 homework 3 (SCENE_FORMAT.md §4.3):
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
//! lucent's extensions (EXTENSIONS.md):
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

use super::Integrator;
use crate::hit::{SurfacePoint, BACKGROUND};
use crate::light::Light;
use crate::math::Color;
use crate::ray::{Ray, EPSILON};
use crate::sampler::{stratified, Sampler};
use crate::scene::Scene;
use crate::shading::bump;
use crate::shading::optics::{fresnel_dielectric, phong_lobe, reflect, refract};

/// Branches of the ray tree whose weight falls below this add less than a tenth of an
/// 8-bit step: they are not traced.
const MIN_WEIGHT: f32 = 1.0 / 2048.0;

/// What one camera sample's ray tree shares.
struct Tracing<'a> {
    scene: &'a Scene,
    sampler: &'a mut Sampler,
    /// Every ray traced.
    rays: &'a mut u64,
}

pub struct Whitted {
    /// Bounces allowed after the primary hit.
    pub max_depth: u32,
    /// `lightsamples`: shadow rays per quad light per shading point.
    pub light_samples: u32,
    /// `lightstratify`: the light samples on a jittered √N × √N grid.
    pub light_stratify: bool,
}

impl Whitted {
    /// The local terms at the closest hit of `ray` (ambient, emission, lights) and the
    /// hit; `None` when the ray escapes.
    fn shade(&self, t: &mut Tracing, ray: &Ray) -> Option<(Color, SurfacePoint)> {
        let scene = t.scene;
        *t.rays += 1;
        let hit = scene.closest_hit(ray)?;
        let mut sp = scene.surface_point(&hit, ray);
        if let Some(light) = sp.light {
            return Some((scene.lights[light as usize].radiance_seen(ray.dir, sp.normal), sp));
        }
        let m = &scene.materials[sp.material as usize];
        if let Some(bump) = m.bump_map {
            let (dpdu, dpdv) = scene.tangents(&hit, ray);
            sp.normal = bump::bumped_normal(&scene.textures[bump.texture as usize], bump, &sp, dpdu, dpdv);
        }
        let diffuse = match m.diffuse_map {
            Some(t) => m.diffuse * scene.textures[t as usize].eval(sp.uv, sp.point),
            None => m.diffuse,
        };
        let n = sp.normal;
        let view = -ray.dir;
        let mut color = m.ambient + m.emission;
        for light in &scene.lights {
            if let Light::Quad(q) = light {
                let count = self.light_samples.max(1);
                let mut sum = Color::ZERO;
                for k in 0..count {
                    let (u, v) = t.sampler.uniform2();
                    let (u, v) = if self.light_stratify {
                        stratified(k, count, u, v)
                    } else {
                        (u, v)
                    };
                    let inc = q.incidence(sp.point, q.point(u, v));
                    let reflected = diffuse * n.dot(inc.dir).max(0.0)
                        + m.specular * n.dot((inc.dir + view).normalize()).max(0.0).powf(m.shininess);
                    if reflected == Color::ZERO || inc.intensity == Color::ZERO {
                        continue;
                    }
                    *t.rays += 1;
                    // Aimed at a point on the light: stops just before it.
                    let shadow = Ray::segment(sp.point, inc.dir, EPSILON, inc.distance - EPSILON);
                    if !scene.occluded(&shadow) {
                        sum += inc.intensity * reflected;
                    }
                }
                color += sum / count as f32;
                continue;
            }
            let inc = light.incidence(sp.point);
            let n_dot_l = n.dot(inc.dir).max(0.0);
            let n_dot_h = n.dot((inc.dir + view).normalize()).max(0.0);
            let reflected = diffuse * n_dot_l + m.specular * n_dot_h.powf(m.shininess);
            // A light that could add nothing needs no shadow ray.
            if reflected == Color::ZERO || inc.intensity == Color::ZERO {
                continue;
            }
            *t.rays += 1;
            let shadow = Ray::segment(sp.point, inc.dir, EPSILON, inc.distance - EPSILON);
            if !scene.occluded(&shadow) {
                color += inc.intensity * reflected;
            }
        }
        Some((color, sp))
    }

    /// Adds `weight · I(ray)` to `total`. The mirror chain `I0 + S0 (I1 + S1 (…))` runs
    /// as a loop (the product of the specular colours so far weighs each hit's local
    /// terms); only refraction and glossy reflection branch, by recursion.
    fn trace(&self, t: &mut Tracing, ray: Ray, depth: u32, weight: Color, total: &mut Color) {
        let scene = t.scene;
        let (mut ray, mut depth, mut weight) = (ray, depth, weight);
        loop {
            let Some((local, sp)) = self.shade(t, &ray) else {
                if let Some(env) = &scene.environment {
                    *total += weight * env.radiance(ray.dir);
                }
                break;
            };
            *total += weight * local;
            // A light's surface reflects nothing.
            if sp.light.is_some() || depth >= self.max_depth {
                break;
            }
            let m = &scene.materials[sp.material as usize];
            let (d, n) = (ray.dir, sp.normal);
            let mut mirror = m.specular;
            if m.transparent != Color::ZERO {
                // Entering when the ray meets the side the normal points to.
                let entering = d.dot(n) < 0.0;
                let (facing, n_i, n_t) = if entering { (n, 1.0, m.ior) } else { (-n, m.ior, 1.0) };
                let f = fresnel_dielectric(-d.dot(facing), n_i, n_t);
                let through = weight * m.transparent * (1.0 - f);
                if f < 1.0 && through.max_element() > MIN_WEIGHT {
                    if let Some(dir) = refract(d, facing, n_i / n_t) {
                        self.trace(t, Ray::new(sp.point, dir), depth + 1, through, total);
                    }
                }
                mirror *= f;
            }
            // (Opaque mirrors are never pruned: the course images depend on every bounce.)
            let negligible = m.transparent != Color::ZERO && (weight * mirror).max_element() <= MIN_WEIGHT;
            if mirror == Color::ZERO || negligible {
                break;
            }
            let r = reflect(d, n).normalize();
            if let Some(g) = m.glossy {
                let count = if depth == 0 { g.samples.max(1) } else { 1 };
                let w = weight * mirror / count as f32;
                // Rays leave on the side the reflected ray is on.
                let side = if r.dot(n) >= 0.0 { n } else { -n };
                for _ in 0..count {
                    let (u, v) = t.sampler.uniform2();
                    let dir = phong_lobe(r, g.exponent, u, v);
                    if dir.dot(side) > 0.0 {
                        self.trace(t, Ray::new(sp.point, dir), depth + 1, w, total);
                    }
                }
                break;
            }
            weight *= mirror;
            ray = Ray::new(sp.point, r);
            depth += 1;
        }
    }
}

impl Integrator for Whitted {
    fn radiance(&self, scene: &Scene, ray: &Ray, sampler: &mut Sampler, rays: &mut u64) -> Color {
        let mut total = BACKGROUND;
        let mut t = Tracing { scene, sampler, rays };
        self.trace(&mut t, *ray, 0, Color::ONE, &mut total);
        total
    }
}
