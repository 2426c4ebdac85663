//! The registry: every built-in BSDF over its parameter range and a set of outgoing directions.
//!
//! Adding a built-in model means adding its cases here; every check then covers it.

use std::f32::consts::PI;

use glam::Vec3;

use crate::bsdf::microfacet::roughness_to_alpha;
use crate::bsdf::{
    BuiltinBsdf, ConductorFresnel, Lambertian, RoughConductor, RoughDielectric, SmoothDielectric,
    SpecularReflection, TrowbridgeReitz,
};
use crate::color::Rgb;
use crate::testing::{BsdfCase, DeltaExpectation};

/// Outgoing directions as `(cos theta, phi)`: normal incidence, oblique, grazing (cos 0.03) and
/// two from inside (one beyond the critical angle of eta 1.5).
const DIRECTIONS: [(f32, f32); 7] = [
    (1.0, 0.0),
    (0.8, 0.4),
    (0.45, 1.5),
    (0.1, 2.6),
    (0.03, 3.9),
    (-0.7, 5.0),
    (-0.25, 0.9),
];

fn dir(cos_theta: f32, phi: f32) -> Vec3 {
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    Vec3::new(sin_theta * phi.cos(), sin_theta * phi.sin(), cos_theta)
}

fn push_all(
    out: &mut Vec<BsdfCase<BuiltinBsdf>>,
    name: &str,
    bsdf: impl Into<BuiltinBsdf> + Clone,
    eta: f32,
    delta: DeltaExpectation,
    albedo: Option<Rgb>,
) {
    for (c, phi) in DIRECTIONS {
        let wo = dir(c, phi);
        out.push(BsdfCase {
            name: format!("{name}, wo theta {:.1} deg", c.acos() * 180.0 / PI),
            bsdf: bsdf.clone().into(),
            wo,
            eta,
            delta,
            albedo,
        });
    }
}

/// Roughness values (perceptual, `alpha = r^2`) and relative IORs of the registry.
const ROUGHNESS: [f32; 4] = [0.1, 0.3, 0.6, 1.0];
const ETAS: [f32; 5] = [1.05, 1.5, 2.5, 1.0 / 1.5, 1.0 / 2.5];

/// Every built-in BSDF with a range of parameters, each at seven outgoing directions
/// (normal, oblique, grazing, and from inside):
///
/// - Lambertian, coloured and white (lossless: albedo 1);
/// - the ideal mirror, tinted (throughput equals the tint);
/// - the rough conductor at roughness 0.05, 0.2, 0.5 and 1 (Schlick and measured gold Fresnel),
///   anisotropic `alpha = (0.3, 0.15)`, and its smooth limit with `F0 = 1` (lossless);
/// - the smooth dielectric at eta 1.05, 1.33, 1.5, 2.5, 1/1.5 and 1/2.5 (lossless), and tinted;
/// - the rough dielectric at roughness 0.1, 0.3, 0.6 and 1 for eta 1.05, 1.5, 2.5, 1/1.5 and
///   1/2.5, at roughness 0.05 for eta 1.5, and anisotropic for eta 1.5 and 1/1.5.
#[must_use]
pub fn builtin_bsdf_cases() -> Vec<BsdfCase<BuiltinBsdf>> {
    let mut out = Vec::new();
    let none = DeltaExpectation::None;

    push_all(
        &mut out,
        "lambertian(0.8, 0.5, 0.2)",
        Lambertian::new(Rgb::new(0.8, 0.5, 0.2)),
        1.0,
        none,
        Some(Rgb::new(0.8, 0.5, 0.2)),
    );
    push_all(
        &mut out,
        "lambertian(1)",
        Lambertian::new(Rgb::WHITE),
        1.0,
        none,
        Some(Rgb::WHITE),
    );

    let tint = Rgb::new(0.9, 0.7, 0.4);
    push_all(
        &mut out,
        "mirror(0.9, 0.7, 0.4)",
        SpecularReflection::new(tint),
        1.0,
        DeltaExpectation::Reflection { weight: Some(tint) },
        Some(tint),
    );

    let schlick = ConductorFresnel::Schlick(Rgb::new(0.95, 0.64, 0.54));
    for (r, fresnel, label) in [
        (0.05, ConductorFresnel::GOLD, "gold"),
        (0.2, schlick, "schlick"),
        (0.5, ConductorFresnel::GOLD, "gold"),
        (1.0, schlick, "schlick"),
    ] {
        let a = roughness_to_alpha(r);
        push_all(
            &mut out,
            &format!("conductor(roughness {r}, {label})"),
            RoughConductor::new(TrowbridgeReitz::isotropic(a), fresnel),
            1.0,
            none,
            None,
        );
    }
    push_all(
        &mut out,
        "conductor(alpha 0.3 x 0.15, gold)",
        RoughConductor::new(TrowbridgeReitz::new(0.3, 0.15), ConductorFresnel::GOLD),
        1.0,
        none,
        None,
    );
    push_all(
        &mut out,
        "conductor(smooth, F0 1)",
        RoughConductor::new(
            TrowbridgeReitz::isotropic(0.0),
            ConductorFresnel::Schlick(Rgb::WHITE),
        ),
        1.0,
        DeltaExpectation::Reflection {
            weight: Some(Rgb::WHITE),
        },
        Some(Rgb::WHITE),
    );

    for eta in [1.05, 1.33, 1.5, 2.5, 1.0 / 1.5, 1.0 / 2.5] {
        push_all(
            &mut out,
            &format!("smooth dielectric(eta {eta:.3})"),
            SmoothDielectric::new(eta, Rgb::WHITE),
            eta,
            DeltaExpectation::Dielectric {
                eta,
                tint: Rgb::WHITE,
            },
            Some(Rgb::WHITE),
        );
    }
    let glass_tint = Rgb::new(0.9, 0.6, 0.3);
    push_all(
        &mut out,
        "smooth dielectric(eta 1.5, tinted)",
        SmoothDielectric::new(1.5, glass_tint),
        1.5,
        DeltaExpectation::Dielectric {
            eta: 1.5,
            tint: glass_tint,
        },
        None,
    );

    for r in ROUGHNESS {
        for eta in ETAS {
            push_all(
                &mut out,
                &format!("rough dielectric(roughness {r}, eta {eta:.3})"),
                RoughDielectric::new(
                    TrowbridgeReitz::isotropic(roughness_to_alpha(r)),
                    eta,
                    Rgb::WHITE,
                ),
                eta,
                none,
                None,
            );
        }
    }
    push_all(
        &mut out,
        "rough dielectric(roughness 0.05, eta 1.5)",
        RoughDielectric::new(
            TrowbridgeReitz::isotropic(roughness_to_alpha(0.05)),
            1.5,
            Rgb::WHITE,
        ),
        1.5,
        none,
        None,
    );
    for eta in [1.5, 1.0 / 1.5] {
        push_all(
            &mut out,
            &format!("rough dielectric(alpha 0.3 x 0.15, eta {eta:.3})"),
            RoughDielectric::new(TrowbridgeReitz::new(0.3, 0.15), eta, Rgb::WHITE),
            eta,
            none,
            None,
        );
    }
    out
}
