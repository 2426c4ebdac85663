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

mod common;

use common::{Defaults, Flag, die, parse};
use pt::pt_accel::AccelKind;
use pt::pt_core::Glass;

const NAME: &str = "glass_bunny";

fn main() {
    let args = parse(
        NAME,
        Defaults {
            width: 512,
            height: 512,
            spp: 128,
            max_depth: 16,
            out: "out/glass_bunny.png",
        },
        &[
            Flag {
                name: "roughness",
                value: Some("R"),
                help: "GGX roughness in [0, 1] (default 0: smooth glass)",
            },
            Flag {
                name: "eta",
                value: Some("ETA"),
                help: "index of refraction (default 1.5)",
            },
        ],
    );
    let roughness: f32 = args
        .parsed("roughness", "a number in [0, 1]")
        .unwrap_or(0.0);
    let eta: f32 = args.parsed("eta", "a positive number").unwrap_or(1.5);
    let glass = Glass::new(eta)
        .and_then(|g| g.with_roughness(roughness))
        .unwrap_or_else(|e| {
            eprintln!("{NAME}: {e}");
            std::process::exit(2)
        });

    let bundle = pt::pt_scene::presets::bunny_in_box(Some(glass.into()), AccelKind::Auto)
        .unwrap_or_else(|e| die(NAME, e));
    let out = common::render(&args, &bundle.scene, &bundle.camera);
    common::finish(
        &args,
        &out,
        &format!(", bunny: glass, eta {eta}, roughness {roughness}"),
    );
}
