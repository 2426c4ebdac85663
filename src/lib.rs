//! `pt`: a physically based CPU path tracer.
//!
//! This facade re-exports the three crates pt is made of and offers a [`prelude`] with what a
//! program needs for the common path: get a scene, choose options, render, write the image.
//!
//! - [`pt_accel`]: rays, triangle meshes, watertight intersection, BVHs (built with obvhs).
//! - [`pt_core`]: color, sampling, BSDFs, lights, materials, cameras, film, scenes, the path
//!   integrator.
//! - [`pt_scene`]: scene files (glTF 2.0, OBJ/MTL, PLY), environment maps, assets, and preset
//!   scenes such as the Cornell box.
//!
//! # Example
//!
//! ```no_run
//! use pt::prelude::*;
//!
//! let bundle = presets::cornell_box()?;
//! let options = RenderOptions::new(512, 512).spp(64);
//! let out = bundle.render(&options, None)?;
//! out.image.write_png("cornell_box.png")?;
//! println!("{}", out.stats);
//!
//! // A scene file instead: glTF, OBJ/MTL or PLY, with the file's camera or one that frames it.
//! let bundle = load_scene("model.glb")?.build(&BuildOptions::default())?;
//! let out = bundle.render(&options, None)?;
//! let pixels: &[f32] = out.image.as_slice(); // linear RGB, row by row from the top
//! # let _ = pixels;
//! # Ok::<(), pt::Error>(())
//! ```
//!
//! # Errors
//!
//! Each crate has its own error types, which name the file, object or option and the problem;
//! all of them convert into [`Error`], so a program can use `?` across loading, building,
//! rendering and writing with one error type.
//!
//! # Speed in debug builds
//!
//! Cargo compiles dependencies unoptimised in a program's debug builds (`cargo run`), and pt
//! then renders about 45 times slower. Optimise pt (and every other dependency) in them with
//! these lines in the program's `Cargo.toml`:
//!
//! ```toml
//! [profile.dev.package."*"]
//! opt-level = 3
//! ```
//!
//! Scenes of the built-in materials and lights then render at close to release speed, through
//! the renderer compiled inside pt (`render` hands them to [`pt_core::render_builtin`]); a program
//! with material or light types of its own compiles the renderer for them itself, so it wants
//! its own crate optimised as well (`[profile.dev] opt-level = 2`).
//!
//! # Features
//!
//! - `parallel` (default): multi-threaded rendering and BVH builds (rayon).
//! - `png` (default): PNG output.
//! - `exr` (default): OpenEXR output, and partial renders as files.
//! - `serde`: `Serialize`/`Deserialize` for the render options.
//! - `denoise`: `RenderOutput::denoise` and `Denoiser`, through Intel Open Image Denoise loaded
//!   at run time (`OIDN_DIR` or the system's library path).
//! - `download`: fetch known assets that are found nowhere locally.
#![forbid(unsafe_code)]

mod error;

pub use error::{Error, Result};
pub use pt_accel;
pub use pt_core;
pub use pt_core::glam;
pub use pt_scene;

/// The types and functions of the common path, for `use pt::prelude::*`.
pub mod prelude {
    pub use pt_accel::{AccelKind, TriangleMesh};
    pub use pt_core::glam::{Affine3A, Vec2, Vec3};
    pub use pt_core::{
        AdaptiveSampling, Aovs, BuiltinLight, BuiltinMaterial, Camera, ConductorFresnel, Denoiser,
        Diffuse, DirectionalLight, Emission, EquirectEnvironment, Glass, Image, LightStrategy,
        Mesh, Metal, Mirror, Object, PartialRender, PinholeCamera, PointLight, Progress,
        RenderControl, RenderError, RenderOptions, RenderOutput, RenderStats, Rgb, SamplerKind,
        Scene, SceneBuilder, SpotLight, ToneMap, UniformEnvironment, render,
    };
    pub use pt_scene::{BuildOptions, SceneBundle, SceneDesc, load_scene, presets};
}

// The README's code is compiled and run as a doctest, so the quickstart cannot rot.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;

// So are the programs in docs/api.md.
#[cfg(doctest)]
#[doc = include_str!("../docs/api.md")]
struct ApiDoctests;
