//! Triangle meshes and instances of them.

use std::fmt;

use glam::{Affine3A, Vec3};

use crate::bounds::Bounds3;

/// An indexed triangle mesh: positions and one `[u32; 3]` per triangle.
///
/// Construction checks that every index is in range. Triangles that are degenerate (zero area)
/// or have a non-finite vertex are kept in the mesh, so triangle ids stay those of the input, but
/// the accelerators skip them and count them (see [`AccelStats`](crate::AccelStats)).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriangleMesh {
    positions: Vec<Vec3>,
    indices: Vec<[u32; 3]>,
}

/// Why a [`TriangleMesh`] could not be built.
#[derive(Clone, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum MeshError {
    /// A triangle refers to a vertex that does not exist.
    IndexOutOfRange {
        /// Triangle number.
        triangle: usize,
        /// The offending index.
        index: u32,
        /// Number of vertices in the mesh.
        vertex_count: usize,
    },
    /// The mesh has more vertices or triangles than a `u32` can index.
    TooLarge,
}

impl fmt::Display for MeshError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::IndexOutOfRange {
                triangle,
                index,
                vertex_count,
            } => write!(
                f,
                "triangle {triangle} uses vertex {index}, but the mesh has {vertex_count} vertices"
            ),
            Self::TooLarge => write!(f, "mesh has more than 2^32 - 1 vertices or triangles"),
        }
    }
}

impl std::error::Error for MeshError {}

impl TriangleMesh {
    /// A mesh from vertex positions and triangles, checking that all indices are in range.
    pub fn new(positions: Vec<Vec3>, indices: Vec<[u32; 3]>) -> Result<Self, MeshError> {
        if positions.len() >= u32::MAX as usize || indices.len() >= u32::MAX as usize {
            return Err(MeshError::TooLarge);
        }
        for (triangle, tri) in indices.iter().enumerate() {
            for &index in tri {
                if index as usize >= positions.len() {
                    return Err(MeshError::IndexOutOfRange {
                        triangle,
                        index,
                        vertex_count: positions.len(),
                    });
                }
            }
        }
        Ok(Self { positions, indices })
    }

    /// A mesh from a flat list of triangle corners (three positions per triangle, no sharing).
    pub fn from_triangles(corners: &[[Vec3; 3]]) -> Result<Self, MeshError> {
        let positions = corners.iter().flatten().copied().collect();
        let n = corners.len() as u32;
        Self::new(
            positions,
            (0..n).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect(),
        )
    }

    /// Vertex positions.
    #[inline]
    #[must_use]
    pub fn positions(&self) -> &[Vec3] {
        &self.positions
    }

    /// Triangles as vertex index triples.
    #[inline]
    #[must_use]
    pub fn indices(&self) -> &[[u32; 3]] {
        &self.indices
    }

    /// Number of triangles.
    #[inline]
    #[must_use]
    pub fn triangle_count(&self) -> usize {
        self.indices.len()
    }

    /// The three corners of triangle `i`.
    ///
    /// # Panics
    /// If `i` is not a triangle of this mesh.
    #[inline]
    #[must_use]
    pub fn triangle(&self, i: usize) -> [Vec3; 3] {
        let [a, b, c] = self.indices[i];
        [
            self.positions[a as usize],
            self.positions[b as usize],
            self.positions[c as usize],
        ]
    }

    /// Bounds of the vertices that are used by triangles and finite.
    #[must_use]
    pub fn bounds(&self) -> Bounds3 {
        Bounds3::from_points(
            self.indices
                .iter()
                .flatten()
                .map(|&i| self.positions[i as usize])
                .filter(|p| p.is_finite()),
        )
    }
}

/// The largest coordinate magnitude a triangle corner may have. Beyond it a BVH's surface-area
/// cost (the square of a box's extent) overflows f32 and the builder's decisions become NaN
/// (obvhs then indexes out of bounds: found by fuzzing the glTF loader), so such triangles are
/// treated like non-finite ones: kept in the mesh, skipped by the accelerators and counted.
/// Scene loaders refuse them with an error.
pub const MAX_COORDINATE: f32 = 1e18;

/// True when a triangle can be hit: all corners finite and within [`MAX_COORDINATE`], and a
/// non-zero area.
#[inline]
#[must_use]
pub fn is_valid_triangle(p: &[Vec3; 3]) -> bool {
    // `<=` is false for NaN, so this also rejects non-finite corners.
    p.iter().all(|v| v.abs().max_element() <= MAX_COORDINATE) && {
        let n = (p[1] - p[0]).cross(p[2] - p[0]);
        n.is_finite() && n != Vec3::ZERO
    }
}

/// The cross product of a triangle's edges, `(p1 - p0) x (p2 - p0)`, in f64: twice its area
/// and its counter-clockwise normal, with no overflow or underflow at any scale pt accepts (in
/// f32 the squared length overflows for triangles 1e11 across and underflows below 1e-11).
#[inline]
#[must_use]
pub fn triangle_cross(p: &[Vec3; 3]) -> glam::DVec3 {
    let [a, b, c] = p.map(|v| v.as_dvec3());
    (b - a).cross(c - a)
}

/// A triangle's unit normal (counter-clockwise winding), or `None` for a degenerate triangle;
/// computed in f64, so right at any scale.
#[inline]
#[must_use]
pub fn triangle_normal(p: &[Vec3; 3]) -> Option<Vec3> {
    let c = triangle_cross(p);
    let len = c.length();
    (len > 0.0 && len.is_finite()).then(|| (c / len).as_vec3())
}

/// One placement of a mesh in the world: a mesh index and an affine object-to-world transform.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Instance {
    /// Index of the mesh in the slice given to [`Accel::build`](crate::Accel::build).
    pub mesh: u32,
    /// Object-to-world transform. Must be invertible.
    pub transform: Affine3A,
}

impl Instance {
    /// The mesh placed with the identity transform.
    #[inline]
    #[must_use]
    pub fn new(mesh: u32) -> Self {
        Self {
            mesh,
            transform: Affine3A::IDENTITY,
        }
    }

    /// The mesh placed with `transform`.
    #[inline]
    #[must_use]
    pub fn with_transform(mesh: u32, transform: Affine3A) -> Self {
        Self { mesh, transform }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_out_of_range_index() {
        let err = TriangleMesh::new(vec![Vec3::ZERO; 3], vec![[0, 1, 3]]).unwrap_err();
        assert_eq!(
            err,
            MeshError::IndexOutOfRange {
                triangle: 0,
                index: 3,
                vertex_count: 3
            }
        );
        assert!(err.to_string().contains("vertex 3"));
    }

    #[test]
    fn degenerate_and_non_finite_triangles_are_invalid() {
        let ok = [Vec3::ZERO, Vec3::X, Vec3::Y];
        assert!(is_valid_triangle(&ok));
        assert!(!is_valid_triangle(&[Vec3::ZERO, Vec3::X, Vec3::X * 2.0]));
        assert!(!is_valid_triangle(&[Vec3::ZERO, Vec3::X, Vec3::NAN]));
        assert!(!is_valid_triangle(&[Vec3::ZERO, Vec3::X, Vec3::Y * 1e19]));
        assert!(is_valid_triangle(&[Vec3::ZERO, Vec3::X, Vec3::Y * 1e18]));
        assert!(!is_valid_triangle(&[
            Vec3::ZERO,
            Vec3::X * f32::MAX,
            Vec3::Y * f32::MAX
        ]));
    }
}
