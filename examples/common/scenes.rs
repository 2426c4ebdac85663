//! The report's figure scenes, built in one place so that each figure's example, the
//! convergence study (`examples/convergence.rs`) and the gallery render the same scene.

use pt::pt_accel::AccelKind;
use pt::pt_core::{BuiltinMaterial, Glass, Rgb};
use pt::pt_scene::SceneBundle;
use pt::pt_scene::presets::CornellBox;

/// A figure scene with the render settings its example uses by default.
pub struct Figure {
    /// The scene and its camera.
    pub bundle: SceneBundle,
    /// Image width, height and maximum path depth of the figure.
    pub width: u32,
    pub height: u32,
    pub max_depth: u32,
}

/// The figure scenes [`figure`] can build by name.
pub const FIGURES: [&str; 5] = [
    "cornell_box",
    "specular_box",
    "diffuse_bunny",
    "specular_bunny",
    "glass_bunny",
];

/// The figure scene `name` with its defaults (the meshes come from `PT_ASSETS_DIR`).
pub fn figure(name: &str) -> Result<Figure, String> {
    let bundle = match name {
        "cornell_box" => cornell_box(AccelKind::Auto)?,
        "specular_box" => specular_box()?,
        "diffuse_bunny" => bunny_in_box(None, AccelKind::Bvh)?,
        "specular_bunny" => {
            bunny_in_box(Some(BuiltinMaterial::mirror(Rgb::WHITE)), AccelKind::Auto)?
        }
        "glass_bunny" => bunny_in_box(
            Some(Glass::new(1.5).map_err(|e| e.to_string())?.into()),
            AccelKind::Auto,
        )?,
        other => {
            return Err(format!(
                "unknown scene {other:?} (expected one of {})",
                FIGURES.join(", ")
            ));
        }
    };
    Ok(Figure {
        bundle,
        width: 512,
        height: 512,
        max_depth: 16,
    })
}

/// The classic Cornell box with the given accelerator.
pub fn cornell_box(kind: AccelKind) -> Result<SceneBundle, String> {
    let mut cb = CornellBox::classic();
    cb.builder().accel(kind);
    cb.build().map_err(|e| e.to_string())
}

/// The Cornell box with a white short block and an ideal-mirror tall block.
pub fn specular_box() -> Result<SceneBundle, String> {
    let mut cb = CornellBox::empty();
    let white = cb.white();
    let mirror = cb
        .builder()
        .add_material(BuiltinMaterial::mirror(Rgb::WHITE));
    cb.add_short_block(white).add_tall_block(mirror);
    cb.build().map_err(|e| e.to_string())
}

/// The Cornell box with the Stanford bunny (330 mm tall, facing the camera, on the middle of the
/// floor), with the given accelerator: in `material` with smooth vertex normals, or (`None`)
/// flat-shaded in the walls' white, as the report's diffuse figure has it.
pub fn bunny_in_box(
    material: Option<BuiltinMaterial>,
    kind: AccelKind,
) -> Result<SceneBundle, String> {
    let mut bunny =
        pt::pt_scene::load_mesh_asset("meshes/stanford-bunny.obj").map_err(|e| e.to_string())?;
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
    cb.build().map_err(|e| e.to_string())
}
