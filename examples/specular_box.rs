//! Figure 2a of the report: the Cornell box with the tall block as an ideal mirror.
//!
//! ```text
//! cargo run --release --example specular_box
//! cargo run --release --example specular_box -- --spp 1024 --out out/specular_box.exr
//! ```
//!
//! The mirror shows the room, the light and the short block; light reflected by the mirror onto
//! the walls and floor (a caustic) is found by BSDF sampling, since next-event estimation cannot
//! sample a path through a delta reflection.

use clap::Parser;
use pt_cli::{Defaults, Failure, Job, RenderArgs};

const NAME: &str = "specular_box";

/// The Cornell box with the tall block as an ideal mirror.
#[derive(Parser)]
struct Cli {
    #[command(flatten)]
    render: RenderArgs,
}

const DEFAULTS: Defaults = Defaults {
    width: 512,
    height: 512,
    spp: 128,
    max_depth: 16,
    out: "out/specular_box.png",
};

fn main() {
    let cli: Cli = pt_cli::parse(NAME, DEFAULTS);
    let job = Job::new(NAME, &cli.render, &DEFAULTS, "").unwrap_or_else(|f| f.exit());
    let bundle = pt::pt_scene::presets::specular_box().unwrap_or_else(|e| Failure::run(e).exit());
    let out = job.render(&bundle.scene, &bundle.camera);
    job.finish(&out, ", tall block: ideal mirror");
}
