//! Figure 4 of the report: the Stanford bunny lit only by its surroundings, a cube map sky box
//! (the report's method) or an HDR environment map, both importance sampled; the background
//! shows the environment.
//!
//! ```text
//! cargo run --release --example env_lighting                      # Park3Med cube map
//! cargo run --release --example env_lighting -- --env sunset      # venice_sunset_1k.hdr
//! cargo run --release --example env_lighting -- --env studio --spheres
//! cargo run --release --example env_lighting -- --env my_map.exr --env-rotate 90
//! ```
//!
//! `--spheres` adds a mirror sphere and a glass sphere beside the bunny. Needs the assets: set
//! `PT_ASSETS_DIR` (see README).

mod common;

use common::{Defaults, Flag, die, parse};
use pt::prelude::*;
use pt::pt_core::BuiltinLight;
use pt::pt_core::glam::Mat3;
use pt::pt_scene::shapes::sphere;

const NAME: &str = "env_lighting";

fn environment(name: &str, scale: f32, rotate_deg: f32) -> BuiltinLight {
    let rotation = Mat3::from_rotation_y(rotate_deg.to_radians());
    let fail = |e: &dyn std::fmt::Display| -> ! {
        eprintln!("{NAME}: {e}");
        std::process::exit(2)
    };
    match name {
        "cubemap" => pt::pt_scene::load_cubemap_asset("env/cubemap-Park3Med")
            .unwrap_or_else(|e| die(NAME, e))
            .with_rotation(rotation)
            .and_then(|m| m.with_scale(scale))
            .unwrap_or_else(|e| fail(&e))
            .into(),
        other => {
            let map = match other {
                "sunset" => pt::pt_scene::load_equirect_asset("env/venice_sunset_1k.hdr"),
                "studio" => pt::pt_scene::load_equirect_asset("env/studio_small_03_1k.hdr"),
                path => pt::pt_scene::load_equirect(path),
            };
            map.unwrap_or_else(|e| die(NAME, e))
                .with_rotation(rotation)
                .and_then(|m| m.with_scale(scale))
                .unwrap_or_else(|e| fail(&e))
                .into()
        }
    }
}

fn main() {
    let args = parse(
        NAME,
        Defaults {
            width: 640,
            height: 480,
            spp: 256,
            max_depth: 16,
            out: "out/env_lighting.png",
        },
        &[
            Flag {
                name: "env",
                value: Some("ENV"),
                help: "cubemap (default), sunset, studio, or a .hdr/.exr file",
            },
            Flag {
                name: "env-scale",
                value: Some("S"),
                help: "multiply the environment's radiance (default 1)",
            },
            Flag {
                name: "env-rotate",
                value: Some("DEG"),
                help: "turn the environment about the vertical axis (default 0)",
            },
            Flag {
                name: "spheres",
                value: None,
                help: "add a mirror sphere and a glass sphere",
            },
        ],
    );
    let env_name = args.value("env").unwrap_or("cubemap").to_string();
    let scale: f32 = args.parsed("env-scale", "a number >= 0").unwrap_or(1.0);
    let rotate: f32 = args
        .parsed("env-rotate", "an angle in degrees")
        .unwrap_or(0.0);

    let mut b = SceneBuilder::new();
    let bunny = pt::pt_scene::load_mesh_asset("meshes/stanford-bunny.obj")
        .unwrap_or_else(|e| die(NAME, e))
        .with_smooth_normals();
    // One unit tall, standing at the origin, facing the camera.
    let bb = bunny.geometry().bounds();
    let s = 1.0 / (bb.max.y - bb.min.y);
    let base = Vec3::new(
        (bb.min.x + bb.max.x) * 0.5,
        bb.min.y,
        (bb.min.z + bb.max.z) * 0.5,
    );
    let place = Affine3A::from_rotation_y(std::f32::consts::PI)
        * Affine3A::from_scale(Vec3::splat(s))
        * Affine3A::from_translation(-base);
    let bunny = b.add_mesh(bunny);
    let clay = b.add_material(BuiltinMaterial::diffuse(Rgb::splat(0.75)));
    b.add_object(Object::new(bunny, clay).with_transform(place));
    if args.flag("spheres") {
        let ball = b.add_mesh(sphere(0.35, 48, 96));
        let mirror = b.add_material(Mirror::new(Rgb::splat(0.95)));
        let glass = b.add_material(Glass::new(1.5).unwrap_or_else(|e| die(NAME, e)));
        b.add_object(
            Object::new(ball, mirror)
                .with_transform(Affine3A::from_translation(Vec3::new(-1.0, 0.35, 0.2))),
        );
        b.add_object(
            Object::new(ball, glass)
                .with_transform(Affine3A::from_translation(Vec3::new(1.0, 0.35, 0.2))),
        );
    }
    b.add_light(environment(&env_name, scale, rotate));
    let scene = b.build().unwrap_or_else(|e| die(NAME, e));
    let aspect_fov = if args.flag("spheres") { 50.0 } else { 40.0 };
    let camera = PinholeCamera::look_at(
        Vec3::new(0.0, 0.9, 2.6),
        Vec3::new(0.0, 0.45, 0.0),
        Vec3::Y,
        aspect_fov,
    )
    .unwrap_or_else(|e| die(NAME, e));
    let out = common::render(&args, &scene, &camera);
    common::finish(&args, &out, &format!(", environment {env_name}"));
}
