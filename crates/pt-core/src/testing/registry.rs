//! The registry: the one list of the built-in models that every check, benchmark and furnace
//! test iterates.
//!
//! - [`builtin_bsdf_cases`]: every built-in BSDF over its parameter range and a set of outgoing
//!   directions (the statistical checks);
//! - [`builtin_bsdf_models`]: one typical instance of each model (the benchmarks);
//! - [`builtin_material_furnace_cases`]: materials in a white furnace with what they must show
//!   (`tests/furnace_bsdf.rs` at the workspace root).
//!
//! Adding a built-in model means adding its entries here; `tests/registry.rs` fails while a
//! variant of [`BuiltinBsdf`] or [`BuiltinMaterial`] has none.

use std::f32::consts::PI;

use glam::Vec3;

use crate::bsdf::microfacet::roughness_to_alpha;
use crate::bsdf::{
    BuiltinBsdf, ConductorFresnel, Lambertian, MetallicRoughness, RoughConductor, RoughDielectric,
    SmoothDielectric, SpecularReflection, TrowbridgeReitz,
};
use crate::color::Rgb;
use crate::material::{BuiltinMaterial, Glass, Metal, Mirror, PbrMaterial};
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
///   1/2.5, at roughness 0.05 for eta 1.5, and anisotropic for eta 1.5 and 1/1.5;
/// - glTF's metallic-roughness model with a coloured base at metallic 0, 0.5 and 1 and
///   roughness 0.05, 0.3, 0.7 and 1, and white and black dielectrics (IOR 1.5 and 2.4).
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

    let base = Rgb::new(0.8, 0.5, 0.2);
    for metallic in [0.0, 0.5, 1.0] {
        for r in [0.05, 0.3, 0.7, 1.0] {
            push_all(
                &mut out,
                &format!("metallic-roughness(metallic {metallic}, roughness {r})"),
                MetallicRoughness::new(base, metallic, r, 1.5),
                1.0,
                none,
                None,
            );
        }
    }
    // KHR_materials_specular: a coloured, strengthened F0 and a weakened one.
    for (specular, color) in [(1.0, Rgb::new(2.0, 1.0, 0.2)), (0.3, Rgb::WHITE)] {
        push_all(
            &mut out,
            &format!("metallic-roughness(specular {specular}, colour {color:?}, roughness 0.4)"),
            MetallicRoughness::new(base, 0.2, 0.4, 1.5).with_specular(specular, color),
            1.0,
            none,
            None,
        );
    }
    // KHR_materials_clearcoat: a smooth coat over a rough base, a rough coat over a metal.
    for (coat, coat_r, metallic, r) in [(1.0, 0.05, 0.0, 0.8), (0.6, 0.5, 1.0, 0.3)] {
        push_all(
            &mut out,
            &format!(
                "metallic-roughness(clearcoat {coat}, coat roughness {coat_r}, metallic {metallic}, roughness {r})"
            ),
            MetallicRoughness::new(base, metallic, r, 1.5).with_clearcoat(coat, coat_r),
            1.0,
            none,
            None,
        );
    }
    // KHR_materials_iridescence: a film over a dielectric and over a metal.
    for (metallic, thickness) in [(0.0, 300.0), (1.0, 450.0)] {
        push_all(
            &mut out,
            &format!(
                "metallic-roughness(iridescence 1, film 1.33 x {thickness} nm, metallic {metallic}, roughness 0.3)"
            ),
            MetallicRoughness::new(base, metallic, 0.3, 1.5).with_iridescence(1.0, 1.33, thickness),
            1.0,
            none,
            None,
        );
    }
    // KHR_materials_sheen: a coloured sheen over a dielectric, a sharp white one over black.
    for (color, sheen_r, base_c) in [
        (Rgb::new(0.9, 0.6, 0.3), 0.5, base),
        (Rgb::WHITE, 0.1, Rgb::BLACK),
    ] {
        push_all(
            &mut out,
            &format!(
                "metallic-roughness(sheen {color:?}, sheen roughness {sheen_r}, roughness 0.6)"
            ),
            MetallicRoughness::new(base_c, 0.0, 0.6, 1.5).with_sheen(color, sheen_r),
            1.0,
            none,
            None,
        );
    }
    // KHR_materials_anisotropy: stretched along a direction off the frame's axes, with a coat.
    push_all(
        &mut out,
        "metallic-roughness(anisotropy 0.8 along (0.6, 0.8), metallic 0.5, roughness 0.3, coat 0.5)",
        MetallicRoughness::new(base, 0.5, 0.3, 1.5)
            .with_anisotropy(0.8, glam::Vec2::new(0.6, 0.8))
            .with_clearcoat(0.5, 0.2),
        1.0,
        none,
        None,
    );
    // Iridescent frosted glass: a thin film on the rough dielectric, from both sides.
    for (r, thickness) in [(0.2, 250.0), (0.5, 600.0)] {
        push_all(
            &mut out,
            &format!("rough dielectric(roughness {r}, eta 1.5, film 1.8 x {thickness} nm)"),
            RoughDielectric::new(
                TrowbridgeReitz::isotropic(roughness_to_alpha(r)),
                1.5,
                Rgb::WHITE,
            )
            .with_film(crate::bsdf::ThinFilm::new(1.0, 1.8, thickness)),
            1.5,
            none,
            None,
        );
    }
    // A coat with its own normal (glTF's coat normal map, or a base normal map the coat does
    // not follow): tilted 0.35 rad, sharp and rough, over an anisotropic base.
    let tilted = Vec3::new(0.35f32.sin() * 0.6, 0.35f32.sin() * 0.8, 0.35f32.cos());
    for (coat_r, metallic) in [(0.05, 0.0), (0.4, 1.0)] {
        push_all(
            &mut out,
            &format!(
                "metallic-roughness(coat 1 tilted 20 deg, coat roughness {coat_r}, metallic {metallic}, roughness 0.5)"
            ),
            MetallicRoughness::new(base, metallic, 0.5, 1.5)
                .with_clearcoat(1.0, coat_r)
                .with_coat_normal(tilted),
            1.0,
            none,
            None,
        );
    }
    push_all(
        &mut out,
        "metallic-roughness(coat 0.7 tilted 20 deg, anisotropy 0.6, metallic 0.3, roughness 0.4)",
        MetallicRoughness::new(base, 0.3, 0.4, 1.5)
            .with_anisotropy(0.6, glam::Vec2::new(0.8, -0.6))
            .with_clearcoat(0.7, 0.2)
            .with_coat_normal(tilted),
        1.0,
        none,
        None,
    );
    for (color, ior) in [(Rgb::WHITE, 1.5), (Rgb::WHITE, 2.4), (Rgb::BLACK, 1.5)] {
        push_all(
            &mut out,
            &format!("metallic-roughness({color:?}, dielectric, roughness 0.5, ior {ior})"),
            MetallicRoughness::new(color, 0.0, 0.5, ior),
            1.0,
            none,
            None,
        );
    }
    out
}

/// One typical instance of every built-in BSDF (roughness 0.3 where it has one), named for the
/// benchmarks (`cargo bench -p pt-core --bench bsdf`).
#[must_use]
pub fn builtin_bsdf_models() -> Vec<(&'static str, BuiltinBsdf)> {
    let ggx = TrowbridgeReitz::isotropic(roughness_to_alpha(0.3));
    vec![
        ("lambertian", Lambertian::new(Rgb::splat(0.5)).into()),
        ("mirror", SpecularReflection::new(Rgb::WHITE).into()),
        (
            "conductor_schlick_r0.3",
            RoughConductor::new(ggx, ConductorFresnel::Schlick(Rgb::splat(0.9))).into(),
        ),
        (
            "conductor_gold_r0.3",
            RoughConductor::new(ggx, ConductorFresnel::GOLD).into(),
        ),
        (
            "smooth_dielectric",
            SmoothDielectric::new(1.5, Rgb::WHITE).into(),
        ),
        (
            "rough_dielectric_r0.3",
            RoughDielectric::new(ggx, 1.5, Rgb::WHITE).into(),
        ),
        (
            "metallic_roughness_m0.5_r0.3",
            MetallicRoughness::new(Rgb::splat(0.5), 0.5, 0.3, 1.5).into(),
        ),
    ]
}

/// What a material must show in a white furnace (a closed enclosure of radiance 1).
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum FurnaceExpectation {
    /// Lossless and deterministic (delta lobes only): every sample is exactly 1.
    Exact,
    /// Lossless but sampled: 1 within the noise.
    WithinNoise,
    /// Loses energy (single-scattering microfacets): never above 1, never below `min_mean`.
    NoGain {
        /// The least image mean allowed.
        min_mean: f64,
    },
}

/// A material for the white furnace and what it must show there.
#[derive(Clone, Debug)]
#[non_exhaustive]
pub struct FurnaceCase {
    /// What the case is.
    pub name: &'static str,
    /// The material, on a sphere in the furnace.
    pub material: BuiltinMaterial,
    /// What the image must show.
    pub expect: FurnaceExpectation,
}

/// Every built-in material in the white-furnace configurations whose outcome is known:
/// lossless ones (white diffuse, mirror, smooth `F0 = 1` metal, smooth glass at eta 1.5 and
/// 1/1.5) are invisible; rough metal and rough glass lose at most 25% at roughness 0.5, and the
/// glTF default material (white metal at roughness 1, where single-scattering GGX loses the most)
/// at most 40%; the rough white glTF dielectric loses at most 10%.
///
/// # Panics
///
/// Never: the parameters are valid constants.
#[must_use]
pub fn builtin_material_furnace_cases() -> Vec<FurnaceCase> {
    let white_metal = |r| Metal::new(ConductorFresnel::Schlick(Rgb::WHITE), r).expect("valid");
    let glass = |eta| Glass::new(eta).expect("valid");
    let case = |name, material: BuiltinMaterial, expect| FurnaceCase {
        name,
        material,
        expect,
    };
    use FurnaceExpectation::{Exact, NoGain, WithinNoise};
    vec![
        case(
            "white diffuse",
            BuiltinMaterial::diffuse(Rgb::WHITE),
            WithinNoise,
        ),
        case("mirror", Mirror::new(Rgb::WHITE).into(), Exact),
        case("smooth conductor F0 = 1", white_metal(0.0).into(), Exact),
        case("glass 1.5", glass(1.5).into(), Exact),
        case("glass 1/1.5", glass(1.0 / 1.5).into(), Exact),
        case(
            "glTF white dielectric, rough (specular layer over diffuse)",
            PbrMaterial {
                metallic: 0.0,
                ..PbrMaterial::default()
            }
            .into(),
            NoGain { min_mean: 0.9 },
        ),
        case(
            "glTF default material (white metal, rough)",
            PbrMaterial {
                metallic: 1.0,
                ..PbrMaterial::default()
            }
            .into(),
            // Roughness 1: single-scattering GGX drops about a third of the energy (Kulla and
            // Conty 2017 report up to 60% at grazing angles); measured mean 0.68.
            NoGain { min_mean: 0.6 },
        ),
        case(
            "rough conductor F0 = 1",
            white_metal(0.5).into(),
            NoGain { min_mean: 0.75 },
        ),
        case(
            "rough glass",
            glass(1.5).with_roughness(0.5).expect("valid").into(),
            NoGain { min_mean: 0.75 },
        ),
    ]
}
