//! Errors from loading scene files and assets. Every error names the file and, where there is
//! one, the element (line, vertex, face, node, ...).

use std::fmt;
use std::path::PathBuf;

use crate::assets::AssetError;

/// Why a file could not be loaded.
#[derive(Debug)]
#[non_exhaustive]
pub enum LoadError {
    /// The file could not be read.
    Io {
        /// The file.
        path: PathBuf,
        /// What the OS said.
        source: std::io::Error,
    },
    /// The file is malformed: bad syntax, truncated data, inconsistent header.
    Parse {
        /// The file.
        path: PathBuf,
        /// Where: "header line 3", "line 120", "face 17", ...
        location: String,
        /// What is wrong.
        message: String,
    },
    /// The file is well formed but uses something pt does not support.
    Unsupported {
        /// The file.
        path: PathBuf,
        /// What is not supported.
        what: String,
    },
    /// The data is well formed but unusable: out-of-range indices, non-finite coordinates, ...
    Invalid {
        /// The file.
        path: PathBuf,
        /// The element: "vertex 12", "face 7", ...
        element: String,
        /// What is wrong with it.
        message: String,
    },
    /// A named asset could not be found.
    Asset(AssetError),
    /// Loading would exceed one of the [`Limits`](crate::Limits).
    Limit {
        /// The file.
        path: PathBuf,
        /// The element: "image 3", "buffer 0", "nodes", ...
        element: String,
        /// The limit's field name in [`Limits`](crate::Limits).
        limit: &'static str,
        /// What the file needs.
        value: u64,
        /// The limit.
        max: u64,
    },
}

impl LoadError {
    pub(crate) fn parse(
        path: impl Into<PathBuf>,
        location: impl Into<String>,
        message: impl Into<String>,
    ) -> Self {
        Self::Parse {
            path: path.into(),
            location: location.into(),
            message: message.into(),
        }
    }

    pub(crate) fn invalid(
        path: impl Into<PathBuf>,
        element: impl Into<String>,
        message: impl Into<String>,
    ) -> Self {
        Self::Invalid {
            path: path.into(),
            element: element.into(),
            message: message.into(),
        }
    }
}

impl fmt::Display for LoadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Io { path, source } => write!(f, "{}: {source}", path.display()),
            Self::Parse {
                path,
                location,
                message,
            } => write!(f, "{}: {location}: {message}", path.display()),
            Self::Unsupported { path, what } => {
                write!(f, "{}: unsupported: {what}", path.display())
            }
            Self::Invalid {
                path,
                element,
                message,
            } => write!(f, "{}: {element}: {message}", path.display()),
            Self::Asset(e) => e.fmt(f),
            Self::Limit {
                path,
                element,
                limit,
                value,
                max,
            } => write!(
                f,
                "{}: {element}: needs {value}, above the limit {limit} = {max} (raise it with \
                 pt_scene::Limits::{limit})",
                path.display()
            ),
        }
    }
}

impl std::error::Error for LoadError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Self::Io { source, .. } => Some(source),
            Self::Asset(e) => Some(e),
            _ => None,
        }
    }
}

impl From<AssetError> for LoadError {
    fn from(e: AssetError) -> Self {
        Self::Asset(e)
    }
}

/// What is wrong with a vertex position, if anything: not finite, or beyond the coordinates
/// an accelerator can handle ([`pt_core::pt_accel::MAX_COORDINATE`]).
pub(crate) fn position_problem(p: pt_core::glam::Vec3) -> Option<String> {
    if !p.is_finite() {
        Some(format!("position {p} is not finite"))
    } else if p.abs().max_element() > pt_core::pt_accel::MAX_COORDINATE {
        Some(format!(
            "position {p} is beyond +-{:e}, the largest coordinate pt can trace",
            pt_core::pt_accel::MAX_COORDINATE
        ))
    } else {
        None
    }
}
