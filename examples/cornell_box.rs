//! The diffuse Cornell box (the report's base figure), from Cornell's measured data.
//!
//! `cargo run --release --example cornell_box -- --spp 256 --out out/cornell_box.png`

mod common;

use common::{Defaults, parse};

fn main() {
    let args = parse(
        "cornell_box",
        Defaults {
            width: 512,
            height: 512,
            spp: 128,
            max_depth: 16,
            out: "out/cornell_box.png",
        },
        &[],
    );
    let bundle = pt::pt_scene::presets::cornell_box().unwrap_or_else(|e| common::die(args.name, e));
    let out = common::render(&args, &bundle.scene, &bundle.camera);
    common::finish(&args, &out, "");
}
