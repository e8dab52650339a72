//! A scene ready to render: primitives with their acceleration structure, materials,
//! textures, lights and the camera. What is rendered of it — the image's size, the
//! pixels, the samples — is a [`crate::render::job::RenderJob`], not part of the scene.

use crate::accel::AccelKind;
use crate::camera::Camera;
use crate::geometry::primitive::Primitive;
use crate::geometry::Geometry;
use crate::hit::{Hit, SurfacePoint};
use crate::light::emitters::{EmissiveSurfaces, Emitters};
use crate::light::environment::EnvironmentLight;
use crate::light::{Light, SampledLight};
use crate::math::{Color, Vec3A};
use crate::ray::{PreparedRay, Ray};
use crate::shading::bsdf::Bsdf;
use crate::shading::material::Material;
use crate::shading::surface;
use crate::shading::texture::{EnvironmentMap, Texture};

pub struct Scene {
    pub camera: Camera,
    pub geometry: Geometry,
    pub materials: Vec<Material>,
    /// Every light; an emitting primitive (the geometry of a `quadLight`) names its own
    /// ([`crate::geometry::primitive::Primitive::light`]).
    pub lights: Vec<Light>,
    /// `texture` and `checker`, indexed by the materials' maps.
    pub textures: Vec<Texture>,
    /// `envmap`: what rays that hit nothing see (black without one).
    pub environment: Option<EnvironmentMap>,
    /// The Monte Carlo integrators' light of every emissive surface (`emission`), if
    /// any can be sampled.
    pub emitters: Option<EmissiveSurfaces>,
    /// Materials that emit on shapes light sampling cannot reach, `(material, shape)`.
    pub unsampled_emitters: Vec<(u32, &'static str)>,
    /// The Monte Carlo integrators' environment light (`envmap`), unless it is black.
    pub environment_light: Option<EnvironmentLight>,
    accel_kind: AccelKind,
    /// See [`Scene::lambertian_and_quad_lit`] (found once: a mesh brings a material per
    /// face).
    lambertian_and_quad_lit: bool,
}

/// Everything a [`Scene`] is made of, before its acceleration structure is built.
pub struct SceneParts {
    pub camera: Camera,
    pub primitives: Vec<Primitive>,
    pub materials: Vec<Material>,
    pub lights: Vec<Light>,
    pub vertex_normals: Vec<[Vec3A; 3]>,
    pub textures: Vec<Texture>,
    pub environment: Option<EnvironmentMap>,
    /// Whether to build the Monte Carlo integrators' lights of emissive surfaces and of
    /// the environment (their tables cost memory the other integrators do not need).
    pub sampled_lights: bool,
}

impl Scene {
    pub fn new(parts: SceneParts, accel: AccelKind) -> Scene {
        let SceneParts {
            camera,
            primitives,
            materials,
            lights,
            vertex_normals,
            textures,
            environment,
            sampled_lights,
        } = parts;
        let found = if sampled_lights {
            EmissiveSurfaces::find(&primitives, &materials)
        } else {
            Emitters {
                light: None,
                unsampled: Vec::new(),
            }
        };
        let lambertian_and_quad_lit = environment.is_none()
            && found.light.is_none()
            && found.unsampled.is_empty()
            && !lights.is_empty()
            && lights.iter().all(|l| matches!(l, Light::Quad(_)))
            && materials.iter().all(Material::is_lambertian);
        Scene {
            lambertian_and_quad_lit,
            camera,
            geometry: Geometry::new(primitives, vertex_normals, accel),
            accel_kind: accel,
            materials,
            lights,
            textures,
            environment_light: environment
                .as_ref()
                .filter(|_| sampled_lights)
                .and_then(EnvironmentLight::new),
            environment,
            emitters: found.light,
            unsampled_emitters: found.unsampled,
        }
    }

    /// Whether every light is a quad light, nothing else emits (no `emission`, no
    /// environment) and every material is plain Lambertian
    /// ([`Material::is_lambertian`]): a path tracer's vertices then all shade the same
    /// way (see `integrator::path::lanes`).
    #[inline]
    pub fn lambertian_and_quad_lit(&self) -> bool {
        self.lambertian_and_quad_lit
    }

    /// What a ray travelling along `dir` that hits nothing sees: the environment map, or
    /// black.
    #[inline]
    pub fn background(&self, dir: Vec3A) -> Color {
        match &self.environment {
            Some(env) => env.radiance(dir),
            None => Color::ZERO,
        }
    }

    /// How many lights next-event estimation chooses among (the Monte Carlo
    /// integrators): the scene's lights, then all emissive surfaces as one, then the
    /// environment.
    #[inline]
    pub fn sampled_light_count(&self) -> usize {
        self.lights.len() + self.emitters.is_some() as usize + self.environment_light.is_some() as usize
    }

    /// Light i of [`Scene::sampled_light_count`].
    #[inline]
    pub fn sampled_light(&self, i: usize) -> SampledLight<'_> {
        if let Some(l) = self.lights.get(i) {
            return SampledLight::Listed(l);
        }
        match (&self.emitters, i - self.lights.len()) {
            (Some(e), 0) => SampledLight::Emitters(e),
            _ => SampledLight::Environment(
                self.environment_light.as_ref().expect("a light index within the count"),
                self.environment.as_ref().expect("an environment light has its map"),
            ),
        }
    }

    #[inline]
    pub fn closest_hit(&self, ray: &Ray) -> Option<Hit> {
        self.geometry.closest_hit(ray)
    }

    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.geometry.occluded(ray)
    }

    /// [`Scene::closest_hit`] of a ray prepared already.
    #[inline]
    pub fn closest_hit_prepared(&self, ray: &PreparedRay) -> Option<Hit> {
        self.geometry.closest_hit_prepared(ray)
    }

    /// [`Scene::closest_hit_prepared`] into `best`, where the caller keeps it: a hit
    /// copied out of the structure's search would be read back whole just after it was
    /// written piece by piece (a stalled store-to-load forward per ray).
    #[inline]
    pub fn closest_hit_into(&self, ray: &PreparedRay, best: &mut Option<Hit>) {
        self.geometry.closest_hit_into(ray, best)
    }

    /// [`Scene::occluded`] of a ray prepared already.
    #[inline]
    pub fn occluded_prepared(&self, ray: &PreparedRay) -> bool {
        self.geometry.occluded_prepared(ray)
    }

    /// [`Scene::closest_hit`] of each of `rays` (`out[i]` for `rays[i]`): coherent rays,
    /// such as the camera rays of a tile, travel through the BVH together.
    pub fn closest_hits(&self, rays: &[Ray], out: &mut [Option<Hit>]) {
        self.geometry.closest_hits(rays, out)
    }

    /// [`Scene::occluded`] of each of `rays` (`out[i]` for `rays[i]`): coherent rays,
    /// such as the shadow rays from one point toward an area light, travel together.
    pub fn occluded_rays(&self, rays: &[Ray], out: &mut [bool]) {
        self.geometry.occluded_rays(rays, out)
    }

    pub fn surface_point(&self, hit: &Hit, ray: &Ray) -> SurfacePoint {
        self.geometry.surface_point(hit, ray.origin, ray.dir)
    }

    /// `∂p/∂u`, `∂p/∂v` at the hit (bump mapping asks for them).
    pub fn tangents(&self, hit: &Hit, ray: &Ray) -> (Vec3A, Vec3A) {
        self.geometry.tangents(hit, ray.origin, ray.dir)
    }

    /// The BSDF of an ordinary (not emitting) surface point `sp` of `hit`: the
    /// material's model around the bump-mapped normal, with the textured diffuse colour.
    pub fn bsdf(&self, hit: &Hit, ray: &Ray, sp: &SurfacePoint) -> Bsdf {
        let m = &self.materials[sp.material as usize];
        let shaded = surface::shade(m, &self.textures, sp, || self.tangents(hit, ray));
        m.bsdf(shaded.normal, sp.geometric_normal, shaded.diffuse)
    }

    pub fn accel_kind(&self) -> AccelKind {
        self.accel_kind
    }

    /// Bytes of every acceleration structure of the scene (see
    /// [`Geometry::accel_memory_bytes`]).
    pub fn accel_memory_bytes(&self) -> usize {
        self.geometry.accel_memory_bytes()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::test_scenes::{analytic_soup, Rng};
    use crate::math::DVec3;
    use crate::ray::PreparedRay;

    fn scene_of(primitives: Vec<Primitive>, accel: AccelKind) -> Scene {
        let camera = Camera::look_at(DVec3::Z, DVec3::ZERO, DVec3::Y, 45.0).unwrap();
        let parts = SceneParts {
            camera,
            primitives,
            materials: vec![Material::default()],
            lights: Vec::new(),
            vertex_normals: Vec::new(),
            textures: Vec::new(),
            environment: None,
            sampled_lights: false,
        };
        Scene::new(parts, accel)
    }

    #[test]
    fn unbounded_planes_are_found_beside_every_structure() {
        let prims = analytic_soup(5, 360); // six planes among them
        let planes = prims.iter().filter(|p| !p.bounds().min.is_finite()).count();
        assert!(planes >= 5, "{planes}");
        let mut rng = Rng(11);
        let rays: Vec<Ray> = (0..2000)
            .map(|_| {
                let o = rng.vec(15.0);
                Ray::new(o, (rng.vec(8.0) - o).normalize())
            })
            .collect();
        // Brute force over every primitive, planes included, with the scene-order tie rule.
        let expected: Vec<Option<Hit>> = rays
            .iter()
            .map(|ray| {
                let r = PreparedRay::new(*ray);
                let mut best: Option<Hit> = None;
                for (i, p) in prims.iter().enumerate() {
                    if let Some(hit) = p.intersect(i as u32, &r, best.map_or(ray.t_max, |b| b.t)) {
                        if Hit::is_closer_than(hit.t, i as u32, &best) {
                            best = Some(hit);
                        }
                    }
                }
                best
            })
            .collect();
        let plane_hits = expected
            .iter()
            .filter(|h| h.is_some_and(|h| !prims[h.prim as usize].bounds().min.is_finite()))
            .count();
        assert!(plane_hits > 100, "{plane_hits}");
        for kind in AccelKind::ALL {
            let scene = scene_of(prims.clone(), kind);
            for (ray, want) in rays.iter().zip(&expected) {
                assert_eq!(scene.closest_hit(ray), *want, "{kind:?}");
                assert_eq!(scene.occluded(ray), want.is_some(), "{kind:?}");
            }
        }
    }
}
