//! Wavefront OBJ: meshes ([`load_obj_mesh`], geometry only) and scenes with their MTL materials
//! ([`load_obj_scene`]).
//!
//! Read with [tobj](https://docs.rs/tobj): polygons are triangulated, and positions, normals and
//! texture coordinates are unified to one index per vertex. All objects and groups of the file are
//! merged into one mesh.

mod text;

use std::path::Path;

use glam::{Vec2, Vec3};
use pt_core::pt_accel::TriangleMesh;
use pt_core::{Mesh, Rgb};

use crate::desc::{InstanceDesc, MaterialDesc, MeshDesc, SceneDesc};
use crate::error::LoadError;
use crate::limits::Limits;
use crate::obj::text::{prepare_text, short_face, short_face_error, tobj_error};

/// tobj options shared by the OBJ readers.
pub(crate) fn tobj_options() -> tobj::LoadOptions {
    tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
    }
}

/// A model's positions, or an error naming the first one that is not finite or too large.
fn checked_positions(model: &tobj::Model, path: &Path) -> Result<Vec<Vec3>, LoadError> {
    model
        .mesh
        .positions
        .chunks_exact(3)
        .enumerate()
        .map(|(i, p)| {
            let p = Vec3::new(p[0], p[1], p[2]);
            match crate::error::position_problem(p) {
                None => Ok(p),
                Some(problem) => Err(LoadError::invalid(
                    path,
                    format!("object `{}`, vertex {i}", model.name),
                    problem,
                )),
            }
        })
        .collect()
}

/// Turn tobj's models into one mesh, checking every position.
pub(crate) fn merge_models(models: &[tobj::Model], path: &Path) -> Result<Mesh, LoadError> {
    let mut positions = Vec::new();
    let mut indices = Vec::new();
    let all_normals = models.iter().all(|m| !m.mesh.normals.is_empty());
    let all_uvs = models.iter().all(|m| !m.mesh.texcoords.is_empty());
    let mut normals = Vec::new();
    let mut uvs = Vec::new();
    for model in models {
        let m = &model.mesh;
        let base = positions.len() as u32;
        positions.extend(checked_positions(model, path)?);
        if all_normals {
            normals.extend(
                m.normals
                    .chunks_exact(3)
                    .map(|n| Vec3::new(n[0], n[1], n[2])),
            );
        }
        if all_uvs {
            uvs.extend(m.texcoords.chunks_exact(2).map(|t| Vec2::new(t[0], t[1])));
        }
        indices.extend(
            m.indices
                .chunks_exact(3)
                .map(|t| [base + t[0], base + t[1], base + t[2]]),
        );
    }
    if indices.is_empty() {
        return Err(LoadError::invalid(path, "faces", "the file has no faces"));
    }
    let geometry = TriangleMesh::new(positions, indices)
        .map_err(|e| LoadError::invalid(path, "faces", e.to_string()))?;
    let mut mesh = Mesh::new(geometry);
    if all_normals && normals.len() == mesh.geometry().positions().len() {
        mesh = mesh
            .with_normals(normals)
            .map_err(|e| LoadError::invalid(path, "normals", e.to_string()))?;
    }
    if all_uvs && uvs.len() == mesh.geometry().positions().len() {
        mesh = mesh
            .with_uvs(uvs)
            .map_err(|e| LoadError::invalid(path, "texture coordinates", e.to_string()))?;
    }
    Ok(mesh)
}

/// Read the geometry of an OBJ file as one mesh.
pub fn load_obj_mesh(path: impl AsRef<Path>) -> Result<Mesh, LoadError> {
    let path = path.as_ref();
    let data = Limits::default().read_file(path)?;
    let text = prepare_text(&data, path)?;
    let (models, _materials) = tobj::load_obj_buf(&mut text.as_bytes(), &tobj_options(), |_| {
        // Geometry only: materials are ignored here.
        Ok((Vec::new(), Default::default()))
    })
    .map_err(|e| tobj_error(path, &text, e))?;
    if models.iter().all(|m| m.mesh.indices.is_empty())
        && let Some((line, n)) = short_face(&text)
    {
        return Err(short_face_error(path, line, n));
    }
    merge_models(&models, path)
}

/// Blinn-Phong exponent `Ns` to perceptual roughness: the Beckmann width of the equivalent
/// lobe is `alpha = sqrt(2 / (Ns + 2))` (Walter et al. 2007, section 5.2), and GGX's `alpha` is
/// taken equal to it, so `roughness = sqrt(alpha)`. `Ns = 0` gives 1, `Ns = 1000` gives 0.21.
#[must_use]
pub fn phong_exponent_to_roughness(ns: f32) -> f32 {
    let ns = if ns.is_finite() { ns.max(0.0) } else { 0.0 };
    (2.0 / (ns + 2.0)).sqrt().sqrt()
}

/// One MTL material as a [`MaterialDesc`]:
///
/// | MTL | meaning in pt |
/// |---|---|
/// | `Kd` | base colour (default 0.8 grey) |
/// | `Ks`, `Ns` | a metal with `F0 = Ks` and roughness from `Ns` ([`phong_exponent_to_roughness`]) when `Ks` is brighter than `Kd` (`illum 2`) |
/// | `illum 3`, `5` | an ideal mirror of reflectance `Ks` |
/// | `illum 4`, `6`, `7`, `9`, or transparency (`1 - d`, or `Tr`) of at least one half | glass with `eta = Ni` (default 1.5), roughness from `Ns`, tint `Tf` (default clear) |
/// | `Ke` | emitted radiance, from the front face only (the side the counter-clockwise winding's normal points to, as in pbrt and Mitsuba); [`BuildOptions::two_sided_lights`](crate::BuildOptions::two_sided_lights) for both sides |
/// | `Ni` | index of refraction of glass; a value that is not a finite number above 0 is replaced by 1.5 with a warning naming the material |
/// | `Ka` above 1 (no `Ke`) | emitted radiance: some exporters (the tinyobjloader Cornell box among them) store a light there, and a reflectance above 1 is impossible |
/// | `map_Kd` | base colour texture (sRGB, bilinear, repeat; replaces `Kd`); a missing or undecodable file is an error naming it |
fn mtl_to_desc(m: &tobj::Material, path: &Path) -> MaterialDesc {
    let v3 = |a: Option<[f32; 3]>| a.map(|a| Rgb::new(a[0], a[1], a[2]));
    let kd = v3(m.diffuse).unwrap_or(Rgb::splat(0.8));
    let ks = v3(m.specular).unwrap_or(Rgb::BLACK);
    let illum = m.illumination_model.unwrap_or(2);
    let roughness = m.shininess.map_or(1.0, phong_exponent_to_roughness);
    let mut desc = MaterialDesc {
        name: m.name.clone(),
        base_color: kd,
        roughness,
        ior: match m.optical_density {
            Some(ni) if ni.is_finite() && ni > 0.0 => ni,
            Some(ni) => {
                log::warn!(
                    "{}: material `{}`: Ni {ni} is not an index of refraction (a number above 0); using 1.5",
                    path.display(),
                    m.name
                );
                1.5
            }
            None => 1.5,
        },
        ..MaterialDesc::default()
    };
    let tr = m
        .unknown_param
        .get("Tr")
        .and_then(|t| t.trim().parse::<f32>().ok());
    let transparency = match (m.dissolve, tr) {
        (Some(d), _) => 1.0 - d,
        (None, Some(t)) => t,
        _ => 0.0,
    };
    if matches!(illum, 4 | 6 | 7 | 9) || transparency >= 0.5 {
        // Glass is tinted by the transmission filter `Tf` when given, else clear.
        desc.transmission = 1.0;
        desc.base_color = m
            .unknown_param
            .get("Tf")
            .and_then(|t| {
                let v: Vec<f32> = t
                    .split_whitespace()
                    .filter_map(|x| x.parse().ok())
                    .collect();
                (v.len() == 3).then(|| Rgb::new(v[0], v[1], v[2]))
            })
            .unwrap_or(Rgb::WHITE);
    } else if matches!(illum, 3 | 5) {
        desc.mirror = Some(ks);
    } else if illum >= 2 && ks.luminance() > kd.luminance() {
        desc.metallic = 1.0;
        desc.base_color = ks;
    }
    if let Some(ke) = v3(m.emissive) {
        desc.emission = ke;
    } else if let Some(ka) = v3(m.ambient)
        && ka.max_component() > 1.0
    {
        desc.emission = ka;
    }
    desc
}

/// Read an OBJ file with its MTL materials as a scene description: one mesh per object or group
/// (`o`/`g`), each placed once with its material. Missing MTL files are a warning (the objects
/// get the default material), as most viewers do.
pub fn load_obj_scene(path: impl AsRef<Path>) -> Result<SceneDesc, LoadError> {
    load_obj_scene_with(path, &Limits::default())
}

/// [`load_obj_scene`] within `limits`: the OBJ, each MTL file (a regular file, relative to the
/// OBJ's folder) and each texture are checked before they are read.
pub fn load_obj_scene_with(
    path: impl AsRef<Path>,
    limits: &Limits,
) -> Result<SceneDesc, LoadError> {
    let path = path.as_ref();
    let data = limits.read_file(path)?;
    let text = prepare_text(&data, path)?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let (models, materials) = tobj::load_obj_buf(&mut text.as_bytes(), &tobj_options(), |mtl| {
        let file = dir.join(mtl);
        let bytes = limits.read_file(&file).map_err(|e| {
            log::warn!("{}: mtllib {}: {e}", path.display(), mtl.display());
            tobj::LoadError::OpenFileFailed
        })?;
        let loaded = tobj::load_mtl_buf(&mut bytes.as_slice());
        if loaded.as_ref().is_ok_and(|(m, _)| m.is_empty()) {
            log::warn!(
                "{}: mtllib {} ({}) defines no materials",
                path.display(),
                mtl.display(),
                file.display()
            );
        }
        loaded
    })
    .map_err(|e| tobj_error(path, &text, e))?;
    if models.iter().all(|m| m.mesh.indices.is_empty())
        && let Some((line, n)) = short_face(&text)
    {
        return Err(short_face_error(path, line, n));
    }
    let triangles: usize = models.iter().map(|m| m.mesh.indices.len() / 3).sum();
    Limits::check(
        path,
        "faces",
        "max_triangles",
        triangles as u64,
        limits.max_triangles as u64,
    )?;
    scene_from_models(path, &models, materials, limits)
}

/// Read OBJ text from memory (no MTL files are read: every object gets the default material);
/// `name` stands for the file in errors.
pub fn load_obj_scene_from_bytes(
    bytes: &[u8],
    name: impl AsRef<Path>,
) -> Result<SceneDesc, LoadError> {
    let path = name.as_ref();
    let text = prepare_text(bytes, path)?;
    let (models, materials) = tobj::load_obj_buf(&mut text.as_bytes(), &tobj_options(), |_| {
        Ok((Vec::new(), Default::default()))
    })
    .map_err(|e| tobj_error(path, &text, e))?;
    if models.iter().all(|m| m.mesh.indices.is_empty())
        && let Some((line, n)) = short_face(&text)
    {
        return Err(short_face_error(path, line, n));
    }
    scene_from_models(path, &models, materials, &Limits::default())
}

fn scene_from_models(
    path: &Path,
    models: &[tobj::Model],
    materials: Result<Vec<tobj::Material>, tobj::LoadError>,
    limits: &Limits,
) -> Result<SceneDesc, LoadError> {
    let materials = match materials {
        Ok(m) => m,
        Err(e) => {
            log::warn!("{}: materials not loaded: {e}", path.display());
            Vec::new()
        }
    };
    let mut desc = SceneDesc {
        source: path.to_path_buf(),
        materials: materials.iter().map(|m| mtl_to_desc(m, path)).collect(),
        ..SceneDesc::default()
    };
    // Diffuse textures (`map_Kd`), relative to the OBJ's folder, decoded from sRGB; OBJ's `v`
    // grows upward.
    let mut loaded: std::collections::HashMap<String, usize> = std::collections::HashMap::new();
    for (i, m) in materials.iter().enumerate() {
        let Some(name) = m
            .diffuse_texture
            .as_deref()
            .filter(|t| !t.trim().is_empty())
        else {
            continue;
        };
        // `map_Kd` may carry options before the file name (`-s 1 1 1 tex.png`): use the last word.
        let file = name.split_whitespace().last().unwrap_or(name);
        let index = match loaded.get(file) {
            Some(&t) => t,
            None => {
                let tex_path = path.parent().unwrap_or(Path::new(".")).join(file);
                let image = crate::environment::load_image_linear_with(&tex_path, limits)?;
                desc.textures
                    .push(std::sync::Arc::new(pt_core::Texture::new(image).flip_v()));
                loaded.insert(file.to_string(), desc.textures.len() - 1);
                desc.textures.len() - 1
            }
        };
        desc.materials[i].base_color_texture = Some(index.into());
        // The texture replaces Kd (MTL multiplies nothing by default).
        desc.materials[i].base_color = Rgb::WHITE;
    }
    for model in models {
        let m = &model.mesh;
        if m.indices.is_empty() {
            continue;
        }
        let positions = checked_positions(model, path)?;
        let normals = if m.normals.len() == m.positions.len() {
            m.normals
                .chunks_exact(3)
                .map(|n| Vec3::new(n[0], n[1], n[2]))
                .collect()
        } else {
            Vec::new()
        };
        let uvs = if m.texcoords.len() / 2 == m.positions.len() / 3 {
            m.texcoords
                .chunks_exact(2)
                .map(|t| Vec2::new(t[0], t[1]))
                .collect()
        } else {
            Vec::new()
        };
        let indices = m
            .indices
            .chunks_exact(3)
            .map(|t| [t[0], t[1], t[2]])
            .collect();
        desc.instances.push(InstanceDesc {
            mesh: desc.meshes.len(),
            material: m.material_id.unwrap_or(usize::MAX),
            transform: glam::Affine3A::IDENTITY,
        });
        desc.meshes.push(MeshDesc {
            name: model.name.clone(),
            positions,
            normals,
            uvs,
            indices,
            ..MeshDesc::default()
        });
    }
    if desc.meshes.is_empty() {
        return Err(LoadError::invalid(path, "faces", "the file has no faces"));
    }
    Ok(desc)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quads_negative_indices_and_odd_whitespace() {
        let dir = std::env::temp_dir().join(format!("pt-obj-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("q.obj");
        std::fs::write(
            &p,
            "# a quad\n\nv 0 0 0\nv 1 0 0\n  v  1 1 0\nv 0 1 0\n   \nf -4 -3 -2 -1\n",
        )
        .unwrap();
        let m = load_obj_mesh(&p).unwrap();
        assert_eq!(m.geometry().triangle_count(), 2);
        std::fs::write(&p, "v 0 0 0\nv 1 0 0\nf 1 2 3\n").unwrap();
        let e = load_obj_mesh(&p).unwrap_err().to_string();
        assert!(e.contains("q.obj"), "{e}");
        let e = load_obj_mesh(dir.join("missing.obj"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("missing.obj"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn parse_errors_name_the_line() {
        let dir = std::env::temp_dir().join(format!("pt-obj-lines-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("bad.obj");
        for (text, line) in [
            ("v 0 0 0\nv 1 0 0\nv 1 x 0\nf 1 2 3\n", 3),
            ("v 0 0 0\nv 1 0 0\nv 1 1 0\n\nf 1 2 7\n", 5),
            ("v 0 0 0\nv 1 0 0\nv 1 1 0\nvn 0 0\nf 1 2 3\n", 4),
            ("v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 -4\n", 4),
        ] {
            std::fs::write(&p, text).unwrap();
            let e = load_obj_scene(&p).unwrap_err().to_string();
            assert!(e.contains(&format!("line {line}")), "{text:?}: {e}");
            assert!(e.contains("bad.obj"), "{e}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn mtl_materials_map_to_models() {
        let dir = std::env::temp_dir().join(format!("pt-mtl-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(
            dir.join("m.mtl"),
            "newmtl lamp\nKd 0 0 0\nKe 5 4 3\n\
             newmtl chrome\nKd 0.1 0.1 0.1\nKs 0.9 0.9 0.9\nillum 3\n\
             newmtl glass\nNi 1.33\nillum 7\n\
             newmtl steel\nKd 0.05 0.05 0.05\nKs 0.6 0.6 0.6\nNs 100\nillum 2\n\
             newmtl paint\nKd 0.7 0.2 0.1\n",
        )
        .unwrap();
        let mut obj = String::from("mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\n");
        for m in ["lamp", "chrome", "glass", "steel", "paint"] {
            obj.push_str(&format!("o {m}\nusemtl {m}\nf 1 2 3\n"));
        }
        std::fs::write(dir.join("s.obj"), obj).unwrap();
        let desc = load_obj_scene(dir.join("s.obj")).unwrap();
        assert_eq!(desc.meshes.len(), 5);
        let get = |n: &str| desc.materials.iter().find(|m| m.name == n).unwrap().clone();
        assert_eq!(get("lamp").emission, Rgb::new(5.0, 4.0, 3.0));
        assert_eq!(get("chrome").mirror, Some(Rgb::splat(0.9)));
        let glass = get("glass");
        assert_eq!((glass.transmission, glass.ior), (1.0, 1.33));
        let steel = get("steel");
        assert_eq!(steel.metallic, 1.0);
        assert!((steel.roughness - phong_exponent_to_roughness(100.0)).abs() < 1e-6);
        assert!(matches!(
            get("paint").to_material().unwrap(),
            pt_core::BuiltinMaterial::Diffuse(_)
        ));
        assert!((phong_exponent_to_roughness(0.0) - 1.0).abs() < 1e-6);
        assert!((phong_exponent_to_roughness(1000.0) - 0.211).abs() < 1e-3);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
