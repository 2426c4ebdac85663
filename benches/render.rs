//! Whole-render throughput (camera samples per second): the Cornell box at the settings the
//! tests and PERFORMANCE.md have tracked since the first path tracer, the Cornell box at Mitsuba
//! 3's benchmark settings (max depth 8; the one-path and the lane path tracer), and the Stanford bunny in the box as a diffuse, a
//! mirror and a glass object (69,451 triangles; the figure preset `pt_scene::presets::bunny_in_box`,
//! skipped when the bunny cannot be found), and the environment figure (its cube map).
//!
//! `cargo bench --bench render`; figures go to docs/PERFORMANCE.md with the command.

// criterion_group! generates undocumented public functions.
#![allow(missing_docs)]

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use pt::prelude::*;

fn cornell_box(c: &mut Criterion) {
    let bundle = presets::cornell_box().expect("preset builds");
    let mut group = c.benchmark_group("render");
    group.sample_size(10);
    for (name, threads) in [
        ("cornell_box_128x128_16spp_1thread", Some(1)),
        ("cornell_box_128x128_16spp_all_threads", None),
    ] {
        let opts = RenderOptions::new(128, 128)
            .spp(16)
            .threads(threads)
            .sampler(SamplerKind::Independent);
        group.throughput(Throughput::Elements(128 * 128 * 16));
        group.bench_function(name, |b| {
            b.iter(|| render(&bundle.scene, &bundle.camera, &opts, None).expect("render succeeds"))
        });
    }
    // Mitsuba 3's own Cornell box benchmark settings, with pt's defaults (Sobol, MIS, the lane
    // tracer: eight paths at once), and by the one-path tracer (the same film).
    for (name, lanes) in [
        ("cornell_box_256x256_8spp_depth8_all_threads", true),
        (
            "cornell_box_256x256_8spp_depth8_all_threads_one_path",
            false,
        ),
    ] {
        let opts = RenderOptions::new(256, 256)
            .spp(8)
            .max_depth(8)
            .lanes(lanes);
        group.throughput(Throughput::Elements(256 * 256 * 8));
        group.bench_function(name, |b| {
            b.iter(|| render(&bundle.scene, &bundle.camera, &opts, None).expect("render succeeds"))
        });
    }
    group.finish();
}

fn bunnies(c: &mut Criterion) {
    let mut group = c.benchmark_group("render");
    group.sample_size(10);
    for (name, material) in [
        ("bunny_diffuse", BuiltinMaterial::diffuse(Rgb::splat(0.75))),
        ("bunny_mirror", BuiltinMaterial::mirror(Rgb::WHITE)),
        ("bunny_glass", Glass::new(1.5).expect("valid glass").into()),
    ] {
        // The figure scene of the bunny examples (smooth normals, in the box).
        let bundle = match presets::bunny_in_box(Some(material), AccelKind::Auto) {
            Ok(b) => b,
            Err(e) => {
                eprintln!("render/{name}: skipped ({e})");
                return;
            }
        };
        let opts = RenderOptions::new(128, 128).spp(8).max_depth(8);
        group.throughput(Throughput::Elements(128 * 128 * 8));
        group.bench_function(format!("{name}_128x128_8spp_depth8_all_threads"), |b| {
            b.iter(|| bundle.render(&opts, None).expect("render succeeds"))
        });
    }
    group.finish();
}

/// The environment figure (the bunny under the Park3Med cube map, 6.3 million texels): what the
/// map's light samples and escaping rays cost in memory (docs/PERFORMANCE.md, "Sampling the
/// maps by cells").
fn environment(c: &mut Criterion) {
    let mut group = c.benchmark_group("render");
    group.sample_size(10);
    let bundle = match presets::env_lighting("cubemap", 1.0, 0.0, false) {
        Ok(b) => b,
        Err(e) => {
            eprintln!("render/env_lighting: skipped ({e})");
            return;
        }
    };
    let opts = RenderOptions::new(128, 128).spp(8).max_depth(8);
    group.throughput(Throughput::Elements(128 * 128 * 8));
    group.bench_function(
        "env_lighting_cubemap_128x128_8spp_depth8_all_threads",
        |b| b.iter(|| bundle.render(&opts, None).expect("render succeeds")),
    );
    group.finish();
}

criterion_group!(benches, cornell_box, bunnies, environment);
criterion_main!(benches);
