//! glTF materials: the metallic-roughness parameters as a [`MaterialDesc`], warnings for what pt
//! ignores, and textures.

use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use pt_core::{Rgb, Texture};

use crate::desc::{MaterialDesc, SceneDesc};
use crate::error::LoadError;
use crate::gltf::checks::{check_image, check_view};
use crate::limits::Limits;

pub(crate) fn material_desc(m: &::gltf::Material<'_>) -> MaterialDesc {
    let pbr = m.pbr_metallic_roughness();
    let [r, g, b, _] = pbr.base_color_factor();
    let [er, eg, eb] = m.emissive_factor();
    let strength = m.emissive_strength().unwrap_or(1.0);
    MaterialDesc {
        name: m.name().map_or_else(
            || format!("material {}", m.index().unwrap_or(0)),
            str::to_string,
        ),
        base_color: Rgb::new(r, g, b),
        metallic: pbr.metallic_factor(),
        roughness: pbr.roughness_factor(),
        emission: Rgb::new(er, eg, eb) * strength,
        // The spec: a double-sided material is lit and emits on both sides.
        two_sided_emission: m.double_sided(),
        transmission: m.transmission().map_or(0.0, |t| t.transmission_factor()),
        ior: m.ior().unwrap_or(1.5),
        mirror: None,
        base_color_texture: None,
        metallic_roughness_texture: None,
        emissive_texture: None,
        gltf: true,
    }
}

/// Warn, naming the file and material, about every property of `m` that pt does not use, so
/// nothing is silently assumed (the table in the module docs lists the same).
pub(crate) fn warn_unused(m: &::gltf::Material<'_>, path: &Path) {
    let mut unused = Vec::new();
    if m.normal_texture().is_some() {
        unused.push("normalTexture");
    }
    if m.occlusion_texture().is_some() {
        unused.push("occlusionTexture");
    }
    if m.alpha_mode() != ::gltf::material::AlphaMode::Opaque {
        unused.push("alphaMode (rendered opaque)");
    }
    if let Some(t) = m.transmission()
        && t.transmission_texture().is_some()
    {
        unused.push("transmissionTexture");
    }
    if let Some(v) = m.volume() {
        unused.push("KHR_materials_volume (no absorption)");
        if v.thickness_texture().is_some() {
            unused.push("thicknessTexture");
        }
    }
    if !unused.is_empty() {
        log::warn!(
            "{}: material {} ({}): pt does not use {}",
            path.display(),
            m.index().unwrap_or(0),
            m.name().unwrap_or("unnamed"),
            unused.join(", ")
        );
    }
}

/// A decoded glTF image as a linear texture (sRGB-decoded when `srgb`).
pub(crate) fn texture_from(data: &::gltf::image::Data, srgb: bool) -> Option<Texture> {
    use ::gltf::image::Format as F;
    let (channels, bytes) = match data.format {
        F::R8 => (1, 1),
        F::R8G8 => (2, 1),
        F::R8G8B8 => (3, 1),
        F::R8G8B8A8 => (4, 1),
        F::R16 => (1, 2),
        F::R16G16 => (2, 2),
        F::R16G16B16 => (3, 2),
        F::R16G16B16A16 => (4, 2),
        F::R32G32B32FLOAT => (3, 4),
        F::R32G32B32A32FLOAT => (4, 4),
    };
    let (w, h) = (data.width, data.height);
    let texel = channels * bytes;
    if data.pixels.len() < w as usize * h as usize * texel {
        return None;
    }
    let read = |px: &[u8], c: usize| -> f32 {
        let o = c * bytes;
        match bytes {
            1 => f32::from(px[o]) / 255.0,
            2 => f32::from(u16::from_le_bytes([px[o], px[o + 1]])) / 65535.0,
            _ => f32::from_le_bytes([px[o], px[o + 1], px[o + 2], px[o + 3]]),
        }
    };
    let decode = |v: f32| {
        if srgb && bytes < 4 {
            pt_core::color::srgb_to_linear(v)
        } else {
            v
        }
    };
    let mut rgb = Vec::with_capacity(w as usize * h as usize * 3);
    for px in data
        .pixels
        .chunks_exact(texel)
        .take(w as usize * h as usize)
    {
        let (r, g, b) = match channels {
            1 => (read(px, 0), read(px, 0), read(px, 0)),
            2 => (read(px, 0), read(px, 1), 0.0),
            _ => (read(px, 0), read(px, 1), read(px, 2)),
        };
        rgb.extend([decode(r), decode(g), decode(b)]);
    }
    pt_core::Image::from_rgb(w, h, rgb).ok().map(Texture::new)
}

/// Decode every texture a material uses, once per (image, colour space), into `desc.textures`,
/// and point the materials' texture slots at them.
pub(super) fn read_textures(
    doc: &::gltf::Document,
    buffers: &[::gltf::buffer::Data],
    path: &Path,
    base: Option<&Path>,
    limits: &Limits,
    desc: &mut SceneDesc,
) -> Result<(), LoadError> {
    let mut decoded: HashMap<(usize, bool), usize> = HashMap::new();
    for m in doc.materials() {
        let pbr = m.pbr_metallic_roughness();
        let uses = [
            (pbr.base_color_texture(), true),
            (pbr.metallic_roughness_texture(), false),
            (m.emissive_texture(), true),
        ];
        for (slot, (info, srgb)) in uses.into_iter().enumerate() {
            let Some(info) = info else { continue };
            if info.tex_coord() != 0 {
                log::warn!(
                    "{}: material {} uses TEXCOORD_{}; pt reads TEXCOORD_0 only",
                    path.display(),
                    m.index().unwrap_or(0),
                    info.tex_coord()
                );
            }
            let image = info.texture().source();
            let key = (image.index(), srgb);
            let index = match decoded.get(&key) {
                Some(&i) => i,
                None => {
                    let texture = decode_image(doc, &image, srgb, buffers, path, base, limits)?;
                    desc.textures.push(Arc::new(texture));
                    decoded.insert(key, desc.textures.len() - 1);
                    desc.textures.len() - 1
                }
            };
            let md = &mut desc.materials[m.index().unwrap_or(0)];
            match slot {
                0 => md.base_color_texture = Some(index),
                1 => md.metallic_roughness_texture = Some(index),
                _ => md.emissive_texture = Some(index),
            }
        }
    }
    Ok(())
}

/// One image as a texture, after the checks its decoding needs (source complete, view within
/// its buffer, encoded and decoded size within the limits).
fn decode_image(
    doc: &::gltf::Document,
    image: &::gltf::Image<'_>,
    srgb: bool,
    buffers: &[::gltf::buffer::Data],
    path: &Path,
    base: Option<&Path>,
    limits: &Limits,
) -> Result<Texture, LoadError> {
    let element = format!("image {}", image.index());
    // `Image::source` panics on an image with neither a URI nor a buffer view (or a buffer view
    // without a MIME type); check the JSON first (found by fuzzing).
    let json = &doc.as_json().images[image.index()];
    let complete = json.uri.is_some() || (json.buffer_view.is_some() && json.mime_type.is_some());
    if !complete {
        return Err(LoadError::invalid(
            path,
            &element,
            "neither a uri nor a buffer view with a MIME type",
        ));
    }
    if let ::gltf::image::Source::View { view, .. } = image.source() {
        check_view(&view, buffers).map_err(|e| LoadError::invalid(path, &element, e))?;
    }
    check_image(image, json, buffers, path, base, limits)?;
    let data = ::gltf::image::Data::from_source(image.source(), base, buffers)
        .map_err(|e| LoadError::invalid(path, &element, e.to_string()))?;
    let pixels = u64::from(data.width) * u64::from(data.height);
    Limits::check(
        path,
        &element,
        "max_image_pixels",
        pixels,
        limits.max_image_pixels,
    )?;
    texture_from(&data, srgb)
        .ok_or_else(|| LoadError::invalid(path, &element, "pixel data shorter than its size"))
}
