//! The metallic-roughness model of glTF 2.0 (the specification's Appendix B, "BRDF
//! Implementation"): a metal and a dielectric mixed by `metallic`.
//!
//! - metal: `specular * (base + (1 - base) (1 - |v.h|)^5)` (Schlick's Fresnel with `F0` = the
//!   base colour);
//! - dielectric: the specification's `fresnel_mix(diffuse, specular)`, a specular coating `F
//!   specular` with `F = F0 + (1 - F0) (1 - |v.h|)^5` and `F0 = ((ior - 1) / (ior + 1))^2` (0.04
//!   for 1.5), over a diffuse base `base / pi` weighted by what the coating lets through both
//!   ways, `(1 - F(n.v)) (1 - F(n.l))`. The specification weights the base by `1 - F(v.h)`
//!   instead, which is not reciprocal and reflects more than it receives near grazing angles
//!   (directional albedo 1.36 for a rough white-ish dielectric at 84 degrees, 1.6 at 88,
//!   measured by pt's energy check); the coupled weights keep the look (a 4% coating over the
//!   base colour) and conserve energy;
//! - `specular = D G / (4 |n.l| |n.v|)`: Trowbridge-Reitz (GGX) with `alpha = roughness^2`,
//!   Smith's height-correlated shadowing.
//!
//! `f = (1 - metallic) dielectric + metallic metal`, reflection only (both faces act alike).
//! Sampled as a mixture: the specular lobe by visible normals (Heitz 2018) with probability
//! `p = w_s / (w_s + w_d)`, `w_s = metallic + (1 - metallic) F(n.v)`, `w_d = (1 - metallic)
//! (1 - F(n.v)) luminance(base)`, a cosine-weighted direction otherwise; the density is the
//! mixture's, `p pdf_spec + (1 - p) cos/pi`, so every sample weighs `f cos / pdf` exactly.
//!
//! | parameter | meaning |
//! |---|---|
//! | `base_color` | linear RGB in `[0, 1]` (clamped) |
//! | `metallic` | `[0, 1]` (clamped) |
//! | `roughness` | perceptual, `[0, 1]`; `alpha = roughness^2`, at least `SMOOTH_ALPHA` (a mirror-smooth glTF surface is a very sharp glossy lobe, not a delta, so that its diffuse part keeps next-event estimation) |
//! | `ior` | of the dielectric, for `F0` (glTF's default 1.5; `KHR_materials_ior`) |
//!
//! The model is reciprocal (`|v.h| = |l.h|`), and its directional albedo is below 1: the GGX lobe
//! loses the energy of multiple scattering at high roughness, as in the specification.

use std::f32::consts::FRAC_1_PI;

use glam::{Vec2, Vec3};

use crate::bsdf::fresnel::reflect;
use crate::bsdf::microfacet::{SMOOTH_ALPHA, TrowbridgeReitz, roughness_to_alpha};
use crate::bsdf::{Bsdf, BsdfFlags, BsdfSample, TransportMode, same_hemisphere};
use crate::color::Rgb;
use crate::sampling::sample_cosine_hemisphere;

/// glTF's metallic-roughness BRDF. See the module documentation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MetallicRoughness {
    base_color: Rgb,
    metallic: f32,
    distribution: TrowbridgeReitz,
    /// The dielectric's reflectance at normal incidence.
    f0: f32,
}

/// `(1 - c)^5`, Schlick's weight.
#[inline]
fn schlick_weight(c: f32) -> f32 {
    let m = (1.0 - c).clamp(0.0, 1.0);
    let m2 = m * m;
    m2 * m2 * m
}

/// `w` in the upper hemisphere (both faces reflect alike).
#[inline]
fn upper(w: Vec3) -> Vec3 {
    Vec3::new(w.x, w.y, w.z.abs())
}

impl MetallicRoughness {
    /// The model for these parameters (clamped to their ranges; NaN becomes 0, an IOR that is
    /// not finite or not above 0 becomes 1.5).
    #[must_use]
    pub fn new(base_color: Rgb, metallic: f32, roughness: f32, ior: f32) -> Self {
        let unit = |v: f32| if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
        let base_color = Rgb::new(unit(base_color.r), unit(base_color.g), unit(base_color.b));
        let alpha = roughness_to_alpha(unit(roughness)).max(SMOOTH_ALPHA);
        let ior = if ior.is_finite() && ior > 0.0 {
            ior
        } else {
            1.5
        };
        let r = (ior - 1.0) / (ior + 1.0);
        Self {
            base_color,
            metallic: unit(metallic),
            distribution: TrowbridgeReitz::isotropic(alpha),
            f0: r * r,
        }
    }

    /// Probability of sampling the specular lobe, seen from `wo` (upper hemisphere).
    #[inline]
    fn specular_probability(&self, wo: Vec3) -> f32 {
        let f = self.f0 + (1.0 - self.f0) * schlick_weight(wo.z);
        let m = self.metallic;
        let w_spec = m + (1.0 - m) * f;
        let w_diff = (1.0 - m) * (1.0 - f) * self.base_color.luminance().max(0.0);
        if w_spec + w_diff > 0.0 {
            w_spec / (w_spec + w_diff)
        } else {
            1.0
        }
    }

    /// `f` for `wo`, `wi` in the upper hemisphere.
    #[inline]
    fn eval_upper(&self, wo: Vec3, wi: Vec3) -> Rgb {
        let wm = wo + wi;
        if wm.length_squared() == 0.0 || wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::BLACK;
        }
        let wm = wm.normalize();
        let w5 = schlick_weight(wo.dot(wm).abs());
        let d = &self.distribution;
        let specular = d.d(wm) * d.g(wo, wi) / (4.0 * wo.z * wi.z);
        let fresnel = |w: f32| self.f0 + (1.0 - self.f0) * w;
        let f_dielectric = fresnel(w5);
        // The base layer gets what the coating transmits on the way in and on the way out.
        let through = (1.0 - fresnel(schlick_weight(wo.z))) * (1.0 - fresnel(schlick_weight(wi.z)));
        let base = self.base_color;
        let f_metal = base + (Rgb::WHITE - base) * w5;
        let m = self.metallic;
        let dielectric = base * (through * FRAC_1_PI) + Rgb::splat(f_dielectric * specular);
        dielectric * (1.0 - m) + f_metal * (specular * m)
    }

    /// The mixture density for `wo`, `wi` in the upper hemisphere.
    #[inline]
    fn pdf_upper(&self, wo: Vec3, wi: Vec3) -> f32 {
        let wm = wo + wi;
        if wm.length_squared() == 0.0 || wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let wm = wm.normalize();
        let p = self.specular_probability(wo);
        let spec = self.distribution.pdf(wo, wm) / (4.0 * wo.dot(wm).abs());
        p * spec + (1.0 - p) * wi.z * FRAC_1_PI
    }
}

impl Bsdf for MetallicRoughness {
    #[inline]
    fn flags(&self) -> BsdfFlags {
        BsdfFlags::DIFFUSE_REFLECTION | BsdfFlags::GLOSSY_REFLECTION
    }

    #[inline]
    fn eval(&self, wo: Vec3, wi: Vec3, _mode: TransportMode) -> Rgb {
        if !same_hemisphere(wo, wi) {
            return Rgb::BLACK;
        }
        self.eval_upper(upper(wo), upper(wi))
    }

    #[inline]
    fn pdf(&self, wo: Vec3, wi: Vec3, _mode: TransportMode) -> f32 {
        if !same_hemisphere(wo, wi) {
            return 0.0;
        }
        self.pdf_upper(upper(wo), upper(wi))
    }

    #[inline]
    fn sample(&self, wo: Vec3, uc: f32, u: Vec2, _mode: TransportMode) -> Option<BsdfSample> {
        if wo.z == 0.0 {
            return None;
        }
        let wo_u = upper(wo);
        let specular = uc < self.specular_probability(wo_u);
        let mut wi = if specular {
            reflect(wo_u, self.distribution.sample_wm(wo_u, u))
        } else {
            sample_cosine_hemisphere(u)
        };
        if wi.z <= 0.0 {
            return None;
        }
        let pdf = self.pdf_upper(wo_u, wi);
        if !(pdf.is_finite() && pdf > 0.0) {
            return None;
        }
        let f = self.eval_upper(wo_u, wi);
        if wo.z < 0.0 {
            wi.z = -wi.z;
        }
        Some(BsdfSample {
            wi,
            f,
            pdf,
            flags: if specular {
                BsdfFlags::GLOSSY_REFLECTION
            } else {
                BsdfFlags::DIFFUSE_REFLECTION
            },
            eta: 1.0,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A white dielectric's `F0` is the Fresnel reflectance at normal incidence: 0.04 for IOR
    /// 1.5; metallic 1 with a white base reflects everything the GGX lobe keeps.
    #[test]
    fn parameters_map_as_the_specification_says() {
        let m = MetallicRoughness::new(Rgb::WHITE, 0.0, 0.5, 1.5);
        assert!((m.f0 - 0.04).abs() < 1e-6);
        let clamped = MetallicRoughness::new(Rgb::new(2.0, -1.0, f32::NAN), 3.0, f32::NAN, -1.0);
        assert_eq!(clamped.base_color, Rgb::new(1.0, 0.0, 0.0));
        assert_eq!(clamped.metallic, 1.0);
        assert!((clamped.f0 - 0.04).abs() < 1e-6);
        // Normal incidence, a half vector along the normal: the metal's Fresnel is its base.
        let metal = MetallicRoughness::new(Rgb::new(0.9, 0.6, 0.3), 1.0, 0.5, 1.5);
        let f = metal.eval(Vec3::Z, Vec3::Z, TransportMode::Radiance);
        let d = &metal.distribution;
        let spec = d.d(Vec3::Z) * d.g(Vec3::Z, Vec3::Z) / 4.0;
        assert!((f.r - 0.9 * spec).abs() < 1e-4 * spec && (f.b - 0.3 * spec).abs() < 1e-4 * spec);
        // A rough black dielectric is only its specular coating: 0.04 of the lobe there.
        let black = MetallicRoughness::new(Rgb::BLACK, 0.0, 0.5, 1.5);
        let f = black.eval(Vec3::Z, Vec3::Z, TransportMode::Radiance);
        assert!((f.g - 0.04 * spec).abs() < 1e-4 * spec);
    }
}
