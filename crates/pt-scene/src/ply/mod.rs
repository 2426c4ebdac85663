//! PLY (Stanford polygon file format) meshes: ASCII, binary little-endian and binary big-endian.
//!
//! Reads the `vertex` element's `x y z` (and `nx ny nz`, and `u v` / `s t` / `texture_u
//! texture_v` when present) and the `face` element's `vertex_indices` (or `vertex_index`) list;
//! polygons are triangulated as fans. Other elements and properties are read and skipped. Every
//! count in the header is checked against the data before anything is allocated for it, so a
//! corrupt header cannot make the reader allocate gigabytes; every failure is a [`LoadError`]
//! naming the file and the header line, vertex or face.

mod body;
mod header;

use std::path::Path;

use pt_core::Mesh;
use pt_core::pt_accel::TriangleMesh;

use crate::error::LoadError;
use crate::ply::body::{Ascii, Binary, read_body};
use crate::ply::header::{Format, parse_header};

/// Parse PLY data; `path` is used in error messages only.
pub fn parse_ply(data: &[u8], path: &Path) -> Result<Mesh, LoadError> {
    let header = parse_header(data, path)?;
    let body = &data[header.body..];
    let (vertices, triangles) = match header.format {
        Format::Ascii => read_body(&mut Ascii { data: body, pos: 0 }, &header, path)?,
        Format::BinaryLittleEndian | Format::BinaryBigEndian => read_body(
            &mut Binary {
                data: body,
                pos: 0,
                big_endian: header.format == Format::BinaryBigEndian,
            },
            &header,
            path,
        )?,
    };
    if triangles.is_empty() {
        return Err(LoadError::invalid(
            path,
            "element `face`",
            "the file has no faces",
        ));
    }
    let geometry = TriangleMesh::new(vertices.positions, triangles)
        .map_err(|e| LoadError::invalid(path, "mesh", e.to_string()))?;
    let mut mesh = Mesh::new(geometry);
    if let Some(n) = vertices.normals {
        mesh = mesh
            .with_normals(n)
            .map_err(|e| LoadError::invalid(path, "normals", e.to_string()))?;
    }
    if let Some(uv) = vertices.uvs {
        mesh = mesh
            .with_uvs(uv)
            .map_err(|e| LoadError::invalid(path, "uvs", e.to_string()))?;
    }
    Ok(mesh)
}

/// Read a PLY file.
pub fn load_ply(path: impl AsRef<Path>) -> Result<Mesh, LoadError> {
    let path = path.as_ref();
    let data = crate::Limits::default().read_file(path)?;
    parse_ply(&data, path)
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;

    const ASCII: &str = "ply\nformat ascii 1.0\ncomment a square\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0 0 0 1\n1 0 0 0 0 1\n1 1 0 0 0 1\n0 1 0 0 0 1\n4 0 1 2 3\n";

    fn binary(big_endian: bool) -> Vec<u8> {
        let fmt = if big_endian {
            "binary_big_endian"
        } else {
            "binary_little_endian"
        };
        let mut d = format!("ply\nformat {fmt} 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement edge 1\nproperty int a\nproperty int b\nelement face 1\nproperty uchar flags\nproperty list uchar uint vertex_indices\nend_header\n").into_bytes();
        let f = |d: &mut Vec<u8>, v: f32| {
            d.extend(if big_endian {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            })
        };
        let u = |d: &mut Vec<u8>, v: u32| {
            d.extend(if big_endian {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            })
        };
        for p in [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 2.0, 0.0]] {
            for c in p {
                f(&mut d, c);
            }
        }
        u(&mut d, 0);
        u(&mut d, 1);
        d.push(7);
        d.push(3);
        for i in [0, 1, 2] {
            u(&mut d, i);
        }
        d
    }

    #[test]
    fn ascii_with_normals_and_a_quad() {
        let m = parse_ply(ASCII.as_bytes(), Path::new("square.ply")).unwrap();
        assert_eq!(m.geometry().positions().len(), 4);
        assert_eq!(m.geometry().indices(), &[[0, 1, 2], [0, 2, 3]]);
        assert_eq!(m.normals().unwrap()[2], Vec3::Z);
    }

    #[test]
    fn binary_both_endians_skipping_other_elements() {
        for be in [false, true] {
            let m = parse_ply(&binary(be), Path::new("t.ply")).unwrap();
            assert_eq!(m.geometry().positions()[2], Vec3::new(0.0, 2.0, 0.0));
            assert_eq!(m.geometry().indices(), &[[0, 1, 2]]);
        }
    }

    fn err(data: &[u8]) -> String {
        parse_ply(data, Path::new("bad.ply"))
            .unwrap_err()
            .to_string()
    }

    #[test]
    fn malformed_files_give_clear_errors() {
        assert!(err(b"plx\n").contains("not a PLY file"));
        assert!(err(b"ply\nformat ascii 1.0\nelement vertex 3\n").contains("without `end_header`"));
        assert!(err(b"ply\nformat weird 1.0\nend_header\n").contains("unknown format"));
        assert!(
            err(b"ply\nformat ascii 1.0\nelement vertex -3\nend_header\n")
                .contains("header line 3")
        );
        assert!(
            err(b"ply\nformat ascii 1.0\nproperty float x\nend_header\n")
                .contains("before any element")
        );
        assert!(
            err(b"ply\nformat ascii 1.0\nelement vertex 1\nproperty quaternion x\nend_header\n")
                .contains("unknown type")
        );
        // Truncated body: header promises more than the data holds (no huge allocation).
        let big = "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
        assert!(err(big.as_bytes()).contains("file ends before them"));
        let cut = &binary(false)[..binary(false).len() - 3];
        assert!(err(cut).contains("face 0"), "{}", err(cut));
        // Bad data.
        let oob = ASCII.replace("4 0 1 2 3", "3 0 1 9");
        assert!(err(oob.as_bytes()).contains("face 0: vertex index 9 is out of range"));
        let nan = ASCII.replace("1 1 0 0 0 1", "1 nan 0 0 0 1");
        assert!(
            err(nan.as_bytes()).contains("vertex 2"),
            "{}",
            err(nan.as_bytes())
        );
        let two = ASCII.replace("4 0 1 2 3", "2 0 1");
        assert!(err(two.as_bytes()).contains("fewer than 3"));
        let frac = ASCII.replace("4 0 1 2 3", "3 0 1.5 2");
        assert!(err(frac.as_bytes()).contains("face 0"));
    }
}
