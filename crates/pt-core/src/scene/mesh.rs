//! Meshes with shading attributes.

use glam::{Vec2, Vec3, Vec4};
use pt_accel::TriangleMesh;

use crate::scene::SceneError;

/// The number of texture-coordinate sets a mesh can carry (glTF's `TEXCOORD_0` to `TEXCOORD_3`).
pub const MAX_UV_SETS: usize = 4;

/// A triangle mesh with optional per-vertex shading attributes: normals, texture coordinates
/// (up to [`MAX_UV_SETS`] sets), colours and tangents.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    geometry: TriangleMesh,
    normals: Option<Vec<Vec3>>,
    /// Set `i` at index `i`; `None` for sets not given.
    uv_sets: Vec<Option<Vec<Vec2>>>,
    colors: Option<Vec<Vec4>>,
    tangents: Option<Vec<Vec4>>,
}

impl Mesh {
    /// A mesh with positions only (shading uses the geometric normal).
    #[must_use]
    pub fn new(geometry: TriangleMesh) -> Self {
        Self {
            geometry,
            normals: None,
            uv_sets: Vec::new(),
            colors: None,
            tangents: None,
        }
    }

    /// Checks one value per vertex, all finite.
    fn check<T: Copy>(
        &self,
        attribute: &'static str,
        values: &[T],
        finite: impl Fn(T) -> bool,
    ) -> Result<(), SceneError> {
        if values.len() != self.geometry.positions().len() {
            return Err(SceneError::AttributeCount {
                attribute,
                expected: self.geometry.positions().len(),
                actual: values.len(),
            });
        }
        if let Some(vertex) = values.iter().position(|&v| !finite(v)) {
            return Err(SceneError::NonFiniteAttribute { attribute, vertex });
        }
        Ok(())
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

    /// Attach per-vertex texture coordinates (one per position) as set 0. Non-finite ones are
    /// refused.
    pub fn with_uvs(self, uvs: Vec<Vec2>) -> Result<Self, SceneError> {
        self.with_uv_set(0, uvs)
    }

    /// Attach texture-coordinate set `set` (glTF's `TEXCOORD_<set>`, below [`MAX_UV_SETS`]),
    /// one per position. Non-finite coordinates and sets out of range are refused.
    pub fn with_uv_set(mut self, set: usize, uvs: Vec<Vec2>) -> Result<Self, SceneError> {
        if set >= MAX_UV_SETS {
            return Err(SceneError::UvSet {
                set,
                max: MAX_UV_SETS,
            });
        }
        self.check("texture coordinates", &uvs, Vec2::is_finite)?;
        if self.uv_sets.len() <= set {
            self.uv_sets.resize(set + 1, None);
        }
        self.uv_sets[set] = Some(uvs);
        Ok(self)
    }

    /// Attach per-vertex linear RGBA colours (glTF's `COLOR_0`), one per position. Non-finite
    /// ones are refused.
    pub fn with_colors(mut self, colors: Vec<Vec4>) -> Result<Self, SceneError> {
        self.check("colours", &colors, Vec4::is_finite)?;
        self.colors = Some(colors);
        Ok(self)
    }

    /// Attach per-vertex tangents, one per position: `xyz` the direction of increasing `u` of
    /// texture-coordinate set 0 (need not be unit length) and `w` (`+1` or `-1`) the handedness,
    /// so that the bitangent is `w * cross(normal, tangent)`, as in glTF. Non-finite ones are
    /// refused.
    pub fn with_tangents(mut self, tangents: Vec<Vec4>) -> Result<Self, SceneError> {
        self.check("tangents", &tangents, Vec4::is_finite)?;
        self.tangents = Some(tangents);
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

    /// Per-vertex texture coordinates of set 0, if any.
    #[inline]
    #[must_use]
    pub fn uvs(&self) -> Option<&[Vec2]> {
        self.uv_set(0)
    }

    /// Per-vertex texture coordinates of set `set`, if given.
    #[inline]
    #[must_use]
    pub fn uv_set(&self, set: usize) -> Option<&[Vec2]> {
        self.uv_sets.get(set).and_then(Option::as_deref)
    }

    /// Per-vertex linear RGBA colours, if any.
    #[inline]
    #[must_use]
    pub fn colors(&self) -> Option<&[Vec4]> {
        self.colors.as_deref()
    }

    /// Per-vertex tangents with handedness in `w`, if any.
    #[inline]
    #[must_use]
    pub fn tangents(&self) -> Option<&[Vec4]> {
        self.tangents.as_deref()
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
