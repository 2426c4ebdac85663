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
//! `--spheres` adds a mirror sphere and a glass sphere beside the bunny. The bunny and the maps are
//! fetched on first use (see README, Assets).

mod common;

use common::{Defaults, Flag, parse};

const NAME: &str = "env_lighting";

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

    let bundle =
        pt::pt_scene::presets::env_lighting(&env_name, scale, rotate, args.flag("spheres"))
            .unwrap_or_else(|e| {
                eprintln!("{NAME}: {e}");
                std::process::exit(2)
            });
    let (scene, camera) = (bundle.scene, bundle.camera);
    let out = common::render(&args, &scene, &camera);
    common::finish(&args, &out, &format!(", environment {env_name}"));
}
