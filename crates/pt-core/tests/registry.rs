//! The registry covers every built-in model: adding a variant to `BuiltinBsdf`,
//! `BuiltinMaterial` or `BuiltinLight` without registry entries fails here, so the statistical checks, the
//! benchmarks and the furnace tests cannot silently skip it (CONTRIBUTING.md, "Adding a model").

use std::collections::BTreeSet;

use pt_core::testing::{
    builtin_bsdf_cases, builtin_bsdf_models, builtin_light_cases, builtin_material_furnace_cases,
};
use pt_core::{BuiltinBsdf, BuiltinLight, BuiltinMaterial};

fn missing(all: &[&'static str], seen: &BTreeSet<&'static str>) -> Vec<&'static str> {
    all.iter().copied().filter(|v| !seen.contains(v)).collect()
}

#[test]
fn every_bsdf_variant_has_statistical_cases() {
    let seen: BTreeSet<_> = builtin_bsdf_cases()
        .iter()
        .map(|c| c.bsdf.variant_name())
        .collect();
    let gaps = missing(BuiltinBsdf::VARIANTS, &seen);
    assert!(
        gaps.is_empty(),
        "BuiltinBsdf variants without cases in testing/registry.rs (builtin_bsdf_cases): {gaps:?}"
    );
}

#[test]
fn every_bsdf_variant_is_benchmarked() {
    let seen: BTreeSet<_> = builtin_bsdf_models()
        .iter()
        .map(|(_, b)| b.variant_name())
        .collect();
    let gaps = missing(BuiltinBsdf::VARIANTS, &seen);
    assert!(
        gaps.is_empty(),
        "BuiltinBsdf variants missing from builtin_bsdf_models (the benchmarks): {gaps:?}"
    );
}

#[test]
fn every_material_variant_has_a_furnace_case() {
    let seen: BTreeSet<_> = builtin_material_furnace_cases()
        .iter()
        .map(|c| c.material.variant_name())
        .collect();
    let gaps = missing(BuiltinMaterial::VARIANTS, &seen);
    assert!(
        gaps.is_empty(),
        "BuiltinMaterial variants without a furnace case (builtin_material_furnace_cases): {gaps:?}"
    );
}

#[test]
fn every_light_variant_has_sampling_cases() {
    let seen: BTreeSet<_> = builtin_light_cases()
        .iter()
        .map(|c| c.light.variant_name())
        .collect();
    let gaps = missing(BuiltinLight::VARIANTS, &seen);
    assert!(
        gaps.is_empty(),
        "BuiltinLight variants without cases in testing/lights.rs (builtin_light_cases): {gaps:?}"
    );
}

#[test]
fn variant_names_come_from_the_enum_declarations() {
    assert!(BuiltinBsdf::VARIANTS.contains(&"Lambertian"));
    assert!(BuiltinMaterial::VARIANTS.contains(&"Pbr"));
    assert_eq!(
        BuiltinMaterial::diffuse(pt_core::Rgb::WHITE).variant_name(),
        "Diffuse"
    );
}
