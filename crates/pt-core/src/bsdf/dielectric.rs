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
use crate::bsdf::{Bsdf, BsdfFlags, BsdfSample, SampleInputs, ThinFilm, TransportMode, clamp_unit};
use crate::color::Rgb;

/// A perfectly smooth dielectric boundary.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SmoothDielectric {
    eta: f32,
    tint: Rgb,
    film: Option<ThinFilm>,
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
            film: None,
        }
    }

    /// The same boundary under a thin film ([`ThinFilm`]: iridescent glass): reflection is
    /// chosen with the probability of the film's mean reflectance and weighted per channel.
    #[must_use]
    pub fn with_film(mut self, film: ThinFilm) -> Self {
        self.film = Some(film);
        self
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
    fn sample_inputs(&self) -> SampleInputs {
        SampleInputs::LOBE
    }

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
        sample_smooth(self.eta, self.tint, self.film.as_ref(), wo, uc, mode)
    }
}

/// The interface's reflectance per channel for light meeting it at cosine `cos` (signed) with
/// relative IOR `eta`, under `film` if any, and the probability of sampling reflection: the bare
/// Fresnel `F` (then the reflectance is `F` in every channel), else the mean of the film's.
#[inline]
pub(crate) fn interface_fresnel(film: Option<&ThinFilm>, cos: f32, eta: f32) -> (Rgb, f32) {
    match film {
        None => {
            let f = fresnel_dielectric(cos, eta);
            (Rgb::splat(f), f)
        }
        Some(film) => {
            let r = film.reflectance(cos, eta);
            (r, ((r.r + r.g + r.b) / 3.0).clamp(0.0, 1.0))
        }
    }
}

/// The smooth dielectric's sampling routine, shared with the rough model's smooth limit:
/// reflection chosen with probability `p` ([`interface_fresnel`]), weighted by `R / p`, and
/// transmission by `(1 - R) / (1 - p)`, so each channel's expected throughput is its own `R`
/// and `1 - R` (exactly 1 and `tint` without a film).
#[inline]
pub(crate) fn sample_smooth(
    eta: f32,
    tint: Rgb,
    film: Option<&ThinFilm>,
    wo: Vec3,
    uc: f32,
    mode: TransportMode,
) -> Option<BsdfSample> {
    if wo.z == 0.0 {
        return None;
    }
    let (r, p) = interface_fresnel(film, wo.z, eta);
    if uc < p {
        let wi = Vec3::new(-wo.x, -wo.y, wo.z);
        return Some(BsdfSample {
            wi,
            f: r / wi.z.abs(),
            pdf: p,
            flags: BsdfFlags::SPECULAR_REFLECTION,
            eta: 1.0,
        });
    }
    let (wi, etap) = refract(wo, Vec3::Z, eta)?;
    if wi.z == 0.0 || p >= 1.0 {
        return None;
    }
    let mut f = tint * (Rgb::WHITE - r) / wi.z.abs();
    if mode == TransportMode::Radiance {
        f /= etap * etap;
    }
    Some(BsdfSample {
        wi,
        f,
        pdf: 1.0 - p,
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

    /// A film on glass: per channel, what is reflected and what is transmitted (importance
    /// mode, untinted) sum to 1, the reflection varies with colour, and the reflectance from
    /// inside equals the outside's for the direction Snell's law pairs with it.
    #[test]
    fn a_film_keeps_each_channel_lossless_and_reciprocal() {
        let film = ThinFilm::new(1.0, 1.8, 400.0);
        let g = SmoothDielectric::new(1.5, Rgb::WHITE).with_film(film);
        for cos in [1.0f32, 0.7, 0.3] {
            let wo = Vec3::new((1.0 - cos * cos).sqrt(), 0.0, cos);
            let mut sum = Rgb::BLACK;
            let n = 4000;
            for i in 0..n {
                let uc = (i as f32 + 0.5) / n as f32;
                let s = g
                    .sample(wo, uc, Vec2::ZERO, TransportMode::Importance)
                    .unwrap();
                sum += s.f * (s.wi.z.abs() / s.pdf) / n as f32;
            }
            assert!(
                (sum - Rgb::WHITE).max_component().abs() < 1e-3,
                "{cos}: {sum:?}"
            );
            assert!(
                (sum.r.min(sum.g).min(sum.b) - 1.0).abs() < 1e-3,
                "{cos}: {sum:?}"
            );
            let r = film.reflectance(cos, 1.5);
            assert!(r.max_component() - r.r.min(r.g).min(r.b) > 0.01, "{r:?}");
            // From inside, along the refracted direction.
            let sin_in = (1.0 - cos * cos).sqrt() / 1.5;
            let r_in = film.reflectance(-(1.0 - sin_in * sin_in).sqrt(), 1.5);
            assert!((r_in - r).max_component().abs() < 1e-4, "{r_in:?} {r:?}");
        }
        // Without weight, the bare interface.
        let none = ThinFilm::new(0.0, 1.8, 400.0).reflectance(0.6, 1.5);
        assert_eq!(
            none,
            Rgb::splat(crate::bsdf::fresnel::fresnel_dielectric(0.6, 1.5))
        );
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
