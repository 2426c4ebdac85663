//! Direct illumination with a closed form: a diffuse plane (albedo `rho`) under a square light of
//! radiance `Le` facing down. The irradiance at a point `p` from a uniform polygon is exact by
//! Lambert's formula, `E(p) = Le / 2 * sum_i theta_i (n . Gamma_i)` (angle `theta_i` subtended by
//! edge `i`, `Gamma_i` the unit normal of the plane through `p` and that edge), and the plane
//! reflects `L = rho / pi * E(p)`. Nothing else is in the scene and the light is black on its
//! back, so there is no indirect light at any depth.
//!
//! Each pixel's expected value is `L` averaged over the pixel footprint (an 8x8 quadrature of the
//! same camera rays the renderer uses; the box filter makes a pixel the plain mean of its
//! samples). Pixels that see the light or miss the plane are left out.
//!
//! Statistics: the residuals `r = (value - expected) / expected` are grouped into four rings of
//! equal pixel count by distance from the point under the light (a wrong cosine or distance factor biases rings
//! differently). In each ring the mean residual must be within `z * s / sqrt(n)` of 0, `s` the
//! ring's residual spread, `z` the normal quantile at significance 0.01 with a Šidák correction
//! over every ring of every test in this file (5 tests x 4 rings = 20 tests). MIS and light
//! sampling run twice: with the light sampled by area (the default) and by solid angle.

use crate::support;

use std::f64::consts::PI;

use pt::prelude::*;
use pt::pt_core::glam::DVec3;
use pt::pt_core::{BuiltinLight, CameraSample, LightStrategy};
use pt::pt_scene::shapes::quad;
use support::{mean_std, sidak_z};

const RHO: f32 = 0.6;
const LE: f32 = 5.0;
const HALF: f32 = 0.3; // the light is 0.6 x 0.6
const HEIGHT: f32 = 1.0;
const SIZE: u32 = 48;
const TESTS: usize = 20;

fn light_corners() -> [Vec3; 4] {
    // Wound so that the normal points down, at the plane.
    [
        Vec3::new(-HALF, HEIGHT, -HALF),
        Vec3::new(HALF, HEIGHT, -HALF),
        Vec3::new(HALF, HEIGHT, HALF),
        Vec3::new(-HALF, HEIGHT, HALF),
    ]
}

/// Exact outgoing radiance of the plane at `p` (y = 0), by Lambert's polygon formula.
fn exact_radiance(p: DVec3) -> f64 {
    let q = light_corners().map(|c| (c.as_dvec3() - p).normalize());
    let n = DVec3::Y;
    let mut sum = 0.0;
    for i in 0..4 {
        let (a, b) = (q[i], q[(i + 1) % 4]);
        let theta = a.dot(b).clamp(-1.0, 1.0).acos();
        sum += theta * n.dot(a.cross(b).normalize());
    }
    let irradiance = f64::from(LE) / 2.0 * sum.abs();
    f64::from(RHO) / PI * irradiance
}

fn camera() -> PinholeCamera {
    PinholeCamera::look_at(
        Vec3::new(0.0, 0.75, 2.0),
        Vec3::new(0.0, 0.0, -0.2),
        Vec3::Y,
        60.0,
    )
    .unwrap()
}

/// Expected pixel values (None where a footprint sample sees the light or misses the plane).
fn expected_image(cam: &PinholeCamera) -> Vec<Option<(f64, f64)>> {
    let k = 8;
    let mut out = Vec::new();
    for y in 0..SIZE {
        for x in 0..SIZE {
            let mut sum = 0.0;
            let mut ok = true;
            let mut centre_dist = 0.0;
            for j in 0..k {
                for i in 0..k {
                    let film = Vec2::new(
                        (x as f32 + (i as f32 + 0.5) / k as f32) / SIZE as f32,
                        (y as f32 + (j as f32 + 0.5) / k as f32) / SIZE as f32,
                    );
                    let ray = cam.generate_ray(&CameraSample::new(film, 1.0));
                    let (o, d) = (ray.origin.as_dvec3(), ray.dir.as_dvec3());
                    let t_light = (f64::from(HEIGHT) - o.y) / d.y;
                    let pl = o + d * t_light;
                    if t_light > 0.0
                        && pl.x.abs() <= f64::from(HALF) + 1e-3
                        && pl.z.abs() <= f64::from(HALF) + 1e-3
                    {
                        ok = false;
                    }
                    let t = -o.y / d.y;
                    let p = o + d * t;
                    if t <= 0.0 || p.x.abs() > 9.9 || p.z.abs() > 9.9 {
                        ok = false;
                    }
                    sum += exact_radiance(p);
                    centre_dist += (p.x * p.x + p.z * p.z).sqrt();
                }
            }
            let n = f64::from(k * k);
            out.push(ok.then_some((sum / n, centre_dist / n)));
        }
    }
    out
}

fn scene(solid_angle: bool) -> Scene {
    let mut b = SceneBuilder::new();
    b.solid_angle_light_sampling(solid_angle);
    let plane = b.add_mesh(quad([
        Vec3::new(-10.0, 0.0, -10.0),
        Vec3::new(-10.0, 0.0, 10.0),
        Vec3::new(10.0, 0.0, 10.0),
        Vec3::new(10.0, 0.0, -10.0),
    ]));
    let lamp = b.add_mesh(quad(light_corners()));
    let grey = b.add_material(BuiltinMaterial::diffuse(Rgb::splat(RHO)));
    let black = b.add_material(BuiltinMaterial::diffuse(Rgb::BLACK));
    b.add_object(Object::new(plane, grey));
    b.add_object(Object::new(lamp, black).with_emission(Emission::new(Rgb::splat(LE))));
    let scene = b.build().unwrap();
    for light in scene.lights() {
        let BuiltinLight::Triangle(t) = light else {
            panic!("only the lamp's triangles emit");
        };
        assert_eq!(t.solid_angle_sampling(), solid_angle);
    }
    scene
}

fn check(strategy: LightStrategy, spp: u32, max_depth: u32, solid_angle: bool) {
    let cam = camera();
    let expected = expected_image(&cam);
    let opts = RenderOptions::new(SIZE, SIZE)
        .spp(spp)
        .max_depth(max_depth)
        .seed(3)
        .strategy(strategy);
    let out = render(&scene(solid_angle), &cam, &opts, None).unwrap();
    assert_eq!(out.stats.non_finite_samples, 0);

    // Residuals sorted by distance from the point under the light, split into four rings of
    // equal pixel count.
    let mut by_distance: Vec<(f64, f64)> = expected
        .iter()
        .enumerate()
        .filter_map(|(i, e)| {
            e.map(|(value, dist)| {
                (
                    dist,
                    (f64::from(out.image.as_slice()[3 * i]) - value) / value,
                )
            })
        })
        .collect();
    by_distance.sort_by(|a, b| a.0.total_cmp(&b.0));
    let ring_size = by_distance.len().div_ceil(4);
    let rings: Vec<Vec<f64>> = by_distance
        .chunks(ring_size)
        .map(|c| c.iter().map(|x| x.1).collect())
        .collect();
    let z = sidak_z(0.01, TESTS);
    for (k, r) in rings.iter().enumerate() {
        assert!(r.len() > 50, "ring {k} has only {} pixels", r.len());
        let (mean, s) = mean_std(r);
        let tol = z * s / (r.len() as f64).sqrt();
        println!(
            "{strategy:?} ring {k}: {} pixels, mean relative error {mean:+.5} (tolerance {tol:.5})",
            r.len()
        );
        assert!(
            mean.abs() <= tol,
            "{strategy:?}: ring {k} is biased by {mean:+.5} (tolerance {tol:.5})"
        );
    }
}

#[test]
fn plane_under_square_light_with_mis() {
    check(LightStrategy::Mis, 64, 5, false);
}

#[test]
fn plane_under_square_light_with_mis_and_solid_angle_sampling() {
    check(LightStrategy::Mis, 64, 5, true);
}

#[test]
fn plane_under_square_light_with_solid_angle_light_sampling() {
    check(LightStrategy::LightOnly, 64, 1, true);
}

#[test]
fn plane_under_square_light_with_light_sampling() {
    check(LightStrategy::LightOnly, 64, 1, false);
}

#[test]
fn plane_under_square_light_with_bsdf_sampling() {
    check(LightStrategy::BsdfOnly, 512, 5, false);
}
