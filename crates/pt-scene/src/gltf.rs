//! glTF 2.0 scenes (`.gltf` with external or embedded buffers, and `.glb`), read with the
//! [gltf](https://docs.rs/gltf) crate into a [`SceneDesc`].
//!
//! | glTF | pt |
//! |---|---|
//! | default scene (else the first), node hierarchy with TRS or matrix transforms | instances with their world transforms |
//! | a mesh used by several nodes, primitives sharing accessors | one geometry per distinct set of accessors (POSITION, indices, NORMAL, TEXCOORD_0), instanced (the two-level BVH is chosen automatically) |
//! | primitive mode TRIANGLES, indexed or not | triangles; other modes are skipped with a warning naming the mesh and primitive |
//! | POSITION, NORMAL, TEXCOORD_0 | positions, shading normals, uvs (missing normals: the geometric normal) |
//! | `pbrMetallicRoughness` base colour, metallic and roughness factors and textures (TEXCOORD_0; base colour decoded from sRGB) | [`MaterialDesc`] (mapped to a built-in model as in [`crate::desc`]; textured materials become a per-hit [`PbrMaterial`](pt_core::PbrMaterial)) |
//! | emissive factor x `KHR_materials_emissive_strength`, emissive texture | emission: emissive primitives become area lights, one per triangle, each with the texture's mean over the triangle; one-sided (front face), both sides when the material is `doubleSided` |
//! | a primitive without a material | the specification's default material: base colour 1, metallic 1, roughness 1 ([`MaterialDesc::gltf_default`]) |
//! | `KHR_materials_transmission` factor, `KHR_materials_ior` | glass when transmission is at least 0.5 |
//! | perspective cameras | the first camera in node order becomes the scene's camera (`yfov`; aspect from the image) |
//! | `KHR_lights_punctual` point, spot, directional | [`PointLight`](pt_core::PointLight), [`SpotLight`](pt_core::SpotLight) (glTF's cone falloff), [`DirectionalLight`](pt_core::DirectionalLight); colour times intensity (candela, lux) as radiometric intensity and irradiance; `range` is ignored with a warning |
//!
//! Not yet supported (ignored, listed so nothing is silently assumed): normal and occlusion
//! textures, `transmissionTexture`, `thicknessTexture`, emission varying within a triangle,
//! texture samplers (always bilinear and repeat), `KHR_texture_transform`, alpha modes,
//! `KHR_materials_volume` (attenuation), orthographic cameras, skins and morph targets. Each
//! material property of this list that a file uses is named in a warning at load (file,
//! material index and name), and so is every extension the file uses that pt does not know. A
//! file that *requires* an extension pt does not know is an error naming it. A camera that
//! cannot be used (field of view 0 or not a number, a zero-scale node) is a warning and the
//! framing camera is used, unless the program asked for the file's camera
//! ([`SceneDesc::try_file_camera`](crate::SceneDesc::try_file_camera)).

use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use glam::{Affine3A, Mat4, Vec2, Vec3};
use pt_core::{Rgb, Texture};

use crate::desc::{CameraDesc, InstanceDesc, LightDesc, MaterialDesc, MeshDesc, SceneDesc};
use crate::error::LoadError;
use crate::limits::Limits;

/// Extensions pt reads, or can safely ignore when a file requires them.
const KNOWN_EXTENSIONS: [&str; 5] = [
    "KHR_materials_emissive_strength",
    "KHR_materials_transmission",
    "KHR_materials_ior",
    "KHR_materials_volume",
    "KHR_lights_punctual",
];

fn gltf_error(path: &Path, e: ::gltf::Error) -> LoadError {
    match e {
        ::gltf::Error::Io(source) => LoadError::Io {
            path: path.to_path_buf(),
            source,
        },
        other => LoadError::parse(path, "glTF", other.to_string()),
    }
}

fn material_desc(m: &::gltf::Material<'_>) -> MaterialDesc {
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
    }
}

/// Warn, naming the file and material, about every property of `m` that pt does not use, so
/// nothing is silently assumed (the table in the module docs lists the same).
fn warn_unused(m: &::gltf::Material<'_>, path: &Path) {
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
fn texture_from(data: &::gltf::image::Data, srgb: bool) -> Option<Texture> {
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

/// Read a glTF 2.0 file (`.gltf` or `.glb`) as a scene description.
pub fn load_gltf(path: impl AsRef<Path>) -> Result<SceneDesc, LoadError> {
    load_gltf_with(path, &Limits::default())
}

/// [`load_gltf`] within `limits`: the file, each buffer (read only up to its `byteLength`) and
/// each image (its pixels, from the header) are checked before they are read, and the node
/// graph may place at most `limits.max_instances` instances.
pub fn load_gltf_with(path: impl AsRef<Path>, limits: &Limits) -> Result<SceneDesc, LoadError> {
    let path = path.as_ref();
    let bytes = limits.read_file(path)?;
    let file = parse(&bytes, path)?;
    from_gltf(&file, path, path.parent(), limits)
}

/// Read glTF 2.0 data (`.gltf` JSON or `.glb` bytes) from memory; `name` stands for the file in
/// errors. External buffers are not resolved (only embedded and GLB buffers).
pub fn load_gltf_slice(bytes: &[u8], name: impl AsRef<Path>) -> Result<SceneDesc, LoadError> {
    let path = name.as_ref();
    let file = parse(bytes, path)?;
    from_gltf(&file, path, None, &Limits::default())
}

/// Parse and validate. The `gltf` crate's validation indexes the accessor of every primitive's
/// `POSITION` before checking that it exists, and panics on a file where it does not (found by
/// fuzzing), so accessor references are checked first, on the unvalidated JSON.
fn parse(bytes: &[u8], path: &Path) -> Result<::gltf::Gltf, LoadError> {
    // The `gltf` crate subtracts the 12-byte header from the GLB's declared length unchecked
    // (an overflow panic where overflow checks are on; found by the stable fuzzer).
    if bytes.starts_with(b"glTF") {
        let declared = bytes
            .get(8..12)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize);
        if !declared.is_some_and(|n| (12..=bytes.len()).contains(&n)) {
            return Err(LoadError::parse(
                path,
                "GLB header",
                format!(
                    "declares a length of {} bytes, but the file has {} (a GLB holds at least its 12-byte header)",
                    declared.map_or("no".to_string(), |n| n.to_string()),
                    bytes.len()
                ),
            ));
        }
    }
    let raw =
        ::gltf::Gltf::from_slice_without_validation(bytes).map_err(|e| gltf_error(path, e))?;
    let json = raw.document.as_json();
    let accessors = json.accessors.len();
    for (m, mesh) in json.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            let targets = prim.targets.iter().flatten().flat_map(|t| {
                [&t.positions, &t.normals, &t.tangents]
                    .into_iter()
                    .flatten()
                    .copied()
            });
            let used = prim
                .attributes
                .values()
                .copied()
                .chain(prim.indices)
                .chain(targets);
            for index in used {
                if index.value() >= accessors {
                    return Err(LoadError::invalid(
                        path,
                        format!("mesh {m}, primitive {p}"),
                        format!(
                            "uses accessor {}, but the file has {accessors}",
                            index.value()
                        ),
                    ));
                }
            }
        }
    }
    let document =
        ::gltf::Document::from_json(raw.document.into_json()).map_err(|e| gltf_error(path, e))?;
    Ok(::gltf::Gltf {
        document,
        blob: raw.blob,
    })
}

/// `%XX` escapes of a relative URI decoded (glTF URIs are RFC 3986).
fn percent_decode(uri: &str) -> String {
    let b = uri.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let hex = |c: u8| (c as char).to_digit(16);
        if b[i] == b'%'
            && i + 2 < b.len()
            && let (Some(h), Some(l)) = (hex(b[i + 1]), hex(b[i + 2]))
        {
            out.push((h * 16 + l) as u8);
            i += 3;
        } else {
            out.push(b[i]);
            i += 1;
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// The file an external (not `data:`) URI names, relative to `base`.
fn uri_file(uri: &str, base: Option<&Path>) -> Option<std::path::PathBuf> {
    if uri.starts_with("data:") {
        return None;
    }
    let rel = percent_decode(uri);
    Some(base.map_or_else(|| Path::new(&rel).to_path_buf(), |b| b.join(&rel)))
}

/// Check every buffer before the `gltf` crate reads it: an external file must be a regular
/// file no larger than its declared `byteLength` (plus alignment padding), and the declared
/// length within the limits.
fn check_buffers(
    doc: &::gltf::Document,
    path: &Path,
    base: Option<&Path>,
    limits: &Limits,
) -> Result<(), LoadError> {
    for buffer in doc.buffers() {
        let element = format!("buffer {}", buffer.index());
        let declared = buffer.length() as u64;
        Limits::check(
            path,
            &element,
            "max_file_bytes",
            declared,
            limits.max_file_bytes,
        )?;
        let ::gltf::buffer::Source::Uri(uri) = buffer.source() else {
            continue;
        };
        let Some(file) = uri_file(uri, base) else {
            continue;
        };
        let meta = std::fs::metadata(&file).map_err(|source| LoadError::Io {
            path: file.clone(),
            source,
        })?;
        if !meta.is_file() {
            return Err(LoadError::invalid(
                path,
                element,
                format!(
                    "{} is not a regular file (a directory, device or FIFO)",
                    file.display()
                ),
            ));
        }
        if meta.len() > declared.next_multiple_of(4) + 4 {
            return Err(LoadError::invalid(
                path,
                element,
                format!(
                    "declares {declared} bytes but {} holds {}; refusing to read it",
                    file.display(),
                    meta.len()
                ),
            ));
        }
    }
    Ok(())
}

/// The pixel count an image declares in its header, checked against the limits before it is
/// decoded (uri files and buffer views; a `data:` URI is decoded by the `gltf` crate within
/// the `image` crate's own allocation limit and checked after).
fn check_image(
    image: &::gltf::Image<'_>,
    json: &::gltf::json::Image,
    buffers: &[::gltf::buffer::Data],
    path: &Path,
    base: Option<&Path>,
    limits: &Limits,
) -> Result<(), LoadError> {
    let element = format!("image {}", image.index());
    let invalid = |m: String| LoadError::invalid(path, &element, m);
    let dims = if let Some(file) = json.uri.as_deref().and_then(|u| uri_file(u, base)) {
        let meta = std::fs::metadata(&file).map_err(|source| LoadError::Io {
            path: file.clone(),
            source,
        })?;
        if !meta.is_file() {
            return Err(invalid(format!("{} is not a regular file", file.display())));
        }
        Limits::check(
            path,
            &element,
            "max_file_bytes",
            meta.len(),
            limits.max_file_bytes,
        )?;
        image::ImageReader::open(&file)
            .and_then(image::ImageReader::with_guessed_format)
            .map_err(|e| invalid(format!("{}: {e}", file.display())))?
            .into_dimensions()
            .map_err(|e| invalid(format!("{}: {e}", file.display())))?
    } else if let ::gltf::image::Source::View { view, .. } = image.source() {
        let data = &buffers[view.buffer().index()];
        let bytes = &data[view.offset()..view.offset() + view.length()];
        image::ImageReader::new(std::io::Cursor::new(bytes))
            .with_guessed_format()
            .map_err(|e| invalid(e.to_string()))?
            .into_dimensions()
            .map_err(|e| invalid(e.to_string()))?
    } else {
        return Ok(());
    };
    let pixels = u64::from(dims.0) * u64::from(dims.1);
    Limits::check(
        path,
        element,
        "max_image_pixels",
        pixels,
        limits.max_image_pixels,
    )
}

fn from_gltf(
    file: &::gltf::Gltf,
    path: &Path,
    base: Option<&Path>,
    limits: &Limits,
) -> Result<SceneDesc, LoadError> {
    for ext in file.document.extensions_required() {
        if !KNOWN_EXTENSIONS.contains(&ext) {
            return Err(LoadError::Unsupported {
                path: path.to_path_buf(),
                what: format!("required extension {ext}"),
            });
        }
    }
    let unknown: Vec<&str> = file
        .document
        .extensions_used()
        .filter(|e| !KNOWN_EXTENSIONS.contains(e))
        .collect();
    if !unknown.is_empty() {
        log::warn!(
            "{}: uses extensions pt ignores: {}",
            path.display(),
            unknown.join(", ")
        );
    }
    check_buffers(&file.document, path, base, limits)?;
    let buffers = ::gltf::import_buffers(&file.document, base, file.blob.clone())
        .map_err(|e| gltf_error(path, e))?;
    let doc = &file.document;

    let mut desc = SceneDesc {
        source: path.to_path_buf(),
        ..SceneDesc::default()
    };
    desc.materials = doc.materials().map(|m| material_desc(&m)).collect();
    for m in doc.materials() {
        warn_unused(&m, path);
    }
    // Textures: decoded once per (image, colour space) that a material uses.
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
                    let element = format!("image {}", image.index());
                    // `Image::source` panics on an image with neither a URI nor a buffer view
                    // (or a buffer view without a MIME type); check the JSON first (found by
                    // fuzzing).
                    let json = &doc.as_json().images[image.index()];
                    let complete = json.uri.is_some()
                        || (json.buffer_view.is_some() && json.mime_type.is_some());
                    if !complete {
                        return Err(LoadError::invalid(
                            path,
                            &element,
                            "neither a uri nor a buffer view with a MIME type",
                        ));
                    }
                    if let ::gltf::image::Source::View { view, .. } = image.source() {
                        check_view(&view, &buffers)
                            .map_err(|e| LoadError::invalid(path, &element, e))?;
                    }
                    check_image(&image, json, &buffers, path, base, limits)?;
                    let data = ::gltf::image::Data::from_source(image.source(), base, &buffers)
                        .map_err(|e| LoadError::invalid(path, &element, e.to_string()))?;
                    let pixels = u64::from(data.width) * u64::from(data.height);
                    Limits::check(
                        path,
                        &element,
                        "max_image_pixels",
                        pixels,
                        limits.max_image_pixels,
                    )?;
                    let texture = texture_from(&data, srgb).ok_or_else(|| {
                        LoadError::invalid(path, &element, "pixel data shorter than its size")
                    })?;
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
    let default_material = desc.materials.len();
    desc.materials.push(MaterialDesc::gltf_default());

    // One geometry per distinct set of accessors (primitives often share them and differ only
    // in material), created on first use and then instanced.
    let mut geometry: Vec<Vec<Option<(usize, usize)>>> = doc
        .meshes()
        .map(|m| vec![None; m.primitives().len()])
        .collect();
    let mut by_accessors: HashMap<[Option<usize>; 4], usize> = HashMap::new();

    let Some(scene) = doc.default_scene().or_else(|| doc.scenes().next()) else {
        return Err(LoadError::invalid(path, "scenes", "the file has no scene"));
    };
    // Depth-first over the node graph. A node on the current path met again is a cycle (the
    // spec requires a forest; a node listing itself among its children is the smallest case);
    // shared subtrees are allowed but every placement counts toward `max_instances`, so a
    // graph that places exponentially many instances is refused early.
    enum Step<'a> {
        Enter(::gltf::Node<'a>, Affine3A),
        Leave(usize),
    }
    let mut on_path = vec![false; doc.nodes().len()];
    let mut stack: Vec<Step<'_>> = scene
        .nodes()
        .map(|n| Step::Enter(n, Affine3A::IDENTITY))
        .collect();
    let mut visited = 0u64;
    let mut triangles = 0u64;
    while let Some(step) = stack.pop() {
        let (node, parent) = match step {
            Step::Enter(node, parent) => (node, parent),
            Step::Leave(i) => {
                on_path[i] = false;
                continue;
            }
        };
        if on_path[node.index()] {
            return Err(LoadError::invalid(
                path,
                format!("node {}", node.index()),
                "the node graph is cyclic: this node is its own ancestor",
            ));
        }
        visited += 1;
        Limits::check(
            path,
            "nodes",
            "max_instances",
            visited,
            limits.max_instances as u64,
        )?;
        let local = Mat4::from_cols_array_2d(&node.transform().matrix());
        if !local.is_finite() {
            return Err(LoadError::invalid(
                path,
                format!("node {}", node.index()),
                "transform is not finite",
            ));
        }
        let world = parent * Affine3A::from_mat4(local);
        if let Some(camera) = node.camera()
            && let ::gltf::camera::Projection::Perspective(p) = camera.projection()
        {
            desc.cameras.push(CameraDesc {
                transform: world,
                yfov_deg: p.yfov().to_degrees(),
            });
        }
        if let Some(light) = node.light() {
            let [r, g, b] = light.color();
            let color = Rgb::new(r, g, b) * light.intensity();
            let position = world.transform_point3(Vec3::ZERO);
            let direction = world.transform_vector3(Vec3::NEG_Z).normalize_or_zero();
            use ::gltf::khr_lights_punctual::Kind;
            desc.lights.push(match light.kind() {
                Kind::Point => LightDesc::Point {
                    position,
                    intensity: color,
                },
                Kind::Spot {
                    inner_cone_angle,
                    outer_cone_angle,
                } => LightDesc::Spot {
                    position,
                    direction,
                    intensity: color,
                    inner_angle: inner_cone_angle,
                    outer_angle: outer_cone_angle,
                },
                Kind::Directional => LightDesc::Directional {
                    direction,
                    irradiance: color,
                },
            });
            if light.range().is_some() {
                log::warn!(
                    "{}: light {} has a range; pt ignores it (inverse-square falloff only)",
                    path.display(),
                    light.index()
                );
            }
        }
        if let Some(mesh) = node.mesh() {
            for prim in mesh.primitives() {
                let element = format!("mesh {} primitive {}", mesh.index(), prim.index());
                let slot = &mut geometry[mesh.index()][prim.index()];
                let (mesh_index, material) = match slot {
                    Some(found) => *found,
                    None => {
                        if prim.mode() != ::gltf::mesh::Mode::Triangles {
                            log::warn!(
                                "{}: {element} uses mode {:?}, only TRIANGLES is rendered; skipped",
                                path.display(),
                                prim.mode()
                            );
                            continue;
                        }
                        let accessor = |s: ::gltf::Semantic| prim.get(&s).map(|a| a.index());
                        let key = [
                            accessor(::gltf::Semantic::Positions),
                            prim.indices().map(|a| a.index()),
                            accessor(::gltf::Semantic::Normals),
                            accessor(::gltf::Semantic::TexCoords(0)),
                        ];
                        let index = match by_accessors.get(&key) {
                            Some(&i) => i,
                            None => {
                                // Checked from the accessor's count before anything is read.
                                let corners = prim
                                    .indices()
                                    .or_else(|| prim.get(&::gltf::Semantic::Positions))
                                    .map_or(0, |a| a.count());
                                triangles += corners as u64 / 3;
                                Limits::check(
                                    path,
                                    &element,
                                    "max_triangles",
                                    triangles,
                                    limits.max_triangles as u64,
                                )?;
                                let m = read_primitive(&prim, &buffers, path, &element)?;
                                desc.meshes.push(m);
                                by_accessors.insert(key, desc.meshes.len() - 1);
                                desc.meshes.len() - 1
                            }
                        };
                        let material = prim.material().index().unwrap_or(default_material);
                        let found = (index, material);
                        *slot = Some(found);
                        found
                    }
                };
                desc.instances.push(InstanceDesc {
                    mesh: mesh_index,
                    material,
                    transform: world,
                });
            }
        }
        on_path[node.index()] = true;
        stack.push(Step::Leave(node.index()));
        for child in node.children() {
            stack.push(Step::Enter(child, world));
        }
    }
    Ok(desc)
}

/// Check what the `gltf` crate's readers assume but do not check, and panic on when it is false
/// (found by fuzzing): the accessor has the type the reader will read, is not sparse, has a buffer
/// view, a stride no smaller than its element, and lies within its view and the view within the
/// loaded buffer.
fn check_accessor(
    a: &::gltf::Accessor<'_>,
    dimensions: ::gltf::accessor::Dimensions,
    types: &[::gltf::accessor::DataType],
    buffers: &[::gltf::buffer::Data],
) -> Result<(), String> {
    let index = a.index();
    if a.dimensions() != dimensions || !types.contains(&a.data_type()) {
        return Err(format!(
            "accessor {index} is {:?} of {:?}, expected {dimensions:?} of one of {types:?}",
            a.dimensions(),
            a.data_type()
        ));
    }
    if a.sparse().is_some() {
        return Err(format!(
            "accessor {index} is sparse, which pt does not read"
        ));
    }
    let Some(view) = a.view() else {
        return Err(format!("accessor {index} has no buffer view"));
    };
    check_view(&view, buffers)?;
    let element = a.size();
    let stride = view.stride().unwrap_or(element);
    if stride < element {
        return Err(format!(
            "accessor {index}: byte stride {stride} is smaller than an element ({element} bytes)"
        ));
    }
    let end = (a.count().max(1) - 1)
        .checked_mul(stride)
        .and_then(|n| n.checked_add(a.offset()))
        .and_then(|n| n.checked_add(element));
    match end {
        Some(end) if end <= view.length() => Ok(()),
        _ => Err(format!(
            "accessor {index} ({} elements of {element} bytes, stride {stride}, offset {}) \
             runs past its buffer view ({} bytes)",
            a.count(),
            a.offset(),
            view.length()
        )),
    }
}

/// A buffer view must lie within the data actually loaded for its buffer.
fn check_view(
    view: &::gltf::buffer::View<'_>,
    buffers: &[::gltf::buffer::Data],
) -> Result<(), String> {
    let loaded = buffers.get(view.buffer().index()).map_or(0, |d| d.0.len());
    match view.offset().checked_add(view.length()) {
        Some(end) if end <= loaded => Ok(()),
        _ => Err(format!(
            "buffer view {} (offset {}, {} bytes) runs past the {loaded} bytes of buffer {}",
            view.index(),
            view.offset(),
            view.length(),
            view.buffer().index()
        )),
    }
}

fn read_primitive(
    prim: &::gltf::Primitive<'_>,
    buffers: &[::gltf::buffer::Data],
    path: &Path,
    element: &str,
) -> Result<MeshDesc, LoadError> {
    use ::gltf::Semantic;
    use ::gltf::accessor::{DataType, Dimensions};
    let float = [DataType::F32];
    let checks = [
        (
            prim.get(&Semantic::Positions),
            "POSITION",
            Dimensions::Vec3,
            &float[..],
        ),
        (
            prim.get(&Semantic::Normals),
            "NORMAL",
            Dimensions::Vec3,
            &float[..],
        ),
        (
            prim.get(&Semantic::TexCoords(0)),
            "TEXCOORD_0",
            Dimensions::Vec2,
            &[DataType::F32, DataType::U8, DataType::U16][..],
        ),
        (
            prim.indices(),
            "indices",
            Dimensions::Scalar,
            &[DataType::U8, DataType::U16, DataType::U32][..],
        ),
    ];
    for (accessor, what, dimensions, types) in checks {
        if let Some(a) = accessor {
            check_accessor(&a, dimensions, types, buffers)
                .map_err(|e| LoadError::invalid(path, format!("{element}, {what}"), e))?;
        }
    }
    let reader = prim.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
    let positions: Vec<Vec3> = reader
        .read_positions()
        .ok_or_else(|| LoadError::invalid(path, element, "no POSITION attribute"))?
        .map(Vec3::from)
        .collect();
    if let Some((i, problem)) = positions
        .iter()
        .enumerate()
        .find_map(|(i, &p)| crate::error::position_problem(p).map(|e| (i, e)))
    {
        return Err(LoadError::invalid(
            path,
            format!("{element}, vertex {i}"),
            problem,
        ));
    }
    let normals: Vec<Vec3> = reader
        .read_normals()
        .map(|n| n.map(Vec3::from).collect())
        .unwrap_or_default();
    let uvs: Vec<Vec2> = reader
        .read_tex_coords(0)
        .map(|t| t.into_f32().map(Vec2::from).collect())
        .unwrap_or_default();
    let flat: Vec<u32> = match reader.read_indices() {
        Some(ix) => ix.into_u32().collect(),
        None => (0..positions.len() as u32).collect(),
    };
    if flat.len() % 3 != 0 {
        return Err(LoadError::invalid(
            path,
            element,
            format!("{} indices is not a whole number of triangles", flat.len()),
        ));
    }
    if let Some(&bad) = flat.iter().find(|&&i| i as usize >= positions.len()) {
        return Err(LoadError::invalid(
            path,
            element,
            format!("index {bad} out of range for {} vertices", positions.len()),
        ));
    }
    let indices = flat.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect();
    Ok(MeshDesc {
        name: element.to_string(),
        normals: if normals.len() == positions.len() {
            normals
        } else {
            Vec::new()
        },
        uvs: if uvs.len() == positions.len() {
            uvs
        } else {
            Vec::new()
        },
        positions,
        indices,
    })
}
