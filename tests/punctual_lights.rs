//! Point, spot and directional lights against closed forms: a diffuse plane of albedo `rho` lit
//! by a delta light reflects `L = rho / pi * E`, with irradiance `E = I f cos / d^2` (point, spot
//! with falloff `f`) or `E = E0 cos` (directional). Delta lights are sampled exactly, so the only
//! noise is the pixel jitter (1024 random positions per pixel): each pixel is compared with the
//! closed form averaged over a 16x16 grid of positions in the pixel, within 1% (2e-3 absolute
//! where the value is near zero), and the image mean within 0.2%.

use pt::prelude::*;
use pt::pt_core::{BuiltinLight, Camera, CameraSample, DirectionalLight, PointLight, SpotLight};
use pt::pt_scene::shapes::quad;

const RHO: f32 = 0.5;

fn check(label: &str, light: BuiltinLight, irradiance: impl Fn(Vec3) -> f32) {
    let mut b = SceneBuilder::new();
    let s = 3.0;
    let plane = b.add_mesh(quad([
        Vec3::new(-s, 0.0, -s),
        Vec3::new(-s, 0.0, s),
        Vec3::new(s, 0.0, s),
        Vec3::new(s, 0.0, -s),
    ]));
    let m = b.add_material(BuiltinMaterial::diffuse(Rgb::splat(RHO)));
    b.add_object(Object::new(plane, m));
    b.add_light(light);
    let scene = b.build().unwrap();
    let camera =
        PinholeCamera::look_at(Vec3::new(0.0, 4.0, 0.0), Vec3::ZERO, Vec3::Z, 60.0).unwrap();
    let (w, h) = (32u32, 32u32);
    let out = render(
        &scene,
        &camera,
        &RenderOptions::new(w, h).spp(1024).max_depth(1).seed(2),
        None,
    )
    .unwrap();
    let (mut sum_img, mut sum_ref) = (0.0f64, 0.0f64);
    for y in 0..h {
        for x in 0..w {
            let mut expected = 0.0f64;
            for k in 0..256 {
                let film = Vec2::new(
                    (x as f32 + ((k % 16) as f32 + 0.5) / 16.0) / w as f32,
                    (y as f32 + ((k / 16) as f32 + 0.5) / 16.0) / h as f32,
                );
                let ray = camera.generate_ray(&CameraSample::new(film, 1.0));
                let t = -ray.origin.y / ray.dir.y;
                let p = ray.origin + ray.dir * t;
                expected += f64::from(RHO / std::f32::consts::PI * irradiance(p)) / 256.0;
            }
            let got = f64::from(out.image.get(x, y).g);
            sum_img += got;
            sum_ref += expected;
            assert!(
                (got - expected).abs() <= 0.01 * expected + 2e-3,
                "{label}: pixel ({x}, {y}) = {got}, expected {expected}"
            );
        }
    }
    println!("{label}: image mean {sum_img:.4}, closed form {sum_ref:.4}");
    assert!(
        (sum_img - sum_ref).abs() <= 2e-3 * sum_ref,
        "{label}: means differ"
    );
}

#[test]
fn point_light_inverse_square_law() {
    let pos = Vec3::new(0.3, 1.0, -0.2);
    let i = 3.0;
    let light = PointLight::new(pos, Rgb::splat(i)).unwrap();
    check("point", light.into(), |p| {
        let to = pos - p;
        i * to.y / to.length().powi(3)
    });
}

#[test]
fn spot_light_cone_and_falloff() {
    let pos = Vec3::new(0.0, 1.5, 0.0);
    let i = 4.0;
    let spot = SpotLight::new(pos, Vec3::NEG_Y, Rgb::splat(i), 0.3, 0.6).unwrap();
    check("spot", spot.into(), move |p| {
        let to = pos - p;
        let d = to.length();
        // glTF's recommended falloff, written out here independently of the light's code.
        let cos = (-to / d).dot(Vec3::NEG_Y);
        let t = ((cos - 0.6f32.cos()) / (0.3f32.cos() - 0.6f32.cos())).clamp(0.0, 1.0);
        i * t * t * to.y / d.powi(3)
    });
}

#[test]
fn directional_light_cosine_law() {
    let dir = Vec3::new(0.3, -1.0, 0.4).normalize();
    let e = 2.0;
    let light = DirectionalLight::new(dir, Rgb::splat(e)).unwrap();
    check("directional", light.into(), |_| e * -dir.y);
}
