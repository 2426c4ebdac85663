//! Light sources.
//!
//! # Conventions
//!
//! - [`Light::sample_li`] picks a point on the light as seen from a reference point and returns
//!   the incident radiance `li` arriving there along `wi` (unit, pointing from the reference point
//!   toward the light), the **solid-angle** density of choosing `wi` (for delta lights: 1), and
//!   the point on the light for the shadow ray.
//! - [`Light::pdf_li`] is that density for a given `wi` (zero for delta lights, which only
//!   sampling can reach).
//! - [`Light::l`] is the radiance an area light emits from a surface point along `w` (pointing
//!   away from the light); [`Light::le`] is the radiance an infinite light sends along a ray that
//!   escapes the scene.
//! - [`Light::power`] is the emitted flux (watts, per channel), used to pick lights in proportion
//!   to their power.
//!
//! Users compose their own lights with the built-ins through [`light_enum!`](crate::light_enum).

mod environment;
mod error;
mod power_sampler;
mod punctual;
mod textured;
mod triangle;

use std::ops::BitOr;

use glam::{Vec2, Vec3};
use pt_accel::{Bounds3, Ray};

use crate::color::Rgb;
use crate::interaction::SurfacePoint;
use crate::material::BuiltinMaterial;
use crate::scene::Scene;

pub use environment::{
    CUBE_FACES, CubemapEnvironment, EquirectEnvironment, UniformEnvironment, cube_face_point,
    cube_face_st,
};
pub use error::LightError;
pub use power_sampler::PowerLightSampler;
pub use punctual::{DirectionalLight, PointLight, SpotLight};
pub use textured::TexturedTriangleLight;
pub use triangle::TriangleLight;

/// What kind of light this is, for the integrator's bookkeeping.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct LightFlags(u8);

impl LightFlags {
    /// Emits from a single point (point and spot lights).
    pub const DELTA_POSITION: Self = Self(1);
    /// Emits along a single direction (directional lights).
    pub const DELTA_DIRECTION: Self = Self(2);
    /// Emits from a surface that rays can hit.
    pub const AREA: Self = Self(4);
    /// Surrounds the scene; rays that escape see it.
    pub const INFINITE: Self = Self(8);

    /// A delta light: `pdf_li` is zero and MIS does not apply.
    #[inline]
    #[must_use]
    pub const fn is_delta(self) -> bool {
        self.0 & 3 != 0
    }

    /// An area light.
    #[inline]
    #[must_use]
    pub const fn is_area(self) -> bool {
        self.0 & 4 != 0
    }

    /// An infinite light.
    #[inline]
    #[must_use]
    pub const fn is_infinite(self) -> bool {
        self.0 & 8 != 0
    }
}

impl BitOr for LightFlags {
    type Output = Self;
    #[inline]
    fn bitor(self, o: Self) -> Self {
        Self(self.0 | o.0)
    }
}

/// The reference point of a light query: where the light is seen from.
///
/// Non-exhaustive so that later light sampling (e.g. by BSDF-aware light trees) can add fields;
/// make one with [`LightSampleContext::new`] or [`LightSampleContext::at`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[non_exhaustive]
pub struct LightSampleContext {
    /// The receiving point (position, error bound, geometric normal).
    pub point: SurfacePoint,
    /// Shading normal at the receiving point (zero if none).
    pub ns: Vec3,
}

impl LightSampleContext {
    /// The context at surface point `point` with shading normal `ns` (zero if none).
    #[inline]
    #[must_use]
    pub fn new(point: SurfacePoint, ns: Vec3) -> Self {
        Self { point, ns }
    }

    /// The context at a bare position (no surface: no normal, no error bound), as for a point
    /// in a medium or a test.
    #[inline]
    #[must_use]
    pub fn at(p: Vec3) -> Self {
        Self::new(SurfacePoint::exact(p), Vec3::ZERO)
    }

    /// The position of the receiving point.
    #[inline]
    #[must_use]
    pub fn p(&self) -> Vec3 {
        self.point.p
    }

    /// A shadow-ray target for a light at infinity (environments, directional lights): the
    /// point along `wi` from here that lies beyond every object of a scene whose bounding sphere
    /// has `center` and `radius`, facing back along `-wi`. Nothing past it can block the light.
    #[inline]
    #[must_use]
    pub fn point_beyond(&self, wi: Vec3, center: Vec3, radius: f32) -> SurfacePoint {
        let reach = 2.0 * radius + (self.p() - center).length();
        SurfacePoint {
            p: self.p() + wi * reach,
            p_error: Vec3::ZERO,
            n: -wi,
        }
    }
}

/// A point sampled on a light, seen from a reference point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightSample {
    /// Radiance arriving at the reference point along `wi` (before visibility).
    pub li: Rgb,
    /// Unit direction from the reference point toward the light.
    pub wi: Vec3,
    /// Solid-angle density of `wi` (1 for delta lights).
    pub pdf: f32,
    /// The point on the light, target of the shadow ray.
    pub point: SurfacePoint,
}

/// A light source. See the [module documentation](self) for the conventions.
pub trait Light: Send + Sync {
    /// What kind of light this is.
    fn flags(&self) -> LightFlags;

    /// Total emitted power (flux), per channel.
    fn power(&self) -> Rgb;

    /// Sample a direction toward the light from `ctx`.
    fn sample_li(&self, ctx: &LightSampleContext, u: Vec2) -> Option<LightSample>;

    /// Solid-angle density with which [`sample_li`](Self::sample_li) returns `wi` from `ctx`.
    fn pdf_li(&self, ctx: &LightSampleContext, wi: Vec3) -> f32;

    /// Radiance emitted by an area light at surface point `p` with geometric normal `n` and
    /// surface coordinates `uv`, along `w` (pointing away from the light). Zero for other lights.
    fn l(&self, p: Vec3, n: Vec3, uv: Vec2, w: Vec3) -> Rgb {
        let _ = (p, n, uv, w);
        Rgb::BLACK
    }

    /// Radiance of an infinite light seen along an escaping ray. Zero for other lights.
    fn le(&self, ray: &Ray) -> Rgb {
        let _ = ray;
        Rgb::BLACK
    }

    /// A hint that [`sample_li`](Self::sample_li) will soon be called with `u`: a light whose
    /// sampling reads large tables (an environment map's) may ask for the memory that call
    /// will read. Sampling is a chain of dependent reads, so the hint comes in steps: step 0
    /// asks for what `sample_li` reads first, step 1 for what it reads next (reading, where it
    /// must, what step 0 asked for). The lane path tracer gives step 0 for each of its lanes,
    /// then step 1 for each, so that the lanes wait for their cache misses together rather
    /// than one after another. Never changes a result; does nothing by default.
    #[inline]
    fn prefetch_sample_li(&self, u: Vec2, step: u32) {
        let _ = (u, step);
    }

    /// Called once when the scene is built, with the bounds of its geometry (infinite lights use
    /// them to place sample points and estimate their power).
    fn preprocess(&mut self, scene_bounds: &Bounds3) {
        let _ = scene_bounds;
    }

    /// The light in the form the lane path tracer samples eight at a time, for the built-in
    /// models it knows (`None`, the default, keeps scenes with this light on the one-path
    /// tracer). Not for use outside pt.
    #[doc(hidden)]
    fn lane_light(&self) -> Option<LaneLight> {
        None
    }

    /// [`Material::render_scene`](crate::Material::render_scene)'s second step, for a scene
    /// of [`BuiltinMaterial`]: the renderer compiled in the calling crate (the default), or
    /// for [`BuiltinLight`] the camera's step ([`Camera::render_builtin_scene`](crate::Camera::render_builtin_scene)).
    /// Not for use outside pt.
    #[doc(hidden)]
    fn render_builtin_material_scene<C: crate::Camera, K: crate::SamplerFactory>(
        scene: &Scene<BuiltinMaterial, Self>,
        camera: &C,
        options: &crate::RenderOptions<K>,
        control: Option<&crate::render::RenderControl<'_>>,
    ) -> Result<crate::render::RenderOutput, crate::render::RenderError>
    where
        Self: Sized,
    {
        crate::render::render_generic(scene, camera, options, control)
    }
}

/// The overrides that let [`render`](crate::render) recognise the built-in material and light
/// types ([`Material::render_scene`](crate::Material::render_scene)), inside the impls that
/// `material_enum!` and `light_enum!` write for the enums marked `@builtin`. Not for use
/// outside pt.
#[doc(hidden)]
#[macro_export]
macro_rules! __builtin_hook {
    (builtin material) => {
        fn render_scene<L: $crate::light::Light, C: $crate::Camera, K: $crate::SamplerFactory>(
            scene: &$crate::Scene<Self, L>,
            camera: &C,
            options: &$crate::RenderOptions<K>,
            control: Option<&$crate::RenderControl<'_>>,
        ) -> Result<$crate::RenderOutput, $crate::RenderError> {
            <L as $crate::light::Light>::render_builtin_material_scene(
                scene, camera, options, control,
            )
        }
    };
    (builtin light) => {
        fn render_builtin_material_scene<C: $crate::Camera, K: $crate::SamplerFactory>(
            scene: &$crate::Scene,
            camera: &C,
            options: &$crate::RenderOptions<K>,
            control: Option<&$crate::RenderControl<'_>>,
        ) -> Result<$crate::RenderOutput, $crate::RenderError> {
            $crate::Camera::render_builtin_scene(camera, scene, options, control)
        }
    };
}

/// A light as the lane path tracer samples it (see [`Light::lane_light`]). Not for use outside
/// pt.
#[doc(hidden)]
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum LaneLight {
    /// A triangle sampled uniformly by area.
    Triangle {
        /// Corners.
        p: [Vec3; 3],
        /// Unit normal of the front face.
        n: Vec3,
        /// Area.
        area: f32,
        /// Emitted radiance.
        radiance: Rgb,
        /// Both faces emit.
        two_sided: bool,
    },
}

/// Define an enum over light types with a statically dispatched [`Light`] impl and a `From` impl
/// per variant (see [`bsdf_enum!`](crate::bsdf_enum) for the pattern).
///
/// ```
/// use pt_core::{light_enum, BuiltinLight, TriangleLight};
///
/// light_enum! {
///     /// The built-in lights plus a user light (here a second triangle light type).
///     #[derive(Clone, Debug)]
///     pub enum MyLight {
///         Builtin(BuiltinLight),
///         Mine(TriangleLight),
///     }
/// }
/// ```
#[macro_export]
macro_rules! light_enum {
    (
        $(@$builtin:ident)?
        $(#[$meta:meta])*
        $vis:vis enum $name:ident {
            $( $(#[$vmeta:meta])* $variant:ident($ty:ty) ),+ $(,)?
        }
    ) => {
        $(#[$meta])*
        $vis enum $name {
            $( $(#[$vmeta])* #[allow(missing_docs)] $variant($ty), )+
        }

        $crate::__variant_names!($vis $name { $($variant),+ });

        impl $crate::light::Light for $name {
            #[inline]
            fn flags(&self) -> $crate::light::LightFlags {
                match self { $( Self::$variant(l) => $crate::light::Light::flags(l), )+ }
            }
            #[inline]
            fn power(&self) -> $crate::Rgb {
                match self { $( Self::$variant(l) => $crate::light::Light::power(l), )+ }
            }
            #[inline(always)]
            fn sample_li(
                &self,
                ctx: &$crate::light::LightSampleContext,
                u: $crate::glam::Vec2,
            ) -> Option<$crate::light::LightSample> {
                match self { $( Self::$variant(l) => $crate::light::Light::sample_li(l, ctx, u), )+ }
            }
            // `pdf_li`, `le` and the hint always inlined without AVX2, to compile inside the lane
            // tracer's dispatched entry (see the environment module's docs).
            #[cfg_attr(target_feature = "avx2", inline)]
            #[cfg_attr(not(target_feature = "avx2"), inline(always))]
            fn pdf_li(&self, ctx: &$crate::light::LightSampleContext, wi: $crate::glam::Vec3) -> f32 {
                match self { $( Self::$variant(l) => $crate::light::Light::pdf_li(l, ctx, wi), )+ }
            }
            #[inline]
            fn l(
                &self,
                p: $crate::glam::Vec3,
                n: $crate::glam::Vec3,
                uv: $crate::glam::Vec2,
                w: $crate::glam::Vec3,
            ) -> $crate::Rgb {
                match self { $( Self::$variant(l) => $crate::light::Light::l(l, p, n, uv, w), )+ }
            }
            #[cfg_attr(target_feature = "avx2", inline)]
            #[cfg_attr(not(target_feature = "avx2"), inline(always))]
            fn le(&self, ray: &$crate::pt_accel::Ray) -> $crate::Rgb {
                match self { $( Self::$variant(l) => $crate::light::Light::le(l, ray), )+ }
            }
            #[cfg_attr(target_feature = "avx2", inline)]
            #[cfg_attr(not(target_feature = "avx2"), inline(always))]
            fn prefetch_sample_li(&self, u: $crate::glam::Vec2, step: u32) {
                match self { $( Self::$variant(l) => $crate::light::Light::prefetch_sample_li(l, u, step), )+ }
            }
            fn preprocess(&mut self, scene_bounds: &$crate::pt_accel::Bounds3) {
                match self { $( Self::$variant(l) => $crate::light::Light::preprocess(l, scene_bounds), )+ }
            }
            fn lane_light(&self) -> Option<$crate::light::LaneLight> {
                match self { $( Self::$variant(l) => $crate::light::Light::lane_light(l), )+ }
            }
            $( $crate::__builtin_hook!($builtin light); )?
        }

        $(
            impl From<$ty> for $name {
                #[inline]
                fn from(l: $ty) -> Self {
                    Self::$variant(l)
                }
            }
        )+
    };
}

light_enum! {
    // `@builtin`: see `material_enum!`'s `BuiltinMaterial`.
    @builtin
    /// The lights that ship with pt.
    #[derive(Clone, Debug, PartialEq)]
    #[non_exhaustive]
    pub enum BuiltinLight {
        /// A diffuse emitting triangle.
        Triangle(TriangleLight),
        /// A diffuse emitting triangle modulated by a texture.
        TexturedTriangle(TexturedTriangleLight),
        /// The same radiance from every direction.
        UniformEnvironment(UniformEnvironment),
        /// A latitude-longitude environment map.
        EquirectEnvironment(EquirectEnvironment),
        /// A six-face cube map environment.
        CubemapEnvironment(CubemapEnvironment),
        /// A point light.
        Point(PointLight),
        /// A spot light.
        Spot(SpotLight),
        /// A directional light.
        Directional(DirectionalLight),
    }
}
