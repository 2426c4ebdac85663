//! The cost of the samplers: nanoseconds per camera sample for the draws a path of four
//! bounces takes (a pixel position, a lens sample, and per bounce a light sample whose first
//! number also chooses the light, a BSDF lobe choice, a BSDF sample and a roulette decision:
//! 2 + 4 x 4 = 18 draws).
//!
//! `cargo bench --bench sampler`; figures go to docs/PERFORMANCE.md with the command.

// criterion_group! generates undocumented public functions.
#![allow(missing_docs)]

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use pt::glam::{UVec2, Vec2};
use pt::pt_core::{Sampler, SamplerKind};

fn samplers(c: &mut Criterion) {
    let mut group = c.benchmark_group("sampler");
    const PIXELS: u32 = 64;
    const SPP: u32 = 16;
    group.throughput(Throughput::Elements(u64::from(PIXELS * SPP)));
    for kind in SamplerKind::ALL {
        let mut sampler = kind.sampler(7, SPP);
        group.bench_function(format!("{}_camera_sample_4_bounces", kind.name()), |b| {
            b.iter(|| {
                let mut acc = Vec2::ZERO;
                for p in 0..PIXELS {
                    for i in 0..SPP {
                        sampler.start_pixel_sample(UVec2::new(p, 3), i);
                        acc += sampler.pixel_2d() + sampler.next_2d();
                        for _ in 0..4 {
                            acc += sampler.next_2d();
                            acc.y += sampler.next_1d();
                            acc += sampler.next_2d();
                            acc.x += sampler.next_1d();
                        }
                    }
                }
                black_box(acc)
            })
        });
    }
    group.finish();
}

criterion_group!(benches, samplers);
criterion_main!(benches);
