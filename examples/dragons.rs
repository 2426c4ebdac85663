//! The advanced-BVH figure: 110 instances of the 202,520-triangle Stanford dragon, with varied
//! placements, sizes and diffuse colours, on a floor under an area light, rendered through the
//! two-level BVH (one BVH for the dragon, a top-level BVH over the instances).
//!
//! ```text
//! cargo run --release --example dragons
//! cargo run --release --example dragons -- --accel bvh    # one flat BVH over all 22 million triangles
//! ```
//!
//! The summary line adds the instance count, unique and instanced triangles, and the
//! accelerator's memory. Needs the dragon: set `PT_ASSETS_DIR` (see README).

mod common;

use common::{Defaults, Flag, die, parse};
use pt::prelude::*;
use pt::pt_accel::{AccelKind, TriangleMesh};
use rand::{Rng, SeedableRng};

const NAME: &str = "dragons";
const COLUMNS: usize = 11;
const ROWS: usize = 10;
const SPACING: f32 = 0.25;

/// A saturated but not garish colour from a hue in [0, 1).
fn hue(h: f32) -> Rgb {
    let c = |k: f32| {
        let x = ((h * 6.0 + k) % 6.0 - 3.0).abs() - 1.0;
        0.15 + 0.65 * x.clamp(0.0, 1.0)
    };
    Rgb::new(c(0.0), c(4.0), c(2.0))
}

fn quad(corners: [Vec3; 4]) -> Mesh {
    Mesh::new(
        TriangleMesh::new(corners.to_vec(), vec![[0, 1, 2], [0, 2, 3]]).expect("four corners"),
    )
}

fn main() {
    let args = parse(
        NAME,
        Defaults {
            width: 640,
            height: 360,
            spp: 128,
            max_depth: 8,
            out: "out/dragons.png",
        },
        &[Flag {
            name: "accel",
            value: Some("KIND"),
            help: "two-level (default), bvh (flat), or auto",
        }],
    );
    let accel = match args.value("accel").unwrap_or("two-level") {
        "two-level" => AccelKind::TwoLevel,
        "bvh" => AccelKind::Bvh,
        "auto" => AccelKind::Auto,
        other => {
            eprintln!("{NAME}: --accel expects two-level, bvh or auto, got {other:?}");
            std::process::exit(2)
        }
    };

    let dragon = pt::pt_scene::load_mesh_asset("meshes/dragon_vrip_res2.binary.ply")
        .unwrap_or_else(|e| die(NAME, e));
    let base = dragon.geometry().bounds();
    let unique = dragon.geometry().triangle_count();

    let mut b = SceneBuilder::new();
    b.accel(accel);
    let dragon = b.add_mesh(dragon);
    let mut rng = rand_pcg::Pcg64::seed_from_u64(args.options.seed);
    let (w, d) = ((COLUMNS - 1) as f32 * SPACING, (ROWS - 1) as f32 * SPACING);
    for i in 0..COLUMNS * ROWS {
        let (col, row) = ((i % COLUMNS) as f32, (i / COLUMNS) as f32);
        let colour = b.add_material(BuiltinMaterial::diffuse(hue(rng.random())));
        let scale = rng.random_range(0.7f32..1.3);
        let jitter = Vec3::new(
            rng.random_range(-0.04..0.04),
            0.0,
            rng.random_range(-0.04..0.04),
        );
        // Stand each dragon on the floor (its lowest point at y = 0).
        let transform = Affine3A::from_translation(
            Vec3::new(col * SPACING - w / 2.0, 0.0, row * SPACING - d / 2.0) + jitter,
        ) * Affine3A::from_rotation_y(rng.random_range(0.0..std::f32::consts::TAU))
            * Affine3A::from_scale(Vec3::splat(scale))
            * Affine3A::from_translation(Vec3::new(0.0, -base.min.y, 0.0));
        b.add_object(Object::new(dragon, colour).with_transform(transform));
    }

    let floor = b.add_mesh(quad([
        Vec3::new(-20.0, 0.0, -20.0),
        Vec3::new(-20.0, 0.0, 20.0),
        Vec3::new(20.0, 0.0, 20.0),
        Vec3::new(20.0, 0.0, -20.0),
    ]));
    let grey = b.add_material(BuiltinMaterial::diffuse(Rgb::splat(0.6)));
    b.add_object(Object::new(floor, grey));
    // A square light 1.6 m wide, 3 m above the middle, facing down.
    let lamp = b.add_mesh(quad([
        Vec3::new(-0.8, 3.0, -0.8),
        Vec3::new(0.8, 3.0, -0.8),
        Vec3::new(0.8, 3.0, 0.8),
        Vec3::new(-0.8, 3.0, 0.8),
    ]));
    let black = b.add_material(BuiltinMaterial::diffuse(Rgb::BLACK));
    b.add_object(Object::new(lamp, black).with_emission(Emission::new(Rgb::new(9.0, 8.5, 7.5))));

    let scene = b.build().unwrap_or_else(|e| die(NAME, e));
    let camera = PinholeCamera::look_at(
        Vec3::new(0.7, 0.95, 2.1),
        Vec3::new(0.0, 0.02, -0.15),
        Vec3::Y,
        40.0,
    )
    .unwrap_or_else(|e| die(NAME, e));
    let out = common::render(&args, &scene, &camera);
    let s = scene.stats();
    let note = format!(
        ", {} dragon instances, {unique} unique triangles, {} instanced triangles, accel {} using {:.1} MiB (built in {:.2} s)",
        COLUMNS * ROWS,
        s.instanced_triangles,
        s.accel.kind,
        s.accel.memory_bytes as f64 / f64::from(1 << 20),
        s.accel.build_time.as_secs_f64()
    );
    common::finish(&args, &out, &note);
}
