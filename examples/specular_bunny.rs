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

use clap::Parser;
use pt::pt_accel::AccelKind;
use pt::pt_core::{BuiltinMaterial, ConductorFresnel, Metal, Mirror, Rgb};
use pt_cli::{Defaults, Failure, Job, RenderArgs};

const NAME: &str = "specular_bunny";

/// The Cornell box with a mirror (or glossy metal) Stanford bunny.
#[derive(Parser)]
struct Cli {
    #[command(flatten)]
    render: RenderArgs,
    /// GGX roughness in [0, 1] (0: ideal mirror)
    #[arg(long, value_name = "R", default_value_t = 0.0)]
    roughness: f32,
    /// Metal: mirror (white), silver, gold, copper or aluminium
    #[arg(long, value_name = "NAME", default_value = "mirror", value_parser = parse_metal)]
    metal: ConductorFresnel,
}

fn parse_metal(v: &str) -> Result<ConductorFresnel, String> {
    match v {
        "mirror" => Ok(ConductorFresnel::Schlick(Rgb::WHITE)),
        "silver" => Ok(ConductorFresnel::SILVER),
        "gold" => Ok(ConductorFresnel::GOLD),
        "copper" => Ok(ConductorFresnel::COPPER),
        "aluminium" | "aluminum" => Ok(ConductorFresnel::ALUMINIUM),
        other => Err(format!(
            "expects mirror, silver, gold, copper or aluminium, got {other:?}"
        )),
    }
}

const DEFAULTS: Defaults = Defaults {
    width: 512,
    height: 512,
    spp: 128,
    max_depth: 16,
    out: "out/specular_bunny.png",
};

fn main() {
    let cli: Cli = pt_cli::parse(NAME, DEFAULTS);
    let (roughness, fresnel) = (cli.roughness, cli.metal);
    let extra = format!("roughness {roughness} metal {fresnel:?}");
    let job = Job::new(NAME, &cli.render, &DEFAULTS, &extra).unwrap_or_else(|f| f.exit());
    let ideal = roughness == 0.0 && fresnel == ConductorFresnel::Schlick(Rgb::WHITE);
    let material: BuiltinMaterial = if ideal {
        Mirror::new(Rgb::WHITE).into()
    } else {
        Metal::new(fresnel, roughness)
            .unwrap_or_else(|e| Failure::usage(e).exit())
            .into()
    };
    let bundle = pt::pt_scene::presets::bunny_in_box(Some(material), AccelKind::Auto)
        .unwrap_or_else(|e| Failure::run(e).exit());
    let out = job.render(&bundle.scene, &bundle.camera);
    let what = if ideal {
        ", bunny: ideal mirror".to_string()
    } else {
        format!(", bunny: GGX conductor, roughness {roughness}")
    };
    job.finish(&out, &what);
}
