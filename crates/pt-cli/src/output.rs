//! Writing a finished render: the image, the auxiliary outputs asked for (`--aov`), and the
//! denoised image (`--denoise`) beside the unbiased one.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use pt_core::color::srgb_to_linear;
use pt_core::{Aovs, Denoiser, Image, RenderOutput};

use crate::Failure;

/// The lowercase extension of `path`.
fn extension(path: &Path) -> Option<String> {
    path.extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
}

/// `path` with `.TAG` before its extension: `out/box.png` -> `out/box.TAG.png`.
#[must_use]
pub fn tagged(path: &Path, tag: &str) -> PathBuf {
    let stem = path.file_stem().unwrap_or_default().to_string_lossy();
    let name = match extension(path) {
        Some(ext) => format!("{stem}.{tag}.{ext}"),
        None => format!("{stem}.{tag}"),
    };
    path.with_file_name(name)
}

/// Write the render's image to `path` (`.png` or `.exr`) with the AOVs of `aovs` that it has:
/// as layers of an EXR (`albedo.{R,G,B}`, `normal.{X,Y,Z}`), or beside a PNG as
/// `NAME.albedo.png` and `NAME.normal.png` (the normal encoded as `(n + 1) / 2`, the usual
/// normal-map colours). Returns the files written.
///
/// # Errors
///
/// A [`Failure`] (exit code 1) naming the file that could not be written.
pub fn write_render(out: &RenderOutput, path: &Path, aovs: Aovs) -> Result<Vec<PathBuf>, Failure> {
    let albedo = out.albedo.as_ref().filter(|_| aovs.albedo);
    let normal = out.normal.as_ref().filter(|_| aovs.normal);
    if extension(path).as_deref() == Some("exr") {
        let mut layered = out.clone();
        layered.albedo = albedo.cloned();
        layered.normal = normal.cloned();
        layered.write_exr(path).map_err(Failure::run)?;
        return Ok(vec![path.to_path_buf()]);
    }
    out.image.write(path).map_err(Failure::run)?;
    let mut written = vec![path.to_path_buf()];
    if let Some(albedo) = albedo {
        let p = tagged(path, "albedo");
        albedo.write(&p).map_err(Failure::run)?;
        written.push(p);
    }
    if let Some(normal) = normal {
        let p = tagged(path, "normal");
        normal_preview(normal).write(&p).map_err(Failure::run)?;
        written.push(p);
    }
    Ok(written)
}

/// A normal image as colours `(n + 1) / 2`, stored so that the sRGB encoding of an 8-bit
/// file gives exactly those values.
fn normal_preview(normal: &Image) -> Image {
    let mut image = normal.clone();
    for v in image.as_mut_slice() {
        *v = srgb_to_linear((0.5 * *v + 0.5).clamp(0.0, 1.0));
    }
    image
}

/// Denoise the render (guided by its albedo and normal when it has them) and write the result
/// as `NAME.denoised.EXT` beside `path`. Returns where it went and the time the pass took.
///
/// # Errors
///
/// A [`Failure`] (exit code 1): OIDN missing or failing, or the file not written.
pub fn write_denoised(
    image: &Image,
    albedo: Option<&Image>,
    normal: Option<&Image>,
    path: &Path,
) -> Result<(PathBuf, Duration), Failure> {
    let start = Instant::now();
    let denoised = Denoiser::new()
        .and_then(|d| d.denoise(image, albedo, normal))
        .map_err(|e| Failure::run(format!("--denoise: {e}")))?;
    let took = start.elapsed();
    let p = tagged(path, "denoised");
    denoised.write(&p).map_err(Failure::run)?;
    Ok((p, took))
}

/// Check before any work that `--denoise` can run: the library loads and makes a device.
///
/// # Errors
///
/// A [`Failure`] (exit code 2) saying why not.
pub fn check_denoiser() -> Result<(), Failure> {
    Denoiser::new()
        .map(drop)
        .map_err(|e| Failure::usage(format!("--denoise: {e}")))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tagged_names() {
        assert_eq!(
            tagged(Path::new("out/box.png"), "denoised"),
            PathBuf::from("out/box.denoised.png")
        );
        assert_eq!(
            tagged(Path::new("a.b.EXR"), "albedo"),
            PathBuf::from("a.b.albedo.exr")
        );
    }

    #[test]
    fn normal_preview_encodes_half_plus_half() {
        let n = Image::from_rgb(1, 1, vec![-1.0, 0.0, 1.0]).unwrap();
        let bytes = normal_preview(&n).to_srgb8(pt_core::ToneMap::Clamp);
        assert_eq!(bytes, vec![0, 128, 255]);
    }
}
