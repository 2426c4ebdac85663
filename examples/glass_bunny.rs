//! Figure 3 of the report: the Cornell box with a glass Stanford bunny (eta 1.5, smooth vertex
//! normals); `--roughness R` makes it frosted (GGX rough dielectric).
//!
//! ```text
//! cargo run --release --example glass_bunny
//! cargo run --release --example glass_bunny -- --roughness 0.2
//! cargo run --release --example glass_bunny -- --eta 1.33 --spp 1024
//! ```
//!
//! The caustic under the bunny (light focused through the glass onto the floor) can only be
//! found by BSDF sampling from the floor through the glass to the light, so it converges more
//! slowly than the rest of the image. The bunny is fetched on first use (see README, Assets).

use clap::Parser;
use pt::pt_accel::AccelKind;
use pt::pt_core::Glass;
use pt_cli::{Defaults, Failure, Job, RenderArgs};

const NAME: &str = "glass_bunny";

/// The Cornell box with a glass Stanford bunny.
#[derive(Parser)]
struct Cli {
    #[command(flatten)]
    render: RenderArgs,
    /// GGX roughness in [0, 1] (0: smooth glass)
    #[arg(long, value_name = "R", default_value_t = 0.0)]
    roughness: f32,
    /// Index of refraction
    #[arg(long, value_name = "ETA", default_value_t = 1.5)]
    eta: f32,
}

const DEFAULTS: Defaults = Defaults {
    width: 512,
    height: 512,
    spp: 128,
    max_depth: 16,
    out: "out/glass_bunny.png",
};

fn main() {
    let cli: Cli = pt_cli::parse(NAME, DEFAULTS);
    let (eta, roughness) = (cli.eta, cli.roughness);
    let extra = format!("eta {eta} roughness {roughness}");
    let job = Job::new(NAME, &cli.render, &DEFAULTS, &extra).unwrap_or_else(|f| f.exit());
    let glass = Glass::new(eta)
        .and_then(|g| g.with_roughness(roughness))
        .unwrap_or_else(|e| Failure::usage(e).exit());
    let bundle = pt::pt_scene::presets::bunny_in_box(Some(glass.into()), AccelKind::Auto)
        .unwrap_or_else(|e| Failure::run(e).exit());
    let out = job.render(&bundle.scene, &bundle.camera);
    job.finish(
        &out,
        &format!(", bunny: glass, eta {eta}, roughness {roughness}"),
    );
}
