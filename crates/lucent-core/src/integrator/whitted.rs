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

use super::Integrator;
use crate::hit::{SurfacePoint, BACKGROUND};
use crate::math::Color;
use crate::ray::{Ray, EPSILON};
use crate::scene::Scene;

pub struct Whitted {
    /// Mirror bounces allowed after the primary hit.
    pub max_depth: u32,
}

impl Whitted {
    /// The local terms at the closest hit of `ray` (ambient, emission, lights), the hit,
    /// and its normal; `None` when the ray escapes.
    fn shade(&self, scene: &Scene, ray: &Ray, rays: &mut u64) -> Option<(Color, SurfacePoint)> {
        *rays += 1;
        let hit = scene.closest_hit(ray)?;
        let sp = scene.surface_point(&hit, ray);
        let m = &scene.materials[sp.material as usize];
        let n = sp.normal;
        let view = -ray.dir;
        let mut color = m.ambient + m.emission;
        for light in &scene.lights {
            let inc = light.incidence(sp.point);
            let n_dot_l = n.dot(inc.dir).max(0.0);
            let n_dot_h = n.dot((inc.dir + view).normalize()).max(0.0);
            let reflected = m.diffuse * n_dot_l + m.specular * n_dot_h.powf(m.shininess);
            // A light that could add nothing needs no shadow ray.
            if reflected == Color::ZERO || inc.intensity == Color::ZERO {
                continue;
            }
            *rays += 1;
            let shadow = Ray::segment(sp.point, inc.dir, EPSILON, inc.distance - EPSILON);
            if !scene.occluded(&shadow) {
                color += inc.intensity * reflected;
            }
        }
        Some((color, sp))
    }
}

impl Integrator for Whitted {
    /// The mirror chain `I0 + S0 (I1 + S1 (I2 + …))` as a loop: the product of the
    /// specular colours so far weights each hit's local terms. No recursion, so no
    /// `maxdepth` can exhaust a thread's stack.
    fn radiance(&self, scene: &Scene, ray: &Ray, rays: &mut u64) -> Color {
        let mut total = BACKGROUND;
        let mut weight = Color::ONE;
        let mut ray = *ray;
        let mut depth = 0;
        while let Some((local, sp)) = self.shade(scene, &ray, rays) {
            total += weight * local;
            let specular = scene.materials[sp.material as usize].specular;
            if depth >= self.max_depth || specular == Color::ZERO {
                break;
            }
            weight *= specular;
            let (d, n) = (ray.dir, sp.normal);
            ray = Ray::new(sp.point, (d - n * (2.0 * d.dot(n))).normalize());
            depth += 1;
        }
        total
    }
}
