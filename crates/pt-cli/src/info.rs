//! `pt info FILE`: what a scene file holds and how pt would render it, without rendering.

use std::collections::BTreeMap;
use std::path::Path;

use pt_scene::BuildOptions;

use crate::Failure;

/// What `pt info` reports.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct Info {
    /// The file.
    pub file: String,
    /// Distinct meshes (geometries).
    pub meshes: usize,
    /// Triangles over the distinct meshes.
    pub unique_triangles: usize,
    /// Placed meshes.
    pub instances: usize,
    /// Triangles over all instances.
    pub instanced_triangles: usize,
    /// Materials by the built-in model each maps to (`Diffuse`, `Metal`, `Glass`, `Pbr`, ...).
    pub materials: BTreeMap<String, usize>,
    /// Materials that emit.
    pub emissive_materials: usize,
    /// Punctual lights in the file.
    pub punctual_lights: usize,
    /// Lights of the built scene (one per emitting triangle, punctual lights).
    pub scene_lights: usize,
    /// Decoded textures and their texels.
    pub textures: usize,
    /// Texels over all textures.
    pub texels: u64,
    /// Cameras in the file.
    pub cameras: usize,
    /// The camera a render would use: position, forward direction, vertical field of view,
    /// and whether it is the file's or one framing the scene.
    pub camera: String,
    /// What the scene needs from the renderer, and what a render would skip.
    pub skipped: Vec<&'static str>,
    /// Warnings from loading and building: features the file uses that pt ignores or does not
    /// support.
    pub warnings: Vec<String>,
    /// Memory estimate in bytes: accelerator (nodes, triangle copies), textures (linear f32).
    pub memory_bytes: u64,
    /// The accelerator the scene would use.
    pub accel: String,
}

/// Load and build `file` (without an environment) and describe it.
///
/// # Errors
///
/// Exit code 2 when the file cannot be read or is invalid.
pub fn info(file: &Path) -> Result<Info, Failure> {
    let _ = crate::progress::warnings();
    let desc = crate::scene::describe(file).map_err(Failure::usage)?;
    let mut materials = BTreeMap::new();
    for m in &desc.materials {
        let model = m
            .to_material_with(&desc.textures)
            .map_or("invalid", |b| b.variant_name());
        *materials.entry(model.to_string()).or_insert(0) += 1;
    }
    let emissive_materials = desc
        .materials
        .iter()
        .filter(|m| !m.emission.is_black())
        .count();
    let texels: u64 = desc
        .textures
        .iter()
        .map(|t| u64::from(t.image().width()) * u64::from(t.image().height()))
        .sum();
    let file_camera = desc.file_camera();
    let bundle = desc
        .build(&BuildOptions::default())
        .map_err(Failure::usage)?;
    let stats = bundle.scene.stats();
    let c = &bundle.camera;
    let camera = format!(
        "{} at ({:.3}, {:.3}, {:.3}) looking along ({:.3}, {:.3}, {:.3}), {:.1} deg vertical field of view",
        if file_camera.is_some() {
            "the file's first camera"
        } else {
            "a camera framing the scene"
        },
        c.eye().x,
        c.eye().y,
        c.eye().z,
        c.forward().x,
        c.forward().y,
        c.forward().z,
        c.fov_y_degrees()
    );
    let mut warnings = crate::progress::warnings();
    warnings.dedup();
    Ok(Info {
        file: file.display().to_string(),
        meshes: stats.meshes,
        unique_triangles: stats.unique_triangles,
        instances: stats.objects,
        instanced_triangles: stats.instanced_triangles,
        materials,
        emissive_materials,
        punctual_lights: desc.lights.len(),
        scene_lights: stats.lights,
        textures: desc.textures.len(),
        texels,
        cameras: desc.cameras.len(),
        camera,
        skipped: bundle.scene.features().skipped(),
        warnings,
        memory_bytes: stats.accel.memory_bytes as u64 + texels * 12,
        accel: format!("{:?}", stats.accel.kind),
    })
}

impl Info {
    /// The report as lines of text.
    #[must_use]
    pub fn text(&self) -> String {
        let mut s = format!("{}\n", self.file);
        let mut line = |k: &str, v: String| s.push_str(&format!("  {k:<12} {v}\n"));
        line(
            "geometry",
            format!(
                "{} meshes, {} unique triangles; {} instances, {} instanced triangles",
                self.meshes, self.unique_triangles, self.instances, self.instanced_triangles
            ),
        );
        let models: Vec<String> = self
            .materials
            .iter()
            .map(|(k, v)| format!("{v} {k}"))
            .collect();
        line(
            "materials",
            format!(
                "{} ({}), {} emissive",
                self.materials.values().sum::<usize>(),
                models.join(", "),
                self.emissive_materials
            ),
        );
        line(
            "lights",
            format!(
                "{} punctual in the file; {} in the scene (one per emitting triangle)",
                self.punctual_lights, self.scene_lights
            ),
        );
        line(
            "textures",
            format!("{} ({} texels)", self.textures, self.texels),
        );
        line("cameras", format!("{} in the file", self.cameras));
        line("camera", self.camera.clone());
        line("accelerator", self.accel.clone());
        line(
            "memory",
            format!(
                "about {:.1} MiB (accelerator and textures)",
                self.memory_bytes as f64 / f64::from(1u32 << 20)
            ),
        );
        if !self.skipped.is_empty() {
            line("skips", self.skipped.join(", "));
        }
        if self.warnings.is_empty() {
            line("unsupported", "nothing the file uses is ignored".into());
        } else {
            for w in &self.warnings {
                line("unsupported", w.clone());
            }
        }
        s
    }

    /// The report as JSON.
    #[must_use]
    pub fn json(&self) -> serde_json::Value {
        serde_json::json!({
            "file": self.file,
            "meshes": self.meshes,
            "unique_triangles": self.unique_triangles,
            "instances": self.instances,
            "instanced_triangles": self.instanced_triangles,
            "materials": self.materials,
            "emissive_materials": self.emissive_materials,
            "punctual_lights": self.punctual_lights,
            "scene_lights": self.scene_lights,
            "textures": self.textures,
            "texels": self.texels,
            "cameras": self.cameras,
            "camera": self.camera,
            "accelerator": self.accel,
            "memory_bytes": self.memory_bytes,
            "skipped": self.skipped,
            "warnings": self.warnings,
        })
    }
}
