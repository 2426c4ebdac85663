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

use clap::Parser;
use pt_cli::{Defaults, Failure, Job, RenderArgs};

const NAME: &str = "env_lighting";

/// The Stanford bunny lit only by an environment, importance sampled.
#[derive(Parser)]
struct Cli {
    #[command(flatten)]
    render: RenderArgs,
    /// Environment: cubemap, sunset, studio, or a .hdr/.exr file
    #[arg(long, value_name = "ENV", default_value = "cubemap")]
    env: String,
    /// Multiply the environment's radiance
    #[arg(long, value_name = "S", default_value_t = 1.0)]
    env_scale: f32,
    /// Turn the environment about the vertical axis, in degrees
    #[arg(
        long,
        value_name = "DEG",
        default_value_t = 0.0,
        allow_hyphen_values = true
    )]
    env_rotate: f32,
    /// Add a mirror sphere and a glass sphere
    #[arg(long)]
    spheres: bool,
}

const DEFAULTS: Defaults = Defaults {
    width: 640,
    height: 480,
    spp: 256,
    max_depth: 16,
    out: "out/env_lighting.png",
};

fn main() {
    let cli: Cli = pt_cli::parse(NAME, DEFAULTS);
    let extra = format!(
        "env {} scale {} rotate {} spheres {}",
        cli.env, cli.env_scale, cli.env_rotate, cli.spheres
    );
    let job = Job::new(NAME, &cli.render, &DEFAULTS, &extra).unwrap_or_else(|f| f.exit());
    let bundle =
        pt::pt_scene::presets::env_lighting(&cli.env, cli.env_scale, cli.env_rotate, cli.spheres)
            .unwrap_or_else(|e| Failure::usage(e).exit());
    let (scene, camera) = (bundle.scene, bundle.camera);
    let out = job.render(&scene, &camera);
    job.finish(&out, &format!(", environment {}", cli.env));
}
