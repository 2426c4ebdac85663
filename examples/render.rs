//! Render any scene file: glTF 2.0 (`.gltf`, `.glb`), OBJ with MTL materials, or a PLY mesh.
//!
//! ```text
//! cargo run --release --example render -- scene.glb
//! cargo run --release --example render -- model.obj --look-from 0,1,4 --look-at 0,0.5,0 --fov 35
//! cargo run --release --example render -- model.glb --env ../shared/assets/env/venice_sunset_1k.hdr
//! ```
//!
//! The camera is the file's first camera when it has one (`--camera-from-file` says so
//! explicitly), else `--look-from/--look-at/--up/--fov`, else one that frames the scene. Without
//! lights of its own a scene is dark: give it an environment with `--env` (an equirectangular
//! `.hdr`/`.exr`, a cube-map directory, or `sunset`, `studio`, `cubemap` from the assets).

mod common;

use common::{Defaults, Flag, die, parse_with_file};
use pt::prelude::*;
use pt::pt_core::BuiltinLight;
use pt::pt_scene::BuildOptions;

const NAME: &str = "render";

fn vec3(args: &common::Args, name: &str) -> Option<Vec3> {
    args.value(name).map(|v| {
        let parts: Vec<f32> = v.split(',').filter_map(|x| x.trim().parse().ok()).collect();
        if parts.len() != 3 || parts.iter().any(|x| !x.is_finite()) {
            eprintln!("{NAME}: --{name} expects x,y,z, got {v:?}");
            std::process::exit(2)
        }
        Vec3::new(parts[0], parts[1], parts[2])
    })
}

fn environment(spec: &str, intensity: f32) -> BuiltinLight {
    let light: Result<BuiltinLight, pt::pt_scene::LoadError> = match spec {
        "sunset" => pt::pt_scene::load_equirect_asset("env/venice_sunset_1k.hdr").map(Into::into),
        "studio" => pt::pt_scene::load_equirect_asset("env/studio_small_03_1k.hdr").map(Into::into),
        "cubemap" => pt::pt_scene::load_cubemap_asset("env/cubemap-Park3Med").map(Into::into),
        path if std::path::Path::new(path).is_dir() => {
            pt::pt_scene::load_cubemap(path).map(Into::into)
        }
        path => pt::pt_scene::load_equirect(path).map(Into::into),
    };
    let light = light.unwrap_or_else(|e| die(NAME, e));
    let scaled = match light {
        BuiltinLight::EquirectEnvironment(m) => m.with_scale(intensity).map(Into::into),
        BuiltinLight::CubemapEnvironment(m) => m.with_scale(intensity).map(Into::into),
        other => Ok(other),
    };
    scaled.unwrap_or_else(|e| {
        eprintln!("{NAME}: {e}");
        std::process::exit(2)
    })
}

fn main() {
    let (args, file) = parse_with_file(
        NAME,
        Defaults {
            width: 640,
            height: 480,
            spp: 64,
            max_depth: 16,
            out: "out/render.png",
        },
        &[
            Flag {
                name: "camera-from-file",
                value: None,
                help: "use the file's first camera (the default when it has one)",
            },
            Flag {
                name: "look-from",
                value: Some("X,Y,Z"),
                help: "camera position",
            },
            Flag {
                name: "look-at",
                value: Some("X,Y,Z"),
                help: "point the camera looks at",
            },
            Flag {
                name: "up",
                value: Some("X,Y,Z"),
                help: "up direction (default 0,1,0)",
            },
            Flag {
                name: "fov",
                value: Some("DEG"),
                help: "vertical field of view (default 40)",
            },
            Flag {
                name: "env",
                value: Some("ENV"),
                help: "environment: .hdr/.exr file, cube-map directory, sunset, studio or cubemap",
            },
            Flag {
                name: "env-intensity",
                value: Some("S"),
                help: "multiply the environment's radiance (default 1)",
            },
            Flag {
                name: "solid-angle-lights",
                value: None,
                help: "sample emitting triangles by solid angle (less noise near large lights)",
            },
        ],
    );
    let desc = pt::pt_scene::load_scene(&file).unwrap_or_else(|e| die(NAME, e));
    let mut options = BuildOptions::default();
    let explicit = args.given("look-from") || args.given("look-at") || args.given("fov");
    if explicit && !args.flag("camera-from-file") {
        let from = vec3(&args, "look-from").unwrap_or(Vec3::new(0.0, 0.0, 5.0));
        let at = vec3(&args, "look-at").unwrap_or(Vec3::ZERO);
        let up = vec3(&args, "up").unwrap_or(Vec3::Y);
        let fov: f32 = args.parsed("fov", "degrees in (0, 180)").unwrap_or(40.0);
        options.camera =
            Some(PinholeCamera::look_at(from, at, up, fov).unwrap_or_else(|e| die(NAME, e)));
    } else if args.flag("camera-from-file") && desc.cameras.is_empty() {
        eprintln!(
            "{NAME}: {} has no camera; framing the scene",
            file.display()
        );
    }
    if let Some(env) = args.value("env") {
        let intensity: f32 = args.parsed("env-intensity", "a number >= 0").unwrap_or(1.0);
        options.environment = Some(environment(env, intensity));
    }
    options.solid_angle_light_sampling = args.flag("solid-angle-lights");
    let bundle = desc.build(&options).unwrap_or_else(|e| die(NAME, e));
    let stats = bundle.scene.stats();
    let out = common::render(&args, &bundle.scene, &bundle.camera);
    common::finish(
        &args,
        &out,
        &format!(
            ", {}: {} meshes, {} objects, {} lights",
            file.display(),
            stats.meshes,
            stats.objects,
            stats.lights
        ),
    );
}
