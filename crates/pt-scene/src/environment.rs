//! Environment maps from files: equirectangular Radiance `.hdr` and OpenEXR `.exr` maps, and
//! six-face cube maps (any format the `image` crate decodes here: JPEG, PNG, HDR, EXR).
//!
//! Float images (HDR, EXR) are taken as linear RGB. 8- and 16-bit images are sRGB-encoded and
//! are decoded to linear with the sRGB transfer curve. Alpha is ignored. See
//! [`pt_core::light`] for the mapping of directions to texels.

use std::path::{Path, PathBuf};

use pt_core::Image;
use pt_core::color::{srgb_to_linear, srgb8_to_linear};
use pt_core::light::{CUBE_FACES, CubemapEnvironment, EquirectEnvironment, LightError};

use crate::assets::find_asset;
use crate::error::LoadError;
use crate::limits::Limits;

/// Decode an image file to linear RGB.
pub fn load_image_linear(path: impl AsRef<Path>) -> Result<Image, LoadError> {
    load_image_linear_with(path, &Limits::default())
}

/// [`load_image_linear`] within `limits`: a regular file of at most `max_file_bytes`, whose
/// header declares at most `max_image_pixels` pixels (checked before decoding).
pub fn load_image_linear_with(path: impl AsRef<Path>, limits: &Limits) -> Result<Image, LoadError> {
    let path = path.as_ref();
    let bytes = limits.read_file(path)?;
    let header = image::ImageReader::new(std::io::Cursor::new(&bytes))
        .with_guessed_format()
        .map_err(|source| LoadError::Io {
            path: path.to_path_buf(),
            source,
        })?;
    if header.format().is_some() {
        let (w, h) = header
            .into_dimensions()
            .map_err(|e| LoadError::parse(path, "image header", e.to_string()))?;
        let pixels = u64::from(w) * u64::from(h);
        Limits::check(
            path,
            format!("a {w}x{h} image"),
            "max_image_pixels",
            pixels,
            limits.max_image_pixels,
        )?;
    }
    let mut reader = image::ImageReader::new(std::io::Cursor::new(&bytes));
    // The pixel limit above is what bounds memory; the crate's own allocation limit (512 MB)
    // would refuse large float maps that the pixel limit allows.
    reader.no_limits();
    let reader = reader
        .with_guessed_format()
        .map_err(|source| LoadError::Io {
            path: path.to_path_buf(),
            source,
        })?;
    if reader.format().is_none() {
        return Err(LoadError::Unsupported {
            path: path.to_path_buf(),
            what: "an image format pt cannot read (use .hdr, .exr, .jpg or .png)".into(),
        });
    }
    let img = reader.decode().map_err(|e| match e {
        image::ImageError::IoError(source)
            if source.kind() == std::io::ErrorKind::UnexpectedEof =>
        {
            LoadError::parse(
                path,
                "image data",
                "the file is truncated: its pixels end early",
            )
        }
        image::ImageError::IoError(source) => LoadError::Io {
            path: path.to_path_buf(),
            source,
        },
        image::ImageError::Unsupported(u) => LoadError::Unsupported {
            path: path.to_path_buf(),
            what: u.to_string(),
        },
        other => LoadError::parse(path, "image data", other.to_string()),
    })?;
    let (w, h) = (img.width(), img.height());
    let linear = matches!(
        img,
        image::DynamicImage::ImageRgb32F(_) | image::DynamicImage::ImageRgba32F(_)
    );
    // (Grey images keep the float path: `image` widens grey to float with its own rounding,
    // a few ulps from `v / 255`.)
    let eight_bit = matches!(
        img,
        image::DynamicImage::ImageRgb8(_) | image::DynamicImage::ImageRgba8(_)
    );
    let data: Vec<f32> = if linear {
        img.into_rgb32f().into_raw()
    } else if eight_bit {
        // The common case (JPEG and 8-bit PNG faces) by table, not a powf per channel: the
        // same values (`srgb8_to_linear` is `srgb_to_linear(v / 255)`), a tenth of the time.
        img.into_rgb8()
            .into_raw()
            .into_iter()
            .map(srgb8_to_linear)
            .collect()
    } else {
        img.into_rgb32f()
            .into_raw()
            .into_iter()
            .map(srgb_to_linear)
            .collect()
    };
    Image::from_rgb(w, h, data).map_err(|e| LoadError::invalid(path, "image", e.to_string()))
}

fn env_error(path: &Path, e: LightError) -> LoadError {
    match e {
        LightError::BadTexel { x, y, .. } => LoadError::invalid(
            path,
            format!("texel ({x}, {y})"),
            "negative or not finite radiance",
        ),
        // The light's own message already says "environment map: ..."; not twice.
        LightError::BadSize(s) | LightError::BadParameter(s) => {
            LoadError::invalid(path, "environment map", s)
        }
        other => LoadError::invalid(path, "environment map", other.to_string()),
    }
}

/// Load an equirectangular (latitude-longitude) environment map from a `.hdr` or `.exr` file
/// (an 8-bit image also works, decoded from sRGB).
pub fn load_equirect(path: impl AsRef<Path>) -> Result<EquirectEnvironment, LoadError> {
    let path = path.as_ref();
    let image = load_image_linear(path)?;
    EquirectEnvironment::new(image).map_err(|e| env_error(path, e))
}

/// The file of cube face `name` (`px`, `nx`, ...) in `dir`, whatever its extension.
fn face_file(dir: &Path, name: &str) -> Result<PathBuf, LoadError> {
    for ext in ["jpg", "jpeg", "png", "hdr", "exr"] {
        let p = dir.join(format!("{name}.{ext}"));
        if p.is_file() {
            return Ok(p);
        }
    }
    Err(LoadError::invalid(
        dir,
        format!("cube face {name}"),
        format!("no {name}.jpg, {name}.png, {name}.hdr or {name}.exr in the directory"),
    ))
}

/// Load a cube map from a directory holding the six faces `px nx py ny pz nz` (any of the
/// extensions `.jpg`, `.jpeg`, `.png`, `.hdr`, `.exr`), in the OpenGL cube-map layout.
pub fn load_cubemap(dir: impl AsRef<Path>) -> Result<CubemapEnvironment, LoadError> {
    let dir = dir.as_ref();
    let mut faces: Vec<Image> = Vec::with_capacity(6);
    for name in CUBE_FACES {
        faces.push(load_image_linear(face_file(dir, name)?)?);
    }
    let faces: [Image; 6] = faces
        .try_into()
        .map_err(|_| LoadError::invalid(dir, "cube map", "six faces are needed"))?;
    CubemapEnvironment::new(faces).map_err(|e| env_error(dir, e))
}

/// [`load_equirect`] for a named asset such as `"env/venice_sunset_1k.hdr"`.
pub fn load_equirect_asset(name: &str) -> Result<EquirectEnvironment, LoadError> {
    load_equirect(find_asset(name).map_err(LoadError::Asset)?)
}

/// [`load_cubemap`] for a named asset directory such as `"env/cubemap-Park3Med"`.
pub fn load_cubemap_asset(dir: &str) -> Result<CubemapEnvironment, LoadError> {
    let face = find_asset(&format!("{dir}/px.jpg")).map_err(LoadError::Asset)?;
    let parent = face.parent().map(Path::to_path_buf).unwrap_or_default();
    load_cubemap(parent)
}
