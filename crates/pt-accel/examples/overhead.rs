//! pt-accel against obvhs called directly, on the same BVHs and the same rays.
//!
//! Criterion's separate measurements drift by 20% or more on a shared 2-core machine, which is too
//! coarse for a 10% budget. This program instead runs every variant in turn, 25 rounds, and keeps
//! each variant's fastest round, so slow periods of the host hit all variants alike.
//!
//! ```text
//! PT_ASSETS_DIR=../shared/assets cargo run --release -p pt-accel --example overhead -- \
//!     [meshes/stanford-bunny.obj] [coherent|incoherent]
//! ```
//!
//! The obvhs side uses its own traversal and Möller-Trumbore triangle test, with triangles in leaf
//! order and the hit's original triangle id looked up (as any user of obvhs must); pt-accel uses
//! its conservative node tests and watertight triangle test.

use std::hint::black_box;
use std::time::{Duration, Instant};

use glam::{Vec3, Vec3A};
use obvhs::BvhBuildParams;
use obvhs::bvh2::builder::build_bvh2_from_tris;
use obvhs::cwbvh::builder::build_cwbvh_from_tris;
use obvhs::ray::{Ray as ObRay, RayHit};
use obvhs::triangle::Triangle;
use pt_accel::{Accel, AccelKind, AccelOptions, BvhLayout, Instance, Ray, TriangleMesh};
use rand::{Rng, SeedableRng};

const ROUNDS: usize = 25;
const RAYS: usize = 60_000;

fn incoherent(mesh: &TriangleMesh) -> Vec<Ray> {
    let b = mesh.bounds();
    let mut rng = rand_pcg::Pcg64::seed_from_u64(1);
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

fn coherent(mesh: &TriangleMesh) -> Vec<Ray> {
    let (c, r) = mesh.bounds().bounding_sphere();
    let eye = c + Vec3::new(0.3, 0.2, 1.0).normalize() * r * 2.5;
    let f = (c - eye).normalize();
    let right = f.cross(Vec3::Y).normalize();
    let up = right.cross(f);
    let n = (RAYS as f32).sqrt() as usize;
    let h = 25f32.to_radians().tan();
    (0..n * n)
        .map(|i| {
            let (x, y) = ((i % n) as f32 + 0.5, (i / n) as f32 + 0.5);
            let d = f
                + right * ((2.0 * x / n as f32 - 1.0) * h)
                + up * ((1.0 - 2.0 * y / n as f32) * h);
            Ray::new(eye, d.normalize())
        })
        .collect()
}

fn main() {
    let mut args = std::env::args().skip(1);
    let name = args
        .next()
        .unwrap_or_else(|| "meshes/stanford-bunny.obj".into());
    let set = args.next().unwrap_or_else(|| "incoherent".into());
    let path = pt_scene::find_asset(&name).unwrap_or_else(|e| {
        eprintln!("overhead: {e}");
        std::process::exit(1)
    });
    let mesh = pt_scene::load_mesh(path)
        .expect("mesh loads")
        .geometry()
        .clone();
    let rays = if set == "coherent" {
        coherent(&mesh)
    } else {
        incoherent(&mesh)
    };

    let four = Accel::build(
        &[&mesh],
        &[Instance::new(0)],
        &AccelOptions::new()
            .kind(AccelKind::Bvh)
            .layout(BvhLayout::Four),
    );
    let wide = Accel::build(
        &[&mesh],
        &[Instance::new(0)],
        &AccelOptions::new()
            .kind(AccelKind::Bvh)
            .layout(BvhLayout::Wide),
    );
    let binary = Accel::build(
        &[&mesh],
        &[Instance::new(0)],
        &AccelOptions::new()
            .kind(AccelKind::Bvh)
            .layout(BvhLayout::Binary),
    );
    let tris: Vec<Triangle> = (0..mesh.triangle_count())
        .map(|i| {
            let [a, b, c] = mesh.triangle(i);
            Triangle {
                v0: a.into(),
                v1: b.into(),
                v2: c.into(),
            }
        })
        .collect();
    let params = BvhBuildParams::medium_build();
    let cw = build_cwbvh_from_tris(&tris, params, &mut Duration::default());
    let cw_tris: Vec<Triangle> = cw
        .primitive_indices
        .iter()
        .map(|&i| tris[i as usize])
        .collect();
    let b2 = build_bvh2_from_tris(&tris, params, &mut Duration::default());
    let b2_tris: Vec<Triangle> = b2
        .primitive_indices
        .iter()
        .map(|&i| tris[i as usize])
        .collect();
    let ob = |r: &Ray| {
        ObRay::new(
            Vec3A::from(r.origin),
            Vec3A::from(r.dir),
            0.0,
            f32::INFINITY,
        )
    };

    let cw_closest = || -> u64 {
        rays.iter()
            .filter_map(|r| {
                let mut h = RayHit::none();
                cw.ray_traverse(ob(r), &mut h, |ray, id| cw_tris[id].intersect(ray))
                    .then(|| u64::from(cw.primitive_indices[h.primitive_id as usize]))
            })
            .sum()
    };
    let cw_any = || -> u64 {
        rays.iter()
            .filter(|r| !cw.ray_traverse_miss(ob(r), |ray, id| cw_tris[id].intersect(ray)))
            .count() as u64
    };

    // Pairs: a pt-accel variant, then the obvhs traversal it is compared with (pt's four-wide
    // tree has no obvhs counterpart; it is compared with obvhs' fastest, the CWBVH).
    type Job<'a> = Box<dyn Fn() -> u64 + 'a>;
    let variants: Vec<(&str, Job<'_>)> = vec![
        (
            "closest  pt-accel four",
            Box::new(|| {
                rays.iter()
                    .filter_map(|r| four.intersect(r))
                    .map(|h| u64::from(h.prim))
                    .sum()
            }),
        ),
        ("closest  obvhs cwbvh", Box::new(cw_closest)),
        (
            "closest  pt-accel wide",
            Box::new(|| {
                rays.iter()
                    .filter_map(|r| wide.intersect(r))
                    .map(|h| u64::from(h.prim))
                    .sum()
            }),
        ),
        ("closest  obvhs cwbvh", Box::new(cw_closest)),
        (
            "closest  pt-accel binary",
            Box::new(|| {
                rays.iter()
                    .filter_map(|r| binary.intersect(r))
                    .map(|h| u64::from(h.prim))
                    .sum()
            }),
        ),
        (
            "closest  obvhs bvh2",
            Box::new(|| {
                rays.iter()
                    .filter_map(|r| {
                        let mut h = RayHit::none();
                        b2.ray_traverse(ob(r), &mut h, |ray, id| b2_tris[id].intersect(ray))
                            .then(|| u64::from(b2.primitive_indices[h.primitive_id as usize]))
                    })
                    .sum()
            }),
        ),
        (
            "any-hit  pt-accel four",
            Box::new(|| rays.iter().filter(|r| four.occluded(r)).count() as u64),
        ),
        ("any-hit  obvhs cwbvh", Box::new(cw_any)),
        (
            "any-hit  pt-accel wide",
            Box::new(|| rays.iter().filter(|r| wide.occluded(r)).count() as u64),
        ),
        ("any-hit  obvhs cwbvh", Box::new(cw_any)),
        (
            "any-hit  pt-accel binary",
            Box::new(|| rays.iter().filter(|r| binary.occluded(r)).count() as u64),
        ),
        (
            "any-hit  obvhs bvh2",
            Box::new(|| {
                rays.iter()
                    .filter(|r| !b2.ray_traverse_miss(ob(r), |ray, id| b2_tris[id].intersect(ray)))
                    .count() as u64
            }),
        ),
    ];

    let mut best = vec![f64::MAX; variants.len()];
    for _ in 0..ROUNDS {
        for (i, (_, job)) in variants.iter().enumerate() {
            let start = Instant::now();
            black_box(job());
            best[i] = best[i].min(start.elapsed().as_secs_f64());
        }
    }
    println!(
        "{name}, {} {set} rays, single thread, best of {ROUNDS} interleaved rounds:",
        rays.len()
    );
    for (i, (label, _)) in variants.iter().enumerate() {
        let mrays = rays.len() as f64 / best[i] / 1e6;
        if i % 2 == 0 {
            println!(
                "  {label:26} {mrays:6.2} Mrays/s  {:+.1}% time vs obvhs",
                (best[i] / best[i + 1] - 1.0) * 100.0
            );
        } else {
            println!("  {label:26} {mrays:6.2} Mrays/s");
        }
    }
}
