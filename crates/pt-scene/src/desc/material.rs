//! Materials by their physical parameters, and how they map to pt's built-in models.

use std::sync::Arc;

use pt_core::glam::Affine2;
use pt_core::{
    AlphaMode, BuiltinMaterial, ConductorFresnel, Diffuse, Glass, Metal, Mirror, PbrMaterial, Rgb,
    Texture, TextureMap,
};

/// A texture as a material uses it: an index into [`SceneDesc::textures`](crate::SceneDesc::textures),
/// the texture-coordinate set and a transform of the coordinates (glTF's `texCoord` and
/// `KHR_texture_transform`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TextureRef {
    /// Index into [`SceneDesc::textures`](crate::SceneDesc::textures).
    pub index: usize,
    /// Texture-coordinate set (0 for `TEXCOORD_0`).
    pub uv_set: usize,
    /// Applied to the coordinates before the lookup.
    pub transform: Affine2,
}

impl From<usize> for TextureRef {
    /// The texture at `index`, on coordinate set 0, untransformed.
    fn from(index: usize) -> Self {
        Self {
            index,
            uv_set: 0,
            transform: Affine2::IDENTITY,
        }
    }
}

impl TextureRef {
    /// The map this reference makes with `textures`, if its index is in range.
    #[must_use]
    pub fn resolve(&self, textures: &[Arc<Texture>]) -> Option<TextureMap> {
        let t = textures.get(self.index)?;
        Some(
            TextureMap::new(t.clone())
                .with_uv_set(self.uv_set)
                .with_transform(self.transform),
        )
    }
}

/// A material by its physical parameters (glTF metallic-roughness, extended).
#[derive(Clone, Debug, PartialEq)]
pub struct MaterialDesc {
    /// Name for messages.
    pub name: String,
    /// Diffuse or metal colour, linear RGB.
    pub base_color: Rgb,
    /// 0 dielectric, 1 metal.
    pub metallic: f32,
    /// Perceptual roughness in `[0, 1]`.
    pub roughness: f32,
    /// Emitted radiance (emissive factor times strength), linear RGB.
    pub emission: Rgb,
    /// Whether emission goes out of both faces.
    pub two_sided_emission: bool,
    /// 0 opaque, 1 fully transmissive.
    pub transmission: f32,
    /// Transmission texture (red channel, glTF's `transmissionTexture`).
    pub transmission_texture: Option<TextureRef>,
    /// Index of refraction (glTF default 1.5).
    pub ior: f32,
    /// An ideal mirror with this reflectance (OBJ `illum 3` and `5`), if any.
    pub mirror: Option<Rgb>,
    /// The base colour texture (linear RGB).
    pub base_color_texture: Option<TextureRef>,
    /// The metallic (blue) and roughness (green) texture.
    pub metallic_roughness_texture: Option<TextureRef>,
    /// The emissive texture (linear RGB), which multiplies `emission` where rays hit and light
    /// samples land (see [`pt_core::Emission::texture`]).
    pub emissive_texture: Option<TextureRef>,
    /// The tangent-space normal map.
    pub normal_texture: Option<TextureRef>,
    /// Scale of the normal map's `x` and `y` (glTF's `normalTexture.scale`, default 1).
    pub normal_scale: f32,
    /// Base colour alpha factor (glTF's `baseColorFactor[3]`, default 1).
    pub alpha: f32,
    /// How alpha makes the surface transparent (glTF's `alphaMode` and `alphaCutoff`).
    pub alpha_mode: AlphaMode,
    /// Both faces are seen (default `true`; glTF's `doubleSided`, whose default is `false`).
    /// Single-sided surfaces are invisible from behind, unless they transmit light (glass
    /// needs its back faces).
    pub double_sided: bool,
    /// The colour light keeps after `attenuation_distance` inside a transmissive material
    /// (glTF's `KHR_materials_volume`; default white, no absorption).
    pub attenuation_color: Rgb,
    /// The distance over which light inside becomes `attenuation_color` (default infinite).
    pub attenuation_distance: f32,
    /// The dielectric's specular strength (`KHR_materials_specular`, default 1).
    pub specular: f32,
    /// The dielectric's `F0` tint (`KHR_materials_specular`, default white).
    pub specular_color: Rgb,
    /// Specular strength texture (alpha channel).
    pub specular_texture: Option<TextureRef>,
    /// Specular colour texture (sRGB-decoded).
    pub specular_color_texture: Option<TextureRef>,
    /// Clearcoat weight (`KHR_materials_clearcoat`, default 0: none).
    pub clearcoat: f32,
    /// The coat's perceptual roughness.
    pub clearcoat_roughness: f32,
    /// Clearcoat weight texture (red channel).
    pub clearcoat_texture: Option<TextureRef>,
    /// Coat roughness texture (green channel).
    pub clearcoat_roughness_texture: Option<TextureRef>,
    /// The coat's own tangent-space normal map (`clearcoatNormalTexture`); without it the coat
    /// follows the vertex normal, not `normal_texture`.
    pub clearcoat_normal_texture: Option<TextureRef>,
    /// The scale of `clearcoat_normal_texture`'s `x` and `y`.
    pub clearcoat_normal_scale: f32,
    /// Iridescence weight (`KHR_materials_iridescence`, default 0: none).
    pub iridescence: f32,
    /// The film's index of refraction (default 1.3).
    pub iridescence_ior: f32,
    /// The film's thickness range in nanometres (default 100 to 400).
    pub iridescence_thickness: (f32, f32),
    /// Iridescence weight texture (red channel).
    pub iridescence_texture: Option<TextureRef>,
    /// Film thickness texture (green channel).
    pub iridescence_thickness_texture: Option<TextureRef>,
    /// Sheen colour (`KHR_materials_sheen`, default black: none).
    pub sheen_color: Rgb,
    /// Sheen roughness.
    pub sheen_roughness: f32,
    /// Sheen colour texture (sRGB-decoded).
    pub sheen_color_texture: Option<TextureRef>,
    /// Sheen roughness texture (alpha channel).
    pub sheen_roughness_texture: Option<TextureRef>,
    /// Anisotropy strength (`KHR_materials_anisotropy`, default 0).
    pub anisotropy_strength: f32,
    /// Rotation of the anisotropy direction from the tangent, radians.
    pub anisotropy_rotation: f32,
    /// Anisotropy texture (red-green direction, blue strength).
    pub anisotropy_texture: Option<TextureRef>,
    /// glTF's `KHR_materials_unlit`: the loader made the base colour (factor and texture) the
    /// emission and the surface black; kept for information (`pt info`).
    pub unlit: bool,
    /// Render with glTF's metallic-roughness BSDF ([`pt_core::MetallicRoughness`], a metal and
    /// a Fresnel-layered dielectric mixed by `metallic`), as glTF files mean their materials;
    /// otherwise (OBJ and PLY) the dominant lobe's model (diffuse, metal, mirror, glass).
    pub gltf: bool,
}

impl Default for MaterialDesc {
    /// A white, fully rough, non-metallic (diffuse), non-emissive material: the base that the
    /// OBJ and PLY mappings start from. glTF's default differs: [`MaterialDesc::gltf_default`].
    fn default() -> Self {
        Self {
            name: "default".into(),
            base_color: Rgb::WHITE,
            metallic: 0.0,
            roughness: 1.0,
            emission: Rgb::BLACK,
            two_sided_emission: false,
            transmission: 0.0,
            transmission_texture: None,
            ior: 1.5,
            mirror: None,
            base_color_texture: None,
            metallic_roughness_texture: None,
            emissive_texture: None,
            normal_texture: None,
            normal_scale: 1.0,
            alpha: 1.0,
            alpha_mode: AlphaMode::Opaque,
            double_sided: true,
            attenuation_color: Rgb::WHITE,
            attenuation_distance: f32::INFINITY,
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
            unlit: false,
            gltf: false,
        }
    }
}

impl MaterialDesc {
    /// The default material of the glTF specification (section 3.9.6, for primitives without
    /// one): base colour 1, metallic 1, roughness 1, not emissive, i.e. a rough white metal,
    /// opaque and single-sided.
    #[must_use]
    pub fn gltf_default() -> Self {
        Self {
            name: "glTF default".into(),
            metallic: 1.0,
            double_sided: false,
            gltf: true,
            ..Self::default()
        }
    }

    /// The built-in material this maps to, with its textures from `textures`: a
    /// [`PbrMaterial`] (evaluated per hit) when it comes from glTF or has a texture, else as
    /// [`to_material`](Self::to_material). Texture indices out of range are ignored.
    pub fn to_material_with(
        &self,
        textures: &[Arc<Texture>],
    ) -> Result<BuiltinMaterial, pt_core::MaterialError> {
        self.to_material_on(textures, false)
    }

    /// As [`to_material_with`](Self::to_material_with), for meshes with vertex colours when
    /// `vertex_colors` (they multiply the base colour of glTF materials).
    pub fn to_material_on(
        &self,
        textures: &[Arc<Texture>],
        vertex_colors: bool,
    ) -> Result<BuiltinMaterial, pt_core::MaterialError> {
        let get = |r: &Option<TextureRef>| r.as_ref().and_then(|r| r.resolve(textures));
        let (bc, mr) = (
            get(&self.base_color_texture),
            get(&self.metallic_roughness_texture),
        );
        let normal = get(&self.normal_texture).filter(|_| self.gltf);
        if (bc.is_none() && mr.is_none() && !self.gltf) || self.mirror.is_some() {
            return self.to_material();
        }
        let unit = |v: f32| if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
        Ok(PbrMaterial {
            base_color: self.base_color.map(unit),
            base_color_texture: bc,
            vertex_colors: vertex_colors && self.gltf,
            metallic: unit(self.metallic),
            roughness: unit(self.roughness),
            metallic_roughness_texture: mr,
            normal_texture: normal,
            normal_scale: if self.normal_scale.is_finite() {
                self.normal_scale
            } else {
                1.0
            },
            transmission: unit(self.transmission),
            transmission_texture: get(&self.transmission_texture).filter(|_| self.gltf),
            ior: if self.ior.is_finite() && self.ior > 0.0 {
                self.ior
            } else {
                1.5
            },
            layered: self.gltf,
            alpha: unit(self.alpha),
            alpha_mode: match self.alpha_mode {
                AlphaMode::Mask(c) if !c.is_finite() => AlphaMode::Mask(0.5),
                mode => mode,
            },
            double_sided: self.double_sided || self.transmission > 0.0,
            absorption: PbrMaterial::absorption_from(
                self.attenuation_color,
                self.attenuation_distance,
            ),
            specular: unit(self.specular),
            specular_color: self
                .specular_color
                .map(|c| if c.is_finite() { c.max(0.0) } else { 1.0 }),
            specular_texture: get(&self.specular_texture).filter(|_| self.gltf),
            specular_color_texture: get(&self.specular_color_texture).filter(|_| self.gltf),
            clearcoat: unit(self.clearcoat),
            clearcoat_roughness: unit(self.clearcoat_roughness),
            clearcoat_texture: get(&self.clearcoat_texture).filter(|_| self.gltf),
            clearcoat_roughness_texture: get(&self.clearcoat_roughness_texture)
                .filter(|_| self.gltf),
            clearcoat_normal_texture: get(&self.clearcoat_normal_texture).filter(|_| self.gltf),
            clearcoat_normal_scale: if self.clearcoat_normal_scale.is_finite() {
                self.clearcoat_normal_scale
            } else {
                1.0
            },
            iridescence: unit(self.iridescence),
            iridescence_ior: if self.iridescence_ior.is_finite() && self.iridescence_ior >= 1.0 {
                self.iridescence_ior
            } else {
                1.3
            },
            iridescence_thickness: {
                let t = |v: f32| if v.is_finite() { v.max(0.0) } else { 0.0 };
                (
                    t(self.iridescence_thickness.0),
                    t(self.iridescence_thickness.1),
                )
            },
            iridescence_texture: get(&self.iridescence_texture).filter(|_| self.gltf),
            iridescence_thickness_texture: get(&self.iridescence_thickness_texture)
                .filter(|_| self.gltf),
            sheen_color: self.sheen_color.map(unit),
            sheen_roughness: unit(self.sheen_roughness),
            sheen_color_texture: get(&self.sheen_color_texture).filter(|_| self.gltf),
            sheen_roughness_texture: get(&self.sheen_roughness_texture).filter(|_| self.gltf),
            anisotropy_strength: unit(self.anisotropy_strength),
            anisotropy_rotation: if self.anisotropy_rotation.is_finite() {
                self.anisotropy_rotation
            } else {
                0.0
            },
            anisotropy_texture: get(&self.anisotropy_texture).filter(|_| self.gltf),
        }
        .into())
    }

    /// The built-in material this maps to, ignoring textures (see the
    /// [module documentation](crate::desc)).
    pub fn to_material(&self) -> Result<BuiltinMaterial, pt_core::MaterialError> {
        if self.gltf && self.mirror.is_none() && self.transmission < 0.5 {
            return self.to_material_with(&[]);
        }
        let unit = |v: f32| if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
        let color = self.base_color.map(unit);
        let roughness = unit(self.roughness);
        if self.transmission >= 0.5 {
            let ior = if self.ior.is_finite() && self.ior > 0.0 {
                self.ior
            } else {
                1.5
            };
            return Ok(Glass::new(ior)?
                .with_roughness(roughness)?
                .with_tint(color)
                .into());
        }
        if self.metallic >= 0.5 {
            return Ok(Metal::new(ConductorFresnel::Schlick(color), roughness)?.into());
        }
        if let Some(r) = self.mirror {
            return Ok(Mirror::new(r.map(unit)).into());
        }
        Ok(Diffuse::new(color).into())
    }
}
