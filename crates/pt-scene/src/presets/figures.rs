//! The report's figure scenes, built in one place so that each figure's example, the
//! convergence study, the gallery, the benchmarks and the tests render the same scene. The
//! meshes and maps are known assets ([`crate::assets`]), found or fetched by name.
//!
//! ```no_run
//! use pt_scene::presets::{FIGURES, figure};
//!
//! for name in FIGURES {
//!     let fig = figure(name)?;
//!     println!("{name}: {}x{}, {} spp: {}", fig.width, fig.height, fig.spp, fig.caption);
//! }
//! # Ok::<(), pt_scene::LoadError>(())
//! ```

use std::path::Path;

use glam::{Affine3A, Mat3, Vec3};
use pt_core::pt_accel::AccelKind;
use pt_core::{
    BuiltinLight, BuiltinMaterial, ConductorFresnel, Emission, Glass, Metal, Mirror, Object,
    PinholeCamera, Rgb, SceneBuilder,
};
use rand::{Rng, SeedableRng};

use crate::presets::CornellBox;
use crate::shapes::{quad, sphere};
use crate::{
    LoadError, SceneBundle, load_cubemap_asset, load_equirect, load_equirect_asset, load_mesh_asset,
};

/// A failure to build preset `name` from valid parts (assets that loaded, constants).
fn build_error(name: &str, e: impl std::fmt::Display) -> LoadError {
    LoadError::invalid(Path::new(name), "preset scene", e.to_string())
}

/// A figure scene with the render settings its example uses by default.
#[derive(Clone, Debug)]
#[non_exhaustive]
pub struct Figure {
    /// The scene and its camera.
    pub bundle: SceneBundle,
    /// Image width of the figure.
    pub width: u32,
    /// Image height of the figure.
    pub height: u32,
    /// Samples per pixel of the figure.
    pub spp: u32,
    /// Maximum path depth of the figure.
    pub max_depth: u32,
    /// The example command that renders this figure.
    pub command: &'static str,
    /// What the figure shows.
    pub caption: &'static str,
}

/// The report's figures, by name, in the order of the gallery.
pub const FIGURES: [&str; 11] = [
    "cornell_box",
    "cornell_box_brute",
    "diffuse_bunny",
    "specular_box",
    "specular_bunny",
    "specular_bunny_rough",
    "glass_bunny",
    "glass_bunny_rough",
    "env_lighting",
    "env_lighting_sunset",
    "dragons",
];

/// The figure scene `name` (one of [`FIGURES`]) with its defaults.
///
/// # Errors
///
/// An unknown name, or an asset that cannot be found or read.
pub fn figure(name: &str) -> Result<Figure, LoadError> {
    let square = |bundle, command, caption| Figure {
        bundle,
        width: 512,
        height: 512,
        spp: 128,
        max_depth: 16,
        command,
        caption,
    };
    let metal = |roughness| -> Result<BuiltinMaterial, LoadError> {
        Ok(Metal::new(ConductorFresnel::Schlick(Rgb::WHITE), roughness)
            .map_err(|e| build_error(name, e))?
            .into())
    };
    let glass = |roughness| -> Result<BuiltinMaterial, LoadError> {
        Ok(Glass::new(1.5)
            .and_then(|g| g.with_roughness(roughness))
            .map_err(|e| build_error(name, e))?
            .into())
    };
    Ok(match name {
        "cornell_box" => square(
            cornell_box_with(AccelKind::Auto)?,
            "cargo run --example cornell_box",
            "The diffuse Cornell box (Cornell's measured data), through a BVH.",
        ),
        "cornell_box_brute" => square(
            cornell_box_with(AccelKind::BruteForce)?,
            "cargo run --example cornell_box -- --accel brute",
            "The same box without an acceleration structure: every ray against every triangle.",
        ),
        "diffuse_bunny" => Figure {
            spp: 64,
            ..square(
                bunny_in_box(None, AccelKind::Bvh)?,
                "cargo run --example diffuse_bunny",
                "The Stanford bunny (69,451 triangles, flat-shaded) in the box, through a BVH.",
            )
        },
        "specular_box" => square(
            specular_box()?,
            "cargo run --example specular_box",
            "The tall block as an ideal mirror.",
        ),
        "specular_bunny" => square(
            bunny_in_box(Some(BuiltinMaterial::mirror(Rgb::WHITE)), AccelKind::Auto)?,
            "cargo run --example specular_bunny",
            "A mirror bunny (smooth vertex normals).",
        ),
        "specular_bunny_rough" => square(
            bunny_in_box(Some(metal(0.3)?), AccelKind::Auto)?,
            "cargo run --example specular_bunny -- --roughness 0.3",
            "A glossy bunny: GGX conductor, roughness 0.3.",
        ),
        "glass_bunny" => square(
            bunny_in_box(Some(glass(0.0)?), AccelKind::Auto)?,
            "cargo run --example glass_bunny",
            "A glass bunny (eta 1.5): Fresnel reflection and refraction, total internal reflection.",
        ),
        "glass_bunny_rough" => square(
            bunny_in_box(Some(glass(0.3)?), AccelKind::Auto)?,
            "cargo run --example glass_bunny -- --roughness 0.3",
            "Frosted glass: rough dielectric, roughness 0.3.",
        ),
        "env_lighting" => Figure {
            bundle: env_lighting("cubemap", 1.0, 0.0, false)?,
            width: 640,
            height: 480,
            spp: 256,
            max_depth: 16,
            command: "cargo run --example env_lighting",
            caption: "The bunny lit only by the Park3Med cube map (importance sampled).",
        },
        "env_lighting_sunset" => Figure {
            bundle: env_lighting("sunset", 1.0, 0.0, true)?,
            width: 640,
            height: 480,
            spp: 256,
            max_depth: 16,
            command: "cargo run --example env_lighting -- --env sunset --spheres",
            caption: "The venice sunset HDR map (importance sampled), with a mirror and a glass sphere.",
        },
        "dragons" => Figure {
            bundle: dragons(AccelKind::TwoLevel, 0)?.0,
            width: 640,
            height: 360,
            spp: 128,
            max_depth: 8,
            command: "cargo run --example dragons",
            caption: "110 instanced Stanford dragons (22 million triangles) through the two-level BVH.",
        },
        other => {
            return Err(LoadError::Unsupported {
                path: other.into(),
                what: format!("figure name (expected one of {})", FIGURES.join(", ")),
            });
        }
    })
}

/// The classic Cornell box with the given accelerator.
///
/// # Errors
///
/// None in practice: the box is built from constants.
pub fn cornell_box_with(kind: AccelKind) -> Result<SceneBundle, LoadError> {
    let mut cb = CornellBox::classic();
    cb.builder().accel(kind);
    cb.build().map_err(|e| build_error("cornell_box", e))
}

/// The Cornell box with a white short block and an ideal-mirror tall block.
///
/// # Errors
///
/// None in practice: the box is built from constants.
pub fn specular_box() -> Result<SceneBundle, LoadError> {
    let mut cb = CornellBox::empty();
    let white = cb.white();
    let mirror = cb
        .builder()
        .add_material(BuiltinMaterial::mirror(Rgb::WHITE));
    cb.add_short_block(white).add_tall_block(mirror);
    cb.build().map_err(|e| build_error("specular_box", e))
}

/// The Cornell box with the Stanford bunny (330 mm tall, facing the camera, on the middle of the
/// floor), with the given accelerator: in `material` with smooth vertex normals, or (`None`)
/// flat-shaded in the walls' white, as the report's diffuse figure has it.
///
/// # Errors
///
/// The bunny cannot be found or read.
pub fn bunny_in_box(
    material: Option<BuiltinMaterial>,
    kind: AccelKind,
) -> Result<SceneBundle, LoadError> {
    let mut bunny = load_mesh_asset("meshes/stanford-bunny.obj")?;
    let mut cb = CornellBox::empty();
    let m = match material {
        Some(material) => {
            bunny = bunny.with_smooth_normals();
            cb.builder().add_material(material)
        }
        None => cb.white(),
    };
    cb.add_mesh_on_floor(bunny, m, 330.0, [278.0, 290.0], std::f32::consts::PI);
    cb.builder().accel(kind);
    cb.build().map_err(|e| build_error("bunny_in_box", e))
}

/// An environment by name: `cubemap` (Park3Med), `sunset`, `studio`, or a `.hdr`/`.exr` path,
/// its radiance scaled by `scale` and turned `rotate_deg` degrees about the vertical axis.
///
/// # Errors
///
/// The map cannot be found or read, or `scale` or the rotation is not finite.
pub fn environment(name: &str, scale: f32, rotate_deg: f32) -> Result<BuiltinLight, LoadError> {
    let rotation = Mat3::from_rotation_y(rotate_deg.to_radians());
    let bad =
        |e: pt_core::LightError| LoadError::invalid(Path::new(name), "environment", e.to_string());
    let light: BuiltinLight = match name {
        "cubemap" => load_cubemap_asset("env/cubemap-Park3Med")?
            .with_rotation(rotation)
            .and_then(|m| m.with_scale(scale))
            .map_err(bad)?
            .into(),
        other => {
            let map = match other {
                "sunset" => load_equirect_asset("env/venice_sunset_1k.hdr"),
                "studio" => load_equirect_asset("env/studio_small_03_1k.hdr"),
                path => load_equirect(path),
            };
            map?.with_rotation(rotation)
                .and_then(|m| m.with_scale(scale))
                .map_err(bad)?
                .into()
        }
    };
    Ok(light)
}

/// The bunny (one unit tall, smooth normals, clay white) lit only by an environment; `spheres`
/// adds a mirror and a glass sphere beside it. With its camera (wider with the spheres).
///
/// # Errors
///
/// The bunny or the map cannot be found or read.
pub fn env_lighting(
    env: &str,
    scale: f32,
    rotate_deg: f32,
    spheres: bool,
) -> Result<SceneBundle, LoadError> {
    let fail = |e: &dyn std::fmt::Display| build_error("env_lighting", e);
    let mut b = SceneBuilder::new();
    let bunny = load_mesh_asset("meshes/stanford-bunny.obj")?.with_smooth_normals();
    // One unit tall, standing at the origin, facing the camera.
    let bb = bunny.geometry().bounds();
    let s = 1.0 / (bb.max.y - bb.min.y);
    let base = Vec3::new(
        (bb.min.x + bb.max.x) * 0.5,
        bb.min.y,
        (bb.min.z + bb.max.z) * 0.5,
    );
    let place = Affine3A::from_rotation_y(std::f32::consts::PI)
        * Affine3A::from_scale(Vec3::splat(s))
        * Affine3A::from_translation(-base);
    let bunny = b.add_mesh(bunny);
    let clay = b.add_material(BuiltinMaterial::diffuse(Rgb::splat(0.75)));
    b.add_object(Object::new(bunny, clay).with_transform(place));
    if spheres {
        let ball = b.add_mesh(sphere(0.35, 48, 96));
        let mirror = b.add_material(Mirror::new(Rgb::splat(0.95)));
        let glass = b.add_material(Glass::new(1.5).map_err(|e| fail(&e))?);
        b.add_object(
            Object::new(ball, mirror)
                .with_transform(Affine3A::from_translation(Vec3::new(-1.0, 0.35, 0.2))),
        );
        b.add_object(
            Object::new(ball, glass)
                .with_transform(Affine3A::from_translation(Vec3::new(1.0, 0.35, 0.2))),
        );
    }
    b.add_light(environment(env, scale, rotate_deg)?);
    let scene = b.build().map_err(|e| fail(&e))?;
    let fov = if spheres { 50.0 } else { 40.0 };
    let camera = PinholeCamera::look_at(
        Vec3::new(0.0, 0.9, 2.6),
        Vec3::new(0.0, 0.45, 0.0),
        Vec3::Y,
        fov,
    )
    .map_err(|e| fail(&e))?;
    Ok(SceneBundle { scene, camera })
}

/// Number of dragons in [`dragons`].
pub const DRAGONS: usize = COLUMNS * ROWS;
/// Dragons per row.
const COLUMNS: usize = 11;
/// Rows of dragons.
const ROWS: usize = 10;
/// Distance between neighbouring dragons.
const SPACING: f32 = 0.25;

/// A saturated but not garish colour from a hue in [0, 1).
fn hue(h: f32) -> Rgb {
    let c = |k: f32| {
        let x = ((h * 6.0 + k) % 6.0 - 3.0).abs() - 1.0;
        0.15 + 0.65 * x.clamp(0.0, 1.0)
    };
    Rgb::new(c(0.0), c(4.0), c(2.0))
}

/// The advanced-BVH figure: 110 instances of the 202,520-triangle dragon (placements, sizes and
/// colours drawn from `seed`) on a floor under an area light, with the given accelerator.
/// Returns the scene and the dragon's unique triangle count.
///
/// # Errors
///
/// The dragon cannot be found or read.
pub fn dragons(accel: AccelKind, seed: u64) -> Result<(SceneBundle, usize), LoadError> {
    let dragon = load_mesh_asset("meshes/dragon_vrip_res2.binary.ply")?;
    let base = dragon.geometry().bounds();
    let unique = dragon.geometry().triangle_count();

    let mut b = SceneBuilder::new();
    b.accel(accel);
    let dragon = b.add_mesh(dragon);
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
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

    let scene = b.build().map_err(|e| build_error("dragons", e))?;
    let camera = PinholeCamera::look_at(
        Vec3::new(0.7, 0.95, 2.1),
        Vec3::new(0.0, 0.02, -0.15),
        Vec3::Y,
        40.0,
    )
    .map_err(|e| build_error("dragons", e))?;
    Ok((SceneBundle { scene, camera }, unique))
}
