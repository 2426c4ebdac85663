//! [`Error`]: every error of the pt crates in one type, for programs that use `?` across them.

use std::fmt;

use pt_accel::MeshError;
use pt_core::{
    CameraError, ImageError, LightError, MaterialError, MergeError, OptionsError, RenderError,
    SceneError,
};
use pt_scene::{AssetError, LoadError};

/// Any error of the pt crates: each variant holds the crate's own error, which names the file,
/// object or option and the problem. Every crate error converts into it, so `?` works across
/// loading, building, rendering and writing.
///
/// ```no_run
/// use pt::prelude::*;
///
/// fn run() -> Result<(), pt::Error> {
///     let bundle = load_scene("model.glb")?.build(&BuildOptions::default())?; // LoadError
///     let out = bundle.render(&RenderOptions::new(64, 64).spp(4), None)?; // RenderError
///     out.image.write_png("model.png")?; // ImageError
///     Ok(())
/// }
/// # run().unwrap();
/// ```
#[derive(Debug)]
#[non_exhaustive]
pub enum Error {
    /// A scene file or asset could not be loaded (`pt_scene`).
    Load(LoadError),
    /// A known asset could not be found or fetched (`pt_scene::assets`).
    Asset(AssetError),
    /// A scene built in code is invalid (`pt_core::SceneBuilder::build`).
    Scene(SceneError),
    /// A mesh is invalid (`pt_accel::TriangleMesh::new`).
    Mesh(MeshError),
    /// A material parameter is out of range.
    Material(MaterialError),
    /// A light cannot be made from its data.
    Light(LightError),
    /// A camera cannot be made from its parameters.
    Camera(CameraError),
    /// A render could not run (options out of range, cancelled, no threads).
    Render(RenderError),
    /// Partial renders could not be merged.
    Merge(MergeError),
    /// An image could not be read, written or compared.
    Image(ImageError),
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Load(e) => e.fmt(f),
            Self::Asset(e) => e.fmt(f),
            Self::Scene(e) => e.fmt(f),
            Self::Mesh(e) => e.fmt(f),
            Self::Material(e) => e.fmt(f),
            Self::Light(e) => e.fmt(f),
            Self::Camera(e) => e.fmt(f),
            Self::Render(e) => e.fmt(f),
            Self::Merge(e) => e.fmt(f),
            Self::Image(e) => e.fmt(f),
        }
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        Some(match self {
            Self::Load(e) => e,
            Self::Asset(e) => e,
            Self::Scene(e) => e,
            Self::Mesh(e) => e,
            Self::Material(e) => e,
            Self::Light(e) => e,
            Self::Camera(e) => e,
            Self::Render(e) => e,
            Self::Merge(e) => e,
            Self::Image(e) => e,
        })
    }
}

/// `From` for each crate error.
macro_rules! from_errors {
    ($($variant:ident($ty:ty)),+ $(,)?) => {
        $(
            impl From<$ty> for Error {
                fn from(e: $ty) -> Self {
                    Self::$variant(e)
                }
            }
        )+
    };
}

from_errors!(
    Load(LoadError),
    Asset(AssetError),
    Scene(SceneError),
    Mesh(MeshError),
    Material(MaterialError),
    Light(LightError),
    Camera(CameraError),
    Render(RenderError),
    Merge(MergeError),
    Image(ImageError),
);

impl From<OptionsError> for Error {
    fn from(e: OptionsError) -> Self {
        Self::Render(RenderError::InvalidOptions(e))
    }
}

/// `Result` with [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_crate_error_converts_and_keeps_its_message() {
        let options = pt_core::RenderOptions::new(0, 4).validate().unwrap_err();
        let e: Error = options.clone().into();
        assert!(matches!(e, Error::Render(RenderError::InvalidOptions(_))));
        assert!(e.to_string().contains("0x4"), "{e}");
        assert!(std::error::Error::source(&e).is_some());
        let mesh = pt_accel::TriangleMesh::new(vec![], vec![[0, 1, 2]]).unwrap_err();
        let text = mesh.to_string();
        let e: Error = mesh.into();
        assert_eq!(e.to_string(), text);
    }
}
