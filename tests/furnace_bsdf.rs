//! White furnace for every material of the registry
//! (`pt_core::testing::builtin_material_furnace_cases`): a sphere inside a closed enclosure that emits radiance
//! 1 everywhere (and reflects nothing) is invisible, because a lossless surface returns exactly
//! what it receives. Every pixel must equal the background, 1.
//!
//! - Delta models (ideal mirror, smooth conductor with `F0 = 1`, smooth glass at eta 1.5 and
//!   1/1.5) make every path deterministic: each sample is exactly 1 unless the path is cut by the
//!   maximum depth (10,000, far beyond what rays trapped inside the faceted glass by total internal
//!   reflection need). Tolerance: `1e-4` on the image mean,
//!   and each pixel within one lost sample (`1 / spp`) of 1.
//! - The white Lambertian (albedo 1) and other lossless sampled cases are noisy: image mean within
//!   `z s / sqrt(n)` and every pixel within `z_pix s` of 1, `z` at significance 0.01 (Šidák over
//!   the sampled cases, `TESTS`).
//! - Rough conductors and rough glass lose the energy of inter-reflections between microfacets
//!   (single-scattering models): they must never exceed 1 (mean) and lose no more than the
//!   floor each registry case states (25% at roughness 0.5, 40% for the glTF default material at
//!   roughness 1).
//!
//! The sphere is flat-faceted (no vertex normals) so the test is of the BSDFs and the integrator,
//! not of shading-normal approximations.

use crate::support;

use pt::prelude::*;
use pt::pt_core::testing::{FurnaceCase, FurnaceExpectation, builtin_material_furnace_cases};
use pt::pt_scene::shapes::cube;
use support::{mean_std, sidak_z, uv_sphere};

const SPP: u32 = 16;

fn render_furnace(material: BuiltinMaterial) -> Image {
    let mut b = SceneBuilder::new();
    let room = b.add_mesh(cube(4.0, true));
    let sphere = b.add_mesh(uv_sphere(1.0, 24, 48));
    let black = b.add_material(BuiltinMaterial::diffuse(Rgb::BLACK));
    let m = b.add_material(material);
    b.add_object(Object::new(room, black).with_emission(Emission::new(Rgb::WHITE)));
    b.add_object(Object::new(sphere, m));
    let scene = b.build().unwrap();
    let camera =
        PinholeCamera::look_at(Vec3::new(0.0, 0.5, 3.0), Vec3::ZERO, Vec3::Y, 45.0).unwrap();
    // A generous depth: in a faceted glass sphere about 0.3% of paths are trapped by total
    // internal reflection for more than 100 bounces, and each one cut would darken its pixel.
    let opts = RenderOptions::new(32, 32)
        .spp(SPP)
        .max_depth(10_000)
        .seed(3);
    let out = render(&scene, &camera, &opts, None).unwrap();
    assert_eq!(out.stats.non_finite_samples, 0);
    out.image
}

fn channel_values(image: &Image) -> Vec<f64> {
    image.as_slice().iter().map(|&v| f64::from(v)).collect()
}

fn assert_invisible_exactly(label: &str, material: BuiltinMaterial) {
    let v = channel_values(&render_furnace(material));
    let (mean, _) = mean_std(&v);
    let worst = v.iter().map(|x| (x - 1.0).abs()).fold(0.0, f64::max);
    println!("{label}: mean {mean:.6}, worst pixel deviation {worst:.4}");
    assert!((mean - 1.0).abs() < 1e-4, "{label}: mean {mean} is not 1");
    assert!(
        worst <= 1.0 / f64::from(SPP) + 1e-4,
        "{label}: a pixel deviates by {worst} from 1"
    );
}

/// Every registry case whose outcome is exact: each pixel is 1 within one lost sample.
#[test]
fn lossless_delta_materials_are_invisible() {
    let mut n = 0;
    for case in cases(|e| matches!(e, FurnaceExpectation::Exact)) {
        assert_invisible_exactly(case.name, case.material);
        n += 1;
    }
    assert!(n >= 4, "the registry has the delta cases");
}

/// Every lossless sampled case: 1 within the noise, mean and every pixel.
#[test]
fn lossless_sampled_materials_are_invisible_within_noise() {
    let cases = cases(|e| matches!(e, FurnaceExpectation::WithinNoise));
    assert!(!cases.is_empty());
    for case in cases {
        // Pixels that see the enclosure directly are exactly 1; the statistics are over the
        // sphere's.
        let v: Vec<f64> = channel_values(&render_furnace(case.material))
            .into_iter()
            .filter(|&x| x != 1.0)
            .collect();
        let label = case.name;
        assert!(
            v.len() > 1000,
            "{label}: the sphere covers much of the image"
        );
        let (mean, s) = mean_std(&v);
        let n = v.len();
        let z = sidak_z(0.01, 2 * TESTS);
        let z_pix = sidak_z(0.01, 2 * TESTS * n);
        println!("{label}: mean {mean:.5}, spread {s:.4}");
        assert!(
            (mean - 1.0).abs() <= z * s / (n as f64).sqrt() + 1e-6,
            "{label}: mean {mean}"
        );
        for x in &v {
            assert!((x - 1.0).abs() <= z_pix * s + 1e-6, "{label}: pixel {x}");
        }
    }
}

/// Every lossy case: never above 1 (mean), and not below its floor.
#[test]
fn lossy_materials_never_create_energy() {
    let cases = cases(|e| matches!(e, FurnaceExpectation::NoGain { .. }));
    assert!(!cases.is_empty());
    for case in cases {
        let FurnaceExpectation::NoGain { min_mean } = case.expect else {
            unreachable!()
        };
        let label = case.name;
        let v = channel_values(&render_furnace(case.material));
        let (mean, s) = mean_std(&v);
        let z = sidak_z(0.01, TESTS);
        let tol = z * s / (v.len() as f64).sqrt();
        println!("{label}: mean {mean:.5} (tolerance {tol:.5})");
        assert!(mean <= 1.0 + tol, "{label}: mean {mean} above 1");
        assert!(mean >= min_mean, "{label}: mean {mean} loses too much");
    }
}

/// The number of sampled registry cases, for the Šidák correction.
const TESTS: usize = 5;

fn cases(keep: impl Fn(FurnaceExpectation) -> bool) -> Vec<FurnaceCase> {
    builtin_material_furnace_cases()
        .into_iter()
        .filter(|c| keep(c.expect))
        .collect()
}

#[test]
fn the_correction_counts_every_sampled_case() {
    let sampled = builtin_material_furnace_cases()
        .iter()
        .filter(|c| c.expect != FurnaceExpectation::Exact)
        .count();
    assert!(
        sampled <= TESTS,
        "raise TESTS to {sampled}: the significance level is split over the sampled cases"
    );
}
