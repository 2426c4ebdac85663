//! Environment maps are interpolated bilinearly for every ray (camera, BSDF-sampled, and the
//! radiance returned by light sampling), while their sampling stays piecewise constant over the
//! texels (docs/conventions.md says why that stays unbiased). These tests pin down:
//! - the interpolation: a texel's centre shows the texel, the point halfway between two
//!   centres their mean, across the equirect's `u` seam and across every cube seam (except within
//!   half a texel of the corners);
//! - the condition for an unbiased estimator: the sampling density is positive wherever the
//!   interpolated radiance is, even around a single bright texel at a cube corner;
//! - the estimator itself: the light-sampling estimate of `integral L dw` matches a dense
//!   quadrature of the interpolated radiance (four standard errors, about 6e-5 two-sided).

use pt_core::glam::{Vec2, Vec3};
use pt_core::light::{CubemapEnvironment, EquirectEnvironment, cube_face_point};
use pt_core::{Image, Light, LightSampleContext, Rgb};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

fn sphere_grid(n: usize) -> impl Iterator<Item = Vec3> {
    // Directions at the centres of an n x 2n (cos theta, phi) grid: equal solid angle each.
    (0..n).flat_map(move |i| {
        (0..2 * n).map(move |j| {
            let z = 1.0 - 2.0 * (i as f32 + 0.5) / n as f32;
            let phi = std::f32::consts::PI * (j as f32 + 0.5) / n as f32;
            let r = (1.0 - z * z).max(0.0).sqrt();
            Vec3::new(r * phi.cos(), z, r * phi.sin())
        })
    })
}

/// Direction of equirect image position `(u, v)` (see the module docs of `light`).
fn equirect_dir(u: f32, v: f32) -> Vec3 {
    let theta = std::f32::consts::PI * v;
    let phi = 2.0 * std::f32::consts::PI * (u - 0.5);
    Vec3::new(
        theta.sin() * phi.sin(),
        theta.cos(),
        -theta.sin() * phi.cos(),
    )
}

#[test]
fn equirect_radiance_is_bilinear_and_wraps_in_u() {
    let mut img = Image::new(4, 2);
    img.set(0, 0, Rgb::splat(4.0));
    img.set(1, 0, Rgb::splat(2.0));
    img.set(3, 0, Rgb::splat(1.0));
    let map = EquirectEnvironment::new(img).unwrap();
    let at = |u: f32, v: f32| map.radiance(equirect_dir(u, v)).r;
    assert!(
        (at(0.125, 0.25) - 4.0).abs() < 1e-4,
        "a texel's centre shows the texel"
    );
    assert!(
        (at(0.25, 0.25) - 3.0).abs() < 1e-4,
        "halfway between two centres: their mean"
    );
    assert!(
        (at(0.0, 0.25) - 2.5).abs() < 1e-4,
        "across the u seam: texels 3 and 0"
    );
    assert!(
        (at(0.125, 0.5) - 2.0).abs() < 1e-4,
        "halfway down to the black row"
    );
}

/// A cube map with random texels and a face size of 8.
fn random_cube(seed: u64) -> CubemapEnvironment {
    let mut rng = Pcg64::seed_from_u64(seed);
    let faces = std::array::from_fn(|_| {
        let data = (0..8 * 8 * 3).map(|_| rng.random::<f32>()).collect();
        Image::from_rgb(8, 8, data).unwrap()
    });
    CubemapEnvironment::new(faces).unwrap()
}

#[test]
fn cube_radiance_is_continuous_across_every_seam() {
    let map = random_cube(1);
    // Points along each of the 12 cube edges, approached from the two faces that meet there:
    // a point a hair inside each face. Nearest-neighbour lookups jump there by up to 1. Within
    // half a texel of the 8 corners, where three faces meet, no 2x2 footprint exists (the
    // diagonal tap is the nearest texel of a neighbouring face), so those points are left out.
    let mut rng = Pcg64::seed_from_u64(2);
    let mut worst = 0.0f32;
    for _ in 0..2000 {
        let face = rng.random_range(0..6);
        let along = rng.random_range(1.0 / 16.0..15.0 / 16.0);
        let side = rng.random_range(0..4);
        let st = |eps: f32| match side {
            0 => Vec2::new(eps, along),
            1 => Vec2::new(1.0 - eps, along),
            2 => Vec2::new(along, eps),
            _ => Vec2::new(along, 1.0 - eps),
        };
        // Inside this face, and just beyond its edge (which lies on the neighbouring face).
        let (inside, beyond) = (
            cube_face_point(face, st(1e-4)),
            cube_face_point(face, st(-1e-4)),
        );
        // The map's frame mirrors x before the OpenGL cube lookup.
        let to_world = |p: Vec3| Vec3::new(-p.x, p.y, p.z).normalize();
        let d = map.radiance(to_world(inside)) - map.radiance(to_world(beyond));
        worst = worst.max(d.r.abs().max(d.g.abs()).max(d.b.abs()));
    }
    assert!(worst < 2e-3, "radiance jumps by {worst} across a seam");
}

#[test]
fn sampling_density_is_positive_wherever_interpolated_radiance_is() {
    // One bright texel: the interpolated radiance spreads half a texel around it.
    let mut img = Image::new(16, 8);
    img.set(5, 0, Rgb::WHITE);
    img.set(15, 3, Rgb::WHITE);
    let equirect = EquirectEnvironment::new(img).unwrap();
    // A corner texel of a face, whose interpolation reaches two other faces.
    let mut faces: [Image; 6] = std::array::from_fn(|_| Image::new(8, 8));
    faces[2].set(7, 0, Rgb::WHITE);
    let cube = CubemapEnvironment::new(faces).unwrap();
    positive_where_lit("equirect", &equirect, |d| equirect.radiance(d));
    positive_where_lit("cube", &cube, |d| cube.radiance(d));
}

fn positive_where_lit(name: &str, light: &dyn Light, radiance: impl Fn(Vec3) -> Rgb) {
    let ctx = LightSampleContext::at(Vec3::ZERO);
    let mut lit = 0;
    for d in sphere_grid(400) {
        if !radiance(d).is_black() {
            lit += 1;
            assert!(
                light.pdf_li(&ctx, d) > 0.0,
                "{name}: radiance but pdf 0 at {d}"
            );
        }
    }
    assert!(
        lit > 10,
        "{name}: the test sees the bright texel ({lit} directions)"
    );
}

#[test]
fn light_sampling_estimates_the_integral_of_the_interpolated_radiance() {
    let ctx = LightSampleContext::at(Vec3::ZERO);
    let mut rng = Pcg64::seed_from_u64(3);
    let data: Vec<f32> = (0..16 * 8 * 3)
        .map(|_| {
            if rng.random::<f32>() < 0.2 {
                rng.random::<f32>() * 10.0
            } else {
                0.0
            }
        })
        .collect();
    let equirect = EquirectEnvironment::new(Image::from_rgb(16, 8, data).unwrap()).unwrap();
    let cube = random_cube(4);
    for (name, light) in [
        ("equirect", &equirect as &dyn Light),
        ("cube", &cube as &dyn Light),
    ] {
        // Quadrature of the interpolated radiance (luminance) over the sphere: 4 pi / cells.
        let n = 600;
        let cells = (n * 2 * n) as f64;
        let quad: f64 = sphere_grid(n)
            .map(|d| {
                let l = match name {
                    "equirect" => equirect.radiance(d),
                    _ => cube.radiance(d),
                };
                f64::from(l.luminance())
            })
            .sum::<f64>()
            * 4.0
            * std::f64::consts::PI
            / cells;
        // Light-sampling estimate: mean of L / pdf.
        let samples = 400_000;
        let (mut sum, mut sum2) = (0.0f64, 0.0f64);
        for _ in 0..samples {
            let u = Vec2::new(rng.random(), rng.random());
            let v = light
                .sample_li(&ctx, u)
                .map_or(0.0, |s| f64::from(s.li.luminance()) / f64::from(s.pdf));
            sum += v;
            sum2 += v * v;
        }
        let mean = sum / samples as f64;
        let se = ((sum2 / samples as f64 - mean * mean) / samples as f64).sqrt();
        assert!(
            (mean - quad).abs() < 4.0 * se + 2e-3 * quad,
            "{name}: estimate {mean} +- {se}, quadrature {quad}"
        );
    }
}

/// An intensity scale that would make radiance infinite is refused (it made every lookup
/// infinite, the light's power infinite, and the light sampler then dropped the only light);
/// the power of a map around a scene 1e18 across stays finite.
#[test]
fn scales_that_overflow_are_refused_and_power_stays_finite() {
    let mut img = Image::new(4, 2);
    img.set(1, 1, Rgb::splat(2000.0));
    let map = EquirectEnvironment::new(img).unwrap();
    let e = map.clone().with_scale(3e38).unwrap_err().to_string();
    assert!(e.contains("overflow"), "{e}");
    let mut big = map.with_scale(1e30).unwrap();
    big.preprocess(&pt_core::pt_accel::Bounds3::new(
        Vec3::splat(-1e18),
        Vec3::splat(1e18),
    ));
    let p = big.power();
    assert!(p.r.is_finite() && p.r > 0.0, "{p:?}");
}
