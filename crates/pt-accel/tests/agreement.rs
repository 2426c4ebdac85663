//! The BVH must return exactly what brute force returns: same closest triangle (except at exact
//! ties in `t`), same `t` within 1e-5 relative, same occlusion answer.

use glam::{Affine3A, Vec3};
use pt_accel::{Accel, AccelKind, BuildQuality, Instance, Ray, TriangleMesh};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

fn random_unit_vector(rng: &mut Pcg64) -> Vec3 {
    loop {
        let v = Vec3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        let l = v.length_squared();
        if l > 1e-4 && l <= 1.0 {
            return v / l.sqrt();
        }
    }
}

/// `n` random triangles with corners in the unit cube, mapped through `scale` and `offset`.
fn soup(rng: &mut Pcg64, n: usize, scale: f32, offset: Vec3) -> TriangleMesh {
    let corners: Vec<[Vec3; 3]> = (0..n)
        .map(|_| {
            let c = Vec3::new(rng.random(), rng.random(), rng.random());
            // Small triangles around a random centre, as in a real mesh.
            let t = [0, 1, 2].map(|_| c + random_unit_vector(rng) * rng.random_range(0.01..0.15));
            t.map(|p| p * scale + offset)
        })
        .collect();
    TriangleMesh::from_triangles(&corners).unwrap()
}

/// Compare closest hits and occlusion of `accel` against brute force for `rays` random rays
/// whose origins lie in the scene bounds (so many start inside the geometry).
fn compare(meshes: &[TriangleMesh], instances: &[Instance], rays: usize, seed: u64) {
    let brute = Accel::build(
        meshes,
        instances,
        AccelKind::BruteForce,
        BuildQuality::Medium,
    );
    for quality in [BuildQuality::Medium, BuildQuality::High] {
        let bvh = Accel::build(meshes, instances, AccelKind::Bvh, quality);
        assert_eq!(bvh.stats().kind, AccelKind::Bvh);
        let b = bvh.bounds();
        let mut rng = Pcg64::seed_from_u64(seed);
        let (mut hits, mut mismatched_ties) = (0usize, 0usize);
        for _ in 0..rays {
            let u = Vec3::new(rng.random(), rng.random(), rng.random());
            let origin = b.min + (b.max - b.min) * u;
            let ray = Ray::new(origin, random_unit_vector(&mut rng));
            let (x, y) = (brute.intersect(&ray), bvh.intersect(&ray));
            match (x, y) {
                (None, None) => {}
                (Some(x), Some(y)) => {
                    hits += 1;
                    let tol = 1e-5 * x.t.abs().max(f32::MIN_POSITIVE);
                    assert!(
                        (x.t - y.t).abs() <= tol,
                        "t differs: {x:?} vs {y:?} for {ray:?}"
                    );
                    if (x.instance, x.prim) != (y.instance, y.prim) {
                        // Only acceptable when both triangles are hit at the same distance.
                        assert_eq!(x.t, y.t, "different triangle: {x:?} vs {y:?} for {ray:?}");
                        mismatched_ties += 1;
                    }
                }
                _ => panic!("brute force {x:?} but BVH {y:?} for {ray:?} ({quality:?})"),
            }
            let shadow = Ray::with_t_max(
                ray.origin,
                ray.dir,
                rng.random_range(0.0..1.0) * b.diagonal().length(),
            );
            assert_eq!(
                brute.occluded(&shadow),
                bvh.occluded(&shadow),
                "occlusion differs for {shadow:?}"
            );
        }
        assert!(
            hits > rays / 10,
            "only {hits} of {rays} rays hit: the test is not testing"
        );
        assert!(mismatched_ties < rays / 1000);
    }
}

#[test]
fn bvh_matches_brute_force_on_random_soup() {
    let mut rng = Pcg64::seed_from_u64(1);
    let mesh = soup(&mut rng, 2000, 1.0, Vec3::ZERO);
    compare(&[mesh], &[Instance::new(0)], 100_000, 2);
}

#[test]
fn bvh_matches_brute_force_at_tiny_scale() {
    // At scale 1e-4 most hits are closer than 1e-4: obvhs' own CWBVH node test would miss them.
    let mut rng = Pcg64::seed_from_u64(3);
    let mesh = soup(&mut rng, 500, 1e-4, Vec3::ZERO);
    compare(&[mesh], &[Instance::new(0)], 20_000, 4);
}

#[test]
fn bvh_matches_brute_force_far_from_origin() {
    let mut rng = Pcg64::seed_from_u64(5);
    let mesh = soup(&mut rng, 500, 10.0, Vec3::new(1e5, -1e5, 1e5));
    compare(&[mesh], &[Instance::new(0)], 20_000, 6);
}

#[test]
fn bvh_matches_brute_force_through_instance_transforms() {
    let mut rng = Pcg64::seed_from_u64(7);
    let meshes = [
        soup(&mut rng, 300, 1.0, Vec3::ZERO),
        soup(&mut rng, 200, 1.0, Vec3::ZERO),
    ];
    let instances: Vec<Instance> = (0..10)
        .map(|i| {
            let t = Affine3A::from_scale_rotation_translation(
                Vec3::new(1.0 + i as f32 * 0.1, 0.5, 2.0),
                glam::Quat::from_rotation_y(i as f32),
                Vec3::new(i as f32 * 0.7, 0.0, 0.0),
            );
            Instance::with_transform((i % 2) as u32, t)
        })
        .collect();
    compare(&meshes, &instances, 20_000, 8);
}

#[test]
fn axis_aligned_rays_along_box_faces() {
    // Cornell-box-like walls: rays exactly parallel to the axes, some travelling in a wall's plane.
    let quad = |a: Vec3, b: Vec3, c: Vec3, d: Vec3| [[a, b, c], [a, c, d]];
    let mut tris = Vec::new();
    tris.extend(quad(Vec3::ZERO, Vec3::X, Vec3::new(1.0, 0.0, 1.0), Vec3::Z));
    tris.extend(quad(Vec3::ZERO, Vec3::Y, Vec3::new(0.0, 1.0, 1.0), Vec3::Z));
    tris.extend(quad(
        Vec3::Z,
        Vec3::new(1.0, 0.0, 1.0),
        Vec3::ONE,
        Vec3::new(0.0, 1.0, 1.0),
    ));
    for i in 0..20 {
        let z = 0.05 * i as f32;
        tris.extend(quad(
            Vec3::new(0.2, 0.2, z),
            Vec3::new(0.8, 0.2, z),
            Vec3::new(0.8, 0.8, z),
            Vec3::new(0.2, 0.8, z),
        ));
    }
    let mesh = TriangleMesh::from_triangles(&tris).unwrap();
    let brute = Accel::build(
        &[&mesh],
        &[Instance::new(0)],
        AccelKind::BruteForce,
        BuildQuality::Medium,
    );
    let bvh = Accel::build(
        &[&mesh],
        &[Instance::new(0)],
        AccelKind::Bvh,
        BuildQuality::Medium,
    );
    for dir in [Vec3::X, Vec3::Y, Vec3::Z, -Vec3::X, -Vec3::Y, -Vec3::Z] {
        for i in 0..=40 {
            for j in 0..=40 {
                let (u, v) = (i as f32 / 40.0, j as f32 / 40.0);
                let origin = match dir.abs().max_position() {
                    0 => Vec3::new(0.5 - dir.x * 0.7, u, v),
                    1 => Vec3::new(u, 0.5 - dir.y * 0.7, v),
                    _ => Vec3::new(u, v, 0.5 - dir.z * 0.7),
                };
                let ray = Ray::new(origin, dir);
                let (x, y) = (brute.intersect(&ray), bvh.intersect(&ray));
                assert_eq!(x.map(|h| h.t), y.map(|h| h.t), "{ray:?}");
            }
        }
    }
}

#[test]
fn empty_and_degenerate_scenes_answer_no_hit() {
    let ray = Ray::new(Vec3::new(0.1, 0.1, 1.0), -Vec3::Z);
    for kind in [AccelKind::Auto, AccelKind::BruteForce, AccelKind::Bvh] {
        let empty = Accel::build::<TriangleMesh>(&[], &[], kind, BuildQuality::Medium);
        assert!(empty.intersect(&ray).is_none());
        assert!(!empty.occluded(&ray));
        assert!(empty.bounds().is_empty());

        let bad = TriangleMesh::from_triangles(&[
            [Vec3::ZERO, Vec3::X, Vec3::X * 2.0],
            [Vec3::ZERO, Vec3::NAN, Vec3::Y],
            [Vec3::ZERO, Vec3::splat(f32::INFINITY), Vec3::Y],
            [Vec3::ZERO, Vec3::X, Vec3::Y],
        ])
        .unwrap();
        let accel = Accel::build(&[&bad], &[Instance::new(0)], kind, BuildQuality::Medium);
        assert_eq!(accel.stats().input_triangles, 4);
        assert_eq!(accel.stats().skipped_triangles, 3);
        let hit = accel.intersect(&ray).unwrap();
        assert_eq!(hit.prim, 3);
        // Rays with NaN or zero directions are answered, not panicked on.
        assert!(accel.intersect(&Ray::new(Vec3::ZERO, Vec3::ZERO)).is_none());
        assert!(accel.intersect(&Ray::new(Vec3::NAN, Vec3::Z)).is_none());
    }
}

#[test]
fn auto_picks_brute_force_for_a_handful_of_triangles() {
    let one = TriangleMesh::from_triangles(&[[Vec3::ZERO, Vec3::X, Vec3::Y]]).unwrap();
    let a = Accel::build(
        &[one],
        &[Instance::new(0)],
        AccelKind::Auto,
        BuildQuality::Medium,
    );
    assert_eq!(a.stats().kind, AccelKind::BruteForce);
    let mut rng = Pcg64::seed_from_u64(9);
    let many = soup(&mut rng, 100, 1.0, Vec3::ZERO);
    let b = Accel::build(
        &[many],
        &[Instance::new(0)],
        AccelKind::Auto,
        BuildQuality::Medium,
    );
    assert_eq!(b.stats().kind, AccelKind::Bvh);
    assert!(b.stats().nodes > 0);
}

/// A closed latitude-longitude sphere with jittered radii (pbrt's watertightness scene).
fn jittered_sphere(rng: &mut Pcg64, n_theta: u32, n_phi: u32) -> TriangleMesh {
    let mut positions = vec![Vec3::Z * rng.random_range(0.9..1.1)];
    for i in 1..n_theta {
        let theta = std::f32::consts::PI * i as f32 / n_theta as f32;
        for j in 0..n_phi {
            let phi = 2.0 * std::f32::consts::PI * j as f32 / n_phi as f32;
            let r = rng.random_range(0.9..1.1);
            positions.push(
                r * Vec3::new(
                    theta.sin() * phi.cos(),
                    theta.sin() * phi.sin(),
                    theta.cos(),
                ),
            );
        }
    }
    positions.push(-Vec3::Z * rng.random_range(0.9..1.1));
    let ring = |i: u32, j: u32| 1 + (i - 1) * n_phi + (j % n_phi);
    let south = positions.len() as u32 - 1;
    let mut indices = Vec::new();
    for j in 0..n_phi {
        indices.push([0, ring(1, j), ring(1, j + 1)]);
        indices.push([south, ring(n_theta - 1, j + 1), ring(n_theta - 1, j)]);
        for i in 1..n_theta - 1 {
            indices.push([ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)]);
            indices.push([ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)]);
        }
    }
    TriangleMesh::new(positions, indices).unwrap()
}

#[test]
fn rays_at_vertices_and_edges_of_a_closed_mesh_never_miss() {
    let mut rng = Pcg64::seed_from_u64(11);
    for scale in [1e-4f32, 1.0, 1e4] {
        let sphere = jittered_sphere(&mut rng, 16, 16);
        let inst = [Instance::with_transform(
            0,
            Affine3A::from_scale(Vec3::splat(scale)),
        )];
        for kind in [AccelKind::BruteForce, AccelKind::Bvh] {
            let accel = Accel::build(&[&sphere], &inst, kind, BuildQuality::Medium);
            let mut targets: Vec<Vec3> = sphere.positions().to_vec();
            for t in sphere.indices() {
                for k in 0..3 {
                    let (a, b) = (
                        sphere.positions()[t[k] as usize],
                        sphere.positions()[t[(k + 1) % 3] as usize],
                    );
                    targets.push((a + b) * 0.5);
                }
            }
            for target in targets.iter().map(|&p| p * scale) {
                for _ in 0..8 {
                    // From a random point well inside the sphere, aimed exactly at the target.
                    let origin = random_unit_vector(&mut rng) * rng.random_range(0.0..0.5) * scale;
                    let ray = Ray::new(origin, target - origin);
                    assert!(
                        accel.intersect(&ray).is_some(),
                        "{kind:?} scale {scale}: {ray:?} escaped"
                    );
                    assert!(
                        accel.occluded(&ray),
                        "{kind:?} scale {scale}: {ray:?} not occluded"
                    );
                }
            }
        }
    }
}
