//! Materials: what a surface is made of, turned into a BSDF at each hit.
//!
//! A [`Material`] maps the local surface context (texture coordinates, normals) to a BSDF value
//! on the stack: no heap allocation per hit. [`BuiltinMaterial`] is a closed enum; users extend it
//! with [`material_enum!`](crate::material_enum).

use std::fmt;
use std::sync::Arc;

use glam::{Vec2, Vec3};

use crate::bsdf::microfacet::roughness_to_alpha;
use crate::bsdf::{
    Bsdf, BuiltinBsdf, ConductorFresnel, Lambertian, RoughConductor, RoughDielectric,
    SmoothDielectric, SpecularReflection, TrowbridgeReitz,
};
use crate::color::Rgb;
use crate::texture::Texture;

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
    /// Direction toward the viewer.
    pub wo: Vec3,
}

impl MaterialContext {
    /// The context at position `p` with geometric normal `n`, shading normal `ns`, direction
    /// toward the viewer `wo` and surface coordinates `uv`.
    #[inline]
    #[must_use]
    pub fn new(p: Vec3, n: Vec3, ns: Vec3, wo: Vec3, uv: Vec2) -> Self {
        Self { uv, p, n, ns, wo }
    }
}

/// Turns a surface context into a BSDF.
pub trait Material: Send + Sync {
    /// The BSDF type this material produces.
    type Bsdf: Bsdf;

    /// The BSDF at a surface point.
    fn bsdf(&self, ctx: &MaterialContext) -> Self::Bsdf;

    /// What this material needs from the renderer, for the scene analysis that skips work a
    /// scene does not need (DESIGN.md section 6). The default claims everything, which is
    /// always correct; a material that overrides it must not claim less than it uses.
    fn properties(&self) -> MaterialProperties {
        MaterialProperties::ALL
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
}

impl MaterialProperties {
    /// Needs everything: the safe answer for any material.
    pub const ALL: Self = Self {
        reads_uv: true,
        non_delta: true,
    };

    /// The properties of a material with the given needs.
    #[must_use]
    pub const fn new(reads_uv: bool, non_delta: bool) -> Self {
        Self {
            reads_uv,
            non_delta,
        }
    }
}

/// A matte material: Lambertian reflection with a constant albedo.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Diffuse {
    /// Albedo, per channel in `[0, 1]`.
    pub reflectance: Rgb,
}

impl Diffuse {
    /// A matte material with the given albedo.
    #[must_use]
    pub fn new(reflectance: Rgb) -> Self {
        Self { reflectance }
    }
}

impl Material for Diffuse {
    type Bsdf = Lambertian;

    #[inline]
    fn bsdf(&self, _ctx: &MaterialContext) -> Lambertian {
        Lambertian::new(self.reflectance)
    }

    fn properties(&self) -> MaterialProperties {
        MaterialProperties::new(false, true)
    }
}

/// A perfect mirror: every ray reflects in the mirror direction, attenuated by `reflectance` at
/// every angle ([`SpecularReflection`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mirror {
    /// Reflectance per channel in `[0, 1]` (clamped).
    pub reflectance: Rgb,
}

impl Mirror {
    /// A mirror with the given reflectance.
    #[must_use]
    pub fn new(reflectance: Rgb) -> Self {
        Self { reflectance }
    }
}

impl Material for Mirror {
    type Bsdf = SpecularReflection;

    #[inline]
    fn bsdf(&self, _ctx: &MaterialContext) -> SpecularReflection {
        SpecularReflection::new(self.reflectance)
    }

    fn properties(&self) -> MaterialProperties {
        MaterialProperties::new(false, false)
    }
}

/// A metal: the GGX [`RoughConductor`] with perceptual `roughness` (`alpha = roughness^2`;
/// 0 is a Fresnel-weighted mirror) and a Fresnel model (a tint, or a measured complex IOR such
/// as [`ConductorFresnel::GOLD`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Metal {
    fresnel: ConductorFresnel,
    roughness: f32,
}

impl Metal {
    /// A metal. Fails on a roughness outside `[0, 1]`, a Schlick tint outside `[0, 1]`, or a
    /// complex IOR that is not finite and non-negative.
    pub fn new(fresnel: ConductorFresnel, roughness: f32) -> Result<Self, MaterialError> {
        let bad = |parameter, value: Rgb, expected| MaterialError {
            material: "metal",
            parameter,
            value: format!("{value:?}"),
            expected,
        };
        let all = |v: Rgb, ok: &dyn Fn(f32) -> bool| (0..3).all(|c| ok(v[c]));
        match fresnel {
            ConductorFresnel::Schlick(f0) => {
                if !all(f0, &|x| (0.0..=1.0).contains(&x)) {
                    return Err(bad("F0", f0, "in [0, 1] per channel"));
                }
            }
            ConductorFresnel::Complex { eta, k } => {
                if !all(eta, &|x| x.is_finite() && x > 0.0) {
                    return Err(bad("eta", eta, "finite and > 0 per channel"));
                }
                if !all(k, &|x| x.is_finite() && x >= 0.0) {
                    return Err(bad("k", k, "finite and >= 0 per channel"));
                }
            }
        }
        Ok(Self {
            fresnel,
            roughness: check_roughness("metal", roughness)?,
        })
    }

    /// The Fresnel model.
    #[must_use]
    pub fn fresnel(&self) -> ConductorFresnel {
        self.fresnel
    }

    /// Perceptual roughness in `[0, 1]`.
    #[must_use]
    pub fn roughness(&self) -> f32 {
        self.roughness
    }
}

impl Material for Metal {
    type Bsdf = RoughConductor;

    #[inline]
    fn bsdf(&self, _ctx: &MaterialContext) -> RoughConductor {
        RoughConductor::new(
            TrowbridgeReitz::isotropic(roughness_to_alpha(self.roughness)),
            self.fresnel,
        )
    }

    fn properties(&self) -> MaterialProperties {
        let smooth =
            TrowbridgeReitz::isotropic(roughness_to_alpha(self.roughness)).effectively_smooth();
        MaterialProperties::new(false, !smooth)
    }
}

/// Glass, water, any dielectric: a [`SmoothDielectric`] at roughness 0 (below the smoothness
/// threshold), a GGX [`RoughDielectric`] above. `eta` is `n_inside / n_outside`, with the
/// outside on the side the surface normal points to (the winding, or the vertex normals).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Glass {
    eta: f32,
    roughness: f32,
    tint: Rgb,
}

impl Glass {
    /// Smooth glass of relative IOR `eta` (1.5 for window glass, 1.33 for water). Fails unless
    /// `eta` is finite and positive.
    pub fn new(eta: f32) -> Result<Self, MaterialError> {
        if !(eta.is_finite() && eta > 0.0) {
            return Err(MaterialError {
                material: "glass",
                parameter: "eta",
                value: eta.to_string(),
                expected: "finite and > 0",
            });
        }
        Ok(Self {
            eta,
            roughness: 0.0,
            tint: Rgb::WHITE,
        })
    }

    /// The same glass with perceptual roughness `roughness` (`alpha = roughness^2`). Fails
    /// outside `[0, 1]`.
    pub fn with_roughness(self, roughness: f32) -> Result<Self, MaterialError> {
        Ok(Self {
            roughness: check_roughness("glass", roughness)?,
            ..self
        })
    }

    /// The same glass with a transmission tint (clamped to `[0, 1]`).
    #[must_use]
    pub fn with_tint(self, tint: Rgb) -> Self {
        Self { tint, ..self }
    }

    /// Relative index of refraction.
    #[must_use]
    pub fn eta(&self) -> f32 {
        self.eta
    }

    /// Perceptual roughness.
    #[must_use]
    pub fn roughness(&self) -> f32 {
        self.roughness
    }

    /// Transmission tint.
    #[must_use]
    pub fn tint(&self) -> Rgb {
        self.tint
    }
}

impl Material for Glass {
    type Bsdf = BuiltinBsdf;

    #[inline]
    fn bsdf(&self, _ctx: &MaterialContext) -> BuiltinBsdf {
        let d = TrowbridgeReitz::isotropic(roughness_to_alpha(self.roughness));
        if d.effectively_smooth() {
            SmoothDielectric::new(self.eta, self.tint).into()
        } else {
            RoughDielectric::new(d, self.eta, self.tint).into()
        }
    }

    fn properties(&self) -> MaterialProperties {
        let smooth =
            TrowbridgeReitz::isotropic(roughness_to_alpha(self.roughness)).effectively_smooth();
        MaterialProperties::new(false, !smooth)
    }
}

/// A metallic-roughness material with optional textures (what glTF and textured OBJ files
/// describe), evaluated at each hit and mapped to the built-in model of its dominant lobe:
/// glass when `transmission >= 0.5`, a Schlick conductor with `F0` = base colour when the
/// (textured) metalness is at least 0.5, else Lambertian with the base colour.
///
/// Textures multiply the factors, as in glTF: the base colour texture (linear RGB, decoded from
/// sRGB by the loader) multiplies `base_color`; the metallic-roughness texture's blue channel
/// multiplies `metallic` and its green channel `roughness`.
#[derive(Clone, Debug, PartialEq)]
pub struct PbrMaterial {
    /// Base colour factor, linear RGB in `[0, 1]`.
    pub base_color: Rgb,
    /// Base colour texture.
    pub base_color_texture: Option<Arc<Texture>>,
    /// Metalness factor in `[0, 1]`.
    pub metallic: f32,
    /// Perceptual roughness factor in `[0, 1]`.
    pub roughness: f32,
    /// Metallic (blue) and roughness (green) texture.
    pub metallic_roughness_texture: Option<Arc<Texture>>,
    /// Transmission factor in `[0, 1]`.
    pub transmission: f32,
    /// Index of refraction for transmission.
    pub ior: f32,
}

impl Default for PbrMaterial {
    /// glTF's default: white, fully rough, not metallic, opaque, IOR 1.5.
    fn default() -> Self {
        Self {
            base_color: Rgb::WHITE,
            base_color_texture: None,
            metallic: 0.0,
            roughness: 1.0,
            metallic_roughness_texture: None,
            transmission: 0.0,
            ior: 1.5,
        }
    }
}

impl Material for PbrMaterial {
    type Bsdf = BuiltinBsdf;

    #[inline]
    fn bsdf(&self, ctx: &MaterialContext) -> BuiltinBsdf {
        let mut base = self.base_color;
        if let Some(t) = &self.base_color_texture {
            base *= t.eval(ctx.uv);
        }
        let (mut metallic, mut roughness) = (self.metallic, self.roughness);
        if let Some(t) = &self.metallic_roughness_texture {
            let c = t.eval(ctx.uv);
            metallic *= c.b;
            roughness *= c.g;
        }
        let alpha = roughness_to_alpha(roughness);
        if self.transmission >= 0.5 {
            let d = TrowbridgeReitz::isotropic(alpha);
            return if d.effectively_smooth() {
                SmoothDielectric::new(self.ior, base).into()
            } else {
                RoughDielectric::new(d, self.ior, base).into()
            };
        }
        if metallic >= 0.5 {
            return RoughConductor::new(
                TrowbridgeReitz::isotropic(alpha),
                ConductorFresnel::Schlick(base),
            )
            .into();
        }
        Lambertian::new(base).into()
    }

    fn properties(&self) -> MaterialProperties {
        let textured =
            self.base_color_texture.is_some() || self.metallic_roughness_texture.is_some();
        // Without a texture the BSDF is the same everywhere: ask it whether it has a non-delta
        // lobe. With one, roughness may vary: claim both.
        let non_delta = textured || {
            let ctx = MaterialContext::new(Vec3::ZERO, Vec3::Z, Vec3::Z, Vec3::Z, Vec2::ZERO);
            self.bsdf(&ctx).flags().is_non_specular()
        };
        MaterialProperties::new(textured, non_delta)
    }
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
        $(#[$meta:meta])*
        $vis:vis enum $name:ident -> $bsdf:ty {
            $( $(#[$vmeta:meta])* $variant:ident($ty:ty) ),+ $(,)?
        }
    ) => {
        $(#[$meta])*
        $vis enum $name {
            $( $(#[$vmeta])* #[allow(missing_docs)] $variant($ty), )+
        }

        impl $name {
            /// The names of the variants, in the order they are declared (for registries and
            /// tests that must cover every model).
            #[allow(dead_code)]
            $vis const VARIANTS: &'static [&'static str] = &[$(stringify!($variant)),+];

            /// The name of this value's variant, one of [`Self::VARIANTS`].
            #[allow(dead_code)]
            #[must_use]
            $vis fn variant_name(&self) -> &'static str {
                match self { $( Self::$variant(_) => stringify!($variant), )+ }
            }
        }

        impl $crate::material::Material for $name {
            type Bsdf = $bsdf;
            #[inline]
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
    /// The materials that ship with pt.
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
    use crate::bsdf::BsdfFlags;

    fn ctx() -> MaterialContext {
        MaterialContext {
            uv: Vec2::ZERO,
            p: Vec3::ZERO,
            n: Vec3::Z,
            ns: Vec3::Z,
            wo: Vec3::Z,
        }
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
