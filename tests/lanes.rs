//! The lane path tracer against the one-path tracer: same estimator, same sample values, so
//! for every pixel the same paths (up to rounding differences that change a decision).
//!
//! On the Cornell box presets (every wall Lambertian, the light a triangle pair sampled by
//! area) the two films must be equal bit for bit; scenes the lane tracer does not know
//! (mirrors, environments, another sampler) must render exactly as without lanes.

use pt::prelude::*;
use pt::pt_scene::presets;

/// relMSE of `a` against `b` as the anchors compute it, and the largest per-pixel relative
/// difference.
fn compare(a: &Image, b: &Image) -> (f64, f64) {
    let (mut rel, mut worst) = (0.0f64, 0.0f64);
    let n = (a.width() * a.height()) as f64;
    for y in 0..a.height() {
        for x in 0..a.width() {
            let (p, q) = (a.get(x, y), b.get(x, y));
            for (u, v) in [(p.r, q.r), (p.g, q.g), (p.b, q.b)] {
                let (u, v) = (f64::from(u), f64::from(v));
                rel += (u - v).powi(2) / (v * v + 0.01) / (3.0 * n);
                worst = worst.max((u - v).abs() / (v.abs() + 1e-3));
            }
        }
    }
    (rel, worst)
}

fn render(bundle: &SceneBundle, options: &RenderOptions) -> RenderOutput {
    bundle.render(options, None).unwrap()
}

/// The Cornell box (its BVH, and brute force), at several depths and each light strategy: the
/// lane tracer's film equals the one-path tracer's bit for bit, it traces the same number of
/// rays, and it reports that it ran. (A light sample weighted twice gives relMSE 0.08 at depth 1: checked by hand.)
#[test]
fn the_lane_tracer_renders_the_one_path_tracers_image() {
    let boxes = [
        presets::cornell_box().unwrap(),
        presets::cornell_box_with(AccelKind::BruteForce).unwrap(),
    ];
    for (k, bundle) in boxes.iter().enumerate() {
        for (depth, strategy) in [
            (1, LightStrategy::Mis),
            (5, LightStrategy::Mis),
            (16, LightStrategy::Mis),
            (8, LightStrategy::LightOnly),
            (8, LightStrategy::BsdfOnly),
        ] {
            let options = RenderOptions::new(40, 30)
                .spp(8)
                .max_depth(depth)
                .strategy(strategy)
                .seed(3);
            let one = render(bundle, &options);
            let lanes = render(bundle, &options.clone().lanes(true));
            assert!(
                lanes.stats.lanes && !one.stats.lanes,
                "box {k}: the lane tracer ran"
            );
            // Same paths, and every lane operation rounds as the scalar one it mirrors (the
            // same operations in the same order, sines and cosines from the same library): the
            // films are equal bit for bit.
            let (rel, worst) = compare(&lanes.image, &one.image);
            assert!(
                lanes.film == one.film,
                "box {k}, depth {depth}, {strategy:?}: relMSE {rel:e}, worst pixel {worst:e}"
            );
            assert_eq!(lanes.stats.rays, one.stats.rays);
        }
    }
}

/// A scene the lane tracer does not know renders exactly as without lanes (the one-path
/// tracer runs), and so does a render with another sampler.
#[test]
fn scenes_the_lanes_do_not_know_fall_back_to_the_one_path_tracer() {
    let mirror = presets::specular_box().unwrap();
    let options = RenderOptions::new(24, 24).spp(4).max_depth(6);
    let with = render(&mirror, &options.clone().lanes(true));
    let without = render(&mirror, &options);
    assert!(!with.stats.lanes);
    assert_eq!(with.film, without.film);
    let cornell = presets::cornell_box().unwrap();
    let independent = options.clone().sampler(SamplerKind::Independent);
    let with = render(&cornell, &independent.clone().lanes(true));
    assert!(!with.stats.lanes);
    assert_eq!(with.film, render(&cornell, &independent).film);
}

/// The lane tracer's image is the same for any thread count (tiles merge in a fixed order and
/// each lane's sample depends only on its pixel and index).
#[test]
fn the_lane_tracer_is_deterministic_for_any_thread_count() {
    let cornell = presets::cornell_box().unwrap();
    let options = RenderOptions::new(37, 29).spp(6).max_depth(8).lanes(true);
    let one = render(&cornell, &options.clone().threads(Some(1)));
    let two = render(&cornell, &options.clone().threads(Some(2)));
    assert!(one.stats.lanes);
    assert_eq!(one.film, two.film);
}
