//! Cost of each built-in BSDF: `sample`, `eval` and `pdf`, in nanoseconds per call, for a batch
//! of 1024 precomputed directions and random numbers (so the generator is not measured). The
//! models are the registry's (`pt_core::testing::builtin_bsdf_models`).
//!
//! `cargo bench -p pt-core --bench bsdf`. Figures go to docs/PERFORMANCE.md.

// criterion_group! generates undocumented public functions.
#![allow(missing_docs)]

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::{Vec2, Vec3};
use pt_core::testing::{TestRng, builtin_bsdf_models};
use pt_core::{Bsdf, TransportMode};

const N: usize = 1024;

fn bench(c: &mut Criterion) {
    let mut rng = TestRng::new(1);
    let dir = |rng: &mut TestRng, sign: f32| {
        let u = rng.uniform2();
        let z = 0.05 + 0.95 * u.x;
        let r = (1.0 - z * z).sqrt();
        let phi = std::f32::consts::TAU * u.y;
        Vec3::new(r * phi.cos(), r * phi.sin(), sign * z)
    };
    // Outgoing directions mostly outside, some inside (glass), and random numbers.
    let wos: Vec<Vec3> = (0..N)
        .map(|i| dir(&mut rng, if i % 4 == 3 { -1.0 } else { 1.0 }))
        .collect();
    let us: Vec<(f32, Vec2)> = (0..N).map(|_| (rng.uniform(), rng.uniform2())).collect();
    let mut g = c.benchmark_group("bsdf");
    g.throughput(Throughput::Elements(N as u64));
    for (name, bsdf) in builtin_bsdf_models() {
        // Evaluation pairs: wi from the model's own sampling where it has a density, so eval
        // and pdf do the work of a real lobe, else uniform.
        let wis: Vec<Vec3> = wos
            .iter()
            .zip(&us)
            .map(
                |(&wo, &(uc, u))| match bsdf.sample(wo, uc, u, TransportMode::Radiance) {
                    Some(s) if !s.is_specular() => s.wi,
                    _ => Vec3::new(-wo.x, -wo.y, wo.z),
                },
            )
            .collect();
        g.bench_function(format!("sample/{name}"), |b| {
            b.iter(|| {
                for (&wo, &(uc, u)) in wos.iter().zip(&us) {
                    black_box(bsdf.sample(black_box(wo), uc, u, TransportMode::Radiance));
                }
            })
        });
        g.bench_function(format!("eval/{name}"), |b| {
            b.iter(|| {
                for (&wo, &wi) in wos.iter().zip(&wis) {
                    black_box(bsdf.eval(black_box(wo), wi, TransportMode::Radiance));
                }
            })
        });
        g.bench_function(format!("pdf/{name}"), |b| {
            b.iter(|| {
                for (&wo, &wi) in wos.iter().zip(&wis) {
                    black_box(bsdf.pdf(black_box(wo), wi, TransportMode::Radiance));
                }
            })
        });
    }
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .warm_up_time(std::time::Duration::from_millis(300))
        .measurement_time(std::time::Duration::from_secs(1));
    targets = bench
}
criterion_main!(benches);
