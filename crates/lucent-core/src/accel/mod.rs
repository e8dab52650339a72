//! Acceleration structures: one file per structure, all behind one trait so the
//! renderer and the tests can swap them (`lucent render --accel`).
//!
//! Every structure must return exactly the hit the brute-force [`list::PrimitiveList`]
//! returns. Two rules make that possible: each primitive test is the same function
//! everywhere (so the same ray and primitive give the same `t` to the bit), and ties in
//! `t` go to the primitive that comes first in the scene ([`Hit::is_closer_than`]).

pub mod bvh;
mod cell_walk;
pub mod grid;
pub mod kdtree;
pub mod list;
mod mailbox;
pub mod octree;
pub mod overlap;
#[cfg(test)]
mod tests;

use crate::aabb::Aabb;
use crate::hit::Hit;
use crate::math::Vec3A;
use crate::primitive::Primitive;
use crate::ray::PreparedRay;

/// How far past the closest hit so far a structure keeps looking.
///
/// A box's or cell's entry distance and a primitive's hit distance are rounded
/// differently, so a box can appear to start just beyond a hit that lies on its face, and
/// a primitive in it with an equal `t` (a tie the scene order must decide) would be
/// missed. Structures therefore cull boxes and stop early only beyond
/// `t · (1 + 2⁻¹²)`: far more than the rounding of either, and too little to cost
/// measurable speed.
#[inline(always)]
pub fn search_limit(t: f32) -> f32 {
    t * (1.0 + 1.0 / 4096.0)
}

/// What a structure is built over: the primitives of a scene or of an instanced object
/// (`[Primitive]`), or the triangles of one mesh ([`crate::mesh::TriangleMesh`]), each
/// known by its index.
pub trait PrimitiveSet: Sync {
    fn count(&self) -> usize;
    fn bounds(&self, i: u32) -> Aabb;
    /// The corners of primitive `i` if it is a plain triangle: the BVH packs these into
    /// its SIMD leaves, and cells use them for the exact overlap test.
    fn triangle(&self, i: u32) -> Option<[Vec3A; 3]>;
    /// The hit of `ray` with primitive `i` in `(ray.t_min, t_max]`, with `prim = i`.
    fn intersect(&self, i: u32, ray: &PreparedRay, t_max: f32) -> Option<Hit>;
    /// Whether primitive `i` has any hit in `(ray.t_min, t_max]`.
    #[inline(always)]
    fn occludes(&self, i: u32, ray: &PreparedRay, t_max: f32) -> bool {
        self.intersect(i, ray, t_max).is_some()
    }
}

impl PrimitiveSet for [Primitive] {
    #[inline(always)]
    fn count(&self) -> usize {
        self.len()
    }

    fn bounds(&self, i: u32) -> Aabb {
        self[i as usize].bounds()
    }

    fn triangle(&self, i: u32) -> Option<[Vec3A; 3]> {
        self[i as usize].triangle()
    }

    #[inline(always)]
    fn intersect(&self, i: u32, ray: &PreparedRay, t_max: f32) -> Option<Hit> {
        self[i as usize].intersect(i, ray, t_max)
    }

    #[inline(always)]
    fn occludes(&self, i: u32, ray: &PreparedRay, t_max: f32) -> bool {
        self[i as usize].occludes(ray, t_max)
    }
}

/// The primitives a structure holds: every one with finite bounds, as `(index, bounds)`.
/// Unbounded ones (planes) are tested outside any structure
/// ([`crate::geometry::Geometry`]).
pub fn bounded<P: PrimitiveSet + ?Sized>(prims: &P) -> impl Iterator<Item = (u32, Aabb)> + '_ {
    (0..prims.count() as u32).filter_map(|i| {
        let b = prims.bounds(i);
        is_bounded(&b).then_some((i, b))
    })
}

/// Whether a primitive with these bounds belongs in a structure (see [`bounded`]).
pub fn is_bounded(b: &Aabb) -> bool {
    b.min.is_finite() && b.max.is_finite()
}

/// A structure over the primitive set `P` it was built for.
pub trait Accelerator<P: PrimitiveSet + ?Sized>: Send + Sync {
    /// The closest hit with `ray.t_min < t <= ray.t_max`.
    fn closest_hit(&self, prims: &P, r: &PreparedRay) -> Option<Hit>;
    /// Whether anything lies in `(ray.t_min, ray.t_max]` (shadow rays).
    fn occluded(&self, prims: &P, r: &PreparedRay) -> bool;
    /// Bytes used by the structure itself (not counting the primitives).
    fn memory_bytes(&self) -> usize;
}

/// The structures `lucent render --accel` offers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AccelKind {
    Bvh,
    KdTree,
    Grid,
    Octree,
    List,
}

impl AccelKind {
    pub const ALL: [AccelKind; 5] = [
        AccelKind::Bvh,
        AccelKind::KdTree,
        AccelKind::Grid,
        AccelKind::Octree,
        AccelKind::List,
    ];
    /// The names `--accel` takes, in the order of [`AccelKind::ALL`].
    pub const NAMES: [&'static str; 5] = ["bvh", "kdtree", "grid", "octree", "list"];

    pub fn name(self) -> &'static str {
        AccelKind::NAMES[AccelKind::ALL
            .iter()
            .position(|&k| k == self)
            .expect("every kind is in ALL")]
    }

    pub fn build<P: PrimitiveSet + ?Sized + 'static>(self, prims: &P) -> Box<dyn Accelerator<P>> {
        match self {
            AccelKind::Bvh => Box::new(bvh::Bvh::build(prims)),
            AccelKind::KdTree => Box::new(kdtree::KdTree::build(prims)),
            AccelKind::Grid => Box::new(grid::Grid::build(prims)),
            AccelKind::Octree => Box::new(octree::Octree::build(prims)),
            AccelKind::List => Box::new(list::PrimitiveList::new(prims)),
        }
    }
}

impl std::str::FromStr for AccelKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        AccelKind::ALL.into_iter().find(|k| k.name() == s).ok_or_else(|| {
            format!(
                "unknown acceleration structure '{s}' (expected one of: {})",
                AccelKind::NAMES.join(", ")
            )
        })
    }
}

#[cfg(test)]
pub(crate) mod test_scenes {
    //! Random and degenerate primitive soups shared by the structures' tests.
    use crate::math::{Affine3A, Vec3, Vec3A};
    use crate::primitive::{Primitive, Shape, Sphere};

    pub struct Rng(pub u64);
    impl Rng {
        pub fn next(&mut self) -> f32 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((self.0 >> 40) as f32) / (1u64 << 24) as f32
        }
        pub fn range(&mut self, a: f32, b: f32) -> f32 {
            a + (b - a) * self.next()
        }
        pub fn vec(&mut self, s: f32) -> Vec3A {
            Vec3A::new(self.range(-s, s), self.range(-s, s), self.range(-s, s))
        }
    }

    pub fn soup(seed: u64, n: usize) -> Vec<Primitive> {
        let mut rng = Rng(seed);
        (0..n)
            .map(|i| {
                let c = rng.vec(10.0);
                let shape = if i % 5 == 0 {
                    let m = Affine3A::from_translation(c.into())
                        * Affine3A::from_scale(Vec3::new(
                            rng.range(0.1, 1.0),
                            rng.range(0.1, 1.0),
                            rng.range(0.1, 1.0),
                        ));
                    Shape::Sphere(Sphere::new(m))
                } else {
                    Shape::Triangle {
                        p: [c + rng.vec(1.5), c + rng.vec(1.5), c + rng.vec(1.5)],
                        normals: None,
                    }
                };
                Primitive { shape, material: 0 }
            })
            .collect()
    }

    /// Boxes, cylinders, disks, cones and quadrics under random affine transforms, and a
    /// few unbounded planes (which every structure leaves to the scene).
    pub fn analytic_soup(seed: u64, n: usize) -> Vec<Primitive> {
        use crate::aabb::Aabb;
        use crate::primitive::{Analytic, AnalyticKind};
        let mut rng = Rng(seed);
        (0..n)
            .map(|i| {
                let kind = match i % 6 {
                    0 => AnalyticKind::Cuboid(Aabb::new(rng.vec(1.0), rng.vec(1.0))),
                    1 => AnalyticKind::Cylinder {
                        radius: rng.range(0.2, 1.0),
                        zmin: rng.range(-1.0, 0.0),
                        zmax: rng.range(0.1, 1.0),
                    },
                    2 => AnalyticKind::Disk {
                        radius: rng.range(0.2, 1.0),
                    },
                    3 => AnalyticKind::Cone {
                        radius: rng.range(0.2, 1.0),
                        height: rng.range(-1.5, 1.5),
                    },
                    4 => AnalyticKind::Quadric {
                        // x² + y² − z² − r² (a hyperboloid) clipped to a box.
                        coefficients: [1.0, 1.0, -1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -rng.range(0.1, 0.5)],
                        clip: Aabb::new(Vec3A::splat(-1.0), Vec3A::splat(1.0)),
                    },
                    _ if i % 60 == 5 => AnalyticKind::Plane {
                        point: rng.vec(10.0),
                        normal: rng.vec(1.0),
                    },
                    _ => AnalyticKind::Disk { radius: 0.5 },
                };
                let m = Affine3A::from_translation(rng.vec(10.0).into())
                    * Affine3A::from_axis_angle(rng.vec(1.0).normalize().into(), rng.range(0.0, 6.0))
                    * Affine3A::from_scale(Vec3::new(rng.range(0.3, 2.0), rng.range(0.3, 2.0), rng.range(0.3, 2.0)));
                Primitive {
                    shape: Shape::Analytic(Box::new(Analytic::new(m, kind))),
                    material: 0,
                }
            })
            .collect()
    }

    /// A regular grid of coplanar quads (two triangles each) in z = 0: every shared
    /// edge is an opportunity for ties and leaks.
    pub fn coplanar_grid(n: usize) -> Vec<Primitive> {
        let mut prims = Vec::new();
        for i in 0..n {
            for j in 0..n {
                let p = |a: usize, b: usize| Vec3A::new(a as f32, b as f32, 0.0);
                prims.push(Primitive {
                    shape: Shape::Triangle {
                        p: [p(i, j), p(i + 1, j), p(i + 1, j + 1)],
                        normals: None,
                    },
                    material: 0,
                });
                prims.push(Primitive {
                    shape: Shape::Triangle {
                        p: [p(i, j), p(i + 1, j + 1), p(i, j + 1)],
                        normals: None,
                    },
                    material: 0,
                });
            }
        }
        prims
    }
}
