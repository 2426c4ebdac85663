//! Whole-render throughput (camera samples per second): the Cornell box at the settings the
//! tests and PERFORMANCE.md have tracked since the first path tracer, the Cornell box at Mitsuba
//! 3's benchmark settings (max depth 8), and the Stanford bunny in the box as a diffuse, a
//! mirror and a glass object (69,451 triangles; needs `PT_ASSETS_DIR`, skipped without it).
//!
//! `cargo bench --bench render`; figures go to docs/PERFORMANCE.md with the command.

// criterion_group! generates undocumented public functions.
#![allow(missing_docs)]

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use pt::prelude::*;
use pt::pt_scene::presets::CornellBox;

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
    // Mitsuba 3's own Cornell box benchmark settings, with pt's defaults (Sobol, MIS).
    let opts = RenderOptions::new(256, 256).spp(8).max_depth(8);
    group.throughput(Throughput::Elements(256 * 256 * 8));
    group.bench_function("cornell_box_256x256_8spp_depth8_all_threads", |b| {
        b.iter(|| render(&bundle.scene, &bundle.camera, &opts, None).expect("render succeeds"))
    });
    group.finish();
}

fn bunnies(c: &mut Criterion) {
    let path = match pt::pt_scene::find_asset("meshes/stanford-bunny.obj") {
        Ok(p) => p,
        Err(e) => {
            eprintln!("render/bunny: skipped ({e})");
            return;
        }
    };
    let bunny = pt::pt_scene::load_mesh(path)
        .expect("bunny loads")
        .with_smooth_normals();
    let mut group = c.benchmark_group("render");
    group.sample_size(10);
    for (name, material) in [
        ("bunny_diffuse", BuiltinMaterial::diffuse(Rgb::splat(0.75))),
        ("bunny_mirror", BuiltinMaterial::mirror(Rgb::WHITE)),
        ("bunny_glass", Glass::new(1.5).expect("valid glass").into()),
    ] {
        let mut cb = CornellBox::empty();
        let m = cb.builder().add_material(material);
        cb.add_mesh_on_floor(
            bunny.clone(),
            m,
            330.0,
            [278.0, 290.0],
            std::f32::consts::PI,
        );
        let bundle = cb.build().expect("scene builds");
        let opts = RenderOptions::new(128, 128).spp(8).max_depth(8);
        group.throughput(Throughput::Elements(128 * 128 * 8));
        group.bench_function(format!("{name}_128x128_8spp_depth8_all_threads"), |b| {
            b.iter(|| render(&bundle.scene, &bundle.camera, &opts, None).expect("render succeeds"))
        });
    }
    group.finish();
}

criterion_group!(benches, cornell_box, bunnies);
criterion_main!(benches);
