//! The metallic-roughness material of glTF and textured OBJ files.

use glam::{Vec2, Vec3};

use crate::bsdf::microfacet::roughness_to_alpha;
use crate::bsdf::{
    Bsdf, BuiltinBsdf, ConductorFresnel, Lambertian, MetallicRoughness, RoughConductor,
    RoughDielectric, SmoothDielectric, ThinFilm, TrowbridgeReitz,
};
use crate::color::Rgb;
use crate::material::{Material, MaterialContext, MaterialProperties};
use crate::texture::TextureMap;

/// A metallic-roughness material with optional textures (what glTF and textured OBJ files
/// describe), evaluated at each hit. Glass when `transmission >= 0.5`; otherwise, when
/// `layered` (glTF), glTF's metallic-roughness BSDF ([`MetallicRoughness`]: a Schlick metal
/// with `F0` = base colour and a Fresnel-layered dielectric, mixed by the textured metalness),
/// and when not (textured OBJ materials, whose Phong parameters describe no layering) the model
/// of the dominant lobe: a Schlick conductor with `F0` = base colour when the textured metalness
/// is at least 0.5, else Lambertian with the base colour.
///
/// Textures multiply the factors, as in glTF: the base colour texture (linear RGB, decoded from
/// sRGB by the loader) and, with `vertex_colors`, the interpolated vertex colour multiply
/// `base_color`; the metallic-roughness texture's blue channel multiplies `metallic` and its
/// green channel `roughness`. A normal map (tangent-space, `+y` along the bitangent, as in glTF)
/// replaces the shading normal through [`Material::shading_normal`] on meshes with tangents.
#[derive(Clone, Debug, PartialEq)]
pub struct PbrMaterial {
    /// Base colour factor, linear RGB in `[0, 1]`.
    pub base_color: Rgb,
    /// Base colour texture.
    pub base_color_texture: Option<TextureMap>,
    /// Multiply the base colour by the mesh's vertex colour (glTF's `COLOR_0`).
    pub vertex_colors: bool,
    /// Metalness factor in `[0, 1]`.
    pub metallic: f32,
    /// Perceptual roughness factor in `[0, 1]`.
    pub roughness: f32,
    /// Metallic (blue) and roughness (green) texture.
    pub metallic_roughness_texture: Option<TextureMap>,
    /// Tangent-space normal map (linear, `2 * value - 1` per channel).
    pub normal_texture: Option<TextureMap>,
    /// Scales the normal map's `x` and `y` (glTF's `normalTexture.scale`).
    pub normal_scale: f32,
    /// Transmission factor in `[0, 1]`.
    pub transmission: f32,
    /// `transmissionTexture` (red channel), multiplying `transmission` at each hit.
    pub transmission_texture: Option<TextureMap>,
    /// Index of refraction for transmission and for the dielectric layer's Fresnel term.
    pub ior: f32,
    /// glTF's layered BSDF (`true`, the default) or the dominant lobe's model (`false`).
    pub layered: bool,
    /// Base colour alpha factor in `[0, 1]` (glTF's `baseColorFactor[3]`).
    pub alpha: f32,
    /// How alpha (the factor times the base colour texture's and, with `vertex_colors`, the
    /// vertex colour's alpha) makes the surface transparent.
    pub alpha_mode: AlphaMode,
    /// Both faces are seen (`true`, the default); `false` makes back faces invisible
    /// ([`Material::single_sided`]).
    pub double_sided: bool,
    /// Absorption coefficient per unit length of the medium inside, for transmissive
    /// materials (`transmission >= 0.5`): [`Material::absorption`]. `Rgb::BLACK`, the
    /// default, absorbs nothing. From glTF's `KHR_materials_volume`:
    /// [`PbrMaterial::absorption_from`].
    pub absorption: Rgb,
    /// The dielectric's specular strength (`KHR_materials_specular`'s `specularFactor`,
    /// default 1), multiplied by the alpha of `specular_texture`.
    pub specular: f32,
    /// The dielectric's `F0` tint (`specularColorFactor`, default white, may exceed 1),
    /// multiplied by `specular_color_texture`.
    pub specular_color: Rgb,
    /// `specularTexture` (its alpha channel).
    pub specular_texture: Option<TextureMap>,
    /// `specularColorTexture` (RGB).
    pub specular_color_texture: Option<TextureMap>,
    /// Clearcoat weight (`KHR_materials_clearcoat`'s `clearcoatFactor`, default 0),
    /// multiplied by the red channel of `clearcoat_texture`.
    pub clearcoat: f32,
    /// The coat's perceptual roughness, multiplied by the green channel of
    /// `clearcoat_roughness_texture`.
    pub clearcoat_roughness: f32,
    /// `clearcoatTexture` (red channel).
    pub clearcoat_texture: Option<TextureMap>,
    /// `clearcoatRoughnessTexture` (green channel).
    pub clearcoat_roughness_texture: Option<TextureMap>,
    /// `clearcoatNormalTexture`: the coat's own tangent-space normal map (like
    /// `normal_texture`, around the vertex normal). Without it the coat follows the vertex
    /// normal, not the base's normal map, as the extension specifies.
    pub clearcoat_normal_texture: Option<TextureMap>,
    /// The scale of `clearcoat_normal_texture`'s `x` and `y` (`clearcoatNormalTexture.scale`).
    pub clearcoat_normal_scale: f32,
    /// Thin-film iridescence weight (`KHR_materials_iridescence`'s `iridescenceFactor`,
    /// default 0: none), multiplied by the red channel of `iridescence_texture`.
    pub iridescence: f32,
    /// The film's index of refraction (`iridescenceIor`, default 1.3).
    pub iridescence_ior: f32,
    /// The film's thickness range in nanometres (`iridescenceThicknessMinimum` and
    /// `Maximum`, default 100 and 400): the thickness texture's green channel picks within
    /// it; without the texture the film is the maximum thick.
    pub iridescence_thickness: (f32, f32),
    /// `iridescenceTexture` (red channel).
    pub iridescence_texture: Option<TextureMap>,
    /// `iridescenceThicknessTexture` (green channel).
    pub iridescence_thickness_texture: Option<TextureMap>,
    /// Sheen colour (`KHR_materials_sheen`'s `sheenColorFactor`, default black: no sheen),
    /// multiplied by `sheen_color_texture`.
    pub sheen_color: Rgb,
    /// Sheen roughness, multiplied by the alpha channel of `sheen_roughness_texture`.
    pub sheen_roughness: f32,
    /// `sheenColorTexture` (RGB).
    pub sheen_color_texture: Option<TextureMap>,
    /// `sheenRoughnessTexture` (its alpha channel).
    pub sheen_roughness_texture: Option<TextureMap>,
    /// Anisotropy strength in `[0, 1]` (`KHR_materials_anisotropy`'s `anisotropyStrength`,
    /// default 0: isotropic), multiplied by the blue channel of `anisotropy_texture`. Needs
    /// the mesh's tangents; without them the surface stays isotropic.
    pub anisotropy_strength: f32,
    /// Rotation (radians, counter-clockwise) of the anisotropy direction from the tangent,
    /// in tangent space (`anisotropyRotation`).
    pub anisotropy_rotation: f32,
    /// `anisotropyTexture`: red and green the direction in tangent space (`2 value - 1`),
    /// blue the strength.
    pub anisotropy_texture: Option<TextureMap>,
}

/// How a material's alpha makes its surface transparent (glTF's `alphaMode`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum AlphaMode {
    /// Alpha is ignored: the surface is opaque.
    #[default]
    Opaque,
    /// Opaque where alpha is at least the cutoff, absent elsewhere (glTF's `alphaCutoff`,
    /// default 0.5).
    Mask(f32),
    /// Alpha is coverage: rays stop with probability alpha and pass through otherwise
    /// (stochastic transparency, which converges to blending the surface over what is behind).
    Blend,
}

impl Default for PbrMaterial {
    /// glTF's default: white, fully rough, not metallic, opaque, IOR 1.5.
    fn default() -> Self {
        Self {
            base_color: Rgb::WHITE,
            base_color_texture: None,
            vertex_colors: false,
            metallic: 0.0,
            roughness: 1.0,
            metallic_roughness_texture: None,
            normal_texture: None,
            normal_scale: 1.0,
            transmission: 0.0,
            transmission_texture: None,
            ior: 1.5,
            layered: true,
            alpha: 1.0,
            alpha_mode: AlphaMode::Opaque,
            double_sided: true,
            absorption: Rgb::BLACK,
            specular: 1.0,
            specular_color: Rgb::WHITE,
            specular_texture: None,
            specular_color_texture: None,
            clearcoat: 0.0,
            clearcoat_roughness: 0.0,
            clearcoat_texture: None,
            clearcoat_roughness_texture: None,
            clearcoat_normal_texture: None,
            clearcoat_normal_scale: 1.0,
            iridescence: 0.0,
            iridescence_ior: 1.3,
            iridescence_thickness: (100.0, 400.0),
            iridescence_texture: None,
            iridescence_thickness_texture: None,
            sheen_color: Rgb::BLACK,
            sheen_roughness: 0.0,
            sheen_color_texture: None,
            sheen_roughness_texture: None,
            anisotropy_strength: 0.0,
            anisotropy_rotation: 0.0,
            anisotropy_texture: None,
        }
    }
}

impl PbrMaterial {
    /// `m` made anisotropic as `KHR_materials_anisotropy` says at `ctx`: the direction from
    /// the tangent frame (rotation, texture), expressed in the shading frame the renderer
    /// builds around `ctx.ns` ([`Frame::from_z`](crate::Frame::from_z)).
    fn anisotropic(&self, m: MetallicRoughness, ctx: &MaterialContext) -> MetallicRoughness {
        let t = ctx.attributes.tangent;
        if t.w == 0.0 {
            return m;
        }
        let mut strength = self.anisotropy_strength;
        let mut dir = Vec2::X;
        if let Some(tex) = &self.anisotropy_texture {
            let c = tex.eval(ctx);
            dir = Vec2::new(2.0 * c.r - 1.0, 2.0 * c.g - 1.0).normalize_or(Vec2::X);
            strength *= c.b;
        }
        let (sin, cos) = self.anisotropy_rotation.sin_cos();
        let dir = Vec2::new(cos * dir.x - sin * dir.y, sin * dir.x + cos * dir.y);
        let n = ctx.ns;
        let tangent = (t.truncate() - n * n.dot(t.truncate())).normalize_or_zero();
        if tangent == Vec3::ZERO {
            return m;
        }
        let bitangent = n.cross(tangent) * t.w.signum();
        let world = tangent * dir.x + bitangent * dir.y;
        let local = crate::Frame::from_z(n).to_local(world);
        m.with_anisotropy(strength, Vec2::new(local.x, local.y))
    }

    /// The iridescence film's weight and thickness (nanometres) at `ctx`, from the factors
    /// and their textures.
    fn film_at(&self, ctx: &MaterialContext) -> (f32, f32) {
        let mut weight = self.iridescence;
        if let Some(t) = &self.iridescence_texture {
            weight *= t.eval(ctx).r;
        }
        let (lo, hi) = self.iridescence_thickness;
        let thickness = match &self.iridescence_thickness_texture {
            Some(t) => lo + (hi - lo) * t.eval(ctx).g,
            None => hi,
        };
        (weight, thickness)
    }

    /// The absorption coefficient that makes light keep `color` (per channel, in `(0, 1]`)
    /// after `distance` inside the medium: `-ln(color) / distance` (glTF's
    /// `attenuationColor` and `attenuationDistance`). Black for an infinite or non-positive
    /// distance; a channel of 0 absorbs everything (a large coefficient).
    #[must_use]
    pub fn absorption_from(color: Rgb, distance: f32) -> Rgb {
        if !(distance.is_finite() && distance > 0.0) {
            return Rgb::BLACK;
        }
        color.map(|c| {
            let c = if c.is_nan() { 1.0 } else { c.clamp(1e-30, 1.0) };
            -c.ln() / distance
        })
    }
}

/// The world normal a tangent-space normal `map` (scaled by `scale` in `x` and `y`) gives at
/// `ctx`, around the vertex normal and the tangent frame; `None` without tangents.
fn perturbed_normal(map: &TextureMap, scale: f32, ctx: &MaterialContext) -> Option<Vec3> {
    let t = ctx.attributes.tangent;
    if t.w == 0.0 {
        return None;
    }
    let c = map.eval(ctx);
    let (x, y, z) = (
        (2.0 * c.r - 1.0) * scale,
        (2.0 * c.g - 1.0) * scale,
        2.0 * c.b - 1.0,
    );
    let n0 = ctx.vertex_normal;
    let tangent = t.truncate();
    let bitangent = t.w * n0.cross(tangent);
    let n = (tangent * x + bitangent * y + n0 * z).normalize_or_zero();
    (n != Vec3::ZERO && n.is_finite()).then_some(n)
}

impl Material for PbrMaterial {
    type Bsdf = BuiltinBsdf;

    #[inline]
    fn bsdf(&self, ctx: &MaterialContext) -> BuiltinBsdf {
        let mut base = self.base_color;
        if let Some(t) = &self.base_color_texture {
            base *= t.eval(ctx);
        }
        if self.vertex_colors {
            let c = ctx.attributes.color;
            base *= Rgb::new(c.x, c.y, c.z);
        }
        let (mut metallic, mut roughness) = (self.metallic, self.roughness);
        if let Some(t) = &self.metallic_roughness_texture {
            let c = t.eval(ctx);
            metallic *= c.b;
            roughness *= c.g;
        }
        let unit = |v: f32| if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
        let (base, metallic, roughness) = (base.map(unit), unit(metallic), unit(roughness));
        let alpha = roughness_to_alpha(roughness);
        let mut transmission = self.transmission;
        if let Some(t) = &self.transmission_texture {
            transmission *= t.eval(ctx).r;
        }
        if transmission >= 0.5 {
            let d = TrowbridgeReitz::isotropic(alpha);
            let film = (self.layered && self.iridescence > 0.0).then(|| {
                let (weight, thickness) = self.film_at(ctx);
                ThinFilm::new(weight, self.iridescence_ior, thickness)
            });
            return match (d.effectively_smooth(), film) {
                (true, None) => SmoothDielectric::new(self.ior, base).into(),
                (true, Some(f)) => SmoothDielectric::new(self.ior, base).with_film(f).into(),
                (false, None) => RoughDielectric::new(d, self.ior, base).into(),
                (false, Some(f)) => RoughDielectric::new(d, self.ior, base).with_film(f).into(),
            };
        }
        if self.layered {
            let mut m = MetallicRoughness::new(base, metallic, roughness, self.ior);
            let (mut specular, mut color) = (self.specular, self.specular_color);
            if let Some(t) = &self.specular_texture {
                specular *= t.eval_alpha(ctx);
            }
            if let Some(t) = &self.specular_color_texture {
                color *= t.eval(ctx);
            }
            if specular != 1.0 || color != Rgb::WHITE {
                m = m.with_specular(specular, color);
            }
            let (mut coat, mut coat_roughness) = (self.clearcoat, self.clearcoat_roughness);
            if let Some(t) = &self.clearcoat_texture {
                coat *= t.eval(ctx).r;
            }
            if let Some(t) = &self.clearcoat_roughness_texture {
                coat_roughness *= t.eval(ctx).g;
            }
            if coat > 0.0 {
                m = m.with_clearcoat(coat, coat_roughness);
                // The coat's normal: its own map's, else the vertex normal (the base's map
                // does not bend it), in the frame the renderer builds around `ctx.ns`.
                let cn = match &self.clearcoat_normal_texture {
                    Some(map) => perturbed_normal(map, self.clearcoat_normal_scale, ctx),
                    None => None,
                }
                .unwrap_or(ctx.vertex_normal);
                if cn != ctx.ns {
                    m = m.with_coat_normal(crate::Frame::from_z(ctx.ns).to_local(cn));
                }
            }
            if self.iridescence > 0.0 {
                let (weight, thickness) = self.film_at(ctx);
                m = m.with_iridescence(weight, self.iridescence_ior, thickness);
            }
            if !self.sheen_color.is_black() {
                let mut color = self.sheen_color;
                let mut r = self.sheen_roughness;
                if let Some(t) = &self.sheen_color_texture {
                    color *= t.eval(ctx);
                }
                if let Some(t) = &self.sheen_roughness_texture {
                    r *= t.eval_alpha(ctx);
                }
                m = m.with_sheen(color, r);
            }
            if self.anisotropy_strength > 0.0 {
                m = self.anisotropic(m, ctx);
            }
            m.into()
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

    fn shading_normal(&self, ctx: &MaterialContext) -> Option<Vec3> {
        perturbed_normal(self.normal_texture.as_ref()?, self.normal_scale, ctx)
    }

    fn properties(&self) -> MaterialProperties {
        let maps = [
            &self.base_color_texture,
            &self.metallic_roughness_texture,
            &self.normal_texture,
            &self.specular_texture,
            &self.specular_color_texture,
            &self.clearcoat_texture,
            &self.clearcoat_roughness_texture,
            &self.clearcoat_normal_texture,
            &self.anisotropy_texture,
            &self.sheen_color_texture,
            &self.sheen_roughness_texture,
            &self.iridescence_texture,
            &self.iridescence_thickness_texture,
            &self.transmission_texture,
        ];
        let textured = maps.iter().any(|m| m.is_some());
        // Without a texture the BSDF is the same everywhere: ask it whether it has a non-delta
        // lobe. With one, roughness may vary: claim both.
        let non_delta = textured || {
            let ctx = MaterialContext::new(Vec3::ZERO, Vec3::Z, Vec3::Z, Vec3::Z, Vec2::ZERO);
            self.bsdf(&ctx).flags().is_non_specular()
        };
        let mut p = MaterialProperties::new(textured, non_delta);
        let other_sets = maps
            .iter()
            .flat_map(|m| m.as_ref())
            .any(|m| m.reads_attributes());
        if self.vertex_colors
            || self.normal_texture.is_some()
            || self.clearcoat_normal_texture.is_some()
            || self.anisotropy_strength > 0.0
            || other_sets
        {
            p = p.with_attributes();
        }
        if self.normal_texture.is_some() {
            p = p.with_normal_map();
        }
        if self.alpha_mode != AlphaMode::Opaque {
            p = p.with_coverage();
        }
        p
    }

    #[inline]
    fn coverage(&self, ctx: &MaterialContext) -> f32 {
        if self.alpha_mode == AlphaMode::Opaque {
            return 1.0;
        }
        let mut a = self.alpha;
        if let Some(t) = &self.base_color_texture {
            a *= t.eval_alpha(ctx);
        }
        if self.vertex_colors {
            a *= ctx.attributes.color.w;
        }
        match self.alpha_mode {
            AlphaMode::Mask(cutoff) => {
                if a >= cutoff {
                    1.0
                } else {
                    0.0
                }
            }
            _ => a.clamp(0.0, 1.0),
        }
    }

    fn absorption(&self) -> Option<Rgb> {
        (self.transmission >= 0.5
            && self.absorption.is_valid_nonnegative()
            && !self.absorption.is_black())
        .then_some(self.absorption)
    }

    fn single_sided(&self) -> bool {
        !self.double_sided
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use glam::Vec4;

    use super::*;
    use crate::image::Image;
    use crate::texture::Texture;

    fn constant(c: Rgb) -> TextureMap {
        let mut img = Image::new(1, 1);
        img.set(0, 0, c);
        TextureMap::new(Arc::new(Texture::new(img)))
    }

    #[test]
    fn the_transmission_texture_decides_glass_per_hit() {
        let ctx = MaterialContext::new(Vec3::ZERO, Vec3::Z, Vec3::Z, Vec3::Z, Vec2::ZERO);
        for (red, glass) in [(0.2, false), (0.9, true)] {
            let m = PbrMaterial {
                transmission: 1.0,
                transmission_texture: Some(constant(Rgb::new(red, 0.0, 0.0))),
                ..PbrMaterial::default()
            };
            let flags = m.bsdf(&ctx).flags();
            assert_eq!(flags.is_transmissive(), glass, "red {red}");
        }
    }

    #[test]
    fn sheen_adds_a_rim_to_a_black_surface() {
        let ctx = MaterialContext::new(Vec3::ZERO, Vec3::Z, Vec3::Z, Vec3::Z, Vec2::ZERO);
        let black = PbrMaterial {
            base_color: Rgb::BLACK,
            specular: 0.0,
            ..PbrMaterial::default()
        };
        let sheen = PbrMaterial {
            sheen_color: Rgb::new(1.0, 0.5, 0.0),
            sheen_roughness: 0.3,
            ..black.clone()
        };
        // Grazing view and light from the same side (a grazing half-vector): sheen reflects
        // most there.
        let wo = Vec3::new(0.95, 0.0, 0.31).normalize();
        let wi = wo;
        let mode = crate::bsdf::TransportMode::Radiance;
        assert!(black.bsdf(&ctx).eval(wo, wi, mode).is_black());
        let f = sheen.bsdf(&ctx).eval(wo, wi, mode);
        assert!(
            f.r > 0.1 && (f.g - 0.5 * f.r).abs() < 1e-4 * f.r && f.b == 0.0,
            "{f:?}"
        );
    }

    #[test]
    fn anisotropy_stretches_the_highlight_along_the_rotated_tangent() {
        let mut ctx = MaterialContext::new(Vec3::ZERO, Vec3::Z, Vec3::Z, Vec3::Z, Vec2::ZERO);
        ctx.attributes.tangent = Vec4::new(1.0, 0.0, 0.0, 1.0);
        let tilt = |axis: Vec3| (Vec3::Z + axis * 0.8).normalize();
        // Reflection toward a direction tilted along `axis`, seen from straight above.
        let f = |m: &PbrMaterial, axis: Vec3, ctx: &MaterialContext| {
            let bsdf = m.bsdf(ctx);
            let frame = crate::Frame::from_z(Vec3::Z);
            bsdf.eval(
                Vec3::Z,
                frame.to_local(tilt(axis)),
                crate::bsdf::TransportMode::Radiance,
            )
            .g
        };
        let iso = PbrMaterial {
            metallic: 1.0,
            roughness: 0.3,
            ..PbrMaterial::default()
        };
        let aniso = PbrMaterial {
            anisotropy_strength: 0.8,
            ..iso.clone()
        };
        let (along, across) = (f(&aniso, Vec3::X, &ctx), f(&aniso, Vec3::Y, &ctx));
        assert!(
            (f(&iso, Vec3::X, &ctx) - f(&iso, Vec3::Y, &ctx)).abs() < 1e-4 * f(&iso, Vec3::X, &ctx),
            "isotropic"
        );
        assert!(along > 5.0 * across, "{along} {across}");
        // Rotated a quarter turn, the stretch follows the bitangent.
        let turned = PbrMaterial {
            anisotropy_rotation: std::f32::consts::FRAC_PI_2,
            ..aniso.clone()
        };
        assert!(f(&turned, Vec3::Y, &ctx) > 5.0 * f(&turned, Vec3::X, &ctx));
        // Without a tangent the surface stays isotropic.
        ctx.attributes.tangent = Vec4::ZERO;
        let (x, y) = (f(&aniso, Vec3::X, &ctx), f(&aniso, Vec3::Y, &ctx));
        assert!((x - y).abs() < 1e-4 * x);
    }

    #[test]
    fn normal_maps_tilt_the_shading_normal_in_the_tangent_frame() {
        // A texel tilting the normal 45 degrees toward +x of tangent space.
        let tilt = Vec3::new(1.0, 0.0, 1.0).normalize();
        let texel = (tilt + Vec3::ONE) * 0.5;
        let m = PbrMaterial {
            normal_texture: Some(constant(Rgb::new(texel.x, texel.y, texel.z))),
            ..PbrMaterial::default()
        };
        let p = m.properties();
        assert!(p.normal_map && p.reads_attributes && p.reads_uv);
        let mut ctx = MaterialContext::new(Vec3::ZERO, Vec3::Z, Vec3::Z, Vec3::Z, Vec2::ZERO);
        // No tangent: no normal mapping.
        assert_eq!(m.shading_normal(&ctx), None);
        // Tangent along +y: tangent-space +x is world +y.
        ctx.attributes.tangent = Vec4::new(0.0, 1.0, 0.0, 1.0);
        let n = m.shading_normal(&ctx).unwrap();
        assert!(
            (n - Vec3::new(0.0, 1.0, 1.0).normalize()).length() < 1e-2,
            "{n}"
        );
        // Tangent-space +y is the bitangent w * (n x t): with w = -1, world +x.
        let m = PbrMaterial {
            normal_texture: Some(constant(Rgb::new(0.5, texel.x, texel.z))),
            ..PbrMaterial::default()
        };
        ctx.attributes.tangent = Vec4::new(0.0, 1.0, 0.0, -1.0);
        let n = m.shading_normal(&ctx).unwrap();
        assert!(
            (n - Vec3::new(1.0, 0.0, 1.0).normalize()).length() < 1e-2,
            "{n}"
        );
        // Scale 0 flattens the map.
        let flat = PbrMaterial {
            normal_scale: 0.0,
            ..m
        };
        assert!((flat.shading_normal(&ctx).unwrap() - Vec3::Z).length() < 1e-6);
    }

    /// glTF's coat is not bent by the base's normal map: under a map tilting the base 45
    /// degrees, the coat's sharp reflection stays about the vertex normal; with a coat map of
    /// its own it follows that map instead.
    #[test]
    fn the_coat_keeps_the_vertex_normal_or_its_own_map() {
        let tilt = Vec3::new(1.0, 0.0, 1.0).normalize();
        let texel = (tilt + Vec3::ONE) * 0.5;
        let tilted_map = constant(Rgb::new(texel.x, texel.y, texel.z));
        let flat_map = constant(Rgb::new(0.5, 0.5, 1.0));
        let base_mapped = PbrMaterial {
            base_color: Rgb::BLACK,
            metallic: 0.0,
            roughness: 1.0,
            clearcoat: 1.0,
            clearcoat_roughness: 0.05,
            normal_texture: Some(tilted_map.clone()),
            ..PbrMaterial::default()
        };
        assert!(base_mapped.properties().normal_map);
        let mut ctx = MaterialContext::new(Vec3::ZERO, Vec3::Z, Vec3::Z, Vec3::Z, Vec2::ZERO);
        ctx.attributes.tangent = Vec4::new(1.0, 0.0, 0.0, 1.0);
        // What the integrator does: the map's normal becomes the shading normal.
        let mapped = base_mapped.shading_normal(&ctx).unwrap();
        assert!((mapped - tilt).length() < 1e-2, "{mapped}");
        let mut shaded = ctx;
        shaded.ns = mapped;
        // Seen from above, the reflection about the vertex normal (straight back up) and about
        // the mapped normal, in the shading frame.
        let frame = crate::Frame::from_z(mapped);
        let mirror = |n: Vec3| 2.0 * n.dot(Vec3::Z) * n - Vec3::Z;
        let f = |m: &PbrMaterial, ctx: &MaterialContext, wi: Vec3| {
            m.bsdf(ctx)
                .eval(
                    frame.to_local(Vec3::Z),
                    frame.to_local(wi),
                    crate::bsdf::TransportMode::Radiance,
                )
                .g
        };
        let (about_vertex, about_map) = (
            f(&base_mapped, &shaded, mirror(Vec3::Z)),
            f(&base_mapped, &shaded, mirror(mapped)),
        );
        assert!(
            about_vertex > 100.0 * about_map,
            "{about_vertex} {about_map}"
        );
        // A flat coat map: the same as none.
        let flat_coat = PbrMaterial {
            clearcoat_normal_texture: Some(flat_map),
            ..base_mapped.clone()
        };
        let p = flat_coat.properties();
        assert!(p.reads_attributes);
        let g = f(&flat_coat, &shaded, mirror(Vec3::Z));
        assert!(
            (g - about_vertex).abs() < 1e-2 * about_vertex,
            "{g} {about_vertex}"
        );
        // The coat's own map tilting 20 degrees, the base unmapped: the coat's peak follows
        // the map.
        let tilt = Vec3::new(0.342, 0.0, 0.94).normalize();
        let texel = (tilt + Vec3::ONE) * 0.5;
        let coat_mapped = PbrMaterial {
            normal_texture: None,
            clearcoat_normal_texture: Some(constant(Rgb::new(texel.x, texel.y, texel.z))),
            ..base_mapped
        };
        assert!(!coat_mapped.properties().normal_map && coat_mapped.properties().reads_attributes);
        let frame_flat = crate::Frame::from_z(Vec3::Z);
        let f_flat = |wi: Vec3| {
            coat_mapped
                .bsdf(&ctx)
                .eval(
                    frame_flat.to_local(Vec3::Z),
                    frame_flat.to_local(wi),
                    crate::bsdf::TransportMode::Radiance,
                )
                .g
        };
        let (about_map, about_vertex) = (f_flat(mirror(tilt)), f_flat(mirror(Vec3::Z)));
        assert!(
            about_map > 100.0 * about_vertex,
            "{about_map} {about_vertex}"
        );
    }

    #[test]
    fn vertex_colours_multiply_the_base_colour() {
        let m = PbrMaterial {
            base_color: Rgb::splat(0.5),
            vertex_colors: true,
            metallic: 0.0,
            ..PbrMaterial::default()
        };
        assert!(m.properties().reads_attributes && !m.properties().normal_map);
        let mut ctx = MaterialContext::new(Vec3::ZERO, Vec3::Z, Vec3::Z, Vec3::Z, Vec2::ZERO);
        ctx.attributes.color = Vec4::new(1.0, 0.0, 0.0, 1.0);
        let wo = Vec3::new(0.0, 0.0, 1.0);
        let wi = Vec3::new(0.3, 0.0, 1.0).normalize();
        let f = m
            .bsdf(&ctx)
            .eval(wo, wi, crate::bsdf::TransportMode::Radiance);
        // Green and blue keep only the (white) specular coating; red has the diffuse base too.
        assert!(f.r > 2.0 * f.g && (f.g - f.b).abs() < 1e-6, "{f:?}");
        let plain = PbrMaterial {
            vertex_colors: false,
            ..m
        };
        assert!(!plain.properties().reads_attributes);
    }
}
