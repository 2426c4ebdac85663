//! Materials: what a surface is made of, turned into a BSDF at each hit.
//!
//! A [`Material`] maps the local surface context (texture coordinates, normals) to a BSDF value
//! on the stack: no heap allocation per hit. [`BuiltinMaterial`] is a closed enum; users extend it
//! with [`material_enum!`](crate::material_enum).

use glam::{Vec2, Vec3};

use crate::bsdf::{Bsdf, BuiltinBsdf, Lambertian};
use crate::color::Rgb;

/// The surface context a material is evaluated at.
#[derive(Clone, Copy, Debug, PartialEq)]
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

/// Turns a surface context into a BSDF.
pub trait Material: Send + Sync {
    /// The BSDF type this material produces.
    type Bsdf: Bsdf;

    /// The BSDF at a surface point.
    fn bsdf(&self, ctx: &MaterialContext) -> Self::Bsdf;
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

        impl $crate::material::Material for $name {
            type Bsdf = $bsdf;
            #[inline]
            fn bsdf(&self, ctx: &$crate::material::MaterialContext) -> $bsdf {
                match self {
                    $( Self::$variant(m) => <$bsdf>::from($crate::material::Material::bsdf(m, ctx)), )+
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
    }
}

impl BuiltinMaterial {
    /// A matte material with the given albedo.
    #[must_use]
    pub fn diffuse(reflectance: Rgb) -> Self {
        Diffuse::new(reflectance).into()
    }
}
