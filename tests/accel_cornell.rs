//! On the Cornell box, the BVH and brute force return the same closest hit for 100,000 random
//! rays (origins anywhere in and around the room, uniformly random directions).

use pt::pt_accel::{AccelKind, Ray};
use pt::pt_core::glam::Vec3;
use pt::pt_scene::presets::CornellBox;
use rand::{Rng, SeedableRng};

#[test]
fn bvh_and_brute_force_agree_on_the_cornell_box() {
    let build = |kind| {
        let mut cb = CornellBox::classic();
        cb.builder().accel(kind);
        cb.build().unwrap().scene
    };
    let (brute, bvh) = (build(AccelKind::BruteForce), build(AccelKind::Bvh));
    assert_eq!(brute.stats().accel.kind, AccelKind::BruteForce);
    assert_eq!(bvh.stats().accel.kind, AccelKind::Bvh);

    let bounds = CornellBox::interior();
    let mut rng = rand_pcg::Pcg64::seed_from_u64(42);
    let mut hits = 0;
    for _ in 0..100_000 {
        // Origins in a box 10% larger than the room, so some rays start outside.
        let u = Vec3::new(rng.random(), rng.random(), rng.random());
        let origin = bounds.min - bounds.diagonal() * 0.05 + bounds.diagonal() * 1.1 * u;
        let z: f32 = rng.random_range(-1.0..1.0);
        let phi: f32 = rng.random_range(0.0..std::f32::consts::TAU);
        let r = (1.0 - z * z).sqrt();
        let ray = Ray::new(origin, Vec3::new(r * phi.cos(), r * phi.sin(), z));
        match (brute.intersect(&ray), bvh.intersect(&ray)) {
            (None, None) => {}
            (Some(a), Some(b)) => {
                hits += 1;
                assert!((a.t - b.t).abs() <= 1e-5 * a.t, "t differs for {ray:?}");
                if (a.instance, a.prim) != (b.instance, b.prim) {
                    assert_eq!(
                        a.t, b.t,
                        "different triangles at different distances for {ray:?}"
                    );
                }
            }
            (a, b) => panic!(
                "brute force {:?} vs BVH {:?} for {ray:?}",
                a.map(|h| h.t),
                b.map(|h| h.t)
            ),
        }
    }
    // The room is open toward the camera, so about a quarter of the rays leave it.
    assert!(hits > 50_000, "only {hits} hits");
}
