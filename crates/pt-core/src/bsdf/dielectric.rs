//! Smooth dielectric interface (glass, water): Fresnel-weighted specular reflection and
//! refraction, with total internal reflection.
//!
//! Reference: *Physically Based Rendering*, 4th ed., section 9.5 (`DielectricBxDF`, smooth case).
//!
//! | parameter | meaning | range |
//! |---|---|---|
//! | `eta` | relative index of refraction `n_inside / n_outside`; the outside is the side the shading normal points to (1.5 for glass in air, 1/1.33 for an air bubble in water) | finite, `> 0` |
//! | `tint` | transmittance applied to refracted light (Mitsuba's `specular_transmittance`); white is lossless | `[0, 1]` |
//!
//! Two delta lobes. With `F = fresnel_dielectric(cos theta_o, eta)` (exact, unpolarised),
//! `sample` reflects with probability `F` and refracts (Snell's law) with probability `1 - F`, so
//! the throughput is exactly 1 for reflection and `tint` for refraction in
//! [`TransportMode::Importance`]. In [`TransportMode::Radiance`] a refracted sample is further
//! scaled by `1 / etap^2`, `etap = n_t / n_i`, because radiance is compressed into a smaller
//! solid angle when it enters a denser medium (Veach 1997, section 5.2). A ray arriving from
//! inside (`cos theta_o < 0`) sees the ratio inverted; beyond the critical angle `F = 1` (total
//! internal reflection). `eval` and `pdf` are zero.

use glam::{Vec2, Vec3};

use crate::bsdf::fresnel::{fresnel_dielectric, refract};
use crate::bsdf::{Bsdf, BsdfFlags, BsdfSample, TransportMode, clamp_unit};
use crate::color::Rgb;

/// A perfectly smooth dielectric boundary.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SmoothDielectric {
    eta: f32,
    tint: Rgb,
}

/// `eta` made usable: finite and positive, else 1 (an index-matched, invisible boundary).
#[inline]
pub(crate) fn sanitize_eta(eta: f32) -> f32 {
    if eta.is_finite() && eta > 0.0 {
        eta
    } else {
        1.0
    }
}

impl SmoothDielectric {
    /// A smooth boundary with relative IOR `eta` and transmission tint `tint`. An `eta` that is
    /// not finite and positive becomes 1; the tint is clamped to `[0, 1]`. Validate user input
    /// before this point (see [`Glass::new`](crate::material::Glass::new)).
    #[must_use]
    pub fn new(eta: f32, tint: Rgb) -> Self {
        Self {
            eta: sanitize_eta(eta),
            tint: clamp_unit(tint),
        }
    }

    /// Relative index of refraction `n_inside / n_outside`.
    #[must_use]
    pub fn eta(&self) -> f32 {
        self.eta
    }

    /// Transmission tint.
    #[must_use]
    pub fn tint(&self) -> Rgb {
        self.tint
    }
}

impl Bsdf for SmoothDielectric {
    #[inline]
    fn flags(&self) -> BsdfFlags {
        if self.eta == 1.0 {
            BsdfFlags::SPECULAR_TRANSMISSION
        } else {
            BsdfFlags::SPECULAR_REFLECTION | BsdfFlags::SPECULAR_TRANSMISSION
        }
    }

    #[inline]
    fn eval(&self, _wo: Vec3, _wi: Vec3, _mode: TransportMode) -> Rgb {
        Rgb::BLACK
    }

    #[inline]
    fn pdf(&self, _wo: Vec3, _wi: Vec3, _mode: TransportMode) -> f32 {
        0.0
    }

    #[inline]
    fn sample(&self, wo: Vec3, uc: f32, _u: Vec2, mode: TransportMode) -> Option<BsdfSample> {
        sample_smooth(self.eta, self.tint, wo, uc, mode)
    }
}

/// The smooth dielectric's sampling routine, shared with the rough model's smooth limit.
#[inline]
pub(crate) fn sample_smooth(
    eta: f32,
    tint: Rgb,
    wo: Vec3,
    uc: f32,
    mode: TransportMode,
) -> Option<BsdfSample> {
    if wo.z == 0.0 {
        return None;
    }
    let r = fresnel_dielectric(wo.z, eta);
    let t = 1.0 - r;
    if uc < r {
        // Specular reflection, chosen with probability R: weight R / R = 1.
        let wi = Vec3::new(-wo.x, -wo.y, wo.z);
        return Some(BsdfSample {
            wi,
            f: Rgb::splat(r / wi.z.abs()),
            pdf: r,
            flags: BsdfFlags::SPECULAR_REFLECTION,
            eta: 1.0,
        });
    }
    let (wi, etap) = refract(wo, Vec3::Z, eta)?;
    if wi.z == 0.0 || t <= 0.0 {
        return None;
    }
    let mut f = tint * (t / wi.z.abs());
    if mode == TransportMode::Radiance {
        f /= etap * etap;
    }
    Some(BsdfSample {
        wi,
        f,
        pdf: t,
        flags: BsdfFlags::SPECULAR_TRANSMISSION,
        eta: etap,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_incidence_split_and_weights() {
        let g = SmoothDielectric::new(1.5, Rgb::WHITE);
        let wo = Vec3::Z;
        let refl = g
            .sample(wo, 0.01, Vec2::ZERO, TransportMode::Radiance)
            .unwrap();
        assert_eq!(refl.flags, BsdfFlags::SPECULAR_REFLECTION);
        assert!((refl.pdf - 0.04).abs() < 1e-6);
        assert!((refl.f.r * refl.wi.z / refl.pdf - 1.0).abs() < 1e-6);
        let tr = g
            .sample(wo, 0.5, Vec2::ZERO, TransportMode::Radiance)
            .unwrap();
        assert_eq!(tr.flags, BsdfFlags::SPECULAR_TRANSMISSION);
        assert!((tr.wi - -Vec3::Z).length() < 1e-6);
        assert_eq!(tr.eta, 1.5);
        // Radiance mode: (1 - R) / eta^2 per unit of probability (1 - R).
        let w = tr.f.r * tr.wi.z.abs();
        assert!((w - 0.96 / 2.25).abs() < 1e-6, "{w}");
        let ti = g
            .sample(wo, 0.5, Vec2::ZERO, TransportMode::Importance)
            .unwrap();
        assert!((ti.f.r * ti.wi.z.abs() - 0.96).abs() < 1e-6);
    }

    #[test]
    fn total_internal_reflection_from_inside() {
        let g = SmoothDielectric::new(1.5, Rgb::WHITE);
        // 60 degrees from the normal, inside: beyond the 41.8 degree critical angle.
        let wo = Vec3::new(0.866, 0.0, -0.5);
        for uc in [0.0, 0.5, 0.999] {
            let s = g
                .sample(wo, uc, Vec2::ZERO, TransportMode::Radiance)
                .unwrap();
            assert_eq!(s.flags, BsdfFlags::SPECULAR_REFLECTION);
            assert_eq!(s.pdf, 1.0);
        }
    }

    #[test]
    fn invalid_eta_is_index_matched() {
        for eta in [f32::NAN, -1.0, 0.0, f32::INFINITY] {
            let g = SmoothDielectric::new(eta, Rgb::WHITE);
            assert_eq!(g.eta(), 1.0);
            let wo = Vec3::new(0.6, 0.0, 0.8);
            let s = g
                .sample(wo, 0.5, Vec2::ZERO, TransportMode::Radiance)
                .unwrap();
            assert!((s.wi + wo).length() < 1e-6, "passes straight through");
        }
    }
}
