//! The lane path tracer against the one-path tracer: same estimator, same sample values, so
//! for every pixel the same paths (up to rounding differences that change a decision).
//!
//! On the Cornell box presets (every wall Lambertian, the light a triangle pair sampled by
//! area), the mirror box and the mirror bunny (specular bounces), the diffuse bunny (flat and
//! smooth normals) and the dragons (instances under transforms) the two films must be equal bit
//! for bit, and so on glass boxes and the glass bunny; scenes the lane tracer does not know
//! (rough metal and glass, environments, another sampler) must render exactly as without
//! lanes. The lanes are
//! the default, so `lanes(false)` asks for the one-path tracer.

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

/// `bundle` rendered with `options` (lanes as they say) and by the one-path tracer: the films
/// must be equal bit for bit and the ray counts the same (`what` names the case in failures).
/// Returns both renders, the lane render first.
fn lanes_and_one_path(
    bundle: &SceneBundle,
    options: &RenderOptions,
    what: &str,
) -> (RenderOutput, RenderOutput) {
    let lanes = render(bundle, options);
    let one = render(bundle, &options.clone().lanes(false));
    assert!(!one.stats.lanes, "{what}: the one-path tracer ran");
    let (rel, worst) = compare(&lanes.image, &one.image);
    assert!(
        lanes.film == one.film,
        "{what}: relMSE {rel:e}, worst pixel {worst:e}"
    );
    assert_eq!(lanes.stats.rays, one.stats.rays, "{what}");
    (lanes, one)
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
            assert!(options.lanes, "the lanes are the default");
            // Same paths, and every lane operation rounds as the scalar one it mirrors (the
            // same operations in the same order, sines and cosines from the same library): the
            // films are equal bit for bit.
            let what = format!("box {k}, depth {depth}, {strategy:?}");
            let (lanes, _) = lanes_and_one_path(bundle, &options, &what);
            assert!(lanes.stats.lanes, "{what}: the lane tracer ran");
        }
    }
}

/// The Cornell box with a tall block of `material`.
fn box_with(material: impl Into<BuiltinMaterial>) -> SceneBundle {
    let mut cb = presets::CornellBox::empty();
    let white = cb.white();
    let block = cb.builder().add_material(material.into());
    cb.add_short_block(white).add_tall_block(block);
    cb.build().unwrap()
}

/// Glass in lanes: a smooth glass block (reflection, refraction, total internal reflection,
/// the `1/eta^2` radiance scale and Russian roulette's `eta` factor) and a tinted one, at
/// several depths: the films equal the one-path tracer's bit for bit.
#[test]
fn the_lanes_render_glass_bit_for_bit() {
    for (k, bundle) in [
        box_with(Glass::new(1.5).unwrap()),
        box_with(Glass::new(1.33).unwrap().with_tint(Rgb::new(0.9, 0.6, 0.3))),
    ]
    .iter()
    .enumerate()
    {
        for depth in [2, 6, 16] {
            let options = RenderOptions::new(40, 30).spp(8).max_depth(depth).seed(7);
            let what = format!("glass {k}, depth {depth}");
            let (lanes, _) = lanes_and_one_path(bundle, &options, &what);
            assert!(lanes.stats.lanes, "{what}: the lane tracer ran");
        }
    }
}

/// Lights that sample themselves lane by lane (point and spot lights, which are deltas, and
/// a cube-map environment, which escaping rays also see) beside the box's own quad light, with
/// the glass block and the walls: the films equal the one-path tracer's bit for bit.
#[test]
fn the_lanes_render_punctual_lights_and_environments_bit_for_bit() {
    use pt::pt_core::{PointLight, SpotLight, UniformEnvironment};
    let add = |light: BuiltinLight| {
        let mut cb = presets::CornellBox::empty();
        let white = cb.white();
        let glass = cb.builder().add_material(Glass::new(1.5).unwrap());
        cb.add_short_block(white).add_tall_block(glass);
        cb.builder().add_light(light);
        cb.build().unwrap()
    };
    let scenes = [
        add(
            PointLight::new(Vec3::new(278.0, 400.0, 279.0), Rgb::splat(4e4))
                .unwrap()
                .into(),
        ),
        add(SpotLight::new(
            Vec3::new(200.0, 500.0, 200.0),
            Vec3::NEG_Y,
            Rgb::splat(8e4),
            0.3,
            0.6,
        )
        .unwrap()
        .into()),
        add(UniformEnvironment::new(Rgb::splat(0.5)).unwrap().into()),
    ];
    for (k, bundle) in scenes.iter().enumerate() {
        for depth in [1, 5] {
            let options = RenderOptions::new(32, 24).spp(8).max_depth(depth).seed(11);
            let what = format!("light {k}, depth {depth}");
            let (lanes, one) = lanes_and_one_path(bundle, &options, &what);
            assert!(lanes.stats.lanes, "{what}: the lane tracer ran");
            assert!(
                one.image.mean().luminance() > 0.0,
                "light {k} lights nothing"
            );
        }
    }
}

/// A scene the lane tracer does not know (a rough metal block) renders exactly as without
/// lanes (the one-path tracer runs), and so does a render with another sampler.
#[test]
fn scenes_the_lanes_do_not_know_fall_back_to_the_one_path_tracer() {
    let metal = box_with(Metal::new(ConductorFresnel::Schlick(Rgb::splat(0.8)), 0.3).unwrap());
    let options = RenderOptions::new(24, 24).spp(4).max_depth(6);
    let with = render(&metal, &options);
    let without = render(&metal, &options.clone().lanes(false));
    assert!(!with.stats.lanes);
    assert_eq!(with.film, without.film);
    let cornell = presets::cornell_box().unwrap();
    let independent = options.clone().sampler(SamplerKind::Independent);
    let with = render(&cornell, &independent);
    assert!(!with.stats.lanes);
    assert_eq!(with.film, render(&cornell, &independent.lanes(false)).film);
}

/// The lane tracer's image is the same for any thread count (tiles merge in a fixed order and
/// each lane's sample depends only on its pixel and index).
#[test]
fn the_lane_tracer_is_deterministic_for_any_thread_count() {
    let cornell = presets::cornell_box().unwrap();
    let options = RenderOptions::new(37, 29).spp(6).max_depth(8);
    let one = render(&cornell, &options.clone().threads(Some(1)));
    let two = render(&cornell, &options.clone().threads(Some(2)));
    assert!(one.stats.lanes);
    assert_eq!(one.film, two.film);
}

/// The figure scenes the lanes know (the diffuse bunny, flat-shaded, 69k triangles; the dragons,
/// 25 instances under rotations and scales) and a smooth-shaded Lambertian bunny render the same
/// film with and without lanes; every other figure falls back to the one-path tracer.
#[test]
fn the_lanes_render_the_figure_scenes_they_know_bit_for_bit() {
    use pt::pt_scene::assets::find_asset_or_skip;
    for asset in [
        "meshes/stanford-bunny.obj",
        "meshes/dragon_vrip_res2.binary.ply",
        "env/venice_sunset_1k.hdr",
    ] {
        if find_asset_or_skip(asset).unwrap().is_none() {
            return;
        }
    }
    let smooth = presets::bunny_in_box(
        Some(BuiltinMaterial::diffuse(Rgb::splat(0.7))),
        AccelKind::Auto,
    )
    .unwrap();
    let mut scenes = vec![("smooth diffuse bunny", smooth, 8)];
    for name in presets::FIGURES {
        let fig = presets::figure(name).unwrap();
        scenes.push((name, fig.bundle, fig.max_depth));
    }
    for (name, bundle, depth) in &scenes {
        let options = RenderOptions::new(32, 24).spp(4).max_depth(*depth).seed(5);
        let (lanes, _) = lanes_and_one_path(bundle, &options, name);
        // Everything but the rough conductor and rough glass.
        let knows = !matches!(*name, "specular_bunny_rough" | "glass_bunny_rough");
        assert_eq!(lanes.stats.lanes, knows, "{name}");
    }
}

/// A room far from the origin (1e5), its geometry baked there: hits within their error
/// bound (0.04 units) of an edge are pulled inside their triangles, in lanes for the hits
/// the lane tracer finishes itself. The films equal the one-path tracer's bit for bit.
#[test]
fn the_lanes_pull_hits_off_edges_bit_for_bit() {
    use pt::pt_accel::TriangleMesh;
    use pt::pt_scene::shapes::{cube, quad};
    let at = Vec3::new(1e4, -1e4, 1e5);
    let baked = |mesh: Mesh, offset: Vec3| {
        let g = mesh.geometry();
        let positions = g.positions().iter().map(|&v| v + at + offset).collect();
        Mesh::new(TriangleMesh::new(positions, g.indices().to_vec()).unwrap())
    };
    let mut b = SceneBuilder::new();
    let white = b.add_material(BuiltinMaterial::diffuse(Rgb::splat(0.8)));
    let room = b.add_mesh(baked(cube(250.0, true), Vec3::ZERO));
    b.add_object(Object::new(room, white));
    let block = b.add_mesh(baked(cube(60.0, false), Vec3::new(190.0, -190.0, 0.0)));
    b.add_object(Object::new(block, white));
    let lamp = b.add_mesh(baked(
        quad([
            Vec3::new(-50.0, 240.0, -50.0),
            Vec3::new(50.0, 240.0, -50.0),
            Vec3::new(50.0, 240.0, 50.0),
            Vec3::new(-50.0, 240.0, 50.0),
        ]),
        Vec3::ZERO,
    ));
    b.add_object(
        Object::new(lamp, white).with_emission(Emission::new(Rgb::splat(20.0)).two_sided()),
    );
    let bundle = SceneBundle {
        scene: b.build().unwrap(),
        camera: PinholeCamera::look_at(
            at + Vec3::splat(-200.0),
            at + Vec3::new(250.0, -250.0, 250.0),
            Vec3::Y,
            100.0,
        )
        .unwrap(),
    };
    let options = RenderOptions::new(40, 30).spp(8).max_depth(6).seed(5);
    let (lanes, _) = lanes_and_one_path(&bundle, &options, "room at 1e5");
    assert!(lanes.stats.lanes, "the lane tracer ran");
}

/// A camera the renderer knows only through [`Camera::generate_ray`]: the box's pinhole with
/// its rays' origins moved by the lens sample when `lens` is set (a lens the renderer must
/// draw for), its rays ending at `t_max` when set (a near clipping range), else exactly the
/// pinhole's rays, though not declared a pinhole.
struct UserCamera {
    pinhole: PinholeCamera,
    lens: bool,
    t_max: Option<f32>,
}

impl Camera for UserCamera {
    fn generate_ray(&self, sample: &pt::pt_core::CameraSample) -> pt::pt_accel::Ray {
        let mut ray = self.pinhole.generate_ray(sample);
        if self.lens {
            ray.origin += Vec3::new(sample.lens.x - 0.5, sample.lens.y - 0.5, 0.0) * 0.05;
        }
        if let Some(t_max) = self.t_max {
            ray.t_max = t_max;
        }
        ray
    }

    fn uses_lens(&self) -> bool {
        self.lens
    }
}

/// The lanes make a pinhole's primary rays eight at a time, ahead of the lanes that take
/// them; other cameras' one at a time, with the lens drawn where the camera reads it and the
/// ray's range as the camera set it. All give the one-path tracer's film bit for bit, and a
/// camera whose rays equal the pinhole's gives the pinhole's film. (Rays made in lanes from
/// the second film dimension's draw instead of the first, and camera rays given the full
/// range: both caught, checked by hand.)
#[test]
fn the_lanes_make_every_cameras_rays_as_the_one_path_tracer() {
    let bundle = presets::cornell_box().unwrap();
    let options = RenderOptions::new(23, 17).spp(11).max_depth(6).seed(5);
    let pinhole = lanes_and_one_path(&bundle, &options, "pinhole").0;
    assert!(pinhole.stats.lanes);
    for (lens, t_max) in [
        (false, None),
        (true, None),
        (false, Some(3.0)),
        (true, Some(3.0)),
    ] {
        let camera = UserCamera {
            pinhole: bundle.camera,
            lens,
            t_max,
        };
        let with = pt::pt_core::render(&bundle.scene, &camera, &options, None).unwrap();
        let one_path = options.clone().lanes(false);
        let without = pt::pt_core::render(&bundle.scene, &camera, &one_path, None).unwrap();
        assert!(with.stats.lanes && !without.stats.lanes);
        let what = format!("user camera, lens {lens}, t_max {t_max:?}");
        assert!(with.film == without.film, "{what}");
        assert_eq!(with.stats.rays, without.stats.rays, "{what}");
        assert_eq!(
            with.film == pinhole.film,
            !lens && t_max.is_none(),
            "{what}"
        );
    }
}
