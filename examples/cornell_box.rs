//! The diffuse Cornell box (the report's base figure), from Cornell's measured data, with or
//! without a BVH (`--accel brute` tests every triangle for every ray, the report's "without").
//!
//! `cargo run --release --example cornell_box -- --spp 256 --out out/cornell_box.png`

mod common;

use common::{Defaults, Flag, parse};

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
        &[Flag {
            name: "accel",
            value: Some("KIND"),
            help: "auto (default), bvh, two-level or brute (no acceleration structure)",
        }],
    );
    let kind = common::accel_kind(args.name, args.value("accel").unwrap_or("auto"));
    let bundle =
        pt::pt_scene::presets::cornell_box_with(kind).unwrap_or_else(|e| common::die(args.name, e));
    let out = common::render(&args, &bundle.scene, &bundle.camera);
    let accel = bundle.scene.stats().accel.kind;
    common::finish(&args, &out, &format!(", accel {accel}"));
}
