//! The BVH must return exactly what brute force returns: same closest triangle (except at exact
//! ties in `t`), same `t` within 1e-5 relative, same occlusion answer.

use glam::{Affine3A, Vec3};
use pt_accel::lanes::{Simd, WIDTH, WithSimd, dispatch_portable};
use pt_accel::{
    Accel, AccelKind, AccelOptions, BuildQuality, BvhLayout, Hit, Instance, Ray, RayLanes,
    TriangleMesh,
};
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

/// How far the two-level BVH's object-space ray may sit beside the world ray: advancing the
/// origin by its error bound and rounding it again moves the line by a few gamma(3) |origin|
/// (inverse transforms in these tests scale by at most 2). Differences between variants must be
/// explained by a shift of this size.
fn lateral_shift(ray: &Ray) -> f32 {
    1e-6 * ray.origin.abs().max_element()
}

/// World-space corners of the triangle a hit refers to.
fn world_triangle(meshes: &[TriangleMesh], instances: &[Instance], h: &Hit) -> [Vec3; 3] {
    let inst = &instances[h.instance as usize];
    meshes[inst.mesh as usize]
        .triangle(h.prim as usize)
        .map(|p| inst.transform.transform_point3(p))
}

/// |cos| between the ray and the hit triangle's normal.
fn cos_to_normal(tri: &[Vec3; 3], ray: &Ray) -> f32 {
    (tri[1] - tri[0])
        .cross(tri[2] - tri[0])
        .normalize()
        .dot(ray.dir.normalize())
        .abs()
}

/// True when moving the ray sideways by `lateral_shift` could move this hit across an edge of its
/// triangle, or the hit is closer to the origin than that shift (so a variant may legitimately
/// report another triangle or nothing).
fn near_edge_or_origin(
    meshes: &[TriangleMesh],
    instances: &[Instance],
    h: &Hit,
    ray: &Ray,
) -> bool {
    let tri = world_triangle(meshes, instances, h);
    let slack = lateral_shift(ray) / cos_to_normal(&tri, ray).max(1e-3);
    let p = ray.at(h.t);
    let edge_distance = (0..3)
        .map(|i| {
            let (a, b) = (tri[i], tri[(i + 1) % 3]);
            (p - a).cross(b - a).length() / (b - a).length()
        })
        .fold(f32::INFINITY, f32::min);
    edge_distance <= 4.0 * slack + 1e-5 * h.t || h.t * ray.dir.length() <= 4.0 * lateral_shift(ray)
}

/// Tolerance on the distance to the same triangle: 1e-5 relative, plus the sideways shift over
/// the grazing cosine.
fn t_tolerance(meshes: &[TriangleMesh], instances: &[Instance], h: &Hit, ray: &Ray) -> f32 {
    let cos = cos_to_normal(&world_triangle(meshes, instances, h), ray).max(1e-3);
    1e-5 * h.t.abs() + 4.0 * lateral_shift(ray) / (ray.dir.length() * cos)
}

/// Every strategy and layout under test.
fn variants() -> Vec<(&'static str, AccelOptions)> {
    let o = AccelOptions::new();
    let bvh = |l| o.kind(AccelKind::Bvh).layout(l);
    let two = |l| o.kind(AccelKind::TwoLevel).layout(l);
    vec![
        ("bvh eight", bvh(BvhLayout::Eight)),
        ("bvh four", bvh(BvhLayout::Four)),
        ("bvh wide", bvh(BvhLayout::Wide)),
        ("bvh binary", bvh(BvhLayout::Binary)),
        (
            "bvh eight fastest",
            bvh(BvhLayout::Eight).quality(BuildQuality::Fastest),
        ),
        (
            "bvh four fastest",
            bvh(BvhLayout::Four).quality(BuildQuality::Fastest),
        ),
        (
            "bvh eight high",
            bvh(BvhLayout::Eight).quality(BuildQuality::High),
        ),
        (
            "bvh four high",
            bvh(BvhLayout::Four).quality(BuildQuality::High),
        ),
        (
            "bvh wide high",
            bvh(BvhLayout::Wide).quality(BuildQuality::High),
        ),
        ("two-level eight", two(BvhLayout::Eight)),
        ("two-level four", two(BvhLayout::Four)),
        ("two-level wide", two(BvhLayout::Wide)),
        ("two-level binary", two(BvhLayout::Binary)),
    ]
}

/// A random ray starting in the (slightly enlarged) scene bounds, so many start inside geometry.
fn random_ray(rng: &mut Pcg64, b: &pt_accel::Bounds3) -> Ray {
    let u = Vec3::new(rng.random(), rng.random(), rng.random());
    let d = b.diagonal();
    Ray::new(b.min - d * 0.05 + d * 1.1 * u, random_unit_vector(rng))
}

/// Compare closest hits and occlusion: every variant against the flat wide BVH for `rays` random
/// rays, and against brute force for the first `brute_rays` of them. Closest `t` must agree to
/// 1e-5 relative; a different triangle is accepted only at exactly the same `t` (an exact tie).
fn compare(
    meshes: &[TriangleMesh],
    instances: &[Instance],
    rays: usize,
    brute_rays: usize,
    seed: u64,
) {
    let brute = Accel::build(
        meshes,
        instances,
        &AccelOptions::new().kind(AccelKind::BruteForce),
    );
    let built: Vec<(&str, Accel)> = variants()
        .into_iter()
        .map(|(n, o)| (n, Accel::build(meshes, instances, &o)))
        .collect();
    let reference = &built[0].1;
    for (name, accel) in &built {
        assert_eq!(
            accel.stats().input_triangles,
            brute.stats().input_triangles,
            "{name}"
        );
        assert_eq!(
            accel.stats().skipped_triangles,
            brute.stats().skipped_triangles,
            "{name}"
        );
    }
    let b = reference.bounds();
    let mut rng = Pcg64::seed_from_u64(seed);
    let (mut hits, mut ties) = (0usize, 0usize);
    let mut lanes = Vec::new();
    for n in 0..rays {
        let ray = random_ray(&mut rng, &b);
        let shadow = Ray::with_t_max(
            ray.origin,
            ray.dir,
            rng.random_range(0.0..1.0) * b.diagonal().length(),
        );
        if n < 8_000 {
            lanes.push((ray, shadow));
            if lanes.len() == WIDTH {
                lanes_equal_one_ray_queries(&built, &lanes, n);
                lanes.clear();
            }
        }
        let expected = if n < brute_rays {
            brute.intersect(&ray)
        } else {
            reference.intersect(&ray)
        };
        let expected_occluded = if n < brute_rays {
            brute.occluded(&shadow)
        } else {
            reference.occluded(&shadow)
        };
        hits += usize::from(expected.is_some());
        for (name, accel) in &built {
            let got = accel.intersect(&ray);
            match (expected, got) {
                (None, None) => {}
                (Some(x), Some(y)) if (x.instance, x.prim) == (y.instance, y.prim) => {
                    let tol = t_tolerance(meshes, instances, &x, &ray);
                    assert!(
                        (x.t - y.t).abs() <= tol,
                        "{name}: t differs beyond {tol}: {x:?} vs {y:?} for {ray:?}"
                    );
                }
                // Coincident triangles (the dragon has 1,254 duplicates) hit at the same distance.
                (Some(x), Some(y))
                    if (x.t - y.t).abs() <= t_tolerance(meshes, instances, &x, &ray) =>
                {
                    ties += 1
                }
                _ => {
                    // Another triangle or nothing: only where a rounding-sized sideways shift of
                    // the ray can explain it.
                    let explained = [expected, got]
                        .iter()
                        .flatten()
                        .any(|h| near_edge_or_origin(meshes, instances, h, &ray));
                    assert!(
                        explained,
                        "{name}: expected {expected:?}, got {got:?} for {ray:?}"
                    );
                    ties += 1;
                }
            }
            if accel.occluded(&shadow) != expected_occluded {
                // Same rule for shadow rays: the closest hit along the segment must be marginal.
                let h = reference
                    .intersect(&shadow)
                    .or_else(|| accel.intersect(&shadow));
                let explained = h.is_some_and(|h| {
                    near_edge_or_origin(meshes, instances, &h, &shadow)
                        || (h.t - shadow.t_max).abs() <= t_tolerance(meshes, instances, &h, &shadow)
                });
                assert!(explained, "{name}: occlusion differs for {shadow:?}");
                ties += 1;
            }
        }
    }
    assert!(
        hits > rays / 10,
        "only {hits} of {rays} rays hit: the test is not testing"
    );
    // Marginal differences are rare: a few per ten thousand queries near the origin, more at 1e5
    // where the coordinate spacing (0.008) is a sizeable fraction of a triangle.
    assert!(
        ties <= rays * built.len() / 50,
        "{ties} marginal differences in {rays} rays"
    );
}

/// The lane queries made with given lanes (`intersect_lanes_in`, `occluded_lanes_in`).
struct InLanes<'a> {
    accel: &'a Accel,
    closest: &'a RayLanes,
    shadow: &'a RayLanes,
    mask: u32,
}

impl WithSimd for InLanes<'_> {
    type Output = ([Option<Hit>; WIDTH], u32);
    #[inline(always)]
    fn with_simd<S: Simd>(self, s: S) -> Self::Output {
        (
            self.accel.intersect_lanes_in(s, self.closest, self.mask),
            self.accel.occluded_lanes_in(s, self.shadow, self.mask),
        )
    }
}

/// Every variant's lane queries (`intersect_lanes`, `occluded_lanes`, which run their `_in`
/// forms with the detected lanes, and the `_in` forms with the portable lanes) answer each
/// lane in the mask exactly as its one-ray queries do, leave the others empty, and treat an
/// invalid ray as a miss.
fn lanes_equal_one_ray_queries(built: &[(&str, Accel)], lanes: &[(Ray, Ray)], n: usize) {
    let mut closest: [Ray; WIDTH] = std::array::from_fn(|i| lanes[i].0);
    let shadow: [Ray; WIDTH] = std::array::from_fn(|i| lanes[i].1);
    if n.is_multiple_of(3) {
        closest[n % WIDTH].dir = Vec3::NAN;
    }
    let mask = [0xff, 0xa5, 0x3c, 0x01][n / WIDTH % 4];
    let (closest_lanes, shadow_lanes) = (RayLanes::from(&closest), RayLanes::from(&shadow));
    for (name, accel) in built {
        let job = InLanes {
            accel,
            closest: &closest_lanes,
            shadow: &shadow_lanes,
            mask,
        };
        let got = accel.intersect_lanes(&closest_lanes, mask);
        let blocked = accel.occluded_lanes(&shadow_lanes, mask);
        assert_eq!(
            dispatch_portable(job),
            (got, blocked),
            "{name}: the `_in` queries with the portable lanes"
        );
        for lane in 0..WIDTH {
            let on = mask & (1 << lane) != 0;
            let want = on.then(|| accel.intersect(&closest[lane])).flatten();
            assert_eq!(got[lane], want, "{name}, lane {lane}: {:?}", closest[lane]);
            assert_eq!(
                blocked & (1 << lane) != 0,
                on && accel.occluded(&shadow[lane]),
                "{name}, lane {lane}: {:?}",
                shadow[lane]
            );
        }
    }
}

#[test]
fn all_variants_match_brute_force_on_random_soup() {
    let mut rng = Pcg64::seed_from_u64(1);
    let mesh = soup(&mut rng, 2000, 1.0, Vec3::ZERO);
    compare(&[mesh], &[Instance::new(0)], 100_000, 20_000, 2);
}

#[test]
fn all_variants_match_brute_force_at_tiny_scale() {
    // At scale 1e-4 most hits are closer than 1e-4: obvhs' own CWBVH node test would miss them.
    let mut rng = Pcg64::seed_from_u64(3);
    let mesh = soup(&mut rng, 500, 1e-4, Vec3::ZERO);
    compare(&[mesh], &[Instance::new(0)], 20_000, 20_000, 4);
}

#[test]
fn all_variants_match_brute_force_far_from_origin() {
    let mut rng = Pcg64::seed_from_u64(5);
    let mesh = soup(&mut rng, 500, 10.0, Vec3::new(1e5, -1e5, 1e5));
    compare(&[mesh], &[Instance::new(0)], 20_000, 20_000, 6);
}

/// Ten instances of two meshes with rotations, non-uniform scales and translations.
fn instanced_scene(rng: &mut Pcg64) -> (Vec<TriangleMesh>, Vec<Instance>) {
    let meshes = vec![
        soup(rng, 300, 1.0, Vec3::ZERO),
        soup(rng, 200, 1.0, Vec3::ZERO),
    ];
    let instances = (0..10)
        .map(|i| {
            let t = Affine3A::from_scale_rotation_translation(
                Vec3::new(1.0 + i as f32 * 0.1, 0.5, 2.0),
                glam::Quat::from_euler(glam::EulerRot::XYZ, i as f32, 0.3 * i as f32, 0.1),
                Vec3::new(i as f32 * 0.7, 0.0, 0.0),
            );
            Instance::with_transform((i % 2) as u32, t)
        })
        .collect();
    (meshes, instances)
}

#[test]
fn all_variants_match_brute_force_through_instance_transforms() {
    let mut rng = Pcg64::seed_from_u64(7);
    let (meshes, instances) = instanced_scene(&mut rng);
    compare(&meshes, &instances, 100_000, 20_000, 8);
}

/// The two-level BVH skips an instance when the world ray misses its (padded) world bounds
/// before the closest hit so far. Hits on the bounds themselves must survive that: unit cubes
/// (every face on the box) under rotations, scales from 1e-3 to 1e3 on one axis and
/// translations up to 1e4, hit from outside at random points of their faces, half of them
/// near the faces' corners. The closest hit is found, and a shadow ray whose range ends four
/// ulps beyond the hit's distance is blocked (the object-space range `t_max - dt` rounds by an
/// ulp, so the hit's own distance is not always inside it; the culling test widens its range
/// by eight).
#[test]
fn two_level_instance_culling_keeps_hits_on_the_instance_bounds() {
    let mut rng = Pcg64::seed_from_u64(23);
    let c = |x: u32, y: u32, z: u32| Vec3::new(x as f32, y as f32, z as f32);
    let mut corners = Vec::new();
    for a in 0..3 {
        for side in 0..2 {
            // The face of axis `a` at coordinate `side`, as two triangles.
            let p = |u: u32, v: u32| {
                let mut q = [0; 3];
                q[a] = side;
                q[(a + 1) % 3] = u;
                q[(a + 2) % 3] = v;
                c(q[0], q[1], q[2])
            };
            corners.push([p(0, 0), p(1, 0), p(1, 1)]);
            corners.push([p(0, 0), p(1, 1), p(0, 1)]);
        }
    }
    let cube = TriangleMesh::from_triangles(&corners).unwrap();
    let instances: Vec<Instance> = (0..12)
        .map(|i| {
            let t = Affine3A::from_scale_rotation_translation(
                Vec3::new(10f32.powi(i % 7 - 3), 1.0, 0.5 + i as f32 * 0.1),
                glam::Quat::from_euler(glam::EulerRot::XYZ, 0.7 * i as f32, 0.2, 0.4 * i as f32),
                Vec3::new(i as f32 * 5.0, 10f32.powi(i % 5), -3.0 * i as f32),
            );
            Instance::with_transform(0, t)
        })
        .collect();
    let accel = Accel::build(
        &[&cube],
        &instances,
        &AccelOptions::new().kind(AccelKind::TwoLevel),
    );
    let mut checked = 0;
    for inst in &instances {
        for _ in 0..2_000 {
            // A random point inside a random face, in world space, seen from outside the cube.
            let face = rng.random_range(0..corners.len());
            let [a, b, cc] = corners[face];
            // Half of the points within 1e-3 of a corner of the face (and so of the box, whose
            // extreme corners bound the instance's world box).
            let near = if rng.random::<bool>() { 1e-3 } else { 1.0 };
            let (u, v): (f32, f32) = (rng.random::<f32>() * near, rng.random::<f32>() * near);
            let (u, v) = if u + v > 1.0 {
                (1.0 - u, 1.0 - v)
            } else {
                (u, v)
            };
            let local = a + (b - a) * u + (cc - a) * v;
            let centre = Vec3::splat(0.5);
            let out = (local - centre).normalize_or_zero() + random_unit_vector(&mut rng) * 0.3;
            let from = local + out * rng.random_range(0.5..3.0);
            let (p, o) = (
                inst.transform.transform_point3(local),
                inst.transform.transform_point3(from),
            );
            let ray = Ray::new(o, p - o);
            let Some(hit) = accel.intersect(&ray) else {
                panic!("{ray:?} missed the cube of {:?}", inst.transform);
            };
            let shadow = Ray::with_t_max(ray.origin, ray.dir, hit.t * (1.0 + 2f32.powi(-21)));
            assert!(accel.occluded(&shadow), "{shadow:?} not blocked");
            checked += 1;
        }
    }
    assert_eq!(checked, 24_000);
}

/// The real meshes: every variant against the flat BVH for 400,000 rays, against brute force for
/// the first 1,000 (brute force over 69k triangles is too slow for more in CI; run the ignored
/// test for 20,000).
fn real_mesh(name: &str, rays: usize, brute_rays: usize) {
    let Some(path) = pt_scene::assets::find_asset_or_skip(name).unwrap() else {
        return;
    };
    let mesh = pt_scene::load_mesh(path).unwrap().geometry().clone();
    compare(&[mesh], &[Instance::new(0)], rays, brute_rays, 9);
}

#[test]
fn all_variants_agree_on_the_bunny() {
    real_mesh("meshes/stanford-bunny.obj", 400_000, 1_000);
}

#[test]
fn all_variants_agree_on_the_dragon() {
    real_mesh("meshes/dragon_vrip_res3.ply", 400_000, 1_000);
}

#[test]
#[ignore = "slow: brute force over 20,000 rays of the bunny and dragon"]
fn brute_force_agrees_on_real_meshes_heavy() {
    real_mesh("meshes/stanford-bunny.obj", 20_000, 20_000);
    real_mesh("meshes/dragon_vrip_res2.binary.ply", 20_000, 20_000);
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
        &AccelOptions::new().kind(AccelKind::BruteForce),
    );
    let bvhs: Vec<Accel> = variants()
        .into_iter()
        .map(|(_, o)| Accel::build(&[&mesh], &[Instance::new(0)], &o))
        .collect();
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
                let x = brute.intersect(&ray);
                for (k, bvh) in bvhs.iter().enumerate() {
                    let y = bvh.intersect(&ray);
                    match (x, y) {
                        (None, None) => {}
                        (Some(a), Some(b)) => {
                            let tol = t_tolerance(
                                std::slice::from_ref(&mesh),
                                &[Instance::new(0)],
                                &a,
                                &ray,
                            );
                            assert!(
                                (a.t - b.t).abs() <= tol,
                                "variant {k}: {a:?} vs {b:?} for {ray:?}"
                            )
                        }
                        _ => panic!("variant {k}: {x:?} vs {y:?} for {ray:?}"),
                    }
                }
            }
        }
    }
}

#[test]
fn empty_and_degenerate_scenes_answer_no_hit() {
    let ray = Ray::new(Vec3::new(0.1, 0.1, 1.0), -Vec3::Z);
    for kind in [
        AccelKind::Auto,
        AccelKind::BruteForce,
        AccelKind::Bvh,
        AccelKind::TwoLevel,
    ] {
        let opts = AccelOptions::new().kind(kind);
        let empty = Accel::build::<TriangleMesh>(&[], &[], &opts);
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
        let accel = Accel::build(&[&bad], &[Instance::new(0)], &opts);
        assert_eq!(accel.stats().input_triangles, 4);
        assert_eq!(accel.stats().skipped_triangles, 3);
        let hit = accel.intersect(&ray).unwrap();
        assert_eq!(hit.prim, 3);
        // Rays with NaN or zero directions are answered, not panicked on.
        assert!(accel.intersect(&Ray::new(Vec3::ZERO, Vec3::ZERO)).is_none());
        assert!(accel.intersect(&Ray::new(Vec3::NAN, Vec3::Z)).is_none());
    }
}

/// Finite coordinates too large for a BVH's surface-area costs (the glTF fuzzer's input had
/// corners up to 1.5e37; obvhs then indexed out of bounds) are skipped like non-finite ones, and
/// so are instances placed beyond `MAX_COORDINATE` by their transform; the rest still works.
#[test]
fn huge_coordinates_are_skipped_not_panicked_on() {
    let mut rng = Pcg64::seed_from_u64(5);
    let normal = soup(&mut rng, 60, 1.0, Vec3::ZERO);
    let mut tris: Vec<[Vec3; 3]> = (0..normal.triangle_count())
        .map(|i| normal.triangle(i))
        .collect();
    for k in 0..40 {
        let big = 10f32.powi(19 + k % 19);
        tris.push([
            Vec3::new(0.5, 0.5, 0.5),
            Vec3::new(big, 0.3 * big, 1.0),
            Vec3::new(-0.7 * big, big, -big),
        ]);
    }
    let mesh = TriangleMesh::from_triangles(&tris).unwrap();
    let small = TriangleMesh::from_triangles(&[[Vec3::ZERO, Vec3::X, Vec3::Y]]).unwrap();
    let instances = [
        Instance::new(0),
        Instance::with_transform(1, Affine3A::from_scale(Vec3::splat(1e30))),
        Instance::with_transform(1, Affine3A::from_translation(Vec3::new(0.0, 0.0, 2.0))),
    ];
    // The fuzzer's input itself: a box whose corners were mutated to huge finite values.
    let v = Vec3::new;
    let fuzzed = TriangleMesh::new(
        vec![
            v(0.00061953743, 1.5303065e37, 2.005536e-37),
            v(794624.0, -0.50000465, 6.2573235e-10),
            v(6.2641703e-10, 9.787766e-12, 2.5036746e-12),
            v(2.5036744e-12, 2.5036744e-12, 2.5036746e-12),
            v(2.5036744e-12, 2.5036744e-12, 2.5036744e-12),
            v(2.5036744e-12, 2.5036744e-12, 7.9344614e17),
            v(3.4040395e-18, 4.597624e24, 1.4640373e37),
            v(3.1368877e27, 6.8607355e22, 5.2392223e16),
            v(4.7563575e30, 7.397609e31, 1.8179895e31),
            v(1.1382921e36, 7.744693e31, 2.8701118e32),
            v(3.298635e-18, 681496200.0, 12.832595),
            v(2.7086058e-9, 3491900400.0, 869525.2),
            v(0.00061914785, 2.3376625e-18, 1.725978e25),
            v(3.2986315e-18, 2.3335878e-18, 6.7422188e22),
            v(2.5611809e-12, 7.1440446e31, 2.691459e20),
            v(6.771532e-10, 2.335984e-18, 7.0062382e22),
            v(170107420.0, 3.1502952e-18, 2.335984e-18),
            v(6.711315e22, 4.7428152e30, 0.5),
            v(-0.5, -0.5, -0.5),
            v(-0.5, 0.5, -0.5),
            v(-0.5, -0.5, -0.5),
            v(-0.5, 8.0, -0.5),
            v(0.5, -0.5, -0.5),
            v(0.5, 0.5, -0.5),
        ],
        [
            0, 1, 2, 3, 2, 1, 4, 5, 6, 7, 6, 5, 8, 9, 10, 11, 10, 9, 12, 13, 14, 15, 14, 13, 16,
            17, 18, 19, 18, 17, 20, 21, 22, 23, 22, 21,
        ]
        .chunks_exact(3)
        .map(|t| [t[0], t[1], t[2]])
        .collect(),
    )
    .unwrap();
    let ray = Ray::new(Vec3::new(0.25, 0.25, 5.0), -Vec3::Z);
    for (name, opts) in variants() {
        let accel = Accel::build(&[&fuzzed], &[Instance::new(0)], &opts);
        assert!(accel.stats().skipped_triangles > 0, "{name}");
        let accel = Accel::build(&[&mesh, &small], &instances, &opts);
        let stats = accel.stats();
        assert_eq!(stats.skipped_triangles, 40 + 1, "{name}");
        let hit = accel
            .intersect(&ray)
            .expect("the translated small triangle");
        assert_eq!(hit.instance, 2, "{name}");
    }
}

#[test]
fn auto_picks_brute_force_flat_or_two_level() {
    let one = TriangleMesh::from_triangles(&[[Vec3::ZERO, Vec3::X, Vec3::Y]]).unwrap();
    let a = Accel::build(&[one], &[Instance::new(0)], &AccelOptions::new());
    assert_eq!(a.stats().kind, AccelKind::BruteForce);
    let mut rng = Pcg64::seed_from_u64(9);
    let many = soup(&mut rng, 100, 1.0, Vec3::ZERO);
    let b = Accel::build(&[&many], &[Instance::new(0)], &AccelOptions::new());
    assert_eq!(b.stats().kind, AccelKind::Bvh);
    assert!(b.stats().nodes > 0);
    // Two meshes used once each: still one flat BVH.
    let c = Accel::build(
        &[&many, &many],
        &[Instance::new(0), Instance::new(1)],
        &AccelOptions::new(),
    );
    assert_eq!(c.stats().kind, AccelKind::Bvh);
    // A mesh used twice: its copy is cheap, so still one flat BVH.
    let twice = [
        Instance::new(0),
        Instance::with_transform(0, Affine3A::from_translation(Vec3::X * 3.0)),
    ];
    let d = Accel::build(&[&many], &twice, &AccelOptions::new());
    assert_eq!(d.stats().kind, AccelKind::Bvh);
    // Copies adding more than FLATTEN_MAX_COPIES triangles: two-level (one copy fewer: flat),
    // and the user can still force either.
    let copies = pt_accel::FLATTEN_MAX_COPIES / many.triangle_count() + 1;
    let lots: Vec<Instance> = (0..=copies)
        .map(|i| Instance::with_transform(0, Affine3A::from_translation(Vec3::X * 3.0 * i as f32)))
        .collect();
    let f = Accel::build(&[&many], &lots, &AccelOptions::new());
    assert_eq!(f.stats().kind, AccelKind::TwoLevel);
    let g = Accel::build(&[&many], &lots[..copies], &AccelOptions::new());
    assert_eq!(g.stats().kind, AccelKind::Bvh);
    let e = Accel::build(
        &[&many],
        &twice,
        &AccelOptions::new().kind(AccelKind::TwoLevel),
    );
    assert_eq!(e.stats().kind, AccelKind::TwoLevel);
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
        for (kind, opts) in variants()
            .into_iter()
            .chain([("brute", AccelOptions::new().kind(AccelKind::BruteForce))])
        {
            let accel = Accel::build(&[&sphere], &inst, &opts);
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

/// Count every intersection along a line with brute force (for inside/outside tests).
fn crossings(mesh: &TriangleMesh, origin: Vec3, dir: Vec3) -> usize {
    (0..mesh.triangle_count())
        .filter(|&i| {
            pt_accel::triangle::intersect_triangle(&Ray::new(origin, dir), &mesh.triangle(i))
                .is_some()
        })
        .count()
}

#[test]
fn rays_at_every_vertex_and_edge_of_the_closed_bunny_never_miss() {
    // The low-resolution bunny is closed (0 boundary edges): a ray from an inside point aimed
    // exactly at one of its vertices or edge midpoints must hit it, and so must the ray along the
    // same line coming from outside (beyond the bounding sphere) toward the inside point. (A ray
    // from outside merely aimed at a silhouette vertex may legitimately graze past it.)
    let Some(path) = pt_scene::assets::find_asset_or_skip("meshes/bunny-lowres-npm.obj").unwrap()
    else {
        return;
    };
    let bunny = pt_scene::load_mesh(path).unwrap().geometry().clone();
    let mut rng = Pcg64::seed_from_u64(12);
    let b = bunny.bounds();

    // Inside points: random points whose crossing count is odd along three random directions.
    let mut inside = Vec::new();
    while inside.len() < 4 {
        let p = b.min + b.diagonal() * Vec3::new(rng.random(), rng.random(), rng.random());
        let odd = (0..3)
            .filter(|_| crossings(&bunny, p, random_unit_vector(&mut rng)) % 2 == 1)
            .count();
        if odd == 3 {
            inside.push(p);
        }
    }
    let (_, r) = b.bounding_sphere();

    let mut targets: Vec<Vec3> = bunny.positions().to_vec();
    for t in bunny.indices() {
        for k in 0..3 {
            let (a, b) = (
                bunny.positions()[t[k] as usize],
                bunny.positions()[t[(k + 1) % 3] as usize],
            );
            targets.push((a + b) * 0.5);
        }
    }
    for (name, opts) in variants() {
        let accel = Accel::build(&[&bunny], &[Instance::new(0)], &opts);
        for &target in &targets {
            for &p in &inside {
                let from_outside = target + (target - p).normalize() * 2.0 * r;
                for ray in [
                    Ray::new(p, target - p),
                    Ray::with_t_max(from_outside, p - from_outside, 1.0),
                ] {
                    assert!(
                        accel.intersect(&ray).is_some(),
                        "{name}: {ray:?} slipped through"
                    );
                    assert!(accel.occluded(&ray), "{name}: {ray:?} not occluded");
                }
            }
        }
    }
}

/// Geometry that made obvhs' PLOC build crawl (one merge per pass: quadratic time) builds in
/// bounded time and still agrees with brute force: 30,000 copies of one triangle, a fan of
/// 60,000 slivers around a vertex, one polygon of 1,000,000 corners triangulated from a corner,
/// and 10,000 instances of one triangle with the same transform (seconds to minutes before:
/// 17 s for 10,000 copies, 32 s for the 60k fan, 11.6 s for the instances). The bound is
/// generous (a hang guard, not a benchmark): each build here takes well under a second.
#[test]
fn degenerate_geometry_builds_in_bounded_time_and_agrees() {
    let tau = std::f32::consts::TAU;
    let coincident =
        TriangleMesh::new(vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]; 30_000]).unwrap();
    let fan = {
        let n = 60_000u32;
        let mut p = vec![Vec3::ZERO];
        p.extend((0..=n).map(|i| {
            let a = tau * i as f32 / n as f32;
            Vec3::new(a.cos(), a.sin(), 0.0)
        }));
        TriangleMesh::new(p, (0..n).map(|i| [0, i + 1, i + 2]).collect()).unwrap()
    };
    let polygon = {
        let n = 1_000_000u32;
        let p: Vec<Vec3> = (0..n)
            .map(|i| {
                let a = tau * i as f32 / n as f32;
                Vec3::new(a.cos(), a.sin(), 0.0)
            })
            .collect();
        TriangleMesh::new(p, (1..n - 1).map(|i| [0, i, i + 1]).collect()).unwrap()
    };
    let one = TriangleMesh::new(vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]]).unwrap();
    let mut rng = Pcg64::seed_from_u64(11);
    let rays: Vec<Ray> = (0..64)
        .map(|_| {
            let o = Vec3::new(
                rng.random_range(-1.2..1.2),
                rng.random_range(-1.2..1.2),
                2.0,
            );
            let d = Vec3::new(
                rng.random_range(-0.3..0.3),
                rng.random_range(-0.3..0.3),
                -1.0,
            );
            Ray::new(o, d)
        })
        .collect();
    type Case<'a> = (
        &'a str,
        Vec<&'a TriangleMesh>,
        Vec<Instance>,
        Vec<AccelKind>,
    );
    let cases: Vec<Case<'_>> = vec![
        (
            "coincident",
            vec![&coincident],
            vec![Instance::new(0)],
            vec![AccelKind::Bvh],
        ),
        (
            "fan",
            vec![&fan],
            vec![Instance::new(0)],
            vec![AccelKind::Bvh],
        ),
        (
            "polygon",
            vec![&polygon],
            vec![Instance::new(0)],
            vec![AccelKind::Bvh],
        ),
        (
            "instances",
            vec![&one],
            vec![Instance::with_transform(0, Affine3A::IDENTITY); 10_000],
            vec![AccelKind::TwoLevel, AccelKind::Bvh],
        ),
    ];
    for (name, meshes, instances, kinds) in &cases {
        let brute = Accel::build(
            meshes,
            instances,
            &AccelOptions::new().kind(AccelKind::BruteForce),
        );
        for &kind in kinds {
            for layout in [
                BvhLayout::Eight,
                BvhLayout::Four,
                BvhLayout::Wide,
                BvhLayout::Binary,
            ] {
                let start = std::time::Instant::now();
                let options = AccelOptions::new().kind(kind).layout(layout);
                let accel = Accel::build(meshes, instances, &options);
                let secs = start.elapsed().as_secs_f64();
                assert!(
                    secs < 10.0,
                    "{name} {kind:?} {layout:?}: built in {secs:.1} s"
                );
                for ray in &rays {
                    let (a, b) = (accel.intersect(ray), brute.intersect(ray));
                    assert_eq!(a.is_some(), b.is_some(), "{name} {kind:?} {layout:?}");
                    if let (Some(a), Some(b)) = (a, b) {
                        assert!(
                            (a.t - b.t).abs() <= 1e-5 * b.t,
                            "{name}: {} vs {}",
                            a.t,
                            b.t
                        );
                    }
                    assert_eq!(accel.occluded(ray), brute.occluded(ray));
                }
            }
        }
    }
}
