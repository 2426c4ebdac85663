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
//!
//! The textured light: the same square with an 8x8 emissive texture, nearest filtering, so the
//! light is 64 squares of constant radiance (some black) and the exact irradiance is the sum of
//! Lambert's formula over them. It checks the per-hit radiance of textured emitters (BSDF
//! sampling) and the texture-following light sampling (`TexturedTriangleLight`, light sampling
//! and MIS).

use crate::support;

use std::f64::consts::PI;

use pt::prelude::*;
use pt::pt_core::glam::DVec3;
use pt::pt_core::{BuiltinLight, CameraSample, Image, LightStrategy, Texture};
use pt::pt_scene::shapes::quad;
use support::{mean_std, sidak_z};

const RHO: f32 = 0.6;
const LE: f32 = 5.0;
const HALF: f32 = 0.3; // the light is 0.6 x 0.6
const HEIGHT: f32 = 1.0;
const SIZE: u32 = 48;
const TESTS: usize = 32;
/// Texels per side of the textured light.
const TEXELS: usize = 8;

/// The textured light's texture value at texel `(i, j)` (column, row): a pattern with black
/// texels and a 10:1 range.
fn texel(i: usize, j: usize) -> f32 {
    [0.0, 0.25, 1.0, 2.5][(i * 3 + j * 5 + i * j) % 4]
}

fn light_corners() -> [Vec3; 4] {
    // Wound so that the normal points down, at the plane.
    [
        Vec3::new(-HALF, HEIGHT, -HALF),
        Vec3::new(HALF, HEIGHT, -HALF),
        Vec3::new(HALF, HEIGHT, HALF),
        Vec3::new(-HALF, HEIGHT, HALF),
    ]
}

/// Irradiance at `p` (y = 0, normal up) from a polygon of unit radiance, by Lambert's formula.
fn polygon_irradiance(p: DVec3, corners: [DVec3; 4]) -> f64 {
    let q = corners.map(|c| (c - p).normalize());
    let n = DVec3::Y;
    let mut sum = 0.0;
    for i in 0..4 {
        let (a, b) = (q[i], q[(i + 1) % 4]);
        let theta = a.dot(b).clamp(-1.0, 1.0).acos();
        sum += theta * n.dot(a.cross(b).normalize());
    }
    sum.abs() / 2.0
}

/// Exact outgoing radiance of the plane at `p` (y = 0): the uniform light, or the textured
/// one as the sum over its texels.
fn exact_radiance(p: DVec3, textured: bool) -> f64 {
    let irradiance = if textured {
        let (h, side) = (f64::from(HALF), 2.0 * f64::from(HALF) / TEXELS as f64);
        let mut e = 0.0;
        for j in 0..TEXELS {
            for i in 0..TEXELS {
                let t = texel(i, j);
                if t == 0.0 {
                    continue;
                }
                // u along x, v along z, from the corner (-h, -h).
                let (x0, z0) = (-h + side * i as f64, -h + side * j as f64);
                let y = f64::from(HEIGHT);
                let c = [
                    DVec3::new(x0, y, z0),
                    DVec3::new(x0 + side, y, z0),
                    DVec3::new(x0 + side, y, z0 + side),
                    DVec3::new(x0, y, z0 + side),
                ];
                e += f64::from(t) * polygon_irradiance(p, c);
            }
        }
        f64::from(LE) * e
    } else {
        f64::from(LE) * polygon_irradiance(p, light_corners().map(Vec3::as_dvec3))
    };
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
fn expected_image(cam: &PinholeCamera, textured: bool) -> Vec<Option<(f64, f64)>> {
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
                    sum += exact_radiance(p, textured);
                    centre_dist += (p.x * p.x + p.z * p.z).sqrt();
                }
            }
            let n = f64::from(k * k);
            out.push(ok.then_some((sum / n, centre_dist / n)));
        }
    }
    out
}

/// The light's texture: [`texel`] as an 8x8 image, nearest filtering.
fn light_texture() -> Texture {
    use pt::pt_core::texture::{Filter, Sampling, Wrap};
    let mut img = Image::new(TEXELS as u32, TEXELS as u32);
    for j in 0..TEXELS {
        for i in 0..TEXELS {
            img.set(i as u32, j as u32, Rgb::splat(texel(i, j)));
        }
    }
    Texture::new(img).with_sampling(Sampling {
        wrap_u: Wrap::ClampToEdge,
        wrap_v: Wrap::ClampToEdge,
        filter: Filter::Nearest,
    })
}

fn scene(solid_angle: bool, textured: bool) -> Scene {
    let mut b = SceneBuilder::new();
    b.solid_angle_light_sampling(solid_angle);
    let plane = b.add_mesh(quad([
        Vec3::new(-10.0, 0.0, -10.0),
        Vec3::new(-10.0, 0.0, 10.0),
        Vec3::new(10.0, 0.0, 10.0),
        Vec3::new(10.0, 0.0, -10.0),
    ]));
    // Texture coordinates: u along x, v along z.
    let uvs = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)].map(|(u, v)| Vec2::new(u, v));
    let lamp = b.add_mesh(quad(light_corners()).with_uvs(uvs.to_vec()).unwrap());
    let grey = b.add_material(BuiltinMaterial::diffuse(Rgb::splat(RHO)));
    let black = b.add_material(BuiltinMaterial::diffuse(Rgb::BLACK));
    b.add_object(Object::new(plane, grey));
    let mut emission = Emission::new(Rgb::splat(LE));
    if textured {
        emission = emission.with_texture(light_texture());
    }
    b.add_object(Object::new(lamp, black).with_emission(emission));
    let scene = b.build().unwrap();
    assert_eq!(scene.lights().len(), 2);
    for light in scene.lights() {
        match light {
            BuiltinLight::Triangle(t) if !textured => {
                assert_eq!(t.solid_angle_sampling(), solid_angle);
            }
            // Each triangle covers 32 texels: 3 cells per edge (n = ceil(sqrt(32 / 4))).
            BuiltinLight::TexturedTriangle(t) if textured => assert_eq!(t.subdivision(), 3),
            other => panic!("only the lamp's triangles emit: {other:?}"),
        }
    }
    scene
}

fn check(strategy: LightStrategy, spp: u32, max_depth: u32, solid_angle: bool, textured: bool) {
    let cam = camera();
    let expected = expected_image(&cam, textured);
    let opts = RenderOptions::new(SIZE, SIZE)
        .spp(spp)
        .max_depth(max_depth)
        .seed(3)
        .strategy(strategy);
    let out = render(&scene(solid_angle, textured), &cam, &opts, None).unwrap();
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
            "{strategy:?}{} ring {k}: {} pixels, mean relative error {mean:+.5} (tolerance {tol:.5})",
            if textured { " textured" } else { "" },
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
    check(LightStrategy::Mis, 64, 5, false, false);
}

#[test]
fn plane_under_square_light_with_mis_and_solid_angle_sampling() {
    check(LightStrategy::Mis, 64, 5, true, false);
}

#[test]
fn plane_under_square_light_with_solid_angle_light_sampling() {
    check(LightStrategy::LightOnly, 64, 1, true, false);
}

#[test]
fn plane_under_square_light_with_light_sampling() {
    check(LightStrategy::LightOnly, 64, 1, false, false);
}

#[test]
fn plane_under_square_light_with_bsdf_sampling() {
    check(LightStrategy::BsdfOnly, 512, 5, false, false);
}

#[test]
fn plane_under_textured_light_with_mis() {
    check(LightStrategy::Mis, 64, 5, false, true);
}

#[test]
fn plane_under_textured_light_with_light_sampling() {
    check(LightStrategy::LightOnly, 64, 1, false, true);
}

#[test]
fn plane_under_textured_light_with_bsdf_sampling() {
    check(LightStrategy::BsdfOnly, 512, 5, false, true);
}
