//! The rendering core of the `pt` path tracer.
//!
//! `pt-core` turns a [`Scene`] and a [`Camera`] into an [`Image`] by Monte Carlo path tracing with
//! next-event estimation, multiple importance sampling and Russian roulette. It knows nothing of
//! file formats: scenes come from code (see [`SceneBuilder`]) or from `pt-scene`'s loaders.
//!
//! The extension points are traits with documented conventions, dispatched statically:
//!
//! - [`Bsdf`]: scattering in the local shading frame ([`bsdf`] module docs give the conventions);
//!   built-ins are variants of [`BuiltinBsdf`].
//! - [`Light`]: emitters sampled by solid angle ([`light`] module docs); built-ins in
//!   [`BuiltinLight`].
//! - [`Material`]: turns a surface hit into a BSDF by value; built-ins in [`BuiltinMaterial`].
//! - [`Sampler`]: deterministic sample values; built-ins in [`BuiltinSampler`].
//! - [`Camera`]: primary rays; [`PinholeCamera`].
//!
//! User types join the built-ins through [`bsdf_enum!`], [`light_enum!`] and [`material_enum!`],
//! so the per-ray path has no virtual calls and no allocation.
//!
//! # Example
//!
//! ```
//! use pt_core::{render, BuiltinMaterial, Emission, Mesh, Object, PinholeCamera, RenderOptions, Rgb, SceneBuilder};
//! use pt_core::pt_accel::TriangleMesh;
//! use pt_core::glam::Vec3;
//!
//! // A grey floor lit by a small square light facing down.
//! let quad = |y: f32, s: f32| TriangleMesh::new(
//!     vec![Vec3::new(-s, y, -s), Vec3::new(s, y, -s), Vec3::new(s, y, s), Vec3::new(-s, y, s)],
//!     vec![[0, 2, 1], [0, 3, 2]],
//! );
//! let mut b = SceneBuilder::new();
//! let floor = b.add_mesh(Mesh::new(quad(0.0, 5.0)?));
//! let lamp = b.add_mesh(Mesh::new(quad(2.0, 0.5)?));
//! let grey = b.add_material(BuiltinMaterial::diffuse(Rgb::splat(0.5)));
//! b.add_object(Object::new(floor, grey));
//! // The lamp's winding makes it face up; flip it with a rotation so it faces the floor.
//! let down = pt_core::glam::Affine3A::from_translation(Vec3::Y * 4.0)
//!     * pt_core::glam::Affine3A::from_rotation_x(std::f32::consts::PI);
//! b.add_object(Object::new(lamp, grey).with_transform(down).with_emission(Emission::new(Rgb::splat(10.0))));
//! let scene = b.build()?;
//!
//! let camera = PinholeCamera::look_at(Vec3::new(0.0, 3.0, 6.0), Vec3::ZERO, Vec3::Y, 45.0)?;
//! let out = render(&scene, &camera, &RenderOptions::new(32, 24).spp(8), None)?;
//! assert!(out.image.mean().luminance() > 0.0);
//! assert_eq!(out.stats.non_finite_samples, 0);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! # Features
//!
//! - `parallel` (default): render tiles on the rayon thread pool and build BVHs in parallel.
//! - `png` (default): `Image::write_png` through the `image` crate.
//! - `exr` (default): `Image::write_exr` through the `exr` crate, and partial renders as files
//!   (`PartialRender::write_exr`, `PartialRender::read_exr`).
//! - `testing`: the statistical test harness for BSDFs and lights.
//! - `serde`: `Serialize`/`Deserialize` for [`RenderOptions`], [`LightStrategy`] and
//!   [`SamplerKind`].
//! - `denoise`: [`RenderOutput::denoise`] and [`Denoiser`] through Intel Open Image Denoise,
//!   loaded at run time ([`denoise`](mod@denoise) says where it is looked for).
// Denied everywhere; the denoiser's calls into Open Image Denoise (a C library loaded at run
// time) are the one exception, in `denoise::oidn`.
#![deny(unsafe_code)]

pub use glam;
pub use pt_accel;

pub mod aov;
pub mod bsdf;
pub mod camera;
pub mod color;
pub mod denoise;
pub mod distribution;
pub mod film;
pub mod frame;
pub mod hash;
pub mod image;
pub mod integrator;
pub mod interaction;
pub mod light;
pub mod material;
#[cfg(feature = "exr")]
mod openexr;
pub mod partial;
pub mod render;
pub mod sampler;
pub mod sampling;
pub mod scene;
#[cfg(feature = "testing")]
pub mod testing;
pub mod texture;

pub use aov::Aovs;
pub use bsdf::{
    Bsdf, BsdfFlags, BsdfSample, BuiltinBsdf, ConductorFresnel, Lambertian, MetallicRoughness,
    RoughConductor, RoughDielectric, SampleInputs, SmoothDielectric, SpecularReflection, ThinFilm,
    TransportMode, TrowbridgeReitz,
};
pub use camera::{Camera, CameraError, CameraSample, PinholeCamera};
pub use color::Rgb;
pub use denoise::{DenoiseError, Denoiser};
pub use film::Film;
pub use frame::Frame;
pub use image::{Image, ImageDifference, ImageError, ToneMap};
pub use integrator::LightStrategy;
pub use interaction::{SurfaceAttributes, SurfaceInteraction, SurfacePoint};
pub use light::{
    BuiltinLight, CubemapEnvironment, DirectionalLight, EquirectEnvironment, Light, LightError,
    LightFlags, LightSample, LightSampleContext, PointLight, PowerLightSampler, SpotLight,
    TexturedTriangleLight, TriangleLight, UniformEnvironment,
};
pub use material::{
    AlphaMode, BuiltinMaterial, Diffuse, Glass, Material, MaterialContext, MaterialError,
    MaterialProperties, Metal, Mirror, PbrMaterial,
};
pub use partial::{MergeError, PartialRender};
pub use render::{
    AOV_BYTES_PER_PIXEL, AdaptiveSampling, FILM_BYTES_PER_PIXEL, MAX_PIXELS, MAX_RR_THRESHOLD,
    MAX_THREADS, OptionsError, Progress, RenderControl, RenderError, RenderOptions, RenderOutput,
    RenderStats, render, render_builtin,
};
pub use sampler::{
    BuiltinSampler, IndependentSampler, Sampler, SamplerFactory, SamplerKind, SobolSampler,
    StratifiedSampler,
};
pub use scene::{
    Emission, MAX_UV_SETS, MaterialId, Mesh, MeshId, Object, Scene, SceneBuilder, SceneError,
    SceneFeatures, SceneStats,
};
pub use texture::{Texture, TextureMap};
