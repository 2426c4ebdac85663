//! Wavefront OBJ meshes (geometry only; materials come with the scene loader).
//!
//! Read with [tobj](https://docs.rs/tobj): polygons are triangulated, and positions, normals and
//! texture coordinates are unified to one index per vertex. All objects and groups of the file are
//! merged into one mesh.

use std::path::Path;

use glam::{Vec2, Vec3};
use pt_core::Mesh;
use pt_core::pt_accel::TriangleMesh;

use crate::error::LoadError;

/// tobj options shared by the OBJ readers.
pub(crate) fn tobj_options() -> tobj::LoadOptions {
    tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
    }
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
        for (i, p) in m.positions.chunks_exact(3).enumerate() {
            let p = Vec3::new(p[0], p[1], p[2]);
            if !p.is_finite() {
                return Err(LoadError::invalid(
                    path,
                    format!("object `{}`, vertex {i}", model.name),
                    format!("position {p} is not finite"),
                ));
            }
            positions.push(p);
        }
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

pub(crate) fn tobj_error(path: &Path, e: tobj::LoadError) -> LoadError {
    match e {
        tobj::LoadError::OpenFileFailed | tobj::LoadError::ReadError => LoadError::Io {
            path: path.to_path_buf(),
            source: std::io::Error::other(e.to_string()),
        },
        other => LoadError::parse(path, "file", other.to_string()),
    }
}

/// Read the geometry of an OBJ file as one mesh.
pub fn load_obj_mesh(path: impl AsRef<Path>) -> Result<Mesh, LoadError> {
    let path = path.as_ref();
    let data = std::fs::read(path).map_err(|source| LoadError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let (models, _materials) = tobj::load_obj_buf(&mut data.as_slice(), &tobj_options(), |_| {
        // Geometry only: materials are ignored here.
        Ok((Vec::new(), Default::default()))
    })
    .map_err(|e| tobj_error(path, e))?;
    merge_models(&models, path)
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
}
