//! The unidirectional path tracer: next-event estimation and BSDF sampling combined by multiple
//! importance sampling (power heuristic), Russian roulette, and a maximum depth.
//!
//! Reference: E. Veach, *Robust Monte Carlo Methods for Light Transport Simulation*, 1997, ch. 9;
//! *Physically Based Rendering*, 4th ed., section 13.4 (`PathIntegrator`).
//!
//! Depth counts scattering events: with `max_depth = 0` only emission seen directly is returned,
//! with `max_depth = 1` direct lighting is added, and so on.

use glam::{Vec2, Vec3};
use pt_accel::Ray;

use crate::aov::AovRecord;
use crate::bsdf::{Bsdf, SampleInputs, TransportMode};
use crate::color::Rgb;
use crate::frame::Frame;
use crate::integrator::{Integrator, LightStrategy};
use crate::interaction::{SurfaceInteraction, bend_shading_normal};
use crate::light::{Light, LightSampleContext};
use crate::material::{Material, MaterialContext};
use crate::render::RenderOptions;
use crate::sampler::Sampler;
use crate::sampling::power_heuristic;
use crate::scene::Scene;

/// The path tracer with the settings of one render.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PathTracer {
    pub(super) max_depth: u32,
    pub(super) rr_depth: u32,
    /// The reciprocal of [`RenderOptions::rr_threshold`]: a path's survival probability is its
    /// throughput times this (the lane tracer multiplies by the same number, the same bits).
    pub(super) rr_scale: f32,
    pub(super) strategy: LightStrategy,
    /// Next-event estimation runs: the strategy uses it, the scene has lights to sample and a
    /// material that is not purely specular (the scene analysis, decided once per render).
    pub(super) nee: bool,
    /// Escaping rays look up the environment (the scene has one).
    pub(super) environment: bool,
    /// Some material bends shading normals (the scene analysis).
    normal_maps: bool,
    /// Some material encloses an absorbing medium (the scene analysis).
    media: bool,
    /// Some material reads vertex attributes (the scene analysis).
    attributes: bool,
}

impl PathTracer {
    /// The path tracer for a render of `scene` with these options.
    pub(crate) fn new<M: Material, L: Light, K>(
        scene: &Scene<M, L>,
        options: &RenderOptions<K>,
    ) -> Self {
        let f = scene.features();
        let strategy = options.strategy;
        Self {
            max_depth: options.max_depth,
            rr_depth: options.rr_depth,
            rr_scale: 1.0 / options.rr_threshold,
            strategy,
            nee: strategy != LightStrategy::BsdfOnly && f.light_sampling && f.non_delta_materials,
            environment: f.environment,
            normal_maps: f.normal_maps,
            media: f.absorbing_media,
            attributes: f.vertex_attributes,
        }
    }
}

impl<M: Material, L: Light> Integrator<M, L> for PathTracer {
    #[inline]
    fn radiance<S: Sampler, A: AovRecord>(
        &self,
        scene: &Scene<M, L>,
        ray: Ray,
        sampler: &mut S,
        rays: &mut u64,
        aov: &mut A,
    ) -> Rgb {
        radiance(scene, ray, sampler, self, rays, aov)
    }
}

/// Radiance arriving along `ray`; the rays traced for it are added to `rays`, the AOVs of the
/// first non-specular hit (conventions in [`crate::aov`]) go to `aov`.
fn radiance<M: Material, L: Light, S: Sampler, A: AovRecord>(
    scene: &Scene<M, L>,
    mut ray: Ray,
    sampler: &mut S,
    settings: &PathTracer,
    rays: &mut u64,
    aov: &mut A,
) -> Rgb {
    let mut l = Rgb::BLACK;
    let mut beta = Rgb::WHITE;
    // The previous vertex and the density of the BSDF sample that left it, for MIS on hits.
    let mut prev_ctx = LightSampleContext::default();
    let mut prev_bsdf_pdf = 0.0f32;
    let mut specular_bounce = false;
    // Product of squared relative IORs crossed, so Russian roulette does not see the 1/eta^2
    // radiance scaling of refraction as lost energy.
    let mut eta_scale = 1.0f32;
    let mut depth = 0u32;
    let use_nee = settings.nee;
    // The absorption coefficient of the medium the path is in (entered by refraction through
    // a surface whose material has one), if any.
    let mut medium: Option<Rgb> = None;

    loop {
        *rays += 1;
        let hit = scene.intersect(&ray);
        // Beer-Lambert over the segment just traced (all of it lost if it never leaves).
        if let Some(sigma) = medium {
            let d = hit
                .as_ref()
                .map_or(f32::INFINITY, |si| si.t * ray.dir.length());
            beta *= sigma.map(|s| if s > 0.0 { (-s * d).exp() } else { 1.0 });
            if beta.is_black() {
                break;
            }
        }
        // The MIS weight of emission from light `index` that this ray sees.
        let emission = |index: u32| {
            let direct = depth == 0 || specular_bounce;
            emission_weight(
                scene,
                index,
                direct,
                &prev_ctx,
                &ray,
                prev_bsdf_pdf,
                settings,
            )
        };
        let Some(mut si) = hit else {
            // The ray escapes: add what the environment sends along it.
            if !settings.environment {
                aov.set(Rgb::BLACK, Vec3::ZERO);
                break;
            }
            let mut seen = Rgb::BLACK;
            for &index in scene.infinite_lights() {
                let light = &scene.lights()[index as usize];
                let le = light.le(&ray);
                if A::ON {
                    seen += le;
                }
                if !le.is_black() {
                    l += beta * le * emission(index);
                }
            }
            aov.set(seen, Vec3::ZERO);
            break;
        };

        // Emission seen by this ray.
        let mut emitted = Rgb::BLACK;
        if let Some(light_index) = si.light {
            let light = &scene.lights()[light_index as usize];
            let le = light.l(si.point.p, si.n(), si.uv, si.wo);
            emitted = le;
            if !le.is_black() {
                l += beta * le * emission(light_index);
            }
        }

        if depth == settings.max_depth {
            aov.set(emitted, si.ns());
            break;
        }
        depth += 1;

        let material = &scene.materials()[si.material as usize];
        let mut mctx = MaterialContext::new(si.point.p, si.n(), si.ns(), si.wo, si.uv);
        if settings.attributes {
            mctx.attributes = si.attributes;
        }
        if settings.normal_maps
            && let Some(n) = material.shading_normal(&mctx)
        {
            let n = bend_shading_normal(n, si.n(), si.wo);
            si.shading = Frame::from_z(n);
            mctx.ns = n;
        }
        let bsdf = material.bsdf(&mctx);
        let flags = bsdf.flags();
        if flags.is_empty() {
            aov.set(emitted, si.ns());
            break;
        }
        // The first non-specular hit sets the AOVs (its albedo once the BSDF is sampled below).
        let aov_here = A::ON && !aov.is_set() && flags.is_non_specular();
        let wo = si.shading.to_local(si.wo);
        let ctx = LightSampleContext {
            point: si.point,
            ns: si.ns(),
        };

        // Next-event estimation: sample a light, trace a shadow ray.
        if use_nee && flags.is_non_specular() {
            // One 2D draw: its first number chooses the light and, remapped, with the second
            // places the point on it (relMSE 3% lower on Mitsuba's box than a draw for each).
            let u = sampler.next_2d();
            l += beta * sample_direct(scene, &si, &bsdf, &ctx, wo, u, settings.strategy, rays);
        }

        // Continue the path by sampling the BSDF.
        // Only the numbers this BSDF reads are drawn: a mirror takes none, a Lambertian
        // surface no lobe choice (no sampler dimension spent on a number nobody reads).
        let inputs = bsdf.sample_inputs();
        let uc = if inputs.uc {
            sampler.next_1d()
        } else {
            SampleInputs::UNDRAWN
        };
        let u = if inputs.u {
            sampler.next_2d()
        } else {
            Vec2::splat(SampleInputs::UNDRAWN)
        };
        let sample = bsdf.sample(wo, uc, u, TransportMode::Radiance);
        if aov_here {
            // One sample of the directional albedo: f cos / pdf of the direction drawn.
            let albedo = sample
                .filter(|bs| bs.pdf > 0.0)
                .map_or(Rgb::BLACK, |bs| bs.f * (bs.wi.z.abs() / bs.pdf));
            aov.set(albedo, si.ns());
        }
        let Some(bs) = sample else {
            aov.set(emitted, si.ns());
            break;
        };
        if bs.pdf <= 0.0 || bs.f.is_black() {
            aov.set(emitted, si.ns());
            break;
        }
        let wi = si.shading.from_local(bs.wi);
        if !consistent_sides(&si, wo, si.wo, bs.wi, wi) {
            break;
        }
        beta *= bs.f * (bs.wi.z.abs() / bs.pdf);
        specular_bounce = bs.is_specular();
        prev_bsdf_pdf = bs.pdf;
        prev_ctx = ctx;
        if bs.is_transmission() {
            eta_scale *= bs.eta * bs.eta;
            if settings.media {
                // Into the object (against the outward geometric normal) or out of it.
                medium = if wi.dot(si.n()) < 0.0 {
                    material.absorption()
                } else {
                    None
                };
            }
        }
        ray = si.spawn_ray(wi);

        // Russian roulette: end paths that carry little, boosting the survivors to stay unbiased.
        let rr_beta = beta.max_component() * eta_scale * settings.rr_scale;
        if depth > settings.rr_depth && rr_beta < 1.0 {
            let q = (1.0 - rr_beta).max(0.0);
            if sampler.next_1d() < q {
                break;
            }
            beta /= 1.0 - q;
        }
        if !beta.is_finite() {
            break;
        }
    }
    l
}

/// Weight of emission seen along `ray` (a ray from `prev` that hit an area light or escaped to
/// an infinite light): 1 when the ray is `direct` (a camera ray, or one leaving a specular
/// bounce: nothing else can find that light); else, after a non-delta bounce, 1 or 0 for the
/// single strategies, or the power heuristic against the probability that next-event
/// estimation samples the same direction (light selection times the light's solid-angle
/// density). Both tracers call it for every light they see.
// Always inlined without AVX2, to compile inside the lane tracer's dispatched entry (see the
// environment module's docs).
#[cfg_attr(target_feature = "avx2", inline)]
#[cfg_attr(not(target_feature = "avx2"), inline(always))]
pub(super) fn emission_weight<M: Material, L: Light>(
    scene: &Scene<M, L>,
    light_index: u32,
    direct: bool,
    prev: &LightSampleContext,
    ray: &Ray,
    prev_bsdf_pdf: f32,
    settings: &PathTracer,
) -> f32 {
    if direct {
        return 1.0;
    }
    match settings.strategy {
        LightStrategy::BsdfOnly => 1.0,
        LightStrategy::LightOnly => 0.0,
        LightStrategy::Mis => {
            let light = &scene.lights()[light_index as usize];
            let light_pdf = scene.light_sampler().pmf(light_index as usize)
                * light.pdf_li(prev, ray.dir.normalize());
            power_heuristic(prev_bsdf_pdf, light_pdf)
        }
    }
}

/// True when the geometric normal agrees with the shading normal about whether `wi` is a
/// reflection or a transmission of `wo`. Where they disagree (interpolated normals near
/// silhouettes), following the shading normal would leak light through the surface.
#[inline]
pub(super) fn consistent_sides(
    si: &SurfaceInteraction,
    wo_local: glam::Vec3,
    wo: glam::Vec3,
    wi_local: glam::Vec3,
    wi: glam::Vec3,
) -> bool {
    let n = si.n();
    let geometric = wi.dot(n) * wo.dot(n) > 0.0;
    let shading = wi_local.z * wo_local.z > 0.0;
    geometric == shading
}

/// One light sample for next-event estimation, weighted by MIS against BSDF sampling
/// (`wo_local`: the outgoing direction in the shading frame; `u.x` chooses the light and,
/// remapped within the light's share, places the point with `u.y`).
#[inline]
fn sample_direct<M: Material, L: Light>(
    scene: &Scene<M, L>,
    si: &SurfaceInteraction,
    bsdf: &M::Bsdf,
    ctx: &LightSampleContext,
    wo_local: glam::Vec3,
    u: glam::Vec2,
    strategy: LightStrategy,
    rays: &mut u64,
) -> Rgb {
    let Some((index, pmf, ux)) = scene.light_sampler().sample_remapped(u.x) else {
        return Rgb::BLACK;
    };
    let u = glam::Vec2::new(ux, u.y);
    let light = &scene.lights()[index];
    let Some(ls) = light.sample_li(ctx, u) else {
        return Rgb::BLACK;
    };
    if ls.pdf <= 0.0 || ls.li.is_black() {
        return Rgb::BLACK;
    }
    let wi_local = si.shading.to_local(ls.wi);
    if !consistent_sides(si, wo_local, si.wo, wi_local, ls.wi) {
        return Rgb::BLACK;
    }
    let f = bsdf.eval(wo_local, wi_local, TransportMode::Radiance) * wi_local.z.abs();
    if f.is_black() {
        return Rgb::BLACK;
    }
    *rays += 1;
    if scene.occluded(&si.spawn_ray_to(&ls.point)) {
        return Rgb::BLACK;
    }
    let light_pdf = pmf * ls.pdf;
    let weight = if light.flags().is_delta() || strategy == LightStrategy::LightOnly {
        1.0
    } else {
        power_heuristic(
            light_pdf,
            bsdf.pdf(wo_local, wi_local, TransportMode::Radiance),
        )
    };
    f * ls.li * (weight / light_pdf)
}
