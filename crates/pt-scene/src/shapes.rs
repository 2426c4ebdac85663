//! Simple shapes as triangle meshes, for examples and tests.

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
}
