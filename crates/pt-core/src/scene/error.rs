//! Why a scene could not be built.

use std::fmt;

use pt_accel::MeshError;

/// Why a scene could not be built.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum SceneError {
    /// An object refers to a mesh that was not added.
    MeshOutOfRange {
        /// Object index.
        object: usize,
        /// The mesh it names.
        mesh: u32,
    },
    /// An object refers to a material that was not added.
    MaterialOutOfRange {
        /// Object index.
        object: usize,
        /// The material it names.
        material: u32,
    },
    /// An object's transform is not finite or not invertible.
    InvalidTransform {
        /// Object index.
        object: usize,
    },
    /// An object's emitted radiance is negative or not finite.
    InvalidEmission {
        /// Object index.
        object: usize,
    },
    /// A per-vertex attribute has the wrong number of entries.
    AttributeCount {
        /// Which attribute.
        attribute: &'static str,
        /// One per vertex.
        expected: usize,
        /// What was given.
        actual: usize,
    },
    /// A per-vertex attribute holds a NaN or infinite value.
    NonFiniteAttribute {
        /// Which attribute.
        attribute: &'static str,
        /// The first vertex with a non-finite value.
        vertex: usize,
    },
    /// A texture-coordinate set beyond the ones a mesh can carry.
    UvSet {
        /// The set asked for.
        set: usize,
        /// The number of sets supported.
        max: usize,
    },
    /// A mesh is malformed.
    Mesh(MeshError),
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::MeshOutOfRange { object, mesh } => {
                write!(f, "object {object} uses mesh {mesh}, which does not exist")
            }
            Self::MaterialOutOfRange { object, material } => {
                write!(
                    f,
                    "object {object} uses material {material}, which does not exist"
                )
            }
            Self::InvalidTransform { object } => {
                write!(
                    f,
                    "object {object} has a transform that is not finite or not invertible"
                )
            }
            Self::InvalidEmission { object } => {
                write!(
                    f,
                    "object {object} has emitted radiance that is negative or not finite"
                )
            }
            Self::AttributeCount {
                attribute,
                expected,
                actual,
            } => write!(
                f,
                "mesh has {actual} {attribute}, expected one per vertex ({expected})"
            ),
            Self::NonFiniteAttribute { attribute, vertex } => write!(
                f,
                "mesh {attribute} of vertex {vertex} are not finite (NaN or infinite)"
            ),
            Self::UvSet { set, max } => write!(
                f,
                "texture-coordinate set {set} is not supported (sets 0 to {} are)",
                max - 1
            ),
            Self::Mesh(e) => write!(f, "invalid mesh: {e}"),
        }
    }
}

impl std::error::Error for SceneError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Self::Mesh(e) => Some(e),
            _ => None,
        }
    }
}

impl From<MeshError> for SceneError {
    fn from(e: MeshError) -> Self {
        Self::Mesh(e)
    }
}
