//! Why a light cannot be made from the given data.

use std::fmt;

/// A light (environment map, punctual light) that cannot be made from the given data.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum LightError {
    /// The image has no texels, or cube faces are not square or not all the same size.
    BadSize(String),
    /// A texel is negative or not finite (the first one found).
    BadTexel {
        /// Which image (face name for cube maps).
        image: &'static str,
        /// Column.
        x: u32,
        /// Row.
        y: u32,
    },
    /// The intensity scale or rotation is not usable.
    BadParameter(String),
}

impl fmt::Display for LightError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::BadSize(s) => write!(f, "environment map: {s}"),
            Self::BadTexel { image, x, y } => write!(
                f,
                "environment map: texel ({x}, {y}) of {image} is negative or not finite"
            ),
            Self::BadParameter(s) => write!(f, "light: {s}"),
        }
    }
}

impl std::error::Error for LightError {}
