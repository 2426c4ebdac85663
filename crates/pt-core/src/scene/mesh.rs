//! Meshes with shading attributes.

use glam::{Vec2, Vec3};
use pt_accel::TriangleMesh;

use crate::scene::SceneError;

/// A triangle mesh with optional per-vertex shading normals and texture coordinates.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    geometry: TriangleMesh,
    normals: Option<Vec<Vec3>>,
    uvs: Option<Vec<Vec2>>,
}

impl Mesh {
    /// A mesh with positions only (shading uses the geometric normal).
    #[must_use]
    pub fn new(geometry: TriangleMesh) -> Self {
        Self {
            geometry,
            normals: None,
            uvs: None,
        }
    }

    /// Attach per-vertex shading normals (one per position; need not be unit length; a zero
    /// normal falls back to the geometric normal). Non-finite normals are refused.
    pub fn with_normals(mut self, normals: Vec<Vec3>) -> Result<Self, SceneError> {
        if normals.len() != self.geometry.positions().len() {
            return Err(SceneError::AttributeCount {
                attribute: "normals",
                expected: self.geometry.positions().len(),
                actual: normals.len(),
            });
        }
        if let Some(vertex) = normals.iter().position(|n| !n.is_finite()) {
            return Err(SceneError::NonFiniteAttribute {
                attribute: "normals",
                vertex,
            });
        }
        self.normals = Some(normals);
        Ok(self)
    }

    /// Attach smooth shading normals computed from the geometry: each vertex gets the sum of the
    /// face normals around it weighted by face area (the unnormalised cross products). Vertices of
    /// degenerate faces only keep the geometric normal. For meshes scanned without normals (the
    /// Stanford bunny and dragon), this is what makes a mirror or glass surface look smooth.
    #[must_use]
    pub fn with_smooth_normals(mut self) -> Self {
        let positions = self.geometry.positions();
        // Area-weighted sums in f64, so that neither tiny nor huge meshes lose their normals.
        let mut sums = vec![glam::DVec3::ZERO; positions.len()];
        for &[a, b, c] in self.geometry.indices() {
            let p = [a, b, c].map(|i| positions[i as usize]);
            let n = pt_accel::triangle_cross(&p);
            if !n.is_finite() {
                continue;
            }
            for i in [a, b, c] {
                sums[i as usize] += n;
            }
        }
        let normals = sums
            .into_iter()
            .map(|n| n.normalize_or_zero().as_vec3())
            .collect();
        self.normals = Some(normals);
        self
    }

    /// Attach per-vertex texture coordinates (one per position). Non-finite ones are refused.
    pub fn with_uvs(mut self, uvs: Vec<Vec2>) -> Result<Self, SceneError> {
        if uvs.len() != self.geometry.positions().len() {
            return Err(SceneError::AttributeCount {
                attribute: "uvs",
                expected: self.geometry.positions().len(),
                actual: uvs.len(),
            });
        }
        if let Some(vertex) = uvs.iter().position(|t| !t.is_finite()) {
            return Err(SceneError::NonFiniteAttribute {
                attribute: "texture coordinates",
                vertex,
            });
        }
        self.uvs = Some(uvs);
        Ok(self)
    }

    /// Positions and triangles.
    #[inline]
    #[must_use]
    pub fn geometry(&self) -> &TriangleMesh {
        &self.geometry
    }

    /// Per-vertex shading normals, if any.
    #[inline]
    #[must_use]
    pub fn normals(&self) -> Option<&[Vec3]> {
        self.normals.as_deref()
    }

    /// Per-vertex texture coordinates, if any.
    #[inline]
    #[must_use]
    pub fn uvs(&self) -> Option<&[Vec2]> {
        self.uvs.as_deref()
    }
}

impl From<TriangleMesh> for Mesh {
    fn from(geometry: TriangleMesh) -> Self {
        Self::new(geometry)
    }
}

impl AsRef<TriangleMesh> for Mesh {
    fn as_ref(&self) -> &TriangleMesh {
        &self.geometry
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn smooth_normals_average_adjacent_faces() {
        // Two faces folded 90 degrees along the x axis: the shared vertices get the diagonal.
        let g = TriangleMesh::new(
            vec![
                Vec3::ZERO,
                Vec3::X,
                Vec3::new(0.0, 0.0, -1.0),
                Vec3::new(0.0, 1.0, 0.0),
            ],
            vec![[0, 1, 2], [0, 1, 3]],
        )
        .unwrap();
        let m = Mesh::new(g).with_smooth_normals();
        let n = m.normals().unwrap();
        let diag = Vec3::new(0.0, 1.0, 1.0).normalize();
        assert!((n[0] - diag).length() < 1e-6 && (n[1] - diag).length() < 1e-6);
        assert!((n[2] - Vec3::Y).length() < 1e-6);
        assert!((n[3] - Vec3::Z).length() < 1e-6);
    }
}
