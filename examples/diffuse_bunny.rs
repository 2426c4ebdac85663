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

mod common;

use common::{Args, Defaults, Flag, die, parse};
use pt::pt_accel::AccelKind;

const NAME: &str = "diffuse_bunny";

/// One render; returns its wall time in seconds (scene build excluded).
fn run(args: &Args, kind: AccelKind) -> f64 {
    let bundle = pt::pt_scene::presets::bunny_in_box(None, kind).unwrap_or_else(|e| die(NAME, e));
    let a = &bundle.scene.stats().accel;
    let out = common::render(args, &bundle.scene, &bundle.camera);
    let note = format!(
        ", accel {} ({} triangles, {:.1} MiB, built in {:.3} s)",
        a.kind,
        a.input_triangles,
        a.memory_bytes as f64 / f64::from(1 << 20),
        a.build_time.as_secs_f64()
    );
    common::finish(args, &out, &note);
    out.stats.elapsed.as_secs_f64()
}

fn main() {
    let mut args = parse(
        NAME,
        Defaults {
            width: 512,
            height: 512,
            spp: 64,
            max_depth: 16,
            out: "out/diffuse_bunny.png",
        },
        &[
            Flag {
                name: "accel",
                value: Some("KIND"),
                help: "auto, brute, bvh or two-level (default bvh)",
            },
            Flag {
                name: "compare",
                value: None,
                help: "render with brute force and with the BVH and print the speed-up",
            },
        ],
    );
    let kind = common::accel_kind(NAME, args.value("accel").unwrap_or("bvh"));
    let slow = kind == AccelKind::BruteForce || args.flag("compare");
    if slow && !args.given("size") && !args.given("spp") {
        args.options.width = 96;
        args.options.height = 96;
        args.options.spp = 4;
        eprintln!(
            "{NAME}: brute force is slow; rendering 96x96 at 4 spp (set --size/--spp to override)"
        );
    }
    if args.flag("compare") {
        let out = args.out.clone();
        args.out = out.with_file_name(format!("{}_brute.{}", stem(&out), ext(&out)));
        let brute = run(&args, AccelKind::BruteForce);
        args.out = out.with_file_name(format!("{}_bvh.{}", stem(&out), ext(&out)));
        let bvh = run(&args, AccelKind::Bvh);
        println!(
            "{NAME}: BVH speed-up over brute force: {:.0}x ({brute:.2} s vs {bvh:.3} s)",
            brute / bvh
        );
    } else {
        run(&args, kind);
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
