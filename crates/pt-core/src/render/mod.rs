//! The render driver: what a render is asked to do ([`RenderOptions`]), how it is watched and
//! stopped ([`RenderControl`]), how its pixels are scheduled, and what it reports
//! ([`RenderStats`]). The light transport itself is the integrator's ([`crate::integrator`]).
//!
//! The image is split into square tiles rendered in parallel on rayon; each pixel's samples are
//! taken in sample-index order by one thread with a sampler whose values depend only on (seed,
//! pixel, sample index, dimension), and tiles are merged in a fixed order. The image is therefore
//! bit-identical for any thread count, tile schedule and run.

mod control;
mod error;
mod options;
mod stats;
mod tiles;

use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

pub use control::{Progress, RenderControl};
pub use error::{OptionsError, RenderError};
pub use options::{
    AOV_BYTES_PER_PIXEL, AdaptiveSampling, FILM_BYTES_PER_PIXEL, MAX_PIXELS, MAX_RR_THRESHOLD,
    MAX_THREADS, RenderOptions,
};
pub use stats::RenderStats;

use crate::aov::{AovSample, NoAov};
use crate::camera::Camera;
use crate::film::Film;
use crate::image::Image;
use crate::integrator::{Integrator, LaneTile, LaneTracer, PathTracer};
use crate::light::Light;
use crate::material::Material;
use crate::sampler::SamplerFactory;
use crate::scene::Scene;
use tiles::{Tile, render_tile, run_tiles, tiles};

/// The result of a render.
#[derive(Clone, Debug)]
#[non_exhaustive]
pub struct RenderOutput {
    /// Linear RGB radiance, the mean of each pixel's samples.
    pub image: Image,
    /// The mean albedo of each pixel's first non-specular hits, when
    /// [`RenderOptions::aovs`](RenderOptions#structfield.aovs) asks for it ([`crate::aov`]).
    pub albedo: Option<Image>,
    /// The mean shading normal of each pixel's first non-specular hits (world space, zero where
    /// rays escaped), when [`RenderOptions::aovs`](RenderOptions#structfield.aovs) asks for it.
    pub normal: Option<Image>,
    /// Per-pixel sums and counts (for exact merging with other sample ranges).
    pub film: Film,
    /// Figures of the render.
    pub stats: RenderStats,
}

/// Render `scene` through `camera`: the one entry point of every render.
///
/// `control` (optional) reports progress and can stop the render. The sampler is the options'
/// [`RenderOptions::sampler`](RenderOptions#structfield.sampler): a [`SamplerKind`](crate::SamplerKind) or a
/// user's [`SamplerFactory`]. The image is the path tracer's ([`crate::integrator`]).
///
/// ```
/// use pt_core::{render, BuiltinMaterial, Emission, Mesh, Object, PinholeCamera, RenderOptions, Rgb, SceneBuilder};
/// use pt_core::pt_accel::TriangleMesh;
/// use pt_core::glam::Vec3;
///
/// // A glowing triangle in front of the camera.
/// let mut b = SceneBuilder::new();
/// let tri = b.add_mesh(Mesh::new(TriangleMesh::new(
///     vec![Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, -1.0, 0.0), Vec3::new(0.0, 1.0, 0.0)],
///     vec![[0, 1, 2]],
/// )?));
/// let black = b.add_material(BuiltinMaterial::diffuse(Rgb::BLACK));
/// b.add_object(Object::new(tri, black).with_emission(Emission::new(Rgb::splat(2.0)).two_sided()));
/// let scene = b.build()?;
/// let camera = PinholeCamera::look_at(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y, 30.0)?;
/// let out = render(&scene, &camera, &RenderOptions::new(16, 16).spp(4), None)?;
/// assert_eq!(out.image.get(8, 8), Rgb::splat(2.0));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
///
/// # Errors
///
/// [`RenderError::InvalidOptions`] before any work when an option is out of range,
/// [`RenderError::ThreadPool`] when worker threads cannot be made, and
/// [`RenderError::Cancelled`] when `control`'s flag was set.
pub fn render<M: Material, L: Light, C: Camera, K: SamplerFactory>(
    scene: &Scene<M, L>,
    camera: &C,
    options: &RenderOptions<K>,
    control: Option<&RenderControl<'_>>,
) -> Result<RenderOutput, RenderError> {
    options.validate()?;
    let integrator = PathTracer::new(scene, options);
    let lanes = LaneTracer::new(scene, options, &integrator);
    drive(
        scene,
        camera,
        options,
        &integrator,
        lanes.as_ref(),
        control.unwrap_or(&RenderControl::new()),
    )
}

/// [`render`] for the built-in materials and lights ([`Scene`]'s default types), the pinhole
/// camera and the built-in samplers, compiled once, in this crate. A crate compiles its own copy
/// of a generic function for the types it calls it with (at opt-level 2 and above), and the
/// path tracer's copy takes seconds to optimise: programs rendering the built-in types (pt-cli,
/// the examples, the `pt` binary) call this instead, so that they need not be optimised as
/// much as the renderer to render at its speed.
///
/// # Errors
///
/// As [`render`].
pub fn render_builtin(
    scene: &Scene,
    camera: &crate::PinholeCamera,
    options: &RenderOptions,
    control: Option<&RenderControl<'_>>,
) -> Result<RenderOutput, RenderError> {
    render(scene, camera, options, control)
}

/// The render driver, generic over the integrator: tiles on threads, merged in a fixed order.
fn drive<M: Material, L: Light, C: Camera, K: SamplerFactory, I: Integrator<M, L>>(
    scene: &Scene<M, L>,
    camera: &C,
    options: &RenderOptions<K>,
    integrator: &I,
    lanes: Option<&LaneTracer>,
    control: &RenderControl<'_>,
) -> Result<RenderOutput, RenderError> {
    let start = Instant::now();
    let sampler = options.sampler.sampler(options.seed, options.spp);
    let tiles = tiles(options.width, options.height, options.tile_size);
    let done = AtomicUsize::new(0);
    let job = |tile: &Tile| {
        let out = match lanes {
            Some(tracer) => pt_accel::lanes::dispatch(LaneTile {
                scene,
                camera,
                options,
                tracer,
                x0: tile.x0,
                y0: tile.y0,
                w: tile.w,
                h: tile.h,
                control,
            }),
            None if options.aovs.any() => render_tile::<_, _, _, _, _, _, AovSample>(
                scene,
                camera,
                options,
                integrator,
                sampler.clone(),
                tile,
                control,
            ),
            None => render_tile::<_, _, _, _, _, _, NoAov>(
                scene,
                camera,
                options,
                integrator,
                sampler.clone(),
                tile,
                control,
            ),
        };
        let n = done.fetch_add(1, Ordering::Relaxed) + 1;
        if let Some(progress) = control.progress {
            progress(Progress {
                tiles_done: n,
                tiles_total: tiles.len(),
            });
        }
        out
    };
    let results = run_tiles(&tiles, options.threads, job)?;
    if control.cancelled() {
        return Err(RenderError::Cancelled);
    }

    // Merge in tile order: the film does not depend on which thread finished first.
    let mut film = Film::new_with(options.width, options.height, options.aovs.any());
    let mut rays = 0u64;
    for (tile, (tile_film, tile_rays)) in tiles.iter().zip(&results) {
        film.add_tile(tile.x0, tile.y0, tile_film);
        rays += tile_rays;
    }
    let range = options.samples();
    let spp = range.end - range.start;
    let samples = film.total_samples();
    let full = u64::from(options.width) * u64::from(options.height) * u64::from(spp);
    let stats = RenderStats {
        width: options.width,
        height: options.height,
        spp,
        sample_range: range,
        total_spp: options.spp,
        seed: options.seed,
        elapsed: start.elapsed(),
        samples,
        adaptive_saved: if options.adaptive.is_some() {
            1.0 - samples as f64 / full as f64
        } else {
            0.0
        },
        rays,
        non_finite_samples: film.non_finite_samples(),
        clamped_samples: film.clamped_samples(),
        saturated_samples: film.saturated_samples(),
        skipped: {
            let mut s = scene.features().skipped();
            if !camera.uses_lens() {
                s.push("lens samples (pinhole camera)");
            }
            s
        },
        lanes: lanes.is_some(),
    };
    Ok(RenderOutput {
        image: film.to_image(),
        albedo: film.albedo_image().filter(|_| options.aovs.albedo),
        normal: film.normal_image().filter(|_| options.aovs.normal),
        film,
        stats,
    })
}
