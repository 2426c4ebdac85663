//! glTF 2.0 scenes (`.gltf` with external or embedded buffers, and `.glb`), read with the
//! [gltf](https://docs.rs/gltf) crate into a [`SceneDesc`].
//!
//! | glTF | pt |
//! |---|---|
//! | default scene (else the first), node hierarchy with TRS or matrix transforms | instances with their world transforms |
//! | `EXT_mesh_gpu_instancing` (TRANSLATION, ROTATION as float or normalised integers, SCALE) | one instance per entry under the node's transform, sharing the geometry (each counts toward `max_instances`) |
//! | a mesh used by several nodes, primitives sharing accessors | one geometry per distinct set of accessors (POSITION, indices, NORMAL, TEXCOORD_0..3, COLOR_0, TANGENT), instanced (the two-level BVH is chosen automatically) |
//! | primitive mode TRIANGLES, indexed or not | triangles; other modes are skipped with a warning naming the mesh and primitive |
//! | POSITION, NORMAL, TEXCOORD_0 to TEXCOORD_3 | positions, shading normals, uv sets 0 to 3 (missing normals: the geometric normal; sets beyond 3 are ignored with a warning) |
//! | COLOR_0 (RGB or RGBA; float or normalized integers) | vertex colours, multiplying the base colour of the primitive's material |
//! | TANGENT (`w` the bitangent's sign) | tangents for normal maps; missing, they are generated with MikkTSpace (as the specification requires) on meshes whose material has a normal map |
//! | `pbrMetallicRoughness` base colour, metallic and roughness factors and textures (base colour decoded from sRGB) | a per-hit [`PbrMaterial`](pt_core::PbrMaterial) rendering with glTF's BSDF, [`MetallicRoughness`](pt_core::MetallicRoughness) (Appendix B: a metal and a Fresnel-layered dielectric mixed by metallic) |
//! | `normalTexture` with `scale` | tangent-space normal map bending the shading normal (kept so reflected directions stay above the surface) |
//! | `occlusionTexture` | ignored by design: it darkens ambient light in rasterisers that cannot trace it; a path tracer computes that occlusion by tracing, and applying the map too would darken twice |
//! | a texture's `texCoord` | the uv set it reads |
//! | samplers: `wrapS`/`wrapT` (REPEAT, CLAMP_TO_EDGE, MIRRORED_REPEAT), `magFilter` (NEAREST, LINEAR) | [`Sampling`](pt_core::texture::Sampling); the minification filter is not used (a path tracer's many samples per pixel filter the texture over the pixel footprint) |
//! | `KHR_texture_transform` (offset, rotation, scale, `texCoord` override) | the texture's coordinate transform, T x R x S as the extension defines it |
//! | emissive factor x `KHR_materials_emissive_strength`, emissive texture | emission: emissive primitives become area lights, one per triangle; a textured one ([`TexturedTriangleLight`](pt_core::TexturedTriangleLight)) emits the texture where rays hit and light samples land, and its samples follow the texture's brightness; one-sided (front face), both sides when the material is `doubleSided` |
//! | `alphaMode` `MASK` with `alphaCutoff`, `BLEND`; alpha from `baseColorFactor`, the base colour texture and `COLOR_0` | [`AlphaMode`](pt_core::AlphaMode): masked surfaces are absent where alpha is below the cutoff; blended ones stop rays with probability alpha (stochastic transparency, for camera, indirect and shadow rays alike, converging to the blend) |
//! | `doubleSided` (default `false`) | single-sided surfaces are invisible from behind, for every ray; the front face is the counter-clockwise winding, clockwise under a node transform with negative determinant, as the specification says; transmissive materials are always double-sided (glass needs its back faces) |
//! | a primitive without a material | the specification's default material: base colour 1, metallic 1, roughness 1 ([`MaterialDesc::gltf_default`]) |
//! | `KHR_materials_transmission` factor and texture, `KHR_materials_ior` | glass where transmission (the factor times the texture's red channel, per hit) is at least 0.5 |
//! | `KHR_materials_specular` (`specularFactor`, `specularColorFactor`, their textures) | the dielectric's Fresnel of [`MetallicRoughness`](pt_core::MetallicRoughness): coloured `F0 = min(F0(ior) colour, 1) specular`, `F90 = specular` |
//! | `KHR_materials_clearcoat` (factor, roughness, normal, their textures) | a GGX coat (IOR 1.5) over the material ([`MetallicRoughness::with_clearcoat`](pt_core::MetallicRoughness::with_clearcoat)); its normal is `clearcoatNormalTexture`'s, else the vertex normal: the base's normal map does not bend it, as the extension says ([`MetallicRoughness::with_coat_normal`](pt_core::MetallicRoughness::with_coat_normal)) |
//! | `KHR_materials_anisotropy` (strength, rotation, texture) | the base's GGX lobes stretched along the direction, `alpha_t = mix(alpha, 1, strength^2)` ([`MetallicRoughness::with_anisotropy`](pt_core::MetallicRoughness::with_anisotropy)); tangents as for normal maps (the file's, or MikkTSpace) |
//! | `KHR_materials_sheen` (colour, roughness, their textures) | a "Charlie" sheen lobe between the base and the coat ([`MetallicRoughness::with_sheen`](pt_core::MetallicRoughness::with_sheen)), the layers below scaled by what it reflects |
//! | `KHR_materials_iridescence` (factor, film IOR, thickness range, their textures) | the Fresnel terms of the dielectric and the metal mixed with Belcour and Barla's thin-film reflectance ([`MetallicRoughness::with_iridescence`](pt_core::MetallicRoughness::with_iridescence)); on transmissive (glass) materials the interface's reflectance per channel, the rest transmitted ([`ThinFilm`](pt_core::ThinFilm)) |
//! | `KHR_materials_unlit` | the surface emits its base colour (factor and texture) and reflects nothing: it shows its colour whatever the lighting, and lights what is near it as an emitter of that radiance would |
//! | `KHR_materials_volume` `attenuationColor`, `attenuationDistance` | the medium inside transmissive materials: paths refracted in lose `exp(-sigma d)` over each distance `d` travelled inside (Beer-Lambert, [`Material::absorption`](pt_core::Material::absorption)), `sigma = -ln(colour) / distance`. `thicknessFactor` and `thicknessTexture` are ignored by design: they tell rasterisers how far light travels inside, which a path tracer measures |
//! | perspective cameras | the first camera in node order becomes the scene's camera (`yfov`; aspect from the image) |
//! | `KHR_lights_punctual` point, spot, directional | [`PointLight`](pt_core::PointLight), [`SpotLight`](pt_core::SpotLight) (glTF's cone falloff), [`DirectionalLight`](pt_core::DirectionalLight); colour times intensity (candela, lux) as radiometric intensity and irradiance; `range` is ignored with a warning |
//!
//! Not yet supported (ignored, listed so nothing is silently assumed): vertex colours on
//! unlit materials, orthographic cameras, skins and morph targets. Each material property of
//! this list that a file uses is named in a warning at load (file, material index and name),
//! and so is every extension the file uses that pt does not know. A
//! file that *requires* an extension pt does not know is an error naming it. A camera that
//! cannot be used (field of view 0 or not a number, a zero-scale node) is a warning and the
//! framing camera is used, unless the program asked for the file's camera
//! ([`SceneDesc::try_file_camera`](crate::SceneDesc::try_file_camera)).

mod checks;
mod materials;
mod nodes;
mod primitive;

use std::path::Path;

use crate::desc::{MaterialDesc, SceneDesc};
use crate::error::LoadError;
use crate::gltf::checks::check_buffers;
use crate::gltf::materials::{material_desc, read_textures, warn_unused};
use crate::gltf::nodes::NodeWalk;
use crate::limits::Limits;

/// Extensions pt reads, or can safely ignore when a file requires them.
const KNOWN_EXTENSIONS: [&str; 13] = [
    "KHR_texture_transform",
    "EXT_mesh_gpu_instancing",
    "KHR_materials_iridescence",
    "KHR_materials_sheen",
    "KHR_materials_anisotropy",
    "KHR_materials_unlit",
    "KHR_materials_specular",
    "KHR_materials_clearcoat",
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
    // Required extensions are checked here, against what pt reads (the gltf crate knows fewer,
    // and would refuse files that require the others), then left out of its validation.
    let mut root = raw.document.into_json();
    for ext in &root.extensions_required {
        if !KNOWN_EXTENSIONS.contains(&ext.as_str()) {
            return Err(LoadError::Unsupported {
                path: path.to_path_buf(),
                what: format!("required extension {ext}"),
            });
        }
    }
    root.extensions_required.clear();
    let document = ::gltf::Document::from_json(root).map_err(|e| gltf_error(path, e))?;
    Ok(::gltf::Gltf {
        document,
        blob: raw.blob,
    })
}

fn from_gltf(
    file: &::gltf::Gltf,
    path: &Path,
    base: Option<&Path>,
    limits: &Limits,
) -> Result<SceneDesc, LoadError> {
    let doc = &file.document;
    check_extensions(doc, path)?;
    check_buffers(doc, path, base, limits)?;
    let buffers =
        ::gltf::import_buffers(doc, base, file.blob.clone()).map_err(|e| gltf_error(path, e))?;

    let mut desc = SceneDesc {
        source: path.to_path_buf(),
        ..SceneDesc::default()
    };
    desc.materials = doc.materials().map(|m| material_desc(&m)).collect();
    for m in doc.materials() {
        warn_unused(&m, path);
    }
    read_textures(doc, &buffers, path, base, limits, &mut desc)?;
    let default_material = desc.materials.len();
    desc.materials.push(MaterialDesc::gltf_default());

    let Some(scene) = doc.default_scene().or_else(|| doc.scenes().next()) else {
        return Err(LoadError::invalid(path, "scenes", "the file has no scene"));
    };
    NodeWalk::new(doc, &buffers, path, limits, default_material).walk(&scene, &mut desc)?;
    Ok(desc)
}

/// Refuse a file that requires an extension pt does not know; warn about used ones.
fn check_extensions(doc: &::gltf::Document, path: &Path) -> Result<(), LoadError> {
    for ext in doc.extensions_required() {
        if !KNOWN_EXTENSIONS.contains(&ext) {
            return Err(LoadError::Unsupported {
                path: path.to_path_buf(),
                what: format!("required extension {ext}"),
            });
        }
    }
    let unknown: Vec<&str> = doc
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
    Ok(())
}
