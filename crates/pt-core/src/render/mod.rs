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
///
/// # Speed in the calling crate's builds
///
/// A generic function is compiled in the crate that calls it, at that crate's optimisation
/// level: a program's debug build (opt-level 0) would run the whole path tracer unoptimised,
/// about 25 times slower, even with pt itself optimised. A scene of the built-in materials
/// and lights ([`Scene`]'s default types), seen through a [`PinholeCamera`](crate::PinholeCamera)
/// and sampled by a [`SamplerKind`](crate::SamplerKind), is therefore rendered by
/// [`render_builtin`], the copy compiled (and optimised) in pt-core: the same image, bit for
/// bit. The types choose it (hidden trait methods, [`Material::render_scene`] first), so a
/// crate rendering only those types does not compile the renderer at all. Other types render
/// with the copy compiled in the caller, so such a program wants its own crate optimised
/// (README, "Use it as a library").
pub fn render<M: Material, L: Light, C: Camera, K: SamplerFactory>(
    scene: &Scene<M, L>,
    camera: &C,
    options: &RenderOptions<K>,
    control: Option<&RenderControl<'_>>,
) -> Result<RenderOutput, RenderError> {
    M::render_scene(scene, camera, options, control)
}

/// [`render`] for any types, compiled where it is called.
pub(crate) fn render_generic<M: Material, L: Light, C: Camera, K: SamplerFactory>(
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
/// of a generic function for the types it calls it with, at its own optimisation level, and the
/// path tracer's copy takes seconds to optimise: [`render`] hands these types to this function,
/// so that programs rendering them (pt-cli, the examples, the `pt` binary) neither compile the
/// renderer nor need to be optimised as much as it to render at its speed.
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
    #[cfg(test)]
    tests::BUILTIN_RENDERS.with(|n| n.set(n.get() + 1));
    render_generic(scene, camera, options, control)
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

#[cfg(test)]
mod tests {
    use std::cell::Cell;

    use glam::Vec3;
    use pt_accel::{Ray, TriangleMesh};

    use super::{render, render_generic};
    use crate::{
        BuiltinLight, BuiltinMaterial, Camera, CameraSample, Emission, IndependentSampler, Light,
        Material, MaterialContext, Mesh, Object, PinholeCamera, RenderOptions, Rgb, SamplerFactory,
        SamplerKind, Scene, SceneBuilder,
    };

    thread_local! {
        /// Calls of `render_builtin` on this thread.
        pub(super) static BUILTIN_RENDERS: Cell<u32> = const { Cell::new(0) };
    }

    /// A built-in material behind a type of the caller's.
    #[derive(Clone, Debug)]
    struct Wrapped(BuiltinMaterial);

    impl Material for Wrapped {
        type Bsdf = <BuiltinMaterial as Material>::Bsdf;
        fn bsdf(&self, ctx: &MaterialContext) -> Self::Bsdf {
            self.0.bsdf(ctx)
        }
    }

    impl From<BuiltinMaterial> for Wrapped {
        fn from(m: BuiltinMaterial) -> Self {
            Self(m)
        }
    }

    crate::light_enum! {
        /// The built-in lights behind a type of the caller's.
        #[derive(Clone, Debug)]
        enum WrappedLight { Builtin(crate::BuiltinLight) }
    }

    /// A pinhole camera that does not say it is one.
    struct Opaque(PinholeCamera);

    impl Camera for Opaque {
        fn generate_ray(&self, s: &CameraSample) -> Ray {
            self.0.generate_ray(s)
        }
    }

    /// Independent samples from a factory that is not a built-in kind.
    struct Independent;

    impl SamplerFactory for Independent {
        type Sampler = IndependentSampler;
        fn sampler(&self, seed: u64, _spp: u32) -> IndependentSampler {
            IndependentSampler::new(seed)
        }
    }

    /// A lit floor and an emitting triangle.
    fn scene<M: Material + From<BuiltinMaterial>, L: Light + From<BuiltinLight>>() -> Scene<M, L> {
        let mut b = SceneBuilder::<M, L>::default();
        let v = |x, y, z| Vec3::new(x, y, z);
        let floor = b.add_mesh(Mesh::new(
            TriangleMesh::new(
                vec![
                    v(-2.0, 0.0, -2.0),
                    v(2.0, 0.0, -2.0),
                    v(2.0, 0.0, 2.0),
                    v(-2.0, 0.0, 2.0),
                ],
                vec![[0, 2, 1], [0, 3, 2]],
            )
            .unwrap(),
        ));
        let lamp = b.add_mesh(Mesh::new(
            TriangleMesh::new(
                vec![v(-0.5, 1.5, -0.5), v(0.5, 1.5, -0.5), v(0.0, 1.5, 0.5)],
                vec![[0, 1, 2]],
            )
            .unwrap(),
        ));
        let grey = b.add_material(BuiltinMaterial::diffuse(Rgb::splat(0.6)));
        let black = b.add_material(BuiltinMaterial::diffuse(Rgb::BLACK));
        b.add_object(Object::new(floor, grey));
        b.add_object(
            Object::new(lamp, black).with_emission(Emission::new(Rgb::splat(5.0)).two_sided()),
        );
        b.build().unwrap()
    }

    fn camera() -> PinholeCamera {
        PinholeCamera::look_at(Vec3::new(0.0, 1.0, 4.0), Vec3::ZERO, Vec3::Y, 40.0).unwrap()
    }

    fn renders_taken(f: impl FnOnce()) -> u32 {
        let before = BUILTIN_RENDERS.with(Cell::get);
        f();
        BUILTIN_RENDERS.with(Cell::get) - before
    }

    /// `render` of the built-in types runs `render_builtin` (compiled here) and gives the
    /// image the generic copy gives; any other type of the four keeps the generic copy.
    #[test]
    fn render_takes_the_builtin_copy_for_the_builtin_types_only() {
        let options = RenderOptions::new(16, 12).spp(4).seed(3).threads(Some(1));
        let builtin = scene::<BuiltinMaterial, BuiltinLight>();
        let mut image = None;
        assert_eq!(
            renders_taken(|| image = Some(render(&builtin, &camera(), &options, None).unwrap())),
            1
        );
        let generic = render_generic(&builtin, &camera(), &options, None).unwrap();
        assert_eq!(image.unwrap().image, generic.image);
        // Every built-in sampler kind.
        for kind in SamplerKind::ALL {
            let options = options.clone().sampler(kind);
            assert_eq!(
                renders_taken(|| drop(render(&builtin, &camera(), &options, None))),
                1
            );
        }
        // A user's material, light, camera or sampler factory: the generic copy.
        let wrapped = scene::<Wrapped, BuiltinLight>();
        assert_eq!(
            renders_taken(|| drop(render(&wrapped, &camera(), &options, None))),
            0
        );
        let wrapped_light = scene::<BuiltinMaterial, WrappedLight>();
        assert_eq!(
            renders_taken(|| drop(render(&wrapped_light, &camera(), &options, None))),
            0
        );
        let opaque = Opaque(camera());
        assert_eq!(
            renders_taken(|| drop(render(&builtin, &opaque, &options, None))),
            0
        );
        let independent = options.clone().sampler(Independent);
        assert_eq!(
            renders_taken(|| drop(render(&builtin, &camera(), &independent, None))),
            0
        );
    }
}
