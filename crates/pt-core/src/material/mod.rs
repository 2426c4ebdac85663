//! Materials: what a surface is made of, turned into a BSDF at each hit.
//!
//! A [`Material`] maps the local surface context (texture coordinates, normals) to a BSDF value
//! on the stack: no heap allocation per hit. [`BuiltinMaterial`] is a closed enum; users extend it
//! with [`material_enum!`](crate::material_enum).

mod diffuse;
mod glass;
mod metal;
mod mirror;
mod pbr;

pub use diffuse::Diffuse;
pub use glass::Glass;
pub use metal::Metal;
pub use mirror::Mirror;
pub use pbr::{AlphaMode, PbrMaterial};

use std::fmt;

use glam::{Vec2, Vec3};

use crate::bsdf::{Bsdf, BuiltinBsdf};
use crate::color::Rgb;
use crate::interaction::SurfaceAttributes;
use crate::light::Light;
use crate::scene::Scene;

/// A material parameter outside its valid range.
#[derive(Clone, Debug, PartialEq)]
pub struct MaterialError {
    /// The material kind ("glass", "metal").
    pub material: &'static str,
    /// The parameter.
    pub parameter: &'static str,
    /// The value given, as text.
    pub value: String,
    /// What a valid value is.
    pub expected: &'static str,
}

impl fmt::Display for MaterialError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} material: {} must be {}, got {}",
            self.material, self.parameter, self.expected, self.value
        )
    }
}

impl std::error::Error for MaterialError {}

fn check_roughness(material: &'static str, roughness: f32) -> Result<f32, MaterialError> {
    if (0.0..=1.0).contains(&roughness) {
        Ok(roughness)
    } else {
        Err(MaterialError {
            material,
            parameter: "roughness",
            value: roughness.to_string(),
            expected: "in [0, 1]",
        })
    }
}

/// The surface context a material is evaluated at.
///
/// Non-exhaustive so that later texture filtering and anisotropic models (tangents, ray
/// differentials) can add fields; make one with [`MaterialContext::new`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct MaterialContext {
    /// Surface coordinates (texture coordinates when the mesh has them, else barycentrics).
    pub uv: Vec2,
    /// World-space position.
    pub p: Vec3,
    /// Geometric normal.
    pub n: Vec3,
    /// Shading normal.
    pub ns: Vec3,
    /// The interpolated vertex normal, before any normal map replaced `ns` (equal to `ns`
    /// without one): layers a normal map does not bend (glTF's clearcoat) use it.
    pub vertex_normal: Vec3,
    /// Direction toward the viewer.
    pub wo: Vec3,
    /// Vertex attributes: every texture-coordinate set, colour, tangent (filled when the
    /// material's [`properties`](Material::properties) claim `reads_attributes`).
    pub attributes: SurfaceAttributes,
}

impl MaterialContext {
    /// The context at position `p` with geometric normal `n`, shading normal `ns`, direction
    /// toward the viewer `wo` and surface coordinates `uv` (also texture-coordinate set 0 of
    /// the default [`attributes`](Self::attributes)).
    #[inline]
    #[must_use]
    pub fn new(p: Vec3, n: Vec3, ns: Vec3, wo: Vec3, uv: Vec2) -> Self {
        let mut attributes = SurfaceAttributes::default();
        attributes.uv[0] = uv;
        Self {
            uv,
            p,
            n,
            ns,
            vertex_normal: ns,
            wo,
            attributes,
        }
    }

    /// The same context with these vertex attributes.
    #[inline]
    #[must_use]
    pub fn with_attributes(mut self, attributes: SurfaceAttributes) -> Self {
        self.attributes = attributes;
        self
    }
}

/// Turns a surface context into a BSDF.
pub trait Material: Send + Sync {
    /// The BSDF type this material produces.
    type Bsdf: Bsdf;

    /// The BSDF at a surface point.
    fn bsdf(&self, ctx: &MaterialContext) -> Self::Bsdf;

    /// A world-space shading normal that replaces the interpolated one (`ctx.ns`) at this point,
    /// such as a normal map's; `None`, the default, keeps `ctx.ns`. The renderer calls it before
    /// [`bsdf`](Self::bsdf), builds the shading frame around the returned normal (bent toward
    /// the geometric normal where needed, so that reflections of `ctx.wo` stay above the
    /// surface) and passes it to `bsdf` as `ctx.ns`. Called only when the material's
    /// [`properties`](Self::properties) claim `normal_map`.
    fn shading_normal(&self, ctx: &MaterialContext) -> Option<Vec3> {
        let _ = ctx;
        None
    }

    /// The probability in `[0, 1]` that a ray meeting the surface here stops on it (its
    /// coverage, glTF's alpha): below 1 the ray passes through with probability `1 - coverage`
    /// (stochastic transparency: camera, indirect and shadow rays alike). 1, the default, is
    /// opaque. Called only when the material's [`properties`](Self::properties) claim
    /// `coverage`.
    fn coverage(&self, ctx: &MaterialContext) -> f32 {
        let _ = ctx;
        1.0
    }

    /// The absorption coefficient (per unit length, per channel) of the medium this surface
    /// encloses, if it bounds one: paths refracted into the object lose `exp(-sigma d)` over
    /// each distance `d` they travel inside, until they leave through a surface again
    /// (Beer-Lambert; glTF's `KHR_materials_volume`). Inside and outside are by the
    /// geometric normal's side (the outside is where it points). `None`, the default, is
    /// no medium. Media do not nest: leaving any surface leaves the medium.
    fn absorption(&self) -> Option<Rgb> {
        None
    }

    /// True when the surface exists only from its front (glTF's `doubleSided: false`): rays
    /// reaching a back face pass through it. The front face is the counter-clockwise winding
    /// of the triangle's corners as the instance places them (for a transform with negative
    /// determinant, clockwise, as glTF says). `false`, the default, sees both faces.
    fn single_sided(&self) -> bool {
        false
    }

    /// What this material needs from the renderer, for the scene analysis that skips work a
    /// scene does not need (DESIGN.md section 6). The default claims everything, which is
    /// always correct; a material that overrides it must not claim less than it uses.
    fn properties(&self) -> MaterialProperties {
        MaterialProperties::ALL
    }

    /// The model in the form the lane path tracer evaluates eight at a time, for the built-in
    /// models it knows (`None`, the default, keeps scenes using this material on the one-path
    /// tracer). Not for use outside pt.
    #[doc(hidden)]
    fn lane_model(&self) -> Option<LaneModel> {
        None
    }

    /// Render `scene`: the renderer compiled in the calling crate (the default), or, for
    /// [`BuiltinMaterial`] with the built-in lights, pinhole camera and samplers, the copy
    /// compiled (and optimised) in pt-core ([`render_builtin`](crate::render_builtin)), chosen
    /// by type through [`Light`], [`Camera`](crate::Camera) and
    /// [`SamplerFactory`](crate::SamplerFactory) in turn, so that a crate rendering only the
    /// built-in types never compiles the renderer itself. [`render`](crate::render) calls it.
    /// Not for use outside pt.
    #[doc(hidden)]
    fn render_scene<L: Light, C: crate::Camera, K: crate::SamplerFactory>(
        scene: &Scene<Self, L>,
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

/// What a material needs from the renderer ([`Material::properties`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub struct MaterialProperties {
    /// It reads [`MaterialContext::uv`] (it has textures), so hits must interpolate texture
    /// coordinates.
    pub reads_uv: bool,
    /// It can produce a BSDF with a non-delta lobe, so paths from it use next-event
    /// estimation and multiple importance sampling.
    pub non_delta: bool,
    /// It reads [`MaterialContext::attributes`] (vertex colours, tangents, texture-coordinate
    /// sets beyond the first), so hits must interpolate them.
    pub reads_attributes: bool,
    /// It bends the shading normal ([`Material::shading_normal`]).
    pub normal_map: bool,
    /// It may be partly transparent ([`Material::coverage`]), so every hit on it asks.
    pub coverage: bool,
}

impl MaterialProperties {
    /// Needs everything: the safe answer for any material.
    pub const ALL: Self = Self {
        reads_uv: true,
        non_delta: true,
        reads_attributes: true,
        normal_map: true,
        coverage: true,
    };

    /// The properties of a material that reads texture coordinates (`reads_uv`) or not, may
    /// produce a non-delta lobe or not, and reads no other attribute nor bends the normal.
    #[must_use]
    pub const fn new(reads_uv: bool, non_delta: bool) -> Self {
        Self {
            reads_uv,
            non_delta,
            reads_attributes: false,
            normal_map: false,
            coverage: false,
        }
    }

    /// These properties, also reading vertex attributes ([`MaterialContext::attributes`]).
    #[must_use]
    pub const fn with_attributes(mut self) -> Self {
        self.reads_attributes = true;
        self
    }

    /// These properties, also bending the shading normal ([`Material::shading_normal`]).
    #[must_use]
    pub const fn with_normal_map(mut self) -> Self {
        self.normal_map = true;
        self
    }

    /// These properties, also partly transparent ([`Material::coverage`]).
    #[must_use]
    pub const fn with_coverage(mut self) -> Self {
        self.coverage = true;
        self
    }
}

/// A material as the lane path tracer evaluates it (see [`Material::lane_model`]). Not for use
/// outside pt.
#[doc(hidden)]
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum LaneModel {
    /// Lambertian reflection with this albedo (already clamped to `[0, 1]`).
    Lambertian(Rgb),
    /// Ideal specular reflection with this reflectance (already clamped to `[0, 1]`).
    Mirror(Rgb),
    /// A smooth dielectric without a thin film ([`SmoothDielectric`](crate::SmoothDielectric)):
    /// relative index of refraction and transmission tint (as the BSDF sanitises them).
    Glass {
        /// `n_inside / n_outside`.
        eta: f32,
        /// Transmittance of refracted light, in `[0, 1]`.
        tint: Rgb,
    },
}

/// Define an enum over material types with a statically dispatched [`Material`] impl whose BSDF
/// type is the given BSDF enum, and a `From` impl per variant. Each variant's BSDF must convert
/// into the BSDF enum.
///
/// ```
/// use pt_core::{bsdf_enum, material_enum, BuiltinBsdf, BuiltinMaterial, Diffuse};
///
/// bsdf_enum! {
///     /// BSDFs of my program.
///     #[derive(Clone, Debug)]
///     pub enum MyBsdf { Builtin(BuiltinBsdf) }
/// }
/// material_enum! {
///     /// Materials of my program, producing `MyBsdf`.
///     #[derive(Clone, Debug)]
///     pub enum MyMaterial -> MyBsdf { Builtin(BuiltinMaterial) }
/// }
/// let m: MyMaterial = BuiltinMaterial::from(Diffuse::new(pt_core::Rgb::splat(0.5))).into();
/// # let _ = m;
/// ```
#[macro_export]
macro_rules! material_enum {
    (
        $(@$builtin:ident)?
        $(#[$meta:meta])*
        $vis:vis enum $name:ident -> $bsdf:ty {
            $( $(#[$vmeta:meta])* $variant:ident($ty:ty) ),+ $(,)?
        }
    ) => {
        $(#[$meta])*
        $vis enum $name {
            $( $(#[$vmeta])* #[allow(missing_docs)] $variant($ty), )+
        }

        $crate::__variant_names!($vis $name { $($variant),+ });

        impl $crate::material::Material for $name {
            type Bsdf = $bsdf;
            #[inline(always)]
            fn bsdf(&self, ctx: &$crate::material::MaterialContext) -> $bsdf {
                match self {
                    $( Self::$variant(m) => <$bsdf>::from($crate::material::Material::bsdf(m, ctx)), )+
                }
            }
            fn properties(&self) -> $crate::material::MaterialProperties {
                match self {
                    $( Self::$variant(m) => $crate::material::Material::properties(m), )+
                }
            }
            #[inline]
            fn shading_normal(
                &self,
                ctx: &$crate::material::MaterialContext,
            ) -> Option<$crate::glam::Vec3> {
                match self {
                    $( Self::$variant(m) => $crate::material::Material::shading_normal(m, ctx), )+
                }
            }
            fn lane_model(&self) -> Option<$crate::material::LaneModel> {
                match self {
                    $( Self::$variant(m) => $crate::material::Material::lane_model(m), )+
                }
            }
            #[inline]
            fn coverage(&self, ctx: &$crate::material::MaterialContext) -> f32 {
                match self {
                    $( Self::$variant(m) => $crate::material::Material::coverage(m, ctx), )+
                }
            }
            fn single_sided(&self) -> bool {
                match self {
                    $( Self::$variant(m) => $crate::material::Material::single_sided(m), )+
                }
            }
            #[inline]
            fn absorption(&self) -> Option<$crate::Rgb> {
                match self {
                    $( Self::$variant(m) => $crate::material::Material::absorption(m), )+
                }
            }
            $( $crate::__builtin_hook!($builtin material); )?
        }

        $(
            impl From<$ty> for $name {
                #[inline]
                fn from(m: $ty) -> Self {
                    Self::$variant(m)
                }
            }
        )+
    };
}

material_enum! {
    // `@builtin`: `render` recognises scenes of these materials and the built-in lights
    // (`Material::render_scene`).
    @builtin
    /// The materials that ship with pt.
    // Materials live once each in the scene's table, not per hit: the size of the glTF
    // material (its texture maps) costs nothing that matters.
    #[allow(clippy::large_enum_variant)]
    #[derive(Clone, Debug, PartialEq)]
    #[non_exhaustive]
    pub enum BuiltinMaterial -> BuiltinBsdf {
        /// Matte (Lambertian).
        Diffuse(Diffuse),
        /// Perfect mirror.
        Mirror(Mirror),
        /// Smooth or rough metal.
        Metal(Metal),
        /// Smooth or rough glass.
        Glass(Glass),
        /// Metallic-roughness with textures (loaded scenes).
        Pbr(PbrMaterial),
    }
}

impl BuiltinMaterial {
    /// A matte material with the given albedo.
    #[must_use]
    pub fn diffuse(reflectance: Rgb) -> Self {
        Diffuse::new(reflectance).into()
    }

    /// A perfect mirror with the given reflectance.
    #[must_use]
    pub fn mirror(reflectance: Rgb) -> Self {
        Mirror::new(reflectance).into()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::{Bsdf, BsdfFlags, ConductorFresnel};

    fn ctx() -> MaterialContext {
        MaterialContext::new(Vec3::ZERO, Vec3::Z, Vec3::Z, Vec3::Z, Vec2::ZERO)
    }

    #[test]
    fn absurd_parameters_are_errors() {
        for eta in [f32::NAN, 0.0, -1.5, f32::INFINITY] {
            let e = Glass::new(eta).unwrap_err();
            assert!(e.to_string().contains("glass material: eta"), "{e}");
        }
        assert!(Glass::new(1.5).unwrap().with_roughness(1.5).is_err());
        assert!(Glass::new(1.5).unwrap().with_roughness(f32::NAN).is_err());
        assert!(Metal::new(ConductorFresnel::GOLD, -0.1).is_err());
        assert!(Metal::new(ConductorFresnel::Schlick(Rgb::splat(1.2)), 0.5).is_err());
        let bad_k = ConductorFresnel::Complex {
            eta: Rgb::WHITE,
            k: Rgb::new(1.0, f32::NAN, 1.0),
        };
        assert!(
            Metal::new(bad_k, 0.5)
                .unwrap_err()
                .to_string()
                .contains("k must be")
        );
    }

    #[test]
    fn glass_picks_the_smooth_or_rough_model() {
        let smooth = BuiltinMaterial::from(Glass::new(1.5).unwrap()).bsdf(&ctx());
        assert!(matches!(smooth, BuiltinBsdf::SmoothDielectric(_)));
        let rough = BuiltinMaterial::from(Glass::new(1.5).unwrap().with_roughness(0.3).unwrap())
            .bsdf(&ctx());
        assert!(matches!(rough, BuiltinBsdf::RoughDielectric(_)));
        let metal = Metal::new(ConductorFresnel::GOLD, 0.0)
            .unwrap()
            .bsdf(&ctx());
        assert_eq!(metal.flags(), BsdfFlags::SPECULAR_REFLECTION);
        let mirror = BuiltinMaterial::mirror(Rgb::WHITE).bsdf(&ctx());
        assert_eq!(mirror.flags(), BsdfFlags::SPECULAR_REFLECTION);
    }
}
