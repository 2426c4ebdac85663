//! Simple shapes as triangle meshes, for scenes built in code, examples and tests.
//!
//! ```
//! use pt_scene::glam::Vec3;
//! use pt_scene::shapes::{cube, quad, sphere};
//!
//! let floor = quad([
//!     Vec3::new(-1.0, 0.0, -1.0),
//!     Vec3::new(-1.0, 0.0, 1.0),
//!     Vec3::new(1.0, 0.0, 1.0),
//!     Vec3::new(1.0, 0.0, -1.0),
//! ]);
//! assert_eq!(floor.geometry().triangle_count(), 2);
//! assert_eq!(cube(1.0, false).geometry().triangle_count(), 12);
//! assert!(sphere(1.0, 8, 16).normals().is_some());
//! ```

use glam::Vec3;
use pt_core::Mesh;
use pt_core::pt_accel::TriangleMesh;

/// A latitude-longitude sphere of `radius` at the origin, `rings` bands from pole to pole and
/// `segments` around, wound outward, with smooth vertex normals (the exact sphere normals).
/// `rings` is at least 2 and `segments` at least 3.
#[must_use]
pub fn sphere(radius: f32, rings: u32, segments: u32) -> Mesh {
    let rings = rings.max(2);
    let segments = segments.max(3);
    let mut positions = vec![Vec3::Y];
    for i in 1..rings {
        let theta = std::f32::consts::PI * i as f32 / rings as f32;
        for j in 0..segments {
            let phi = 2.0 * std::f32::consts::PI * j as f32 / segments as f32;
            positions.push(Vec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                theta.sin() * phi.sin(),
            ));
        }
    }
    let bottom = positions.len() as u32;
    positions.push(Vec3::NEG_Y);
    let ring = |i: u32, j: u32| 1 + (i - 1) * segments + j % segments;
    let mut indices = Vec::new();
    for j in 0..segments {
        indices.push([0, ring(1, j + 1), ring(1, j)]);
        indices.push([bottom, ring(rings - 1, j), ring(rings - 1, j + 1)]);
    }
    for i in 1..rings - 1 {
        for j in 0..segments {
            let (a, b, c, d) = (
                ring(i, j),
                ring(i, j + 1),
                ring(i + 1, j + 1),
                ring(i + 1, j),
            );
            indices.push([a, b, c]);
            indices.push([a, c, d]);
        }
    }
    let normals = positions.clone();
    let positions = positions.into_iter().map(|p| p * radius).collect();
    let geometry = TriangleMesh::new(positions, indices).expect("a valid sphere");
    Mesh::new(geometry)
        .with_normals(normals)
        .expect("one normal per vertex")
}

/// A quad from four corners in order, as two triangles; its front face (the winding normal)
/// follows the right-hand rule. The corners should be coplanar.
///
/// # Panics
///
/// When a corner is not finite (a quad of constants never is).
#[must_use]
pub fn quad(corners: [Vec3; 4]) -> Mesh {
    Mesh::new(
        TriangleMesh::new(corners.to_vec(), vec![[0, 1, 2], [0, 2, 3]])
            .expect("a quad's corners are finite"),
    )
}

/// The six faces of the cube `[-h, h]^3`, each wound so that its normal points outward, or
/// toward the centre when `inward` (a room, a furnace).
///
/// # Panics
///
/// When `h` is not finite.
#[must_use]
pub fn cube(h: f32, inward: bool) -> Mesh {
    let mut positions = Vec::new();
    let mut indices = Vec::new();
    for axis in 0..3 {
        for side in [-1.0f32, 1.0] {
            // Four corners of the face in cyclic order.
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            let mut corners = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)].map(|(a, b)| {
                let mut p = Vec3::ZERO;
                p[axis] = side * h;
                p[u] = a * h;
                p[v] = b * h;
                p
            });
            let n = (corners[1] - corners[0]).cross(corners[2] - corners[0]);
            if (n.dot(-corners[0]) < 0.0) == inward {
                corners.reverse();
            }
            let base = positions.len() as u32;
            positions.extend(corners);
            indices.push([base, base + 1, base + 2]);
            indices.push([base, base + 2, base + 3]);
        }
    }
    Mesh::new(TriangleMesh::new(positions, indices).expect("a cube's corners are finite"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sphere_faces_point_outward() {
        let m = sphere(2.0, 8, 16);
        let g = m.geometry();
        for i in 0..g.triangle_count() {
            let [a, b, c] = g.triangle(i);
            let n = (b - a).cross(c - a);
            assert!(n.dot(a + b + c) > 0.0, "triangle {i} faces inward");
        }
        assert!(
            m.normals()
                .unwrap()
                .iter()
                .all(|n| (n.length() - 1.0).abs() < 1e-5)
        );
    }

    #[test]
    fn cube_faces_point_the_asked_way() {
        for inward in [false, true] {
            let m = cube(2.0, inward);
            let g = m.geometry();
            for t in 0..g.triangle_count() {
                let [a, b, c] = g.triangle(t);
                let n = (b - a).cross(c - a);
                let centre = (a + b + c) / 3.0;
                assert_eq!(n.dot(centre) < 0.0, inward, "triangle {t}");
            }
        }
        let q = quad([Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y]);
        let [a, b, c] = q.geometry().triangle(0);
        assert!((b - a).cross(c - a).z > 0.0);
    }
}
