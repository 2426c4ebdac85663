//! The report's figure scenes (`pt_scene::presets::figure`, shared with the examples and the
//! benchmarks) all build from the known assets and render a lit, finite image; an unknown name
//! is an error that lists the names.

use pt::prelude::*;
use pt::pt_scene::assets::find_asset_or_skip;
use pt::pt_scene::presets::{FIGURES, figure};

#[test]
fn every_figure_builds_and_renders_lit() {
    let assets = [
        "meshes/stanford-bunny.obj",
        "meshes/dragon_vrip_res2.binary.ply",
        "env/venice_sunset_1k.hdr",
    ];
    for asset in assets {
        if find_asset_or_skip(asset).unwrap().is_none() {
            return;
        }
    }
    for name in FIGURES {
        let fig = figure(name).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(fig.width > 0 && fig.spp > 0 && !fig.caption.is_empty());
        assert!(fig.command.starts_with("cargo run --example "), "{name}");
        let opts = RenderOptions::new(24, 16).spp(2).max_depth(fig.max_depth);
        let out = fig.bundle.render(&opts, None).unwrap();
        assert_eq!(out.stats.non_finite_samples, 0, "{name}");
        assert!(out.image.mean().luminance() > 0.0, "{name} renders black");
    }
}

#[test]
fn an_unknown_figure_names_the_known_ones() {
    let e = figure("nope").unwrap_err().to_string();
    assert!(e.contains("nope") && e.contains("cornell_box"), "{e}");
}
