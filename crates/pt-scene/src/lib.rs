//! Scenes for the `pt` path tracer.
//!
//! `pt-scene` is where scenes come from: preset scenes built in code (the Cornell box from
//! Cornell's measured data) and, in later versions, glTF 2.0 and OBJ/MTL files and named assets.
//! It produces a [`SceneBundle`]: a `pt_core::Scene` and the camera to view it with.
//!
//! # Example
//!
//! ```
//! use pt_core::{render, RenderOptions};
//!
//! let bundle = pt_scene::presets::cornell_box()?;
//! let out = render(&bundle.scene, &bundle.camera, &RenderOptions::new(16, 16).spp(2))?;
//! assert_eq!(out.stats.non_finite_samples, 0);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub use glam;
pub use pt_core;

pub mod presets;

use pt_core::{PinholeCamera, Scene};

/// A scene together with the camera it is meant to be seen through.
#[derive(Clone, Debug)]
pub struct SceneBundle {
    /// The scene.
    pub scene: Scene,
    /// Its camera.
    pub camera: PinholeCamera,
}
