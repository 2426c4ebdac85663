//! Figure 1 of the report: the Cornell box with a diffuse Stanford bunny (69,451 triangles),
//! rendered with brute-force ray casting or a BVH.
//!
//! ```text
//! cargo run --release --example diffuse_bunny                      # BVH, 512x512
//! cargo run --release --example diffuse_bunny -- --accel brute     # every ray against every triangle
//! cargo run --release --example diffuse_bunny -- --compare         # both, and the speed-up
//! ```
//!
//! Brute force tests each of the ~5 rays of a path against all 69,451 triangles, about 20,000
//! times the work of the BVH, so with `--accel brute` or `--compare` the defaults drop to 96x96 at
//! 4 spp unless `--size`/`--spp` are given. The bunny is fetched on first use (see README, Assets).

use clap::Parser;
use pt::pt_accel::AccelKind;
use pt_cli::{Defaults, Failure, Job, RenderArgs};

const NAME: &str = "diffuse_bunny";

/// The Cornell box with a diffuse Stanford bunny, by brute force or through a BVH.
#[derive(Parser)]
struct Cli {
    #[command(flatten)]
    render: RenderArgs,
    /// Accelerator: auto, brute, bvh or two-level
    #[arg(long, value_name = "KIND", default_value = "bvh", value_parser = pt_cli::args::parse_accel)]
    accel: AccelKind,
    /// Render with brute force and with the BVH and print the speed-up
    #[arg(long)]
    compare: bool,
}

const DEFAULTS: Defaults = Defaults {
    width: 512,
    height: 512,
    spp: 64,
    max_depth: 16,
    out: "out/diffuse_bunny.png",
};

/// One render; returns its wall time in seconds (scene build excluded).
fn run(job: &Job, kind: AccelKind) -> f64 {
    let bundle =
        pt::pt_scene::presets::bunny_in_box(None, kind).unwrap_or_else(|e| Failure::run(e).exit());
    let a = &bundle.scene.stats().accel;
    let out = job.render(&bundle.scene, &bundle.camera);
    let note = format!(
        ", accel {} ({} triangles, {:.1} MiB, built in {:.3} s)",
        a.kind,
        a.input_triangles,
        a.memory_bytes as f64 / f64::from(1 << 20),
        a.build_time.as_secs_f64()
    );
    job.finish(&out, &note);
    out.stats.elapsed.as_secs_f64()
}

fn main() {
    let (mut cli, matches): (Cli, _) = pt_cli::parse_matches(NAME, DEFAULTS);
    let slow = cli.accel == AccelKind::BruteForce || cli.compare;
    if slow && !pt_cli::given(&matches, "size") && !pt_cli::given(&matches, "spp") {
        cli.render.size = (96, 96);
        cli.render.spp = 4;
        eprintln!(
            "{NAME}: brute force is slow; rendering 96x96 at 4 spp (set --size/--spp to override)"
        );
    }
    let extra = format!("accel {:?}", cli.accel);
    let mut job = Job::new(NAME, &cli.render, &DEFAULTS, &extra).unwrap_or_else(|f| f.exit());
    if cli.compare {
        let out = job.out.clone();
        job.out = out.with_file_name(format!("{}_brute.{}", stem(&out), ext(&out)));
        let brute = run(&job, AccelKind::BruteForce);
        job.out = out.with_file_name(format!("{}_bvh.{}", stem(&out), ext(&out)));
        let bvh = run(&job, AccelKind::Bvh);
        println!(
            "{NAME}: BVH speed-up over brute force: {:.0}x ({brute:.2} s vs {bvh:.3} s)",
            brute / bvh
        );
    } else {
        run(&job, cli.accel);
    }
}
fn stem(p: &std::path::Path) -> String {
    p.file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("out")
        .to_string()
}

fn ext(p: &std::path::Path) -> String {
    p.extension()
        .and_then(|s| s.to_str())
        .unwrap_or("png")
        .to_string()
}
