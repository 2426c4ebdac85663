//! Multiple importance sampling with glossy and delta lobes: light sampling, BSDF sampling and
//! their MIS combination are three unbiased estimators of the same image, so their image means
//! must agree within noise on a glossy floor lit by a small area light (the rough lobe needs both
//! strategies: light sampling for the broad highlight, BSDF sampling for the sharp one), and on a
//! mirror floor (a delta lobe: no strategy may light-sample it, and the reflection of the lamp
//! must reach the camera through BSDF sampling with weight 1 under every strategy).
//!
//! Statistics: each strategy renders 8 independent images (seeds 1..8, 256 spp each; fewer samples make BSDF sampling's estimate of the small lamp's glossy reflection too heavy-tailed for a normal approximation); the
//! standard error of the image mean comes from the spread of the 8 means. Two strategies agree
//! when their means differ by less than `z` combined standard errors, `z` the two-sided normal
//! quantile at 0.01 with a Šidák correction over the comparisons in this file (2 scenes x 2
//! comparisons).

use crate::support;

use pt::prelude::*;
use pt::pt_scene::shapes::quad;
use support::{mean_std, sidak_z};

const SPP: u32 = 256;

fn scene(floor: BuiltinMaterial) -> (Scene, PinholeCamera) {
    let mut b = SceneBuilder::new();
    let s = 2.0;
    let f = b.add_mesh(quad([
        Vec3::new(-s, 0.0, -s),
        Vec3::new(-s, 0.0, s),
        Vec3::new(s, 0.0, s),
        Vec3::new(s, 0.0, -s),
    ]));
    let l = 0.4;
    let lamp = b.add_mesh(quad([
        Vec3::new(-l, 1.0, -l),
        Vec3::new(l, 1.0, -l),
        Vec3::new(l, 1.0, l),
        Vec3::new(-l, 1.0, l),
    ]));
    let m = b.add_material(floor);
    let black = b.add_material(BuiltinMaterial::diffuse(Rgb::BLACK));
    b.add_object(Object::new(f, m));
    b.add_object(Object::new(lamp, black).with_emission(Emission::new(Rgb::splat(4.0))));
    let scene = b.build().unwrap();
    let camera = PinholeCamera::look_at(
        Vec3::new(0.0, 1.0, 2.5),
        Vec3::new(0.0, 0.0, -0.5),
        Vec3::Y,
        50.0,
    )
    .unwrap();
    (scene, camera)
}

/// Mean luminance of the image and its standard error over 8 seeds.
fn estimate(scene: &Scene, camera: &PinholeCamera, strategy: LightStrategy) -> (f64, f64) {
    let means: Vec<f64> = (1..=8)
        .map(|seed| {
            let opts = RenderOptions::new(32, 32)
                .spp(SPP)
                .seed(seed)
                .max_depth(8)
                .strategy(strategy);
            let out = render(scene, camera, &opts, None).unwrap();
            assert_eq!(out.stats.non_finite_samples, 0);
            f64::from(out.image.mean().luminance())
        })
        .collect();
    let (m, s) = mean_std(&means);
    (m, s / (means.len() as f64).sqrt())
}

fn assert_strategies_agree(label: &str, floor: BuiltinMaterial) {
    let (scene, camera) = scene(floor);
    let z = sidak_z(0.01, 4);
    let (mis, se_mis) = estimate(&scene, &camera, LightStrategy::Mis);
    assert!(mis > 0.01, "{label}: the floor shows the lamp");
    for strategy in [LightStrategy::BsdfOnly, LightStrategy::LightOnly] {
        let (other, se) = estimate(&scene, &camera, strategy);
        let tol = z * (se_mis * se_mis + se * se).sqrt() + 1e-6;
        println!("{label}: MIS {mis:.5} ± {se_mis:.5}, {strategy:?} {other:.5} ± {se:.5}");
        assert!(
            (mis - other).abs() <= tol,
            "{label}: MIS {mis} and {strategy:?} {other} differ by more than {tol}"
        );
    }
}

#[test]
fn glossy_floor_all_strategies_agree() {
    let metal = Metal::new(ConductorFresnel::Schlick(Rgb::splat(0.9)), 0.4).unwrap();
    assert_strategies_agree("glossy floor", metal.into());
}

#[test]
fn mirror_floor_all_strategies_agree() {
    assert_strategies_agree("mirror floor", BuiltinMaterial::mirror(Rgb::splat(0.9)));
}
