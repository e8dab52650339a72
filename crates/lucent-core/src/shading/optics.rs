//! Mirror reflection, refraction by Snell's law, the Fresnel reflectance of a dielectric,
//! and directions drawn from a Phong lobe (glossy reflection).

use crate::math::Vec3A;

/// The mirror image of direction `d` about the normal `n` (unit).
#[inline]
pub fn reflect(d: Vec3A, n: Vec3A) -> Vec3A {
    d - n * (2.0 * d.dot(n))
}

/// The direction of `d` (unit) refracted through a surface with unit normal `n` on the
/// side `d` comes from (`d·n < 0`), `eta` = n_incident / n_transmitted (Snell's law
/// `sin θt = eta · sin θi`); `None` beyond the critical angle (total internal reflection).
#[inline]
pub fn refract(d: Vec3A, n: Vec3A, eta: f32) -> Option<Vec3A> {
    let cos_i = -d.dot(n);
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i).max(0.0);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some((d * eta + n * (eta * cos_i - cos_t)).normalize())
}

/// The fraction of light a smooth dielectric interface reflects (unpolarised: the mean of
/// the s and p Fresnel equations), for light arriving at `cos_i` (> 0) from the medium of
/// index `n_i` onto the medium of index `n_t`. 1 beyond the critical angle.
pub fn fresnel_dielectric(cos_i: f32, n_i: f32, n_t: f32) -> f32 {
    let cos_i = cos_i.clamp(0.0, 1.0);
    let sin_t = n_i / n_t * (1.0 - cos_i * cos_i).max(0.0).sqrt();
    if sin_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin_t * sin_t).max(0.0).sqrt();
    let r_s = (n_i * cos_i - n_t * cos_t) / (n_i * cos_i + n_t * cos_t);
    let r_p = (n_t * cos_i - n_i * cos_t) / (n_t * cos_i + n_i * cos_t);
    0.5 * (r_s * r_s + r_p * r_p)
}

/// `w` (unit) if it leaves at least `height` (a cosine) above the surface whose unit
/// normal on the wanted side is `side`; otherwise `w` turned toward `side`, in the plane
/// of the two, until it leaves at exactly `height`. A smooth-shaded or bump-mapped normal
/// can mirror or refract a ray into the true surface it leaves; turning it back just
/// past the surface keeps the ray's direction as close as possible (the remedy of
/// Cycles' `ensure_valid_reflection`) instead of sending it into the object.
#[inline]
pub fn lift_above(w: Vec3A, side: Vec3A, height: f32) -> Vec3A {
    let c = w.dot(side);
    if c >= height {
        return w;
    }
    let along = w - side * c;
    let len = along.length();
    if !(len > 0.0) {
        return side;
    }
    (along * ((1.0 - height * height).max(0.0).sqrt() / len) + side * height).normalize()
}

/// `ng` or `-ng`: the side of the true surface (unit normal `ng`) that `wo` (unit, away
/// from the surface) is on.
#[inline]
pub fn side_of(wo: Vec3A, ng: Vec3A) -> Vec3A {
    if wo.dot(ng) >= 0.0 {
        ng
    } else {
        -ng
    }
}

/// The mirror direction of the viewer direction `wo` (unit, away from the surface) about
/// the shading normal `n`, kept on the viewer's side `viewer` of the true surface
/// ([`lift_above`]: just above it, or closer for a grazing view).
#[inline]
pub fn reflect_above(wo: Vec3A, n: Vec3A, viewer: Vec3A) -> Vec3A {
    lift_above(reflect(-wo, n).normalize(), viewer, (0.9 * wo.dot(viewer)).min(0.01))
}

/// A direction drawn around the unit axis `r` with density ∝ `cos^exponent` of the angle
/// to it (the Phong lobe), from two uniform numbers.
pub fn phong_lobe(r: Vec3A, exponent: f32, u: f32, v: f32) -> Vec3A {
    let cos_t = u.powf(1.0 / (exponent + 1.0));
    let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
    let phi = 2.0 * std::f32::consts::PI * v;
    // An orthonormal frame around r (Duff et al. 2017).
    let sign = 1.0f32.copysign(r.z);
    let a = -1.0 / (sign + r.z);
    let b = r.x * r.y * a;
    let t1 = Vec3A::new(1.0 + sign * r.x * r.x * a, sign * b, -sign * r.x);
    let t2 = Vec3A::new(b, sign + r.y * r.y * a, -r.y);
    (t1 * (sin_t * phi.cos()) + t2 * (sin_t * phi.sin()) + r * cos_t).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lifted_directions_keep_their_azimuth_and_leave_at_the_height_asked() {
        let side = Vec3A::new(0.0, 0.0, 1.0);
        // Already high enough: unchanged.
        let w = Vec3A::new(0.6, 0.0, 0.8);
        assert_eq!(lift_above(w, side, 0.01), w);
        // Below the surface: turned up to height 0.01, same azimuth.
        let w = Vec3A::new(0.6, 0.48, -0.64).normalize();
        let l = lift_above(w, side, 0.01);
        assert!((l.length() - 1.0).abs() < 1e-6 && (l.z - 0.01).abs() < 1e-6, "{l}");
        assert!((l.y / l.x - 0.8).abs() < 1e-5, "{l}");
        // Straight down: nothing to keep, straight up.
        assert_eq!(lift_above(-side, side, 0.01), side);
    }

    #[test]
    fn fresnel_at_normal_incidence_on_glass_is_four_percent() {
        // ((n − 1) / (n + 1))² = (0.5 / 2.5)² = 0.04, from either side.
        assert!((fresnel_dielectric(1.0, 1.0, 1.5) - 0.04).abs() < 1e-6);
        assert!((fresnel_dielectric(1.0, 1.5, 1.0) - 0.04).abs() < 1e-6);
        // Grazing incidence reflects everything.
        assert!(fresnel_dielectric(1e-4, 1.0, 1.5) > 0.99);
    }

    #[test]
    fn beyond_the_critical_angle_everything_is_reflected() {
        // Glass to air: critical angle asin(1/1.5) ≈ 41.8°.
        let critical = (1.0f32 / 1.5).asin();
        for deg in [42.0f32, 50.0, 70.0, 89.0] {
            let a = deg.to_radians();
            assert!(a > critical);
            assert_eq!(fresnel_dielectric(a.cos(), 1.5, 1.0), 1.0);
            let d = Vec3A::new(a.sin(), -a.cos(), 0.0);
            assert!(refract(d, Vec3A::Y, 1.5).is_none());
        }
        let a = 40.0f32.to_radians();
        assert!(fresnel_dielectric(a.cos(), 1.5, 1.0) < 1.0);
        assert!(refract(Vec3A::new(a.sin(), -a.cos(), 0.0), Vec3A::Y, 1.5).is_some());
    }

    #[test]
    fn snells_law_holds_and_a_slab_leaves_rays_parallel() {
        let n = Vec3A::Y;
        for deg in [0.0f32, 10.0, 30.0, 60.0, 85.0] {
            let a = deg.to_radians();
            let d = Vec3A::new(a.sin(), -a.cos(), 0.0);
            // Into glass through the top face…
            let t = refract(d, n, 1.0 / 1.5).unwrap();
            assert!((t.x - d.x / 1.5).abs() < 1e-6, "sin θt = sin θi / 1.5");
            assert!((t.length() - 1.0).abs() < 1e-6 && t.y < 0.0);
            // …and out through the parallel bottom face (its outward normal is −y; the
            // normal on the side t comes from is +y).
            let out = refract(t, n, 1.5).unwrap();
            assert!((out - d).length() < 1e-5, "{out} vs {d}");
        }
    }

    #[test]
    fn mirror_reflection_and_the_phong_lobe() {
        let d = Vec3A::new(1.0, -1.0, 0.0).normalize();
        assert!((reflect(d, Vec3A::Y) - Vec3A::new(1.0, 1.0, 0.0).normalize()).length() < 1e-6);
        // A lobe of exponent e has mean cosine (e + 1) / (e + 2) around its axis.
        let r = Vec3A::new(0.3, 0.5, -0.8).normalize();
        let e = 20.0;
        let mut mean = 0.0;
        let n = 64;
        for i in 0..n {
            for j in 0..n {
                let s = phong_lobe(r, e, (i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                assert!((s.length() - 1.0).abs() < 1e-5);
                mean += s.dot(r);
            }
        }
        mean /= (n * n) as f32;
        assert!((mean - (e + 1.0) / (e + 2.0)).abs() < 1e-3, "{mean}");
    }
}
