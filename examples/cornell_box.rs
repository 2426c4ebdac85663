//! The diffuse Cornell box (the report's base figure), from Cornell's measured data, with or
//! without a BVH (`--accel brute` tests every triangle for every ray, the report's "without").
//!
//! `cargo run --release --example cornell_box -- --spp 256 --out out/cornell_box.png`

use clap::Parser;
use pt::pt_accel::AccelKind;
use pt_cli::{Defaults, Failure, Job, RenderArgs};

const NAME: &str = "cornell_box";

/// The diffuse Cornell box, from Cornell's measured data.
#[derive(Parser)]
struct Cli {
    #[command(flatten)]
    render: RenderArgs,
    /// Accelerator: auto, bvh, two-level or brute (no acceleration structure)
    #[arg(long, value_name = "KIND", default_value = "auto", value_parser = pt_cli::args::parse_accel)]
    accel: AccelKind,
}

const DEFAULTS: Defaults = Defaults {
    width: 512,
    height: 512,
    spp: 128,
    max_depth: 16,
    out: "out/cornell_box.png",
};

fn main() {
    let cli: Cli = pt_cli::parse(NAME, DEFAULTS);
    let job = Job::new(NAME, &cli.render, &DEFAULTS, "").unwrap_or_else(|f| f.exit());
    let bundle = pt::pt_scene::presets::cornell_box_with(cli.accel)
        .unwrap_or_else(|e| Failure::run(e).exit());
    let out = job.render(&bundle.scene, &bundle.camera);
    let accel = bundle.scene.stats().accel.kind;
    job.finish(&out, &format!(", accel {accel}"));
}
