//! Limits on what loading a scene may cost, so that no file can exhaust memory or time.
//!
//! Every loader checks these before it allocates: the size of each file it reads (a file is
//! read only up to what it declares, and devices, FIFOs and directories are refused), the
//! pixels of each image (from its header, before decoding: a 389 KB PNG can claim 20000x20000
//! pixels, 4.8 GB once expanded to linear float RGB), the instances a node graph places (a
//! graph whose nodes share children can place exponentially many), and the triangles. The
//! defaults are far above any real scene; exceeding one is a [`LoadError::Limit`] naming the
//! file, the element, the limit and its value, and how to raise it.

use std::io::Read;
use std::path::Path;

use crate::error::LoadError;

/// Bounds on the resources one scene load may use. `Limits::default()` is what
/// [`load_scene`](crate::load_scene) and the other loaders use;
/// [`load_scene_with`](crate::load_scene_with) takes others.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub struct Limits {
    /// Bytes read from any one file: a scene file, a glTF buffer, an MTL file, an image.
    /// Default 4 GiB.
    pub max_file_bytes: u64,
    /// Pixels of any one decoded image (texture, environment map, cube face): 16 bytes each
    /// once decoded. Default 2^28 (16384 x 16384, 4 GiB decoded).
    pub max_image_pixels: u64,
    /// Instances a glTF node graph may place. Default 2^24 (16.7 million).
    pub max_instances: usize,
    /// Triangles in all the meshes of a file. Default 2^28 (268 million, about 10 GiB of
    /// vertices and indices).
    pub max_triangles: usize,
}

impl Default for Limits {
    fn default() -> Self {
        Self {
            max_file_bytes: 4 << 30,
            max_image_pixels: 1 << 28,
            max_instances: 1 << 24,
            max_triangles: 1 << 28,
        }
    }
}

impl Limits {
    /// Set [`max_file_bytes`](Self::max_file_bytes).
    #[must_use]
    pub fn max_file_bytes(mut self, bytes: u64) -> Self {
        self.max_file_bytes = bytes;
        self
    }

    /// Set [`max_image_pixels`](Self::max_image_pixels).
    #[must_use]
    pub fn max_image_pixels(mut self, pixels: u64) -> Self {
        self.max_image_pixels = pixels;
        self
    }

    /// Set [`max_instances`](Self::max_instances).
    #[must_use]
    pub fn max_instances(mut self, instances: usize) -> Self {
        self.max_instances = instances;
        self
    }

    /// Set [`max_triangles`](Self::max_triangles).
    #[must_use]
    pub fn max_triangles(mut self, triangles: usize) -> Self {
        self.max_triangles = triangles;
        self
    }

    /// An error if `value` exceeds `max` of the limit `name`.
    pub(crate) fn check(
        path: &Path,
        element: impl Into<String>,
        name: &'static str,
        value: u64,
        max: u64,
    ) -> Result<(), LoadError> {
        if value > max {
            return Err(LoadError::Limit {
                path: path.to_path_buf(),
                element: element.into(),
                limit: name,
                value,
                max,
            });
        }
        Ok(())
    }

    /// Read `path` whole, refusing anything but a regular file and more than
    /// [`max_file_bytes`](Self::max_file_bytes) (checked from its size, then enforced while
    /// reading, for files that grow).
    pub(crate) fn read_file(&self, path: &Path) -> Result<Vec<u8>, LoadError> {
        self.read_prefix(path, self.max_file_bytes, "the file")
    }

    /// Read at most `want` bytes of `path` (a glTF buffer reads its `byteLength`), refusing
    /// anything but a regular file, and a `want` above `max_file_bytes`.
    pub(crate) fn read_prefix(
        &self,
        path: &Path,
        want: u64,
        element: &str,
    ) -> Result<Vec<u8>, LoadError> {
        let io = |source| LoadError::Io {
            path: path.to_path_buf(),
            source,
        };
        let meta = std::fs::metadata(path).map_err(io)?;
        if !meta.is_file() {
            return Err(LoadError::invalid(
                path,
                element,
                "not a regular file (a directory, device or FIFO), so it is not read",
            ));
        }
        let want = want.min(meta.len());
        Self::check(path, element, "max_file_bytes", want, self.max_file_bytes)?;
        let mut bytes = Vec::new();
        bytes.try_reserve_exact(want as usize).map_err(|_| {
            LoadError::invalid(path, element, format!("{want} bytes do not fit in memory"))
        })?;
        std::fs::File::open(path)
            .map_err(io)?
            .take(want)
            .read_to_end(&mut bytes)
            .map_err(io)?;
        Ok(bytes)
    }
}
