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

    /// Attach per-vertex shading normals (one per position; need not be unit length).
    pub fn with_normals(mut self, normals: Vec<Vec3>) -> Result<Self, SceneError> {
        if normals.len() != self.geometry.positions().len() {
            return Err(SceneError::AttributeCount {
                attribute: "normals",
                expected: self.geometry.positions().len(),
                actual: normals.len(),
            });
        }
        self.normals = Some(normals);
        Ok(self)
    }

    /// Attach per-vertex texture coordinates (one per position).
    pub fn with_uvs(mut self, uvs: Vec<Vec2>) -> Result<Self, SceneError> {
        if uvs.len() != self.geometry.positions().len() {
            return Err(SceneError::AttributeCount {
                attribute: "uvs",
                expected: self.geometry.positions().len(),
                actual: uvs.len(),
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
