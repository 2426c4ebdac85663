//! Whole-render throughput (camera samples per second) of the Cornell box.
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
        let opts = RenderOptions::new(128, 128).spp(16).threads(threads);
        group.throughput(Throughput::Elements(128 * 128 * 16));
        group.bench_function(name, |b| {
            b.iter(|| render(&bundle.scene, &bundle.camera, &opts).expect("render succeeds"))
        });
    }
    group.finish();
}

criterion_group!(benches, cornell_box);
criterion_main!(benches);
