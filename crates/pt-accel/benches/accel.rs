//! pt-accel benchmarks on the real Stanford bunny (69k triangles) and dragon (202k triangles):
//!
//! - `build/*`: build time per preset;
//! - `trace/*`: closest-hit and any-hit queries, 1,000,000 coherent camera rays and 1,000,000
//!   incoherent rays (random origins inside the bounds, random directions), 1 and 2 threads, for
//!   every node layout (eight-wide, four-wide, compressed wide, binary), and the same rays through obvhs called directly (its own traversal and
//!   Möller-Trumbore triangle test) as the baseline pt-accel's overhead is measured against;
//! - `brute/*`: brute force against the BVH on the bunny;
//! - `instances/*`: one flat BVH against the two-level BVH for 100 instanced dragons.
//!
//! `PT_ASSETS_DIR=../shared/assets cargo bench -p pt-accel --bench accel` (from the workspace
//! root; pass a filter such as `trace/bunny` to run a subset). Throughput is reported in rays
//! (elements) per second. Figures go to docs/PERFORMANCE.md. The comparison with Embree 4 on
//! the same rays is the `ray_queries` example's.

// criterion_group! generates undocumented public functions.
#![allow(missing_docs)]

use std::hint::black_box;
use std::time::Duration;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use glam::{Affine3A, Quat, Vec3, Vec3A};
use obvhs::ray::{Ray as ObRay, RayHit};
use obvhs::triangle::Triangle;
use obvhs::{
    BvhBuildParams, bvh2::builder::build_bvh2_from_tris, cwbvh::builder::build_cwbvh_from_tris,
};
use pt_accel::lanes::WIDTH;
use pt_accel::{
    Accel, AccelKind, AccelOptions, BuildQuality, BvhLayout, Instance, Ray, RayLanes, TriangleMesh,
};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use rayon::prelude::*;

const RAYS: usize = 1_000_000;

fn load(name: &str) -> Option<TriangleMesh> {
    let path = pt_scene::assets::find_asset_or_skip(name).expect("asset required")?;
    Some(
        pt_scene::load_mesh(path)
            .expect("mesh loads")
            .geometry()
            .clone(),
    )
}

/// 1000x1000 pinhole camera rays framing the mesh from the front.
fn coherent_rays(mesh: &TriangleMesh) -> Vec<Ray> {
    let b = mesh.bounds();
    let (c, r) = b.bounding_sphere();
    let eye = c + Vec3::new(0.3, 0.2, 1.0).normalize() * r * 2.5;
    let forward = (c - eye).normalize();
    let right = forward.cross(Vec3::Y).normalize();
    let up = right.cross(forward);
    let n = 1000;
    let half = (25f32.to_radians()).tan();
    (0..n * n)
        .map(|i| {
            let (x, y) = ((i % n) as f32 + 0.5, (i / n) as f32 + 0.5);
            let u = (2.0 * x / n as f32 - 1.0) * half;
            let v = (1.0 - 2.0 * y / n as f32) * half;
            Ray::new(eye, (forward + right * u + up * v).normalize())
        })
        .collect()
}

/// Random origins inside the bounds, uniformly random directions.
fn incoherent_rays(mesh: &TriangleMesh) -> Vec<Ray> {
    let b = mesh.bounds();
    let mut rng = Pcg64::seed_from_u64(1);
    (0..RAYS)
        .map(|_| {
            let o = b.min + b.diagonal() * Vec3::new(rng.random(), rng.random(), rng.random());
            let z: f32 = rng.random_range(-1.0..1.0);
            let phi: f32 = rng.random_range(0.0..std::f32::consts::TAU);
            let s = (1.0 - z * z).sqrt();
            Ray::new(o, Vec3::new(s * phi.cos(), s * phi.sin(), z))
        })
        .collect()
}

fn obvhs_tris(mesh: &TriangleMesh) -> Vec<Triangle> {
    (0..mesh.triangle_count())
        .map(|i| {
            let [a, b, c] = mesh.triangle(i);
            Triangle {
                v0: a.into(),
                v1: b.into(),
                v2: c.into(),
            }
        })
        .collect()
}

fn ob(r: &Ray) -> ObRay {
    ObRay::new(
        Vec3A::from(r.origin),
        Vec3A::from(r.dir),
        0.0,
        f32::INFINITY,
    )
}

/// Run `f` over all rays on `threads` threads; the sum of hit counts keeps the work observable.
fn run(rays: &[Ray], threads: usize, f: impl Fn(&Ray) -> bool + Sync) -> usize {
    if threads == 1 {
        rays.iter().filter(|r| f(r)).count()
    } else {
        rays.par_chunks(4096)
            .map(|c| c.iter().filter(|r| f(r)).count())
            .sum()
    }
}

/// Run `f` over the rays eight at a time (the lane queries), as [`run`]; a last partial group
/// is left out.
fn run_lanes(rays: &[Ray], threads: usize, f: impl Fn(&RayLanes) -> usize + Sync) -> usize {
    let group = |c: &[Ray]| -> usize {
        c.chunks_exact(WIDTH)
            .map(|g| f(&RayLanes::from(&std::array::from_fn(|i| g[i]))))
            .sum()
    };
    if threads == 1 {
        group(rays)
    } else {
        rays.par_chunks(4096).map(group).sum()
    }
}

fn build(c: &mut Criterion) {
    let mut g = c.benchmark_group("build");
    g.sample_size(10).measurement_time(Duration::from_secs(8));
    for name in [
        "meshes/stanford-bunny.obj",
        "meshes/dragon_vrip_res2.binary.ply",
    ] {
        let Some(mesh) = load(name) else { continue };
        let short = if name.contains("bunny") {
            "bunny"
        } else {
            "dragon202k"
        };
        for q in BuildQuality::ALL {
            for layout in [
                BvhLayout::Eight,
                BvhLayout::Four,
                BvhLayout::Wide,
                BvhLayout::Binary,
            ] {
                let opts = AccelOptions::new()
                    .kind(AccelKind::Bvh)
                    .quality(q)
                    .layout(layout);
                g.bench_function(
                    BenchmarkId::new(format!("{short}/{layout:?}"), format!("{q:?}")),
                    |b| b.iter(|| Accel::build(&[&mesh], &[Instance::new(0)], &opts)),
                );
            }
        }
    }
    g.finish();
}

fn trace(c: &mut Criterion) {
    let pool2 = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    let mut g = c.benchmark_group("trace");
    g.sample_size(10)
        .measurement_time(Duration::from_secs(6))
        .throughput(Throughput::Elements(RAYS as u64));
    for name in [
        "meshes/stanford-bunny.obj",
        "meshes/dragon_vrip_res2.binary.ply",
    ] {
        let Some(mesh) = load(name) else { continue };
        let short = if name.contains("bunny") {
            "bunny"
        } else {
            "dragon202k"
        };
        let layouts: Vec<(&str, Accel)> = [
            ("eight", BvhLayout::Eight),
            ("four", BvhLayout::Four),
            ("wide", BvhLayout::Wide),
            ("binary", BvhLayout::Binary),
        ]
        .into_iter()
        .map(|(label, layout)| {
            let opts = AccelOptions::new().kind(AccelKind::Bvh).layout(layout);
            (label, Accel::build(&[&mesh], &[Instance::new(0)], &opts))
        })
        .collect();
        // The same BVHs built by obvhs directly, triangles reordered into leaf order as its docs
        // recommend, traversed with its own closures.
        let tris = obvhs_tris(&mesh);
        let params = BvhBuildParams::medium_build();
        let raw_cw = build_cwbvh_from_tris(&tris, params, &mut Duration::default());
        let cw_tris: Vec<Triangle> = raw_cw
            .primitive_indices
            .iter()
            .map(|&i| tris[i as usize])
            .collect();
        let raw_b2 = build_bvh2_from_tris(&tris, params, &mut Duration::default());
        let b2_tris: Vec<Triangle> = raw_b2
            .primitive_indices
            .iter()
            .map(|&i| tris[i as usize])
            .collect();

        for (set, rays) in [
            ("coherent", coherent_rays(&mesh)),
            ("incoherent", incoherent_rays(&mesh)),
        ] {
            for threads in [1, 2] {
                let id = |what: &str| BenchmarkId::new(format!("{short}/{set}/{threads}t"), what);
                let in_pool = |f: &(dyn Fn() -> usize + Sync)| {
                    if threads == 2 { pool2.install(f) } else { f() }
                };
                for (label, accel) in &layouts {
                    g.bench_function(id(&format!("closest/pt-{label}")), |b| {
                        b.iter(|| {
                            in_pool(&|| {
                                run(&rays, threads, |r| black_box(accel.intersect(r)).is_some())
                            })
                        })
                    });
                }
                let eight = &layouts[0].1;
                g.bench_function(id("closest/pt-eight-lanes"), |b| {
                    b.iter(|| {
                        in_pool(&|| {
                            run_lanes(&rays, threads, |r| {
                                black_box(eight.intersect_lanes(r, 0xff))
                                    .iter()
                                    .filter(|h| h.is_some())
                                    .count()
                            })
                        })
                    })
                });
                g.bench_function(id("closest/obvhs-cwbvh"), |b| {
                    b.iter(|| {
                        in_pool(&|| {
                            run(&rays, threads, |r| {
                                let mut hit = RayHit::none();
                                raw_cw.ray_traverse(ob(r), &mut hit, |ray, id| {
                                    cw_tris[id].intersect(ray)
                                }) && black_box(raw_cw.primitive_indices[hit.primitive_id as usize])
                                    < u32::MAX
                            })
                        })
                    })
                });
                g.bench_function(id("closest/obvhs-bvh2"), |b| {
                    b.iter(|| {
                        in_pool(&|| {
                            run(&rays, threads, |r| {
                                let mut hit = RayHit::none();
                                raw_b2.ray_traverse(ob(r), &mut hit, |ray, id| {
                                    b2_tris[id].intersect(ray)
                                }) && black_box(raw_b2.primitive_indices[hit.primitive_id as usize])
                                    < u32::MAX
                            })
                        })
                    })
                });
                for (label, accel) in &layouts {
                    g.bench_function(id(&format!("anyhit/pt-{label}")), |b| {
                        b.iter(|| in_pool(&|| run(&rays, threads, |r| accel.occluded(r))))
                    });
                }
                g.bench_function(id("anyhit/pt-eight-lanes"), |b| {
                    b.iter(|| {
                        in_pool(&|| {
                            run_lanes(&rays, threads, |r| {
                                eight.occluded_lanes(r, 0xff).count_ones() as usize
                            })
                        })
                    })
                });
                g.bench_function(id("anyhit/obvhs-cwbvh"), |b| {
                    b.iter(|| {
                        in_pool(&|| {
                            run(&rays, threads, |r| {
                                !raw_cw
                                    .ray_traverse_miss(ob(r), |ray, id| cw_tris[id].intersect(ray))
                            })
                        })
                    })
                });
                g.bench_function(id("anyhit/obvhs-bvh2"), |b| {
                    b.iter(|| {
                        in_pool(&|| {
                            run(&rays, threads, |r| {
                                !raw_b2
                                    .ray_traverse_miss(ob(r), |ray, id| b2_tris[id].intersect(ray))
                            })
                        })
                    })
                });
            }
        }
    }
    g.finish();
}

fn brute(c: &mut Criterion) {
    let Some(mesh) = load("meshes/stanford-bunny.obj") else {
        return;
    };
    let rays: Vec<Ray> = incoherent_rays(&mesh).into_iter().take(200).collect();
    let mut g = c.benchmark_group("brute");
    g.sample_size(10)
        .throughput(Throughput::Elements(rays.len() as u64));
    for (label, kind) in [
        ("bunny/brute-force", AccelKind::BruteForce),
        ("bunny/bvh", AccelKind::Bvh),
    ] {
        let accel = Accel::build(
            &[&mesh],
            &[Instance::new(0)],
            &AccelOptions::new().kind(kind),
        );
        g.bench_function(label, |b| {
            b.iter(|| run(&rays, 1, |r| black_box(accel.intersect(r)).is_some()))
        });
    }
    g.finish();
}

/// 100 dragons on a 10x10 grid with varied rotations and scales.
fn dragon_instances() -> Vec<Instance> {
    let mut rng = Pcg64::seed_from_u64(3);
    (0..100)
        .map(|i| {
            let (x, z) = ((i % 10) as f32, (i / 10) as f32);
            Instance::with_transform(
                0,
                Affine3A::from_scale_rotation_translation(
                    Vec3::splat(rng.random_range(0.7..1.3)),
                    Quat::from_rotation_y(rng.random_range(0.0..std::f32::consts::TAU)),
                    Vec3::new(x * 0.25, 0.0, z * 0.25),
                ),
            )
        })
        .collect()
}

fn instances(c: &mut Criterion) {
    let Some(mesh) = load("meshes/dragon_vrip_res2.binary.ply") else {
        return;
    };
    let inst = dragon_instances();
    let mut g = c.benchmark_group("instances");
    g.sample_size(10).measurement_time(Duration::from_secs(8));
    for (label, kind) in [
        ("100-dragons/flat", AccelKind::Bvh),
        ("100-dragons/two-level", AccelKind::TwoLevel),
    ] {
        let opts = AccelOptions::new().kind(kind);
        let accel = Accel::build(&[&mesh], &inst, &opts);
        eprintln!(
            "{label}: {} instanced triangles, {} nodes, {:.1} MiB, built in {:.2} s",
            accel.stats().input_triangles,
            accel.stats().nodes,
            accel.stats().memory_bytes as f64 / (1 << 20) as f64,
            accel.stats().build_time.as_secs_f64()
        );
        // Rays from above the grid toward random points of the floor the dragons stand on.
        let b = accel.bounds();
        let mut rng = Pcg64::seed_from_u64(4);
        let rays: Vec<Ray> = (0..RAYS)
            .map(|_| {
                let o = Vec3::new(
                    rng.random_range(b.min.x..b.max.x),
                    b.max.y * 3.0,
                    rng.random_range(b.min.z..b.max.z),
                );
                let t = Vec3::new(
                    rng.random_range(b.min.x..b.max.x),
                    b.min.y,
                    rng.random_range(b.min.z..b.max.z),
                );
                Ray::new(o, (t - o).normalize())
            })
            .collect();
        g.throughput(Throughput::Elements(RAYS as u64));
        g.bench_function(format!("{label}/trace-1t"), |bch| {
            bch.iter(|| run(&rays, 1, |r| black_box(accel.intersect(r)).is_some()))
        });
        g.throughput(Throughput::Elements(1));
        g.bench_function(format!("{label}/build"), |bch| {
            bch.iter(|| Accel::build(&[&mesh], &inst, &opts))
        });
    }
    g.finish();
}

/// The triangle test alone: 1,000 rays against 1,000 bunny triangles each (1M tests per
/// iteration), pt's watertight test against obvhs' Möller-Trumbore test.
fn triangle(c: &mut Criterion) {
    let Some(mesh) = load("meshes/stanford-bunny.obj") else {
        return;
    };
    let rays: Vec<Ray> = incoherent_rays(&mesh).into_iter().take(1000).collect();
    let corners: Vec<[Vec3A; 3]> = (0..1000)
        .map(|i| mesh.triangle(i * 60).map(Vec3A::from))
        .collect();
    let packed: Vec<pt_accel::triangle::PackedTriangle> = corners
        .iter()
        .map(pt_accel::triangle::PackedTriangle::new)
        .collect();
    let tris = obvhs_tris(&mesh);
    let ob_tris: Vec<Triangle> = (0..1000).map(|i| tris[i * 60]).collect();
    let mut g = c.benchmark_group("triangle");
    g.sample_size(20)
        .throughput(Throughput::Elements(1_000_000));
    g.bench_function("pt-watertight", |b| {
        b.iter(|| {
            let mut n = 0usize;
            for r in &rays {
                let test = pt_accel::triangle::RayTriangleTest::new(r);
                n += packed
                    .iter()
                    .filter(|t| test.intersect_packed(t, f32::INFINITY).is_some())
                    .count();
            }
            n
        })
    });
    g.bench_function("obvhs-moller-trumbore", |b| {
        b.iter(|| {
            let mut n = 0usize;
            for r in &rays {
                let o = ob(r);
                n += ob_tris
                    .iter()
                    .filter(|t| t.intersect(&o) < f32::INFINITY)
                    .count();
            }
            n
        })
    });
    g.finish();
}

criterion_group!(benches, build, trace, brute, instances, triangle);
criterion_main!(benches);
