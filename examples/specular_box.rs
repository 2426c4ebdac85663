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

mod common;

use common::{Defaults, die, parse};

const NAME: &str = "specular_box";

fn main() {
    let args = parse(
        NAME,
        Defaults {
            width: 512,
            height: 512,
            spp: 128,
            max_depth: 16,
            out: "out/specular_box.png",
        },
        &[],
    );
    let bundle = pt::pt_scene::presets::specular_box().unwrap_or_else(|e| die(NAME, e));
    let out = common::render(&args, &bundle.scene, &bundle.camera);
    common::finish(&args, &out, ", tall block: ideal mirror");
}
