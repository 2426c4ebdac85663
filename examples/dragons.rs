//! The advanced-BVH figure: 110 instances of the 202,520-triangle Stanford dragon, with varied
//! placements, sizes and diffuse colours, on a floor under an area light, rendered through the
//! two-level BVH (one BVH for the dragon, a top-level BVH over the instances).
//!
//! ```text
//! cargo run --release --example dragons
//! cargo run --release --example dragons -- --accel bvh    # one flat BVH over all 22 million triangles
//! cargo run --release --example dragons -- --layout-seed 7 # another arrangement of the dragons
//! ```
//!
//! The arrangement (placements, sizes, colours) follows `--layout-seed`, not `--seed`: renders
//! with different sampling seeds, or parts of one render, are of the same scene.
//!
//! The summary line adds the instance count, unique and instanced triangles, and the
//! accelerator's memory. The dragon is fetched on first use (see README, Assets).

use clap::Parser;
use pt::pt_accel::AccelKind;
use pt_cli::{Defaults, Failure, Job, RenderArgs};

const NAME: &str = "dragons";

/// 110 instanced Stanford dragons through the two-level BVH.
#[derive(Parser)]
struct Cli {
    #[command(flatten)]
    render: RenderArgs,
    /// Accelerator: two-level, bvh (one flat BVH over all triangles) or auto
    #[arg(long, value_name = "KIND", default_value = "two-level", value_parser = parse_accel)]
    accel: AccelKind,
    /// Seed of the dragons' placements, sizes and colours (independent of --seed)
    #[arg(long, value_name = "S", default_value_t = 0)]
    layout_seed: u64,
}

fn parse_accel(v: &str) -> Result<AccelKind, String> {
    match v {
        "two-level" => Ok(AccelKind::TwoLevel),
        "bvh" => Ok(AccelKind::Bvh),
        "auto" => Ok(AccelKind::Auto),
        other => Err(format!("expects two-level, bvh or auto, got {other:?}")),
    }
}

const DEFAULTS: Defaults = Defaults {
    width: 640,
    height: 360,
    spp: 128,
    max_depth: 8,
    out: "out/dragons.png",
};

fn main() {
    let cli: Cli = pt_cli::parse(NAME, DEFAULTS);
    let extra = format!("accel {:?} layout-seed {}", cli.accel, cli.layout_seed);
    let job = Job::new(NAME, &cli.render, &DEFAULTS, &extra).unwrap_or_else(|f| f.exit());
    let (bundle, unique) = pt::pt_scene::presets::dragons(cli.accel, cli.layout_seed)
        .unwrap_or_else(|e| Failure::run(e).exit());
    let (scene, camera) = (bundle.scene, bundle.camera);
    let out = job.render(&scene, &camera);
    let s = scene.stats();
    let note = format!(
        ", {} dragon instances, {unique} unique triangles, {} instanced triangles, accel {} using {:.1} MiB (built in {:.2} s)",
        pt::pt_scene::presets::DRAGONS,
        s.instanced_triangles,
        s.accel.kind,
        s.accel.memory_bytes as f64 / f64::from(1 << 20),
        s.accel.build_time.as_secs_f64()
    );
    job.finish(&out, &note);
}
