//! Render any scene file: glTF 2.0 (`.gltf`, `.glb`), OBJ with MTL materials, or a PLY mesh.
//!
//! ```text
//! cargo run --release --example render -- scene.glb
//! cargo run --release --example render -- model.obj --look-from 0,1,4 --look-at 0,0.5,0 --fov 35
//! cargo run --release --example render -- model.glb --env ../shared/assets/env/venice_sunset_1k.hdr
//! ```
//!
//! The camera is the file's first camera when it has one (`--camera-from-file` says so
//! explicitly), else `--look-from/--look-at/--up/--fov`, else one that frames the scene (with a
//! warning when that camera sees mostly back faces: it is inside the model, or outside a closed
//! one). The environment is `--env` (an equirectangular `.hdr`/`.exr`, a cube-map directory, or
//! `sunset`, `studio`, `cubemap` from the assets). Without `--env`, a scene with no lights of its
//! own, and a glTF file without punctual lights (whose emissive materials are meant to be seen
//! under a viewer's light), is lit as glTF viewers light it, by the studio map (fetched like any
//! asset; a uniform white sky when it cannot be had), and the summary says so; `--env none`
//! keeps it dark.

mod common;

use common::{Defaults, Flag, die, parse_with_file};
use pt::prelude::*;
use pt::pt_core::{BuiltinLight, Camera, CameraSample, Scene, UniformEnvironment};
use pt::pt_scene::BuildOptions;

const NAME: &str = "render";

fn vec3(args: &common::Args, name: &str) -> Option<Vec3> {
    args.value(name).map(|v| {
        common::parse_vec3(v).unwrap_or_else(|| {
            common::bad_input(
                NAME,
                format!("--{name} expects three numbers X,Y,Z, got {v:?}"),
            )
        })
    })
}

fn environment(spec: &str, intensity: f32) -> BuiltinLight {
    let light: Result<BuiltinLight, pt::pt_scene::LoadError> = match spec {
        "sunset" => pt::pt_scene::load_equirect_asset("env/venice_sunset_1k.hdr").map(Into::into),
        "studio" => pt::pt_scene::load_equirect_asset("env/studio_small_03_1k.hdr").map(Into::into),
        "cubemap" => pt::pt_scene::load_cubemap_asset("env/cubemap-Park3Med").map(Into::into),
        path if std::path::Path::new(path).is_dir() => pt::pt_scene::load_cubemap(path)
            .map(Into::into)
            .map_err(|e| common::bad_input(NAME, e)),
        path => pt::pt_scene::load_equirect(path)
            .map(Into::into)
            .map_err(|e| common::bad_input(NAME, e)),
    };
    // A named asset that cannot be had is a failure of the run (exit 1); a bad file named on
    // the command line is bad input (exit 2, above).
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
                name: "two-sided-lights",
                value: None,
                help: "emitting surfaces emit from both faces (as Blender Cycles does)",
            },
            Flag {
                name: "solid-angle-lights",
                value: None,
                help: "sample emitting triangles by solid angle (less noise near large lights)",
            },
        ],
    );
    let desc = pt::pt_scene::load_scene(&file).unwrap_or_else(|e| common::bad_input(NAME, e));
    let mut options = BuildOptions::default();
    let explicit = args.given("look-from") || args.given("look-at") || args.given("fov");
    if explicit && !args.flag("camera-from-file") {
        let from = vec3(&args, "look-from").unwrap_or(Vec3::new(0.0, 0.0, 5.0));
        let at = vec3(&args, "look-at").unwrap_or(Vec3::ZERO);
        let up = vec3(&args, "up").unwrap_or(Vec3::Y);
        let fov: f32 = args.parsed("fov", "degrees in (0, 180)").unwrap_or(40.0);
        options.camera = Some(
            PinholeCamera::look_at(from, at, up, fov)
                .unwrap_or_else(|e| common::bad_input(NAME, format!("camera: {e}"))),
        );
    } else if args.flag("camera-from-file") {
        // Asked for, the file's camera must be usable: an invalid one is an error, not a
        // silent switch to the framing camera (build() only warns when it was not asked for).
        match desc.try_file_camera() {
            Ok(Some(camera)) => options.camera = Some(camera),
            Ok(None) => log::warn!("{} has no camera; framing the scene", file.display()),
            Err(e) => {
                eprintln!("{NAME}: --camera-from-file: {e}");
                std::process::exit(2)
            }
        }
    }
    let intensity: f32 = args.parsed("env-intensity", "a number >= 0").unwrap_or(1.0);
    let mut lit_by = String::new();
    match args.value("env") {
        Some("none") => {}
        Some(env) => options.environment = Some(environment(env, intensity)),
        // glTF viewers light a file by their environment unless it brings punctual lights: its
        // emissive materials (labels, screens) are meant to be seen under that light too. So a
        // glTF file without punctual lights gets the default environment, as does any file
        // without emitters at all.
        None if !desc.has_lights() || (is_gltf(&file) && desc.lights.is_empty()) => {
            let (light, what) = default_environment(intensity);
            options.environment = Some(light);
            let why = if desc.has_lights() {
                "no punctual lights in the glTF file"
            } else {
                "no lights in the file"
            };
            lit_by = format!(", {why}: lit by {what} (--env none for none)");
        }
        None => {}
    }
    options.solid_angle_light_sampling = args.flag("solid-angle-lights");
    options.two_sided_lights = args.flag("two-sided-lights");
    let framing = options.camera.is_none() && desc.file_camera().is_none();
    let bundle = desc.build(&options).unwrap_or_else(|e| die(NAME, e));
    if framing {
        let aspect = args.options.width as f32 / args.options.height.max(1) as f32;
        let back = back_face_fraction(&bundle.scene, &bundle.camera, aspect);
        if back > 0.5 {
            log::warn!(
                "{}: {:.0}% of what the framing camera sees are back faces: it is inside the model \
                 or outside a room; pass --look-from X,Y,Z --look-at X,Y,Z (and --fov)",
                file.display(),
                back * 100.0
            );
        }
    }
    let stats = bundle.scene.stats();
    let out = common::render(&args, &bundle.scene, &bundle.camera);
    common::finish(
        &args,
        &out,
        &format!(
            ", {}: {} meshes, {} objects, {} lights{lit_by}",
            file.display(),
            stats.meshes,
            stats.objects,
            stats.lights
        ),
    );
}

fn is_gltf(file: &std::path::Path) -> bool {
    file.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("gltf") || e.eq_ignore_ascii_case("glb"))
}

/// The studio map glTF viewers light with, fetched like any asset; a uniform white sky when it
/// cannot be had (offline, say), with a warning saying why.
fn default_environment(intensity: f32) -> (BuiltinLight, &'static str) {
    const STUDIO: &str = "env/studio_small_03_1k.hdr";
    let studio = pt::pt_scene::load_equirect_asset(STUDIO)
        .map_err(|e| e.to_string())
        .and_then(|m| m.with_scale(intensity).map_err(|e| e.to_string()));
    match studio {
        Ok(m) => (m.into(), "the studio environment"),
        Err(e) => {
            log::warn!(
                "the default environment {STUDIO} is not available ({e}); using a uniform sky"
            );
            let sky = UniformEnvironment::new(Rgb::splat(intensity)).unwrap_or_else(|e| {
                eprintln!("{NAME}: --env-intensity: {e}");
                std::process::exit(2)
            });
            (sky.into(), "a uniform white sky")
        }
    }
}

/// Of a 16x16 grid of primary rays, the fraction of those that hit something that hit a surface
/// from behind (against its geometric normal): near 1 when the camera is inside a model or
/// outside a room. 0 when nothing is hit.
fn back_face_fraction<C: Camera>(scene: &Scene, camera: &C, aspect: f32) -> f32 {
    let n = 16;
    let (mut back, mut hits) = (0, 0);
    for j in 0..n {
        for i in 0..n {
            let film = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
            let ray = camera.generate_ray(&CameraSample::new(film, aspect));
            if let Some(hit) = scene.intersect(&ray) {
                hits += 1;
                if hit.point.n.dot(ray.dir) > 0.0 {
                    back += 1;
                }
            }
        }
    }
    back as f32 / hits.max(1) as f32
}
