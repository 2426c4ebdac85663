//! White furnace for every lossless BSDF: a sphere inside a closed enclosure that emits radiance
//! 1 everywhere (and reflects nothing) is invisible, because a lossless surface returns exactly
//! what it receives. Every pixel must equal the background, 1.
//!
//! - Delta models (ideal mirror, smooth conductor with `F0 = 1`, smooth glass at eta 1.5 and
//!   1/1.5) make every path deterministic: each sample is exactly 1 unless the path is cut by the
//!   maximum depth (10,000, far beyond what rays trapped inside the faceted glass by total internal
//!   reflection need). Tolerance: `1e-4` on the image mean,
//!   and each pixel within one lost sample (`1 / spp`) of 1.
//! - The white Lambertian (albedo 1) is lossless but noisy: image mean within `z s / sqrt(n)` and
//!   every pixel within `z_pix s` of 1, `z` at significance 0.01 (Šidák over the tests here).
//! - Rough conductors and rough glass lose the energy of inter-reflections between microfacets
//!   (single-scattering models): they must never exceed 1 (mean) and lose at most 25%.
//!
//! The sphere is flat-faceted (no vertex normals) so the test is of the BSDFs and the integrator,
//! not of shading-normal approximations.

use crate::support;

use pt::prelude::*;
use pt::pt_core::{ConductorFresnel, Glass, Metal, Mirror};
use support::{inward_box, mean_std, sidak_z, uv_sphere};

const SPP: u32 = 16;

fn render_furnace(material: BuiltinMaterial) -> Image {
    let mut b = SceneBuilder::new();
    let room = b.add_mesh(inward_box(4.0));
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

#[test]
fn ideal_mirror_is_invisible() {
    assert_invisible_exactly("mirror", Mirror::new(Rgb::WHITE).into());
}

#[test]
fn smooth_white_conductor_is_invisible() {
    let m = Metal::new(ConductorFresnel::Schlick(Rgb::WHITE), 0.0).unwrap();
    assert_invisible_exactly("smooth conductor F0 = 1", m.into());
}

#[test]
fn smooth_glass_is_invisible() {
    assert_invisible_exactly("glass 1.5", Glass::new(1.5).unwrap().into());
    assert_invisible_exactly("glass 1/1.5", Glass::new(1.0 / 1.5).unwrap().into());
}

#[test]
fn white_lambertian_is_invisible_within_noise() {
    // Pixels that see the enclosure directly are exactly 1; the statistics are over the sphere's.
    let v: Vec<f64> = channel_values(&render_furnace(BuiltinMaterial::diffuse(Rgb::WHITE)))
        .into_iter()
        .filter(|&x| x != 1.0)
        .collect();
    assert!(v.len() > 1000, "the sphere covers much of the image");
    let (mean, s) = mean_std(&v);
    let n = v.len();
    let z = sidak_z(0.01, 2);
    let z_pix = sidak_z(0.01, 2 * n);
    println!("white lambertian: mean {mean:.5}, spread {s:.4}");
    assert!((mean - 1.0).abs() <= z * s / (n as f64).sqrt() + 1e-6);
    for x in &v {
        assert!((x - 1.0).abs() <= z_pix * s + 1e-6, "pixel {x}");
    }
}

#[test]
fn rough_models_never_create_energy() {
    let cases: [(&str, BuiltinMaterial); 2] = [
        (
            "rough conductor F0 = 1",
            Metal::new(ConductorFresnel::Schlick(Rgb::WHITE), 0.5)
                .unwrap()
                .into(),
        ),
        (
            "rough glass",
            Glass::new(1.5).unwrap().with_roughness(0.5).unwrap().into(),
        ),
    ];
    for (label, m) in cases {
        let v = channel_values(&render_furnace(m));
        let (mean, s) = mean_std(&v);
        let z = sidak_z(0.01, 2);
        let tol = z * s / (v.len() as f64).sqrt();
        println!("{label}: mean {mean:.5} (tolerance {tol:.5})");
        assert!(mean <= 1.0 + tol, "{label}: mean {mean} above 1");
        assert!(mean >= 0.75, "{label}: mean {mean} loses too much");
    }
}
