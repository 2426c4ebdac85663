//! Scenes for the `pt` path tracer.
//!
//! `pt-scene` is where scenes come from: preset scenes built in code (the Cornell box from
//! Cornell's measured data), meshes read from OBJ and PLY files ([`load_mesh`]), and real assets
//! found by name ([`assets`]). It produces a [`SceneBundle`]: a `pt_core::Scene` and the camera to
//! view it with. Every loading failure is a [`LoadError`] naming the file and the element.
//!
//! # Example
//!
//! ```
//! use pt_core::RenderOptions;
//!
//! let bundle = pt_scene::presets::cornell_box()?;
//! let out = bundle.render(&RenderOptions::new(16, 16).spp(2), None)?;
//! assert_eq!(out.stats.non_finite_samples, 0);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![forbid(unsafe_code)]

pub use glam;
pub use pt_core;

pub mod assets;
pub mod desc;
pub mod environment;
mod error;
pub mod gltf;
mod limits;
pub mod obj;
pub mod ply;
pub mod presets;
pub mod shapes;

use std::path::Path;

use pt_core::{
    BuiltinLight, BuiltinMaterial, Light, Material, Mesh, PinholeCamera, RenderControl,
    RenderError, RenderOptions, RenderOutput, SamplerFactory, Scene,
};

pub use assets::{AssetError, find_asset};
pub use desc::{BuildOptions, SceneDesc};
pub use environment::{
    load_cubemap, load_cubemap_asset, load_equirect, load_equirect_asset, load_image_linear,
    load_image_linear_with,
};
pub use error::LoadError;
pub use limits::Limits;

/// Load a scene file as a description: `.gltf`/`.glb` (see [`gltf`]), `.obj` with its MTL
/// materials (see [`obj`]), or a lone `.ply` mesh (one white diffuse object). Build it into a
/// scene and camera with [`SceneDesc::build`].
///
/// ```
/// use pt_scene::{BuildOptions, load_scene};
///
/// let dir = std::env::temp_dir().join(format!("pt-scene-doc-{}", std::process::id()));
/// std::fs::create_dir_all(&dir)?;
/// let path = dir.join("triangle.obj");
/// std::fs::write(&path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")?;
/// let bundle = load_scene(&path)?.build(&BuildOptions::default())?;
/// assert_eq!(bundle.scene.stats().unique_triangles, 1);
/// // Bad input is an error that names the file, never a panic.
/// std::fs::write(&path, "v 0 0 0\nf 1 2 9\n")?;
/// let err = load_scene(&path).unwrap_err().to_string();
/// assert!(err.contains("triangle.obj"), "{err}");
/// # std::fs::remove_dir_all(&dir)?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn load_scene(path: impl AsRef<Path>) -> Result<SceneDesc, LoadError> {
    load_scene_with(path, &Limits::default())
}

/// [`load_scene`] within `limits` (see [`Limits`]): what a file may make pt read, decode and
/// place is checked before it is allocated.
pub fn load_scene_with(path: impl AsRef<Path>, limits: &Limits) -> Result<SceneDesc, LoadError> {
    let path = path.as_ref();
    match path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("gltf" | "glb") => gltf::load_gltf_with(path, limits),
        Some("obj") => obj::load_obj_scene_with(path, limits),
        Some("ply") => {
            let mesh = ply::load_ply(path)?;
            let g = mesh.geometry();
            Ok(SceneDesc {
                source: path.to_path_buf(),
                meshes: vec![desc::MeshDesc {
                    name: "ply".into(),
                    positions: g.positions().to_vec(),
                    normals: mesh.normals().map(<[_]>::to_vec).unwrap_or_default(),
                    uvs: mesh.uvs().map(<[_]>::to_vec).unwrap_or_default(),
                    indices: g.indices().to_vec(),
                    ..desc::MeshDesc::default()
                }],
                materials: vec![desc::MaterialDesc::default()],
                instances: vec![desc::InstanceDesc {
                    mesh: 0,
                    material: 0,
                    transform: glam::Affine3A::IDENTITY,
                }],
                cameras: Vec::new(),
                lights: Vec::new(),
                textures: Vec::new(),
            })
        }
        _ => Err(LoadError::Unsupported {
            path: path.to_path_buf(),
            what: "scene file extension (expected .gltf, .glb, .obj or .ply)".into(),
        }),
    }
}

/// Read a mesh file, choosing the reader by extension: `.obj` or `.ply`.
pub fn load_mesh(path: impl AsRef<Path>) -> Result<Mesh, LoadError> {
    let path = path.as_ref();
    match path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("obj") => obj::load_obj_mesh(path),
        Some("ply") => ply::load_ply(path),
        _ => Err(LoadError::Unsupported {
            path: path.to_path_buf(),
            what: "mesh file extension (expected .obj or .ply)".into(),
        }),
    }
}

/// Find a known asset by name (see [`assets`]) and read it as a mesh.
pub fn load_mesh_asset(name: &str) -> Result<Mesh, LoadError> {
    load_mesh(find_asset(name)?)
}

/// A scene together with the camera it is meant to be seen through. The material and light
/// types are the built-in ones unless a preset was built for user types
/// ([`presets::CornellBox::empty_with`]).
#[derive(Clone, Debug)]
pub struct SceneBundle<M = BuiltinMaterial, L = BuiltinLight> {
    /// The scene.
    pub scene: Scene<M, L>,
    /// Its camera.
    pub camera: PinholeCamera,
}

impl<M: Material, L: Light> SceneBundle<M, L> {
    /// Render the scene through its camera: [`pt_core::render`](fn@pt_core::render) with the bundle's parts.
    ///
    /// # Errors
    ///
    /// As [`pt_core::render`](fn@pt_core::render): options out of range, no worker threads, or cancelled.
    pub fn render<K: SamplerFactory>(
        &self,
        options: &RenderOptions<K>,
        control: Option<&RenderControl<'_>>,
    ) -> Result<RenderOutput, RenderError> {
        pt_core::render(&self.scene, &self.camera, options, control)
    }
}
