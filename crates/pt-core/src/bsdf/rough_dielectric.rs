//! Rough dielectric interface (frosted glass): GGX microfacet reflection and transmission.
//!
//! References: B. Walter, S. Marschner, H. Li, K. Torrance, "Microfacet Models for Refraction
//! through Rough Surfaces", EGSR 2007; *Physically Based Rendering*, 4th ed., section 9.7.
//!
//! | parameter | meaning | range |
//! |---|---|---|
//! | `distribution` | GGX widths `alpha_x`, `alpha_y` (`alpha = roughness^2`) | `[0, 1]` each |
//! | `eta` | relative IOR `n_inside / n_outside` (outside: the side the normal points to) | finite, `> 0` |
//! | `tint` | transmittance applied to refracted light | `[0, 1]` |
//!
//! A microfacet normal `wm` is drawn from the visible normals seen from `wo`; the sample reflects
//! about `wm` with probability `F(wo . wm)` and refracts through it otherwise. With the
//! generalized half vector `wm ~ etap wi + wo` (Walter's eq. 16):
//!
//! - reflection: `f = D G F / (4 |cos_o cos_i|)`, `pdf = D_wo(wm) / (4 |wo . wm|) F`;
//! - transmission: `f = D G (1 - F) |wi . wm| |wo . wm| / (|cos_o cos_i| (wi . wm + wo . wm / etap)^2)`,
//!   divided by `etap^2` in [`TransportMode::Radiance`], and
//!   `pdf = D_wo(wm) |wi . wm| / (wi . wm + wo . wm / etap)^2 (1 - F)`.
//!
//! Microfacets that face away from either direction contribute nothing. Below
//! [`SMOOTH_ALPHA`](super::microfacet::SMOOTH_ALPHA), or for `eta = 1`, the model is the
//! [`SmoothDielectric`](super::SmoothDielectric). Like every single-scattering microfacet model it
//! loses the energy of inter-reflections between microfacets.

use glam::{Vec2, Vec3};

use crate::bsdf::ThinFilm;
use crate::bsdf::dielectric::{interface_fresnel, sample_smooth, sanitize_eta};
use crate::bsdf::fresnel::{reflect, refract};
use crate::bsdf::microfacet::TrowbridgeReitz;
use crate::bsdf::{Bsdf, BsdfFlags, BsdfSample, TransportMode, clamp_unit, same_hemisphere};
use crate::color::Rgb;

/// A rough dielectric boundary.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoughDielectric {
    distribution: TrowbridgeReitz,
    eta: f32,
    tint: Rgb,
    film: Option<ThinFilm>,
}

impl RoughDielectric {
    /// A rough boundary. An `eta` that is not finite and positive becomes 1; the tint is clamped
    /// to `[0, 1]`.
    #[must_use]
    pub fn new(distribution: TrowbridgeReitz, eta: f32, tint: Rgb) -> Self {
        Self {
            distribution,
            eta: sanitize_eta(eta),
            tint: clamp_unit(tint),
            film: None,
        }
    }

    /// The same interface under a thin film ([`ThinFilm`]: iridescent frosted glass): each
    /// microfacet reflects the film's reflectance per channel and transmits the rest;
    /// reflection is sampled with the probability of its mean.
    #[must_use]
    pub fn with_film(mut self, film: ThinFilm) -> Self {
        self.film = Some(film);
        self
    }

    /// The microfacet's reflectance per channel at cosine `cos` (signed, to `wm`), and the
    /// probability of sampling reflection there ([`interface_fresnel`]).
    #[inline]
    fn fresnel(&self, cos: f32) -> (Rgb, f32) {
        interface_fresnel(self.film.as_ref(), cos, self.eta)
    }

    /// The microfacet distribution.
    #[must_use]
    pub fn distribution(&self) -> TrowbridgeReitz {
        self.distribution
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

    #[inline]
    fn is_smooth(&self) -> bool {
        self.eta == 1.0 || self.distribution.effectively_smooth()
    }

    /// The generalized half vector of a pair, facing up, with `etap` for a transmission pair;
    /// `None` when it is undefined or a microfacet faces away from either direction.
    #[inline]
    fn half_vector(&self, wo: Vec3, wi: Vec3) -> Option<(Vec3, f32, bool)> {
        let (cos_o, cos_i) = (wo.z, wi.z);
        if cos_o == 0.0 || cos_i == 0.0 {
            return None;
        }
        let reflect = cos_o * cos_i > 0.0;
        let etap = if reflect {
            1.0
        } else if cos_o > 0.0 {
            self.eta
        } else {
            1.0 / self.eta
        };
        let wm = wi * etap + wo;
        if wm.length_squared() == 0.0 {
            return None;
        }
        let mut wm = wm.normalize();
        if wm.z < 0.0 {
            wm = -wm;
        }
        if wm.dot(wi) * cos_i < 0.0 || wm.dot(wo) * cos_o < 0.0 {
            return None;
        }
        Some((wm, etap, reflect))
    }
}

impl Bsdf for RoughDielectric {
    #[inline]
    fn flags(&self) -> BsdfFlags {
        if self.eta == 1.0 {
            BsdfFlags::SPECULAR_TRANSMISSION
        } else if self.distribution.effectively_smooth() {
            BsdfFlags::SPECULAR_REFLECTION | BsdfFlags::SPECULAR_TRANSMISSION
        } else {
            BsdfFlags::GLOSSY_REFLECTION | BsdfFlags::GLOSSY_TRANSMISSION
        }
    }

    #[inline]
    fn eval(&self, wo: Vec3, wi: Vec3, mode: TransportMode) -> Rgb {
        if self.is_smooth() {
            return Rgb::BLACK;
        }
        let Some((wm, etap, reflect)) = self.half_vector(wo, wi) else {
            return Rgb::BLACK;
        };
        let d = &self.distribution;
        let (f, _) = self.fresnel(wo.dot(wm));
        if reflect {
            return f * (d.d(wm) * d.g(wo, wi) / (4.0 * wo.z * wi.z).abs());
        }
        let denom = sqr(wi.dot(wm) + wo.dot(wm) / etap) * wi.z * wo.z;
        let mut ft = d.d(wm) * d.g(wo, wi) * (wi.dot(wm) * wo.dot(wm) / denom).abs();
        if mode == TransportMode::Radiance {
            ft /= etap * etap;
        }
        self.tint * (Rgb::WHITE - f) * ft
    }

    #[inline]
    fn pdf(&self, wo: Vec3, wi: Vec3, _mode: TransportMode) -> f32 {
        if self.is_smooth() {
            return 0.0;
        }
        let Some((wm, etap, reflect)) = self.half_vector(wo, wi) else {
            return 0.0;
        };
        let d = &self.distribution;
        let (_, r) = self.fresnel(wo.dot(wm));
        if reflect {
            d.pdf(wo, wm) / (4.0 * wo.dot(wm).abs()) * r
        } else {
            let denom = sqr(wi.dot(wm) + wo.dot(wm) / etap);
            d.pdf(wo, wm) * wi.dot(wm).abs() / denom * (1.0 - r)
        }
    }

    #[inline]
    fn sample(&self, wo: Vec3, uc: f32, u: Vec2, mode: TransportMode) -> Option<BsdfSample> {
        if self.is_smooth() {
            return sample_smooth(self.eta, self.tint, self.film.as_ref(), wo, uc, mode);
        }
        if wo.z == 0.0 {
            return None;
        }
        let d = &self.distribution;
        let wm = d.sample_wm(wo, u);
        let (fr, r) = self.fresnel(wo.dot(wm));
        if uc < r {
            let wi = reflect(wo, wm);
            if !same_hemisphere(wo, wi) {
                return None;
            }
            let pdf = d.pdf(wo, wm) / (4.0 * wo.dot(wm).abs()) * r;
            let f = fr * (d.d(wm) * d.g(wo, wi) / (4.0 * wo.z * wi.z).abs());
            if !(pdf.is_finite() && pdf > 0.0) {
                return None;
            }
            return Some(BsdfSample {
                wi,
                f,
                pdf,
                flags: BsdfFlags::GLOSSY_REFLECTION,
                eta: 1.0,
            });
        }
        let (wi, etap) = refract(wo, wm, self.eta)?;
        if same_hemisphere(wo, wi) || wi.z == 0.0 {
            return None;
        }
        let t = 1.0 - r;
        let denom = sqr(wi.dot(wm) + wo.dot(wm) / etap);
        let pdf = d.pdf(wo, wm) * wi.dot(wm).abs() / denom * t;
        if !(pdf.is_finite() && pdf > 0.0) {
            return None;
        }
        let mut ft =
            d.d(wm) * d.g(wo, wi) * (wi.dot(wm) * wo.dot(wm) / (denom * wi.z * wo.z)).abs();
        if mode == TransportMode::Radiance {
            ft /= etap * etap;
        }
        Some(BsdfSample {
            wi,
            f: self.tint * (Rgb::WHITE - fr) * ft,
            pdf,
            flags: BsdfFlags::GLOSSY_TRANSMISSION,
            eta: etap,
        })
    }
}

#[inline]
fn sqr(x: f32) -> f32 {
    x * x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sample_matches_eval_and_pdf() {
        let b = RoughDielectric::new(TrowbridgeReitz::isotropic(0.3), 1.5, Rgb::WHITE);
        let mut n_refl = 0;
        let mut n_tr = 0;
        for wo in [
            Vec3::new(0.3, 0.2, 0.9).normalize(),
            Vec3::new(0.3, 0.2, -0.9).normalize(),
        ] {
            for i in 0..64 {
                let uc = (i as f32 + 0.5) / 64.0;
                let u = Vec2::new(
                    (i * 7 % 64) as f32 / 64.0 + 0.01,
                    (i * 13 % 64) as f32 / 64.0,
                );
                let Some(s) = b.sample(wo, uc, u, TransportMode::Radiance) else {
                    continue;
                };
                if s.is_transmission() {
                    n_tr += 1;
                } else {
                    n_refl += 1;
                }
                let f = b.eval(wo, s.wi, TransportMode::Radiance);
                let pdf = b.pdf(wo, s.wi, TransportMode::Radiance);
                assert!(
                    (f - s.f).max_component().abs() <= 1e-3 * f.max_component(),
                    "{f:?} vs {:?}",
                    s.f
                );
                assert!((pdf - s.pdf).abs() <= 1e-3 * pdf, "{pdf} vs {}", s.pdf);
            }
        }
        assert!(n_refl > 0 && n_tr > 0);
    }

    #[test]
    fn smooth_limit_delegates() {
        let b = RoughDielectric::new(TrowbridgeReitz::isotropic(0.0), 1.5, Rgb::WHITE);
        assert!(b.flags().is_specular());
        let s = b
            .sample(Vec3::Z, 0.5, Vec2::splat(0.5), TransportMode::Radiance)
            .unwrap();
        assert_eq!(s.flags, BsdfFlags::SPECULAR_TRANSMISSION);
    }
}
