//! The metallic-roughness material of glTF and textured OBJ files.

use std::sync::Arc;

use glam::{Vec2, Vec3};

use crate::bsdf::microfacet::roughness_to_alpha;
use crate::bsdf::{
    Bsdf, BuiltinBsdf, ConductorFresnel, Lambertian, MetallicRoughness, RoughConductor,
    RoughDielectric, SmoothDielectric, TrowbridgeReitz,
};
use crate::color::Rgb;
use crate::material::{Material, MaterialContext, MaterialProperties};
use crate::texture::Texture;

/// A metallic-roughness material with optional textures (what glTF and textured OBJ files
/// describe), evaluated at each hit. Glass when `transmission >= 0.5`; otherwise, when
/// `layered` (glTF), glTF's metallic-roughness BSDF ([`MetallicRoughness`]: a Schlick metal
/// with `F0` = base colour and a Fresnel-layered dielectric, mixed by the textured metalness),
/// and when not (textured OBJ materials, whose Phong parameters describe no layering) the model
/// of the dominant lobe: a Schlick conductor with `F0` = base colour when the textured metalness
/// is at least 0.5, else Lambertian with the base colour.
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
    /// Index of refraction for transmission and for the dielectric layer's Fresnel term.
    pub ior: f32,
    /// glTF's layered BSDF (`true`, the default) or the dominant lobe's model (`false`).
    pub layered: bool,
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
            layered: true,
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
        if self.layered {
            MetallicRoughness::new(base, metallic, roughness, self.ior).into()
        } else if metallic >= 0.5 {
            RoughConductor::new(
                TrowbridgeReitz::isotropic(alpha),
                ConductorFresnel::Schlick(base),
            )
            .into()
        } else {
            Lambertian::new(base).into()
        }
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
