//! The advanced-BVH figure: 110 instances of the 202,520-triangle Stanford dragon, with varied
//! placements, sizes and diffuse colours, on a floor under an area light, rendered through the
//! two-level BVH (one BVH for the dragon, a top-level BVH over the instances).
//!
//! ```text
//! cargo run --release --example dragons
//! cargo run --release --example dragons -- --accel bvh    # one flat BVH over all 22 million triangles
//! ```
//!
//! The summary line adds the instance count, unique and instanced triangles, and the
//! accelerator's memory. The dragon is fetched on first use (see README, Assets).

mod common;

use common::{Defaults, Flag, die, parse};
use pt::pt_accel::AccelKind;

const NAME: &str = "dragons";
fn main() {
    let args = parse(
        NAME,
        Defaults {
            width: 640,
            height: 360,
            spp: 128,
            max_depth: 8,
            out: "out/dragons.png",
        },
        &[Flag {
            name: "accel",
            value: Some("KIND"),
            help: "two-level (default), bvh (flat), or auto",
        }],
    );
    let accel = match args.value("accel").unwrap_or("two-level") {
        "two-level" => AccelKind::TwoLevel,
        "bvh" => AccelKind::Bvh,
        "auto" => AccelKind::Auto,
        other => {
            eprintln!("{NAME}: --accel expects two-level, bvh or auto, got {other:?}");
            std::process::exit(2)
        }
    };

    let (bundle, unique) =
        pt::pt_scene::presets::dragons(accel, args.options.seed).unwrap_or_else(|e| die(NAME, e));
    let (scene, camera) = (bundle.scene, bundle.camera);
    let out = common::render(&args, &scene, &camera);
    let s = scene.stats();
    let note = format!(
        ", {} dragon instances, {unique} unique triangles, {} instanced triangles, accel {} using {:.1} MiB (built in {:.2} s)",
        pt::pt_scene::presets::DRAGONS,
        s.instanced_triangles,
        s.accel.kind,
        s.accel.memory_bytes as f64 / f64::from(1 << 20),
        s.accel.build_time.as_secs_f64()
    );
    common::finish(&args, &out, &note);
}
