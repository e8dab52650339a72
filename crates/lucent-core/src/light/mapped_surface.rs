//! Points drawn uniformly by world area on a surface of object space (the unit sphere, a
//! disk, a cylinder, a cone) under an affine transform M: for the emissive shapes of
//! [`super::emitters`]. A point is drawn uniformly in object space and kept with
//! probability s / s_max, where s = |det M| · |M⁻ᵀ n| is how much M stretches the area
//! around it (rejection is skipped where s is constant: a disk, a shape under a rotation
//! and uniform scale). The world area is the object area times the mean of s, by
//! quadrature where s varies (a 128 × 128 midpoint rule on a smooth integrand: error
//! below 10⁻⁵).

use crate::math::{Affine3A, Mat3A, Vec3A};

/// A surface of object space under an affine transform.
#[derive(Clone, Copy, Debug)]
pub(super) struct Mapped {
    surface: ObjectSurface,
    to_world: Affine3A,
    /// |det M| · M⁻ᵀ: s(n) = |stretch · n| for a unit object normal n.
    stretch: Mat3A,
    /// An upper bound of s, or `None` where s is constant (no rejection).
    s_max: Option<f32>,
    /// World area.
    pub(super) area: f32,
}

/// The object-space surfaces: the unit sphere and the course's analytic shapes.
#[derive(Clone, Copy, Debug)]
pub(super) enum ObjectSurface {
    Sphere,
    Disk { radius: f32 },
    Cylinder { radius: f32, zmin: f32, zmax: f32 },
    Cone { radius: f32, height: f32 },
}

impl ObjectSurface {
    /// A point drawn uniformly by object-space area from `(u, v)`, with its unit normal.
    fn point(&self, u: f32, v: f32) -> (Vec3A, Vec3A) {
        use std::f32::consts::TAU;
        match *self {
            ObjectSurface::Sphere => {
                let z = 1.0 - 2.0 * u;
                let r = (1.0 - z * z).max(0.0).sqrt();
                let (s, c) = (TAU * v).sin_cos();
                let p = Vec3A::new(r * c, r * s, z);
                (p, p)
            }
            ObjectSurface::Disk { radius } => {
                let r = radius * u.sqrt();
                let (s, c) = (TAU * v).sin_cos();
                (Vec3A::new(r * c, r * s, 0.0), Vec3A::Z)
            }
            ObjectSurface::Cylinder { radius, zmin, zmax } => {
                let (s, c) = (TAU * u).sin_cos();
                let z = zmin + (zmax - zmin) * v;
                (Vec3A::new(radius * c, radius * s, z), Vec3A::new(c, s, 0.0))
            }
            ObjectSurface::Cone { radius, height } => {
                // Area grows linearly with the distance from the apex.
                let f = u.sqrt();
                let (s, c) = (TAU * v).sin_cos();
                let k = radius / height;
                let p = Vec3A::new(radius * f * c, radius * f * s, height * (1.0 - f));
                (p, Vec3A::new(c, s, k) / (1.0 + k * k).sqrt())
            }
        }
    }

    fn area(&self) -> f32 {
        use std::f32::consts::PI;
        match *self {
            ObjectSurface::Sphere => 4.0 * PI,
            ObjectSurface::Disk { radius } => PI * radius * radius,
            ObjectSurface::Cylinder { radius, zmin, zmax } => 2.0 * PI * radius * (zmax - zmin).abs(),
            ObjectSurface::Cone { radius, height } => PI * radius * (radius * radius + height * height).sqrt(),
        }
    }
}

impl Mapped {
    pub(super) fn new(surface: ObjectSurface, to_world: Affine3A) -> Mapped {
        let m = to_world.matrix3;
        let stretch = m.inverse().transpose() * m.determinant().abs();
        // s is constant on a planar surface, and everywhere when M is a rotation times a
        // uniform scale (MᵀM a multiple of the identity).
        let mtm = m.transpose() * m;
        let scale = mtm.x_axis.x.max(mtm.y_axis.y).max(mtm.z_axis.z);
        let off = (mtm - Mat3A::from_diagonal(glam::Vec3::splat(scale))).to_cols_array();
        let conformal = off.iter().all(|e| e.abs() <= 1e-5 * scale);
        let constant = conformal || matches!(surface, ObjectSurface::Disk { .. });
        let s = |n: Vec3A| (stretch * n).length();
        let (mean, s_max) = if constant {
            (s(surface.point(0.5, 0.5).1), None)
        } else {
            const N: usize = 128;
            let mut sum = 0f64;
            for i in 0..N {
                for j in 0..N {
                    let (u, v) = ((i as f32 + 0.5) / N as f32, (j as f32 + 0.5) / N as f32);
                    sum += s(surface.point(u, v).1) as f64;
                }
            }
            // The largest stretch of any direction: |det M| / σ_min(M), σ_min² the
            // smallest eigenvalue of MᵀM (bounded below by Gershgorin's discs), with a
            // margin for rounding.
            let cols = mtm.to_cols_array_2d();
            let min_eig = (0..3)
                .map(|i| cols[i][i] - (0..3).filter(|&j| j != i).map(|j| cols[i][j].abs()).sum::<f32>())
                .fold(f32::INFINITY, f32::min);
            let bound = if min_eig > 0.0 {
                m.determinant().abs() / min_eig.sqrt()
            } else {
                // No useful bound from the discs: the largest s on a fine grid, doubled.
                let mut best = 0f32;
                for i in 0..512 {
                    for j in 0..64 {
                        best = best.max(s(surface.point((i as f32 + 0.5) / 512.0, (j as f32 + 0.5) / 64.0).1));
                    }
                }
                2.0 * best
            };
            ((sum / (N * N) as f64) as f32, Some(bound * 1.0001))
        };
        Mapped {
            surface,
            to_world,
            stretch,
            s_max,
            area: surface.area() * mean,
        }
    }

    /// A point drawn uniformly by world area, from `(u, v)` and, when a draw is
    /// rejected, numbers hashed from them (deterministic). `None` after 64 rejections
    /// in a row (a chance below 10⁻¹⁹ unless the shape is stretched more than 2:1).
    pub(super) fn point(&self, u: f32, v: f32) -> Option<(Vec3A, Vec3A)> {
        let (mut u, mut v) = (u, v);
        let mut state = ((u.to_bits() as u64) << 32 | v.to_bits() as u64) ^ 0x9e37_79b9_7f4a_7c15;
        for _ in 0..64 {
            let (p, n) = self.surface.point(u, v);
            let accept = match self.s_max {
                None => true,
                Some(max) => {
                    let w = next_unit(&mut state);
                    w * max < (self.stretch * n).length()
                }
            };
            if accept {
                // Normals go to world by M⁻ᵀ (`stretch` is a positive multiple of it).
                return Some((self.to_world.transform_point3a(p), (self.stretch * n).normalize()));
            }
            u = next_unit(&mut state);
            v = next_unit(&mut state);
        }
        None
    }
}

/// A uniform number in [0, 1) from a splitmix64 state.
pub(super) fn next_unit(state: &mut u64) -> f32 {
    *state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^= z >> 31;
    (z >> 40) as f32 / (1u64 << 24) as f32
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Quat, Vec3};

    fn place(scale: Vec3, axis: Vec3, angle: f32, at: Vec3) -> Affine3A {
        Affine3A::from_scale_rotation_translation(scale, Quat::from_axis_angle(axis.normalize(), angle), at)
    }

    /// The object-space parameters (u, v) of `Mapped::point`'s draw that landed at `p`.
    fn parameters(m: &Mapped, p: Vec3A) -> (f32, f32) {
        let q = m.to_world.inverse().transform_point3a(p);
        let turn = |y: f32, x: f32| (y.atan2(x) / std::f32::consts::TAU).rem_euclid(1.0);
        match m.surface {
            ObjectSurface::Sphere => ((1.0 - q.z) / 2.0, turn(q.y, q.x)),
            ObjectSurface::Disk { radius } => ((q.x * q.x + q.y * q.y) / (radius * radius), turn(q.y, q.x)),
            ObjectSurface::Cylinder { zmin, zmax, .. } => (turn(q.y, q.x), (q.z - zmin) / (zmax - zmin)),
            ObjectSurface::Cone { radius, .. } => ((q.x * q.x + q.y * q.y) / (radius * radius), turn(q.y, q.x)),
        }
    }

    #[test]
    fn curved_emitters_are_uniform_by_world_area() {
        // Points drawn on stretched shapes, binned by their object-space parameters on
        // a 16 × 16 grid: each bin must get its share of the world area, the mean of
        // the stretch s over the bin (by an 8 × 8 midpoint rule) times its object area.
        let shapes = [
            Mapped::new(
                ObjectSurface::Sphere,
                place(Vec3::new(1.0, 0.4, 3.0), Vec3::new(1.0, 1.0, 0.0), 0.7, Vec3::ZERO),
            ),
            Mapped::new(
                ObjectSurface::Cylinder {
                    radius: 0.5,
                    zmin: -1.0,
                    zmax: 2.0,
                },
                Affine3A::from_cols(
                    Vec3A::X,
                    Vec3A::new(0.6, 1.0, 0.0),
                    Vec3A::new(0.0, 0.3, 0.5),
                    Vec3A::ZERO,
                ),
            ),
            Mapped::new(
                ObjectSurface::Cone {
                    radius: 0.8,
                    height: 1.2,
                },
                place(Vec3::new(3.0, 1.0, 0.5), Vec3::Z, 0.3, Vec3::ONE),
            ),
        ];
        const B: usize = 16;
        for (k, m) in shapes.iter().enumerate() {
            assert!(m.s_max.is_some(), "shape {k} is stretched unevenly");
            let s = |u: f32, v: f32| (m.stretch * m.surface.point(u, v).1).length() as f64;
            let mut expected = vec![0f64; B * B];
            for (b, e) in expected.iter_mut().enumerate() {
                let (bu, bv) = ((b / B) as f32, (b % B) as f32);
                for i in 0..8 {
                    for j in 0..8 {
                        *e += s(
                            (bu + (i as f32 + 0.5) / 8.0) / B as f32,
                            (bv + (j as f32 + 0.5) / 8.0) / B as f32,
                        );
                    }
                }
            }
            let n = 400_000;
            let total: f64 = expected.iter().sum();
            expected.iter_mut().for_each(|e| *e *= n as f64 / total);
            let mut observed = vec![0f64; B * B];
            for i in 0..n {
                let (u, v) = crate::sampler::Sampler::new(5, i, 0, 0).uniform2();
                let (p, normal) = m.point(u, v).expect("a point within 64 tries");
                let (pu, pv) = parameters(m, p);
                let (bu, bv) = (
                    ((pu * B as f32) as usize).min(B - 1),
                    ((pv * B as f32) as usize).min(B - 1),
                );
                observed[bu * B + bv] += 1.0;
                // The normal is the surface's: perpendicular to the tangents (central
                // differences of the parametrisation, away from the poles and the apex
                // where it has a square root).
                let eps = 1e-3;
                let at = |u: f32, v: f32| m.to_world.transform_point3a(m.surface.point(u, v).0);
                if !(0.05..0.95).contains(&pu) {
                    continue;
                }
                for t in [at(pu + eps, pv) - at(pu - eps, pv), at(pu, pv + eps) - at(pu, pv - eps)] {
                    if t.length() > 1e-4 {
                        assert!(t.normalize().dot(normal).abs() < 1e-2, "shape {k}: {t} {normal}");
                    }
                }
            }
            let r = crate::sampling::chi2::pearson(&observed, &expected).unwrap();
            eprintln!("shape {k}: {r:?}");
            assert!(r.p_value >= crate::sampling::chi2::SIGNIFICANCE, "shape {k}: {r:?}");
        }
    }

    #[test]
    fn mapped_shapes_have_their_world_area() {
        use std::f32::consts::PI;
        // A prolate spheroid with semi-axes 1, 1, 2: 2π(1 + c·asin(e)/e), e² = 1 − 1/c².
        let spheroid = Mapped::new(ObjectSurface::Sphere, Affine3A::from_scale(Vec3::new(1.0, 1.0, 2.0)));
        let e = (1.0f32 - 0.25).sqrt();
        let exact = 2.0 * PI * (1.0 + 2.0 * e.asin() / e);
        assert!(
            (spheroid.area - exact).abs() < 1e-4 * exact,
            "{} {exact}",
            spheroid.area
        );
        // A cylinder squashed into an elliptic one: the ellipse's perimeter (Ramanujan's
        // second formula is exact to 10⁻⁶ here) times the height.
        let elliptic = Mapped::new(
            ObjectSurface::Cylinder {
                radius: 1.0,
                zmin: 0.0,
                zmax: 3.0,
            },
            Affine3A::from_scale(Vec3::new(2.0, 1.0, 1.0)),
        );
        let (a, b) = (2.0f32, 1.0f32);
        let h = ((a - b) / (a + b)).powi(2);
        let perimeter = PI * (a + b) * (1.0 + 3.0 * h / (10.0 + (4.0 - 3.0 * h).sqrt()));
        assert!(
            (elliptic.area - 3.0 * perimeter).abs() < 1e-4 * elliptic.area,
            "{}",
            elliptic.area
        );
        // Under a rotation and a uniform scale no rejection is needed and the area is exact.
        let sphere = Mapped::new(
            ObjectSurface::Sphere,
            place(Vec3::splat(2.0), Vec3::new(1.0, 2.0, 3.0), 0.9, Vec3::ONE),
        );
        assert!(sphere.s_max.is_none());
        assert!((sphere.area - 16.0 * PI).abs() < 1e-4 * sphere.area);
    }
}
