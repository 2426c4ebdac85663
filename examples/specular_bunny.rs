//! Figure 2b of the report: the Cornell box with a mirror Stanford bunny (69,451 triangles,
//! smooth vertex normals); `--roughness R` turns the mirror into a glossy GGX conductor.
//!
//! ```text
//! cargo run --release --example specular_bunny                        # ideal mirror
//! cargo run --release --example specular_bunny -- --roughness 0.3     # glossy
//! cargo run --release --example specular_bunny -- --metal gold --roughness 0.2
//! ```
//!
//! The bunny is fetched on first use (see README, Assets).

mod common;

use common::{Defaults, Flag, die, parse};
use pt::pt_accel::AccelKind;
use pt::pt_core::{BuiltinMaterial, ConductorFresnel, Metal, Mirror, Rgb};

const NAME: &str = "specular_bunny";

fn main() {
    let args = parse(
        NAME,
        Defaults {
            width: 512,
            height: 512,
            spp: 128,
            max_depth: 16,
            out: "out/specular_bunny.png",
        },
        &[
            Flag {
                name: "roughness",
                value: Some("R"),
                help: "GGX roughness in [0, 1] (default 0: ideal mirror)",
            },
            Flag {
                name: "metal",
                value: Some("NAME"),
                help: "mirror (white, default), silver, gold, copper or aluminium",
            },
        ],
    );
    let roughness: f32 = args
        .parsed("roughness", "a number in [0, 1]")
        .unwrap_or(0.0);
    let fresnel = match args.value("metal").unwrap_or("mirror") {
        "mirror" => ConductorFresnel::Schlick(Rgb::WHITE),
        "silver" => ConductorFresnel::SILVER,
        "gold" => ConductorFresnel::GOLD,
        "copper" => ConductorFresnel::COPPER,
        "aluminium" | "aluminum" => ConductorFresnel::ALUMINIUM,
        other => {
            eprintln!(
                "{NAME}: --metal expects mirror, silver, gold, copper or aluminium, got {other:?}"
            );
            std::process::exit(2)
        }
    };
    let ideal = roughness == 0.0 && fresnel == ConductorFresnel::Schlick(Rgb::WHITE);
    let material: BuiltinMaterial = if ideal {
        Mirror::new(Rgb::WHITE).into()
    } else {
        Metal::new(fresnel, roughness)
            .unwrap_or_else(|e| {
                eprintln!("{NAME}: {e}");
                std::process::exit(2)
            })
            .into()
    };

    let bundle = pt::pt_scene::presets::bunny_in_box(Some(material), AccelKind::Auto)
        .unwrap_or_else(|e| die(NAME, e));
    let out = common::render(&args, &bundle.scene, &bundle.camera);
    let what = if ideal {
        ", bunny: ideal mirror".to_string()
    } else {
        format!(", bunny: GGX conductor, roughness {roughness}")
    };
    common::finish(&args, &out, &what);
}
