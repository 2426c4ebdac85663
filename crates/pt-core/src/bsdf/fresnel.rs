//! Fresnel reflectance and the geometry of specular reflection and refraction.
//!
//! Reference: *Physically Based Rendering*, 4th ed., section 9.3 (`FrDielectric`, `FrComplex`,
//! `Refract`). All functions work in the local shading frame or with an explicit normal, and
//! take the **relative** index of refraction `eta = n_inside / n_outside`, where "outside" is the
//! side the normal points to.

use glam::Vec3;

use crate::color::Rgb;

/// Unpolarised Fresnel reflectance of a dielectric interface.
///
/// `cos_i` is the cosine between the incident direction and the normal: positive when the
/// direction is on the normal's side (outside), negative from inside, where the interface is seen
/// with the inverse ratio `1 / eta`. Returns 1 beyond the critical angle (total internal
/// reflection). At normal incidence the value is `((eta - 1) / (eta + 1))^2`.
#[inline]
#[must_use]
pub fn fresnel_dielectric(cos_i: f32, eta: f32) -> f32 {
    let mut cos_i = cos_i.clamp(-1.0, 1.0);
    let mut eta = eta;
    if cos_i < 0.0 {
        eta = 1.0 / eta;
        cos_i = -cos_i;
    }
    let sin2_i = (1.0 - cos_i * cos_i).max(0.0);
    let sin2_t = sin2_i / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
    let r_parl = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    0.5 * (r_parl * r_parl + r_perp * r_perp)
}

/// A complex number, just enough for the conductor Fresnel equations.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Complex {
    re: f32,
    im: f32,
}

impl Complex {
    const fn new(re: f32, im: f32) -> Self {
        Self { re, im }
    }
    fn add(self, o: Self) -> Self {
        Self::new(self.re + o.re, self.im + o.im)
    }
    fn sub(self, o: Self) -> Self {
        Self::new(self.re - o.re, self.im - o.im)
    }
    fn mul(self, o: Self) -> Self {
        Self::new(
            self.re * o.re - self.im * o.im,
            self.re * o.im + self.im * o.re,
        )
    }
    fn scale(self, s: f32) -> Self {
        Self::new(self.re * s, self.im * s)
    }
    fn div(self, o: Self) -> Self {
        let d = o.re * o.re + o.im * o.im;
        Self::new(
            (self.re * o.re + self.im * o.im) / d,
            (self.im * o.re - self.re * o.im) / d,
        )
    }
    fn norm(self) -> f32 {
        self.re * self.re + self.im * self.im
    }
    /// Principal square root.
    fn sqrt(self) -> Self {
        let n = self.norm().sqrt();
        if n == 0.0 {
            return Self::new(0.0, 0.0);
        }
        let t1 = (0.5 * (n + self.re.abs())).sqrt();
        let t2 = 0.5 * self.im / t1;
        if self.re >= 0.0 {
            Self::new(t1, t2)
        } else {
            Self::new(t2.abs(), t1.copysign(self.im))
        }
    }
}

/// Unpolarised Fresnel reflectance of a conductor with complex index of refraction `eta + i k`
/// (relative to the outside medium), for `cos_i` in `[0, 1]` (clamped).
#[inline]
#[must_use]
pub fn fresnel_conductor_channel(cos_i: f32, eta: f32, k: f32) -> f32 {
    let cos_i = cos_i.clamp(0.0, 1.0);
    let eta = Complex::new(eta, k);
    let sin2_i = 1.0 - cos_i * cos_i;
    let sin2_t = Complex::new(sin2_i, 0.0).div(eta.mul(eta));
    let cos_t = Complex::new(1.0, 0.0).sub(sin2_t).sqrt();
    let ci = Complex::new(cos_i, 0.0);
    let eta_ci = eta.scale(cos_i);
    let r_parl = eta_ci.sub(cos_t).div(eta_ci.add(cos_t));
    let eta_ct = eta.mul(cos_t);
    let r_perp = ci.sub(eta_ct).div(ci.add(eta_ct));
    0.5 * (r_parl.norm() + r_perp.norm())
}

/// [`fresnel_conductor_channel`] for each RGB channel.
#[inline]
#[must_use]
pub fn fresnel_conductor(cos_i: f32, eta: Rgb, k: Rgb) -> Rgb {
    Rgb::new(
        fresnel_conductor_channel(cos_i, eta.r, k.r),
        fresnel_conductor_channel(cos_i, eta.g, k.g),
        fresnel_conductor_channel(cos_i, eta.b, k.b),
    )
}

/// Schlick's approximation `F0 + (1 - F0)(1 - cos)^5`, for `cos_i` in `[0, 1]` (clamped).
#[inline]
#[must_use]
pub fn fresnel_schlick(cos_i: f32, f0: Rgb) -> Rgb {
    let m = 1.0 - cos_i.clamp(0.0, 1.0);
    let m5 = (m * m) * (m * m) * m;
    f0 + (Rgb::WHITE - f0) * m5
}

/// Mirror reflection of `w` about the unit normal `n` (both pointing away from the surface).
#[inline]
#[must_use]
pub fn reflect(w: Vec3, n: Vec3) -> Vec3 {
    -w + n * (2.0 * w.dot(n))
}

/// Refraction of `wi` (pointing away from the surface) through an interface with unit normal `n`
/// and relative index `eta = n_inside / n_outside` (inside is opposite to `n`).
///
/// Returns the transmitted direction (unit, pointing away on the other side) and the ratio
/// `etap = n_t / n_i` actually used (`eta` from outside, `1 / eta` from inside), or `None` under
/// total internal reflection.
#[inline]
#[must_use]
pub fn refract(wi: Vec3, n: Vec3, eta: f32) -> Option<(Vec3, f32)> {
    let mut cos_i = n.dot(wi);
    let mut eta = eta;
    let mut n = n;
    if cos_i < 0.0 {
        eta = 1.0 / eta;
        cos_i = -cos_i;
        n = -n;
    }
    let sin2_i = (1.0 - cos_i * cos_i).max(0.0);
    let sin2_t = sin2_i / (eta * eta);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let wt = -wi / eta + n * (cos_i / eta - cos_t);
    Some((wt, eta))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dielectric_normal_incidence_and_tir() {
        for eta in [1.05f32, 1.33, 1.5, 2.5] {
            let r0 = ((eta - 1.0) / (eta + 1.0)).powi(2);
            assert!((fresnel_dielectric(1.0, eta) - r0).abs() < 1e-6);
            // From inside at normal incidence the reflectance is the same.
            assert!((fresnel_dielectric(-1.0, eta) - r0).abs() < 1e-6);
            // Beyond the critical angle seen from inside: total internal reflection.
            let critical = (1.0 / eta).asin();
            let beyond = (critical + 0.01).cos();
            assert_eq!(fresnel_dielectric(-beyond, eta), 1.0);
            let before = (critical - 0.01).cos();
            assert!(fresnel_dielectric(-before, eta) < 1.0);
            // Grazing incidence from outside reflects everything.
            assert!(fresnel_dielectric(1e-6, eta) > 0.999);
        }
        assert_eq!(fresnel_dielectric(0.7, 1.0), 0.0);
    }

    #[test]
    fn conductor_reduces_to_dielectric_for_zero_k() {
        for cos in [0.05f32, 0.3, 0.7, 1.0] {
            let a = fresnel_conductor_channel(cos, 1.5, 0.0);
            let b = fresnel_dielectric(cos, 1.5);
            assert!((a - b).abs() < 1e-5, "{a} vs {b}");
        }
        // Gold-like values reflect strongly and reach 1 at grazing incidence.
        let f = fresnel_conductor_channel(1.0, 0.143, 3.983);
        assert!(f > 0.9 && f < 1.0);
        assert!(fresnel_conductor_channel(0.0, 0.143, 3.983) > 0.999);
    }

    #[test]
    fn refraction_obeys_snell() {
        let eta = 1.5f32;
        let wi = Vec3::new(0.6, 0.0, 0.8);
        let (wt, etap) = refract(wi, Vec3::Z, eta).unwrap();
        assert_eq!(etap, eta);
        assert!((wt.length() - 1.0).abs() < 1e-6);
        assert!(wt.z < 0.0 && wt.x < 0.0);
        // n_i sin_i = n_t sin_t
        assert!((0.6 - eta * wt.x.abs()).abs() < 1e-6);
        // Back through the interface from inside returns the original direction.
        let (back, etap2) = refract(wt, Vec3::Z, eta).unwrap();
        assert!((etap2 - 1.0 / eta).abs() < 1e-7);
        assert!((back - wi).length() < 1e-6);
        // Total internal reflection from inside at a steep angle.
        assert!(refract(Vec3::new(0.9, 0.0, -0.436), Vec3::Z, eta).is_none());
    }

    #[test]
    fn schlick_endpoints() {
        let f0 = Rgb::new(0.9, 0.5, 0.1);
        assert_eq!(fresnel_schlick(1.0, f0), f0);
        assert_eq!(fresnel_schlick(0.0, f0), Rgb::WHITE);
    }
}
