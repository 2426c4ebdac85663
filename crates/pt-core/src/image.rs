//! Linear RGB images and writing them as PNG (tone-mapped sRGB) or OpenEXR (linear f32).

use std::fmt;
use std::path::{Path, PathBuf};

use crate::color::{Rgb, linear_to_srgb};

/// A linear-light RGB image stored as interleaved `f32` triples, row by row from the top.
///
/// ```
/// use pt_core::{Image, Rgb, ToneMap};
///
/// let mut image = Image::new(4, 2);
/// image.set(3, 1, Rgb::new(0.5, 1.0, 2.0));
/// // The pixels as a flat slice: index 3 * (y * width + x) is the red of pixel (x, y).
/// let data: &[f32] = image.as_slice();
/// assert_eq!(data.len(), 4 * 2 * 3);
/// assert_eq!(&data[3 * (4 + 3)..][..3], &[0.5, 1.0, 2.0]);
/// // Display values: tone-mapped, sRGB-encoded 8-bit RGB.
/// let srgb = image.to_srgb8(ToneMap::Clamp);
/// assert_eq!(&srgb[3 * (4 + 3)..][..3], &[188, 255, 255]);
/// // Wrong buffer sizes are errors, not panics.
/// assert!(Image::from_rgb(4, 2, vec![0.0; 5]).is_err());
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    width: u32,
    height: u32,
    data: Vec<f32>,
}

/// The error of an image against a reference ([`Image::difference`]), averaged over every pixel
/// and channel.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[non_exhaustive]
pub struct ImageDifference {
    /// Relative mean squared error, `(v - r)^2 / (r + 0.01)^2` (pbrt's definition; the 0.01
    /// keeps black pixels from dominating).
    pub rel_mse: f64,
    /// Mean squared error.
    pub mse: f64,
    /// Mean absolute error.
    pub mae: f64,
}

/// How linear radiance is mapped to the displayable range before sRGB encoding.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[non_exhaustive]
pub enum ToneMap {
    /// Clip each channel to `[0, 1]`.
    #[default]
    Clamp,
    /// The ACES filmic curve (Narkowicz's fit): compresses highlights smoothly.
    Aces,
}

impl ToneMap {
    #[inline]
    fn apply(self, v: f32) -> f32 {
        match self {
            Self::Clamp => v.clamp(0.0, 1.0),
            Self::Aces => {
                let v = v.max(0.0);
                ((v * (2.51 * v + 0.03)) / (v * (2.43 * v + 0.59) + 0.14)).clamp(0.0, 1.0)
            }
        }
    }
}

/// Why an image could not be written.
#[derive(Debug)]
#[non_exhaustive]
pub enum ImageError {
    /// The pixel buffer does not hold `width * height * 3` values.
    SizeMismatch {
        /// Expected number of floats.
        expected: usize,
        /// Number given.
        actual: usize,
    },
    /// The file extension is not one this build can write.
    UnsupportedFormat(PathBuf),
    /// Creating or writing the file failed.
    Io {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        source: std::io::Error,
    },
    /// The encoder reported an error.
    Encode {
        /// The file.
        path: PathBuf,
        /// The encoder's message.
        message: String,
    },
    /// A file could not be read as what was asked for (corrupt, or of another kind).
    Decode {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
}

impl fmt::Display for ImageError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::SizeMismatch { expected, actual } => {
                write!(f, "image buffer holds {actual} floats, expected {expected}")
            }
            Self::UnsupportedFormat(p) => write!(
                f,
                "{}: unsupported image format (this build writes {})",
                p.display(),
                supported_formats()
            ),
            Self::Io { path, source } => write!(f, "{}: {source}", path.display()),
            Self::Encode { path, message } | Self::Decode { path, message } => {
                write!(f, "{}: {message}", path.display())
            }
        }
    }
}

impl std::error::Error for ImageError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Self::Io { source, .. } => Some(source),
            _ => None,
        }
    }
}

fn supported_formats() -> &'static str {
    match (cfg!(feature = "png"), cfg!(feature = "exr")) {
        (true, true) => ".png and .exr",
        (true, false) => ".png",
        (false, true) => ".exr",
        (false, false) => "no formats: enable the `png` or `exr` feature",
    }
}

impl Image {
    /// A black image.
    #[must_use]
    pub fn new(width: u32, height: u32) -> Self {
        Self {
            width,
            height,
            data: vec![0.0; width as usize * height as usize * 3],
        }
    }

    /// An image from interleaved RGB floats.
    pub fn from_rgb(width: u32, height: u32, data: Vec<f32>) -> Result<Self, ImageError> {
        let expected = width as usize * height as usize * 3;
        if data.len() != expected {
            return Err(ImageError::SizeMismatch {
                expected,
                actual: data.len(),
            });
        }
        Ok(Self {
            width,
            height,
            data,
        })
    }

    /// Width in pixels.
    #[inline]
    #[must_use]
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    #[inline]
    #[must_use]
    pub fn height(&self) -> u32 {
        self.height
    }

    /// The pixels as interleaved RGB floats, row by row from the top.
    #[inline]
    #[must_use]
    pub fn as_slice(&self) -> &[f32] {
        &self.data
    }

    /// Mutable access to the interleaved RGB floats.
    #[inline]
    #[must_use]
    pub fn as_mut_slice(&mut self) -> &mut [f32] {
        &mut self.data
    }

    /// The pixel buffer, consuming the image.
    #[must_use]
    pub fn into_vec(self) -> Vec<f32> {
        self.data
    }

    /// Ask for the cache lines of pixels `(x, y)` and `(x + 1, y)` (a hint; nothing for pixels
    /// outside the image).
    #[inline]
    pub(crate) fn prefetch_pair(&self, x: u32, y: u32) {
        let i = 3 * (y as usize * self.width as usize + x as usize);
        for k in [i, i + 5] {
            if let Some(v) = self.data.get(k) {
                pt_accel::lanes::prefetch(v);
            }
        }
    }

    /// The pixel at column `x`, row `y` (row 0 at the top).
    ///
    /// # Panics
    /// If the pixel is outside the image.
    #[inline]
    #[must_use]
    pub fn get(&self, x: u32, y: u32) -> Rgb {
        assert!(
            x < self.width && y < self.height,
            "pixel ({x}, {y}) outside {}x{}",
            self.width,
            self.height
        );
        let i = 3 * (y as usize * self.width as usize + x as usize);
        Rgb::new(self.data[i], self.data[i + 1], self.data[i + 2])
    }

    /// Set the pixel at column `x`, row `y`.
    ///
    /// # Panics
    /// If the pixel is outside the image.
    #[inline]
    pub fn set(&mut self, x: u32, y: u32, c: Rgb) {
        assert!(
            x < self.width && y < self.height,
            "pixel ({x}, {y}) outside {}x{}",
            self.width,
            self.height
        );
        let i = 3 * (y as usize * self.width as usize + x as usize);
        self.data[i..i + 3].copy_from_slice(&c.to_array());
    }

    /// Iterate over pixels, row by row.
    pub fn pixels(&self) -> impl Iterator<Item = Rgb> + '_ {
        self.data
            .chunks_exact(3)
            .map(|c| Rgb::new(c[0], c[1], c[2]))
    }

    /// Mean of all pixels (accumulated in f64).
    #[must_use]
    pub fn mean(&self) -> Rgb {
        let n = (self.width as usize * self.height as usize).max(1) as f64;
        let mut s = [0.0f64; 3];
        for c in self.data.chunks_exact(3) {
            for k in 0..3 {
                s[k] += f64::from(c[k]);
            }
        }
        Rgb::new((s[0] / n) as f32, (s[1] / n) as f32, (s[2] / n) as f32)
    }

    /// The error of this image against `reference`, over every pixel and channel: relMSE
    /// (pbrt's definition, `(v - r)^2 / (r + 0.01)^2`), MSE and mean absolute error, in f64.
    /// Fails with [`ImageError::SizeMismatch`] when the sizes differ.
    ///
    /// ```
    /// use pt_core::{Image, Rgb};
    /// let reference = Image::new(2, 1);
    /// let mut image = Image::new(2, 1);
    /// image.set(0, 0, Rgb::splat(0.1));
    /// let d = image.difference(&reference)?;
    /// assert!((d.mae - 0.05).abs() < 1e-7);
    /// assert!((d.rel_mse - 0.5 * 0.01 / 1e-4).abs() < 1e-3); // (0.1 / 0.01)^2 on half the values
    /// # Ok::<(), pt_core::ImageError>(())
    /// ```
    pub fn difference(&self, reference: &Image) -> Result<ImageDifference, ImageError> {
        if (self.width, self.height) != (reference.width, reference.height) {
            return Err(ImageError::SizeMismatch {
                expected: reference.data.len(),
                actual: self.data.len(),
            });
        }
        let (mut rel, mut sq, mut abs) = (0.0f64, 0.0f64, 0.0f64);
        for (&v, &r) in self.data.iter().zip(&reference.data) {
            let (v, r) = (f64::from(v), f64::from(r));
            let d = v - r;
            rel += d * d / ((r + 0.01) * (r + 0.01));
            sq += d * d;
            abs += d.abs();
        }
        let n = self.data.len().max(1) as f64;
        Ok(ImageDifference {
            rel_mse: rel / n,
            mse: sq / n,
            mae: abs / n,
        })
    }

    /// 8-bit sRGB bytes (RGB interleaved) after tone mapping.
    #[must_use]
    pub fn to_srgb8(&self, tone_map: ToneMap) -> Vec<u8> {
        self.data
            .iter()
            .map(|&v| {
                let v = if v.is_finite() { v } else { 0.0 };
                (linear_to_srgb(tone_map.apply(v)) * 255.0 + 0.5) as u8
            })
            .collect()
    }

    /// Write to `path`, choosing the format by extension: `.png` (tone-mapped with
    /// [`ToneMap::Clamp`]) or `.exr` (linear f32).
    pub fn write(&self, path: impl AsRef<Path>) -> Result<(), ImageError> {
        let path = path.as_ref();
        match path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref()
        {
            #[cfg(feature = "png")]
            Some("png") => self.write_png(path),
            #[cfg(feature = "exr")]
            Some("exr") => self.write_exr(path),
            _ => Err(ImageError::UnsupportedFormat(path.to_path_buf())),
        }
    }

    /// Write an 8-bit sRGB PNG, clamping radiance to `[0, 1]`.
    #[cfg(feature = "png")]
    pub fn write_png(&self, path: impl AsRef<Path>) -> Result<(), ImageError> {
        self.write_png_with(path, ToneMap::Clamp)
    }

    /// Write an 8-bit sRGB PNG with the given tone mapping.
    #[cfg(feature = "png")]
    pub fn write_png_with(
        &self,
        path: impl AsRef<Path>,
        tone_map: ToneMap,
    ) -> Result<(), ImageError> {
        let path = path.as_ref();
        let bytes = self.to_srgb8(tone_map);
        let buf = image::RgbImage::from_raw(self.width, self.height, bytes).ok_or_else(|| {
            ImageError::Encode {
                path: path.to_path_buf(),
                message: "pixel buffer size mismatch".into(),
            }
        })?;
        buf.save_with_format(path, image::ImageFormat::Png)
            .map_err(|e| match e {
                image::ImageError::IoError(source) => ImageError::Io {
                    path: path.to_path_buf(),
                    source,
                },
                other => ImageError::Encode {
                    path: path.to_path_buf(),
                    message: other.to_string(),
                },
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pixels_round_trip_and_mean() {
        let mut img = Image::new(3, 2);
        img.set(2, 1, Rgb::new(3.0, 6.0, 9.0));
        assert_eq!(img.get(2, 1), Rgb::new(3.0, 6.0, 9.0));
        assert_eq!(img.as_slice()[15..18], [3.0, 6.0, 9.0]);
        assert_eq!(img.mean(), Rgb::new(0.5, 1.0, 1.5));
        assert!(Image::from_rgb(2, 2, vec![0.0; 11]).is_err());
    }

    #[test]
    fn srgb8_encoding() {
        let img = Image::from_rgb(2, 1, vec![0.0, 0.5, 1.0, 2.0, f32::NAN, -1.0]).unwrap();
        assert_eq!(img.to_srgb8(ToneMap::Clamp), vec![0, 188, 255, 255, 0, 0]);
        assert!(img.to_srgb8(ToneMap::Aces)[3] < 255);
    }

    #[cfg(all(feature = "png", feature = "exr"))]
    #[test]
    fn writes_files_and_reports_bad_paths() {
        let dir = std::env::temp_dir().join(format!("pt-image-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let img = Image::from_rgb(2, 1, vec![0.25, 0.5, 1.0, 4.0, 0.0, 0.1]).unwrap();
        img.write(dir.join("a.png")).unwrap();
        img.write(dir.join("a.exr")).unwrap();
        assert!(std::fs::metadata(dir.join("a.png")).unwrap().len() > 0);
        assert!(std::fs::metadata(dir.join("a.exr")).unwrap().len() > 0);
        assert!(matches!(
            img.write(dir.join("a.bmp")),
            Err(ImageError::UnsupportedFormat(_))
        ));
        let err = img
            .write(dir.join("missing-dir").join("a.png"))
            .unwrap_err();
        assert!(err.to_string().contains("missing-dir"), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
