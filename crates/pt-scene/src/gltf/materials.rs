//! glTF materials: the metallic-roughness parameters as a [`MaterialDesc`], warnings for what pt
//! ignores, and textures.

use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use pt_core::glam::{Affine2, Mat2, Vec2};
use pt_core::texture::{Filter, Sampling, Wrap};
use pt_core::{AlphaMode, Rgb, Texture};

use crate::desc::{MaterialDesc, SceneDesc, TextureRef};
use crate::error::LoadError;
use crate::gltf::checks::{check_image, check_view};
use crate::limits::Limits;

/// A number of a material extension's JSON, or `default` when it is absent or not a finite
/// number.
fn ext_f32(ext: Option<&::gltf::json::Value>, key: &str, default: f32) -> f32 {
    ext.and_then(|e| e.get(key))
        .and_then(::gltf::json::Value::as_f64)
        .map(|v| v as f32)
        .filter(|v| v.is_finite())
        .unwrap_or(default)
}

/// An RGB triple of a material extension's JSON, or `default`.
fn ext_rgb(ext: Option<&::gltf::json::Value>, key: &str, default: Rgb) -> Rgb {
    let Some(a) = ext.and_then(|e| e.get(key)).and_then(|v| v.as_array()) else {
        return default;
    };
    let c: Vec<f32> = a
        .iter()
        .filter_map(::gltf::json::Value::as_f64)
        .map(|v| v as f32)
        .filter(|v| v.is_finite())
        .collect();
    if c.len() == 3 && a.len() == 3 {
        Rgb::new(c[0], c[1], c[2])
    } else {
        default
    }
}

pub(crate) fn material_desc(m: &::gltf::Material<'_>) -> MaterialDesc {
    let pbr = m.pbr_metallic_roughness();
    let [r, g, b, _] = pbr.base_color_factor();
    let [er, eg, eb] = m.emissive_factor();
    let strength = m.emissive_strength().unwrap_or(1.0);
    let specular = m.extension_value("KHR_materials_specular");
    let clearcoat = m.extension_value("KHR_materials_clearcoat");
    let unlit = m.extension_value("KHR_materials_unlit").is_some();
    let anisotropy = m.extension_value("KHR_materials_anisotropy");
    let sheen = m.extension_value("KHR_materials_sheen");
    let iridescence = m.extension_value("KHR_materials_iridescence");
    let mut desc = MaterialDesc {
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
        transmission_texture: None,
        ior: m.ior().unwrap_or(1.5),
        mirror: None,
        base_color_texture: None,
        metallic_roughness_texture: None,
        emissive_texture: None,
        normal_texture: None,
        normal_scale: 1.0,
        alpha: pbr.base_color_factor()[3],
        alpha_mode: match m.alpha_mode() {
            ::gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
            ::gltf::material::AlphaMode::Mask => AlphaMode::Mask(m.alpha_cutoff().unwrap_or(0.5)),
            ::gltf::material::AlphaMode::Blend => AlphaMode::Blend,
        },
        double_sided: m.double_sided(),
        attenuation_color: m
            .volume()
            .map_or(Rgb::WHITE, |v| Rgb::from(v.attenuation_color())),
        attenuation_distance: m
            .volume()
            .map_or(f32::INFINITY, |v| v.attenuation_distance()),
        specular: ext_f32(specular, "specularFactor", 1.0),
        specular_color: ext_rgb(specular, "specularColorFactor", Rgb::WHITE),
        specular_texture: None,
        specular_color_texture: None,
        clearcoat: ext_f32(clearcoat, "clearcoatFactor", 0.0),
        clearcoat_roughness: ext_f32(clearcoat, "clearcoatRoughnessFactor", 0.0),
        clearcoat_texture: None,
        clearcoat_roughness_texture: None,
        clearcoat_normal_texture: None,
        clearcoat_normal_scale: clearcoat
            .and_then(|c| c.get("clearcoatNormalTexture"))
            .and_then(|t| t.get("scale"))
            .and_then(::gltf::json::Value::as_f64)
            .map_or(1.0, |s| s as f32),
        iridescence: ext_f32(iridescence, "iridescenceFactor", 0.0),
        iridescence_ior: ext_f32(iridescence, "iridescenceIor", 1.3),
        iridescence_thickness: (
            ext_f32(iridescence, "iridescenceThicknessMinimum", 100.0),
            ext_f32(iridescence, "iridescenceThicknessMaximum", 400.0),
        ),
        iridescence_texture: None,
        iridescence_thickness_texture: None,
        sheen_color: ext_rgb(sheen, "sheenColorFactor", Rgb::BLACK),
        sheen_roughness: ext_f32(sheen, "sheenRoughnessFactor", 0.0),
        sheen_color_texture: None,
        sheen_roughness_texture: None,
        anisotropy_strength: ext_f32(anisotropy, "anisotropyStrength", 0.0),
        anisotropy_rotation: ext_f32(anisotropy, "anisotropyRotation", 0.0),
        anisotropy_texture: None,
        unlit: false,
        gltf: true,
    };
    if unlit {
        // KHR_materials_unlit: the surface shows its base colour whatever the lighting. A path
        // tracer makes that an emitter of the base colour that reflects nothing (its base
        // colour texture becomes the emissive one in `read_textures`).
        desc.emission = desc.base_color;
        desc.base_color = Rgb::BLACK;
        desc.specular = 0.0;
        desc.metallic = 0.0;
        desc.clearcoat = 0.0;
        desc.unlit = true;
    }
    desc
}

/// Warn, naming the file and material, about every property of `m` that pt does not use, so
/// nothing is silently assumed (the table in the module docs lists the same).
pub(crate) fn warn_unused(m: &::gltf::Material<'_>, path: &Path) {
    let mut unused = Vec::new();
    // Occlusion maps are not a warning: they approximate, for rasterisers, the shadowing of
    // ambient light that a path tracer computes (the module docs say so).
    // KHR_materials_volume's thickness (factor and texture) is not a warning: it approximates,
    // for rasterisers, the distance a path tracer measures (the module docs say so).
    if m.volume().is_some() && m.transmission().is_none() {
        unused.push("KHR_materials_volume without transmission (no medium)");
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

/// A decoded glTF image as a linear texture (sRGB-decoded when `srgb`), with its alpha channel
/// when `alpha` and the image has one. Grey images (one channel, or grey and alpha) give grey
/// RGB.
pub(crate) fn texture_from(data: &::gltf::image::Data, srgb: bool, alpha: bool) -> Option<Texture> {
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
    // Two channels are grey and alpha (the gltf crate's decode of a grey-alpha PNG: glTF
    // images cannot hold a red-green pair).
    let keep_alpha = alpha && (channels == 4 || channels == 2);
    let alpha_channel = if channels == 2 { 1 } else { 3 };
    let mut alphas = Vec::with_capacity(if keep_alpha {
        w as usize * h as usize
    } else {
        0
    });
    let mut rgb = Vec::with_capacity(w as usize * h as usize * 3);
    for px in data
        .pixels
        .chunks_exact(texel)
        .take(w as usize * h as usize)
    {
        let (r, g, b) = match channels {
            1 => (read(px, 0), read(px, 0), read(px, 0)),
            2 => (read(px, 0), read(px, 0), read(px, 0)),
            _ => (read(px, 0), read(px, 1), read(px, 2)),
        };
        if srgb && bytes == 1 {
            // The common case (8-bit colour textures) by table, not three powf per texel.
            let c =
                |i: usize| pt_core::color::srgb8_to_linear(px[if channels < 3 { 0 } else { i }]);
            rgb.extend([c(0), c(1), c(2)]);
        } else {
            rgb.extend([decode(r), decode(g), decode(b)]);
        }
        if keep_alpha {
            alphas.push(read(px, alpha_channel));
        }
    }
    let texture = pt_core::Image::from_rgb(w, h, rgb).ok().map(Texture::new)?;
    if keep_alpha {
        texture.with_alpha(alphas)
    } else {
        Some(texture)
    }
}

/// A material's use of a texture, before decoding.
struct Use<'a> {
    texture: ::gltf::Texture<'a>,
    tex_coord: u32,
    transform: Option<::gltf::json::Value>,
    /// Colour data, decoded from sRGB.
    srgb: bool,
    /// Keep the alpha channel (base colour).
    alpha: bool,
}

/// How glTF's sampler says to sample `texture`.
fn sampling(texture: &::gltf::Texture<'_>) -> Sampling {
    use ::gltf::texture::{MagFilter, WrappingMode};
    let wrap = |w: WrappingMode| match w {
        WrappingMode::ClampToEdge => Wrap::ClampToEdge,
        WrappingMode::MirroredRepeat => Wrap::MirroredRepeat,
        WrappingMode::Repeat => Wrap::Repeat,
    };
    let s = texture.sampler();
    Sampling {
        wrap_u: wrap(s.wrap_s()),
        wrap_v: wrap(s.wrap_t()),
        filter: match s.mag_filter() {
            Some(MagFilter::Nearest) => Filter::Nearest,
            _ => Filter::Linear,
        },
    }
}

/// `KHR_texture_transform` (offset, rotation, scale, and a `texCoord` override) from its JSON:
/// `uv' = T(offset) R(rotation) S(scale) uv`, with the extension's rotation convention. A
/// malformed transform is warned about and ignored.
pub(crate) fn texture_transform(
    json: Option<&::gltf::json::Value>,
    path: &Path,
    element: &str,
) -> (Affine2, Option<u32>) {
    let Some(v) = json else {
        return (Affine2::IDENTITY, None);
    };
    let pair = |key: &str, default: [f32; 2]| -> Option<[f32; 2]> {
        match v.get(key) {
            None => Some(default),
            Some(a) => {
                let a = a.as_array()?;
                let x = a.first()?.as_f64()? as f32;
                let y = a.get(1)?.as_f64()? as f32;
                (a.len() == 2 && x.is_finite() && y.is_finite()).then_some([x, y])
            }
        }
    };
    let rotation = match v.get("rotation") {
        None => Some(0.0),
        Some(r) => r.as_f64().map(|r| r as f32).filter(|r| r.is_finite()),
    };
    let tex_coord = v.get("texCoord").and_then(::gltf::json::Value::as_u64);
    match (
        pair("offset", [0.0, 0.0]),
        rotation,
        pair("scale", [1.0, 1.0]),
    ) {
        (Some(offset), Some(rotation), Some(scale)) => {
            let (sin, cos) = rotation.sin_cos();
            let m = Mat2::from_cols(
                Vec2::new(cos, -sin) * scale[0],
                Vec2::new(sin, cos) * scale[1],
            );
            (
                Affine2::from_mat2_translation(m, Vec2::from(offset)),
                tex_coord.and_then(|t| u32::try_from(t).ok()),
            )
        }
        _ => {
            log::warn!(
                "{}: {element}: malformed KHR_texture_transform (offset, rotation and scale \
                 must be finite numbers); ignored",
                path.display()
            );
            (Affine2::IDENTITY, None)
        }
    }
}

/// Decode every texture a material uses, once per (image, colour space, alpha, sampler), into
/// `desc.textures`, and point the materials' texture slots at them with their coordinate sets
/// and transforms.
pub(super) fn read_textures(
    doc: &::gltf::Document,
    buffers: &[::gltf::buffer::Data],
    path: &Path,
    base: Option<&Path>,
    limits: &Limits,
    desc: &mut SceneDesc,
) -> Result<(), LoadError> {
    let mut decoded: HashMap<(usize, bool, bool, Sampling), usize> = HashMap::new();
    // Each distinct texture gets its index here, in first-use order, and is decoded after the
    // loop, in parallel.
    let first = desc.textures.len();
    let mut pending: Vec<(::gltf::Image<'_>, bool, bool, Sampling)> = Vec::new();
    for m in doc.materials() {
        let pbr = m.pbr_metallic_roughness();
        fn info<'a>(i: ::gltf::texture::Info<'a>, srgb: bool, alpha: bool) -> Use<'a> {
            Use {
                texture: i.texture(),
                tex_coord: i.tex_coord(),
                transform: i.extension_value("KHR_texture_transform").cloned(),
                srgb,
                alpha,
            }
        }
        let normal = m.normal_texture();
        let ext = |name: &str, key: &str, srgb: bool, alpha: bool| -> Option<Use<'_>> {
            let v = m.extension_value(name)?.get(key)?;
            let texture = v
                .get("index")
                .and_then(::gltf::json::Value::as_u64)
                .and_then(|i| doc.textures().nth(usize::try_from(i).ok()?));
            let Some(texture) = texture else {
                log::warn!(
                    "{}: material {}: {name} {key} names no texture of the file; ignored",
                    path.display(),
                    m.index().unwrap_or(0)
                );
                return None;
            };
            Some(Use {
                texture,
                tex_coord: v
                    .get("texCoord")
                    .and_then(::gltf::json::Value::as_u64)
                    .and_then(|t| u32::try_from(t).ok())
                    .unwrap_or(0),
                transform: v
                    .get("extensions")
                    .and_then(|e| e.get("KHR_texture_transform"))
                    .cloned(),
                srgb,
                alpha,
            })
        };
        let uses = [
            pbr.base_color_texture().map(|i| info(i, true, true)),
            pbr.metallic_roughness_texture()
                .map(|i| info(i, false, false)),
            m.emissive_texture().map(|i| info(i, true, false)),
            normal.as_ref().map(|n| Use {
                texture: n.texture(),
                tex_coord: n.tex_coord(),
                transform: n.extension_value("KHR_texture_transform").cloned(),
                srgb: false,
                alpha: false,
            }),
            ext("KHR_materials_specular", "specularTexture", false, true),
            ext(
                "KHR_materials_specular",
                "specularColorTexture",
                true,
                false,
            ),
            ext("KHR_materials_clearcoat", "clearcoatTexture", false, false),
            ext(
                "KHR_materials_clearcoat",
                "clearcoatRoughnessTexture",
                false,
                false,
            ),
            ext(
                "KHR_materials_anisotropy",
                "anisotropyTexture",
                false,
                false,
            ),
            ext("KHR_materials_sheen", "sheenColorTexture", true, false),
            ext("KHR_materials_sheen", "sheenRoughnessTexture", false, true),
            ext(
                "KHR_materials_iridescence",
                "iridescenceTexture",
                false,
                false,
            ),
            ext(
                "KHR_materials_iridescence",
                "iridescenceThicknessTexture",
                false,
                false,
            ),
            m.transmission()
                .and_then(|t| t.transmission_texture())
                .map(|i| info(i, false, false)),
            ext(
                "KHR_materials_clearcoat",
                "clearcoatNormalTexture",
                false,
                false,
            ),
        ];
        let material = m.index().unwrap_or(0);
        for (slot, u) in uses.into_iter().enumerate() {
            let Some(u) = u else { continue };
            let element = format!("material {material}");
            let (transform, tex_coord) = texture_transform(u.transform.as_ref(), path, &element);
            let uv_set = tex_coord.unwrap_or(u.tex_coord) as usize;
            if uv_set >= pt_core::MAX_UV_SETS {
                log::warn!(
                    "{}: {element} reads TEXCOORD_{uv_set}; pt reads sets 0 to {}, so the \
                     texture is ignored",
                    path.display(),
                    pt_core::MAX_UV_SETS - 1
                );
                continue;
            }
            let image = u.texture.source();
            let sampling = sampling(&u.texture);
            let key = (image.index(), u.srgb, u.alpha, sampling);
            let index = *decoded.entry(key).or_insert_with(|| {
                pending.push((image, u.srgb, u.alpha, sampling));
                first + pending.len() - 1
            });
            let r = Some(TextureRef {
                index,
                uv_set,
                transform,
            });
            let md = &mut desc.materials[material];
            match slot {
                0 => {
                    md.base_color_texture = r;
                    if md.unlit {
                        md.emissive_texture = r;
                    }
                }
                1 => md.metallic_roughness_texture = r,
                2 if md.unlit => {}
                2 => md.emissive_texture = r,
                3 => {
                    md.normal_texture = r;
                    md.normal_scale = normal.as_ref().map_or(1.0, |n| n.scale());
                }
                4 => md.specular_texture = r,
                5 => md.specular_color_texture = r,
                6 => md.clearcoat_texture = r,
                7 => md.clearcoat_roughness_texture = r,
                8 => md.anisotropy_texture = r,
                9 => md.sheen_color_texture = r,
                10 => md.sheen_roughness_texture = r,
                11 => md.iridescence_texture = r,
                12 => md.iridescence_thickness_texture = r,
                13 => md.transmission_texture = r,
                _ => md.clearcoat_normal_texture = r,
            }
        }
    }
    let textures = in_parallel(&pending, |(image, srgb, alpha, sampling)| {
        decode_image(doc, image, *srgb, *alpha, buffers, path, base, limits)
            .map(|t| t.with_sampling(*sampling))
    });
    // The first failure in use order, as a sequential decode would report it.
    for texture in textures {
        desc.textures.push(Arc::new(texture?));
    }
    Ok(())
}

/// `f` of every item, on up to as many threads as the machine has cores (images decode
/// independently: a model's textures load in about half the time on two cores), the results
/// in the items' order.
fn in_parallel<T: Sync, R: Send>(items: &[T], f: impl Fn(&T) -> R + Sync) -> Vec<R> {
    let threads = std::thread::available_parallelism()
        .map_or(1, std::num::NonZeroUsize::get)
        .min(items.len());
    if threads <= 1 {
        return items.iter().map(f).collect();
    }
    let next = std::sync::atomic::AtomicUsize::new(0);
    let mut done: Vec<(usize, R)> = std::thread::scope(|scope| {
        let workers: Vec<_> = (0..threads)
            .map(|_| {
                scope.spawn(|| {
                    let mut out = Vec::new();
                    loop {
                        let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                        let Some(item) = items.get(i) else { break };
                        out.push((i, f(item)));
                    }
                    out
                })
            })
            .collect();
        workers
            .into_iter()
            .flat_map(|w| w.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
            .collect()
    });
    done.sort_by_key(|(i, _)| *i);
    done.into_iter().map(|(_, r)| r).collect()
}

/// One image as a texture, after the checks its decoding needs (source complete, view within
/// its buffer, encoded and decoded size within the limits).
#[allow(clippy::too_many_arguments)]
fn decode_image(
    doc: &::gltf::Document,
    image: &::gltf::Image<'_>,
    srgb: bool,
    alpha: bool,
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
    texture_from(&data, srgb, alpha)
        .ok_or_else(|| LoadError::invalid(path, &element, "pixel data shorter than its size"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grey_alpha_images_are_grey_with_alpha() {
        // One texel: grey 255, alpha 64 (a grey-alpha PNG as the gltf crate decodes it).
        let data = ::gltf::image::Data {
            pixels: vec![255, 64],
            format: ::gltf::image::Format::R8G8,
            width: 1,
            height: 1,
        };
        let t = texture_from(&data, true, true).unwrap();
        let c = t.eval(Vec2::splat(0.5));
        assert_eq!((c.r, c.g, c.b), (1.0, 1.0, 1.0));
        assert!((t.eval_alpha(Vec2::splat(0.5)) - 64.0 / 255.0).abs() < 1e-6);
    }
}
