//! Denoising with Intel Open Image Denoise (OIDN), guided by the albedo and normal AOVs.
//!
//! With the feature `denoise`, [`Denoiser`] loads OIDN's shared library **at run time** and runs
//! its `RT` filter (the one for path-traced images) on the CPU. The library is found through
//! the environment variable `OIDN_DIR` (an OIDN install or release directory: the one that holds
//! `lib/`), else through the system's library search path (`LD_LIBRARY_PATH`, the package
//! manager's install). Nothing of OIDN is needed to build pt, and a program built with the
//! feature starts and renders where OIDN is missing; only denoising then fails, with an error
//! that names `OIDN_DIR` and where it looked. Without the feature the same API exists and
//! [`Denoiser::new`] says so ([`DenoiseError::NotBuilt`]).
//!
//! OIDN comes from the package manager (where it has one), from Intel's releases
//! (<https://github.com/RenderKit/oidn/releases>), or from the PyPI wheel `pyoidn`, whose
//! `pyoidn/oidn` directory is an `OIDN_DIR` (`python3 -m pip install pyoidn`).
//!
//! The colour is denoised in HDR mode (linear radiance, any range). With guides, the albedo
//! and normal images are those of [`crate::aov`]; they are averaged like the colour and carry
//! some noise of their own where the first non-specular hit is reached through glass or a
//! glossy lobe's albedo varies, so OIDN prefilters them (`cleanAux` off) unless
//! [`Denoiser::clean_aux`] says they are clean. The denoised image is a biased estimate: it is
//! returned beside the unbiased one, never in its place.
//!
//! ```no_run
//! use pt_core::{render, Aovs, RenderOptions};
//! # use pt_core::{BuiltinMaterial, Emission, Mesh, Object, PinholeCamera, Rgb, SceneBuilder};
//! # use pt_core::pt_accel::TriangleMesh;
//! # use pt_core::glam::Vec3;
//! # let mut b = SceneBuilder::new();
//! # let tri = b.add_mesh(Mesh::new(TriangleMesh::new(
//! #     vec![Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, -1.0, 0.0), Vec3::new(0.0, 1.0, 0.0)],
//! #     vec![[0, 1, 2]],
//! # )?));
//! # let m = b.add_material(BuiltinMaterial::diffuse(Rgb::splat(0.5)));
//! # b.add_object(Object::new(tri, m).with_emission(Emission::new(Rgb::splat(2.0))));
//! # let scene = b.build()?;
//! # let camera = PinholeCamera::look_at(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y, 30.0)?;
//! let options = RenderOptions::new(64, 64).spp(16).aovs(Aovs::ALL);
//! let out = render(&scene, &camera, &options, None)?;
//! let clean = out.denoise()?; // the noisy `out.image` stays as it was
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::fmt;
use std::path::{Path, PathBuf};

use crate::image::Image;
use crate::render::RenderOutput;

/// Why denoising failed.
#[derive(Clone, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum DenoiseError {
    /// pt was built without the `denoise` feature.
    NotBuilt,
    /// OIDN's library could not be loaded.
    Library {
        /// Where it was looked for, and why each failed.
        tried: Vec<String>,
    },
    /// OIDN reported an error (device creation, filter set-up or execution).
    Oidn(String),
    /// A guide image has another size than the colour.
    Size {
        /// Which guide.
        guide: &'static str,
        /// The colour's size.
        expected: (u32, u32),
        /// The guide's size.
        found: (u32, u32),
    },
}

impl fmt::Display for DenoiseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NotBuilt => f.write_str(
                "this program was built without denoising (rebuild with `--features denoise`)",
            ),
            Self::Library { tried } => write!(
                f,
                "Intel Open Image Denoise was not found: set OIDN_DIR to its install directory \
                 (the one holding lib/), or install it (package manager, \
                 https://github.com/RenderKit/oidn/releases, or `pip install pyoidn`, whose \
                 pyoidn/oidn directory is an OIDN_DIR); tried: {}",
                tried.join("; ")
            ),
            Self::Oidn(message) => write!(f, "Open Image Denoise: {message}"),
            Self::Size {
                guide,
                expected,
                found,
            } => write!(
                f,
                "the {guide} guide is {}x{}, the image {}x{}",
                found.0, found.1, expected.0, expected.1
            ),
        }
    }
}

impl std::error::Error for DenoiseError {}

/// An Open Image Denoise CPU device with its library loaded: make one and denoise any number
/// of images with it (loading the library and creating the device take a few milliseconds).
pub struct Denoiser {
    #[cfg(feature = "denoise")]
    oidn: oidn::Device,
    clean_aux: bool,
}

impl fmt::Debug for Denoiser {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Denoiser")
            .field("clean_aux", &self.clean_aux)
            .finish_non_exhaustive()
    }
}

impl Denoiser {
    /// Load OIDN (`OIDN_DIR`, then the system's search path) and create its CPU device.
    ///
    /// # Errors
    ///
    /// [`DenoiseError::NotBuilt`] without the `denoise` feature, [`DenoiseError::Library`]
    /// when the library is found nowhere, [`DenoiseError::Oidn`] when it cannot create a device
    /// (an unsupported CPU, a library without its CPU device module).
    pub fn new() -> Result<Self, DenoiseError> {
        Self::load(std::env::var_os("OIDN_DIR").map(PathBuf::from), true)
    }

    /// Load OIDN from the install directory `dir` only (the one holding `lib/`), whatever
    /// `OIDN_DIR` and the system's search path say.
    ///
    /// # Errors
    ///
    /// As [`Denoiser::new`].
    pub fn from_dir(dir: impl AsRef<Path>) -> Result<Self, DenoiseError> {
        Self::load(Some(dir.as_ref().to_path_buf()), false)
    }

    #[cfg_attr(not(feature = "denoise"), allow(unused_variables))]
    fn load(dir: Option<PathBuf>, system: bool) -> Result<Self, DenoiseError> {
        #[cfg(feature = "denoise")]
        {
            Ok(Self {
                oidn: oidn::Device::new(dir, system)?,
                clean_aux: false,
            })
        }
        #[cfg(not(feature = "denoise"))]
        {
            Err(DenoiseError::NotBuilt)
        }
    }

    /// Whether the guides are free of noise (OIDN's `cleanAux`: no prefiltering). Off by
    /// default: pt's guides are averages of samples and carry noise behind glass.
    #[must_use]
    pub fn clean_aux(mut self, clean: bool) -> Self {
        self.clean_aux = clean;
        self
    }

    /// Denoise a linear HDR image, with the albedo and (only together with it) normal guides
    /// when given. The inputs are not changed.
    ///
    /// # Errors
    ///
    /// [`DenoiseError::Size`] when a guide's size differs from the colour's,
    /// [`DenoiseError::Oidn`] when OIDN fails.
    pub fn denoise(
        &self,
        color: &Image,
        albedo: Option<&Image>,
        normal: Option<&Image>,
    ) -> Result<Image, DenoiseError> {
        let size = |i: &Image| (i.width(), i.height());
        for (guide, image) in [("albedo", albedo), ("normal", normal)] {
            if let Some(image) = image
                && size(image) != size(color)
            {
                return Err(DenoiseError::Size {
                    guide,
                    expected: size(color),
                    found: size(image),
                });
            }
        }
        if normal.is_some() && albedo.is_none() {
            log::warn!("denoising: a normal guide needs an albedo guide too; using neither");
        }
        #[cfg(feature = "denoise")]
        {
            let normal = albedo.and(normal);
            let out = self.oidn.filter(
                color.as_slice(),
                albedo.map(Image::as_slice),
                normal.map(Image::as_slice),
                (color.width() as usize, color.height() as usize),
                self.clean_aux,
            )?;
            Ok(Image::from_rgb(color.width(), color.height(), out)
                .expect("the output has the input's size"))
        }
        #[cfg(not(feature = "denoise"))]
        {
            Err(DenoiseError::NotBuilt)
        }
    }
}

impl RenderOutput {
    /// The image denoised by Open Image Denoise ([`Denoiser`]), guided by the render's albedo
    /// and normal when it has them ([`RenderOptions::aovs`](crate::RenderOptions#structfield.aovs);
    /// without them OIDN sees the colour alone, and does worse). `self.image` is not changed.
    ///
    /// # Errors
    ///
    /// As [`Denoiser::new`] and [`Denoiser::denoise`].
    pub fn denoise(&self) -> Result<Image, DenoiseError> {
        Denoiser::new()?.denoise(&self.image, self.albedo.as_ref(), self.normal.as_ref())
    }
}

/// The library, loaded at run time, and its C API (OIDN 2, `oidn.h`): the one place pt-core
/// calls foreign code.
#[cfg(feature = "denoise")]
#[allow(unsafe_code)]
mod oidn {
    use std::ffi::{CStr, c_char, c_int, c_void};
    use std::path::PathBuf;

    use libloading::Library;

    use super::DenoiseError;

    type DeviceHandle = *mut c_void;
    type FilterHandle = *mut c_void;

    const DEVICE_TYPE_CPU: c_int = 1;
    const FORMAT_FLOAT3: c_int = 3;
    const ERROR_NONE: c_int = 0;

    /// The entry points pt uses, resolved once.
    struct Api {
        new_device: unsafe extern "C" fn(c_int) -> DeviceHandle,
        commit_device: unsafe extern "C" fn(DeviceHandle),
        release_device: unsafe extern "C" fn(DeviceHandle),
        get_device_error: unsafe extern "C" fn(DeviceHandle, *mut *const c_char) -> c_int,
        new_filter: unsafe extern "C" fn(DeviceHandle, *const c_char) -> FilterHandle,
        set_shared_filter_image: unsafe extern "C" fn(
            FilterHandle,
            *const c_char,
            *mut c_void,
            c_int,
            usize,
            usize,
            usize,
            usize,
            usize,
        ),
        set_filter_bool: unsafe extern "C" fn(FilterHandle, *const c_char, bool),
        commit_filter: unsafe extern "C" fn(FilterHandle),
        execute_filter: unsafe extern "C" fn(FilterHandle),
        release_filter: unsafe extern "C" fn(FilterHandle),
    }

    /// The file names of the library, newest ABI first.
    #[cfg(target_os = "linux")]
    const NAMES: &[&str] = &["libOpenImageDenoise.so.2", "libOpenImageDenoise.so"];
    #[cfg(target_os = "macos")]
    const NAMES: &[&str] = &["libOpenImageDenoise.2.dylib", "libOpenImageDenoise.dylib"];
    #[cfg(windows)]
    const NAMES: &[&str] = &["OpenImageDenoise.dll"];
    #[cfg(not(any(target_os = "linux", target_os = "macos", windows)))]
    const NAMES: &[&str] = &["libOpenImageDenoise.so.2", "libOpenImageDenoise.so"];

    /// Load the library from `dir` (its `lib`, `lib64` and `bin`), then, if `system`, from the
    /// system's search path. Every attempt and its failure go into the error.
    fn load(dir: Option<PathBuf>, system: bool) -> Result<Library, DenoiseError> {
        let mut tried = Vec::new();
        let mut candidates: Vec<PathBuf> = Vec::new();
        match dir {
            Some(dir) => {
                for sub in ["lib", "lib64", "bin"] {
                    for name in NAMES {
                        let path = dir.join(sub).join(name);
                        if path.is_file() {
                            candidates.push(path);
                        }
                    }
                }
                if candidates.is_empty() {
                    tried.push(format!(
                        "{} (no {} in its lib, lib64 or bin)",
                        dir.display(),
                        NAMES[0]
                    ));
                }
            }
            None => tried.push("OIDN_DIR (not set)".into()),
        }
        if system {
            candidates.extend(NAMES.iter().map(PathBuf::from));
        }
        for path in candidates {
            // SAFETY: loading runs the library's initialisers; OIDN's only set up its own
            // state (and its device modules, loaded from its own directory).
            match unsafe { Library::new(&path) } {
                Ok(lib) => return Ok(lib),
                Err(e) => tried.push(format!("{}: {e}", path.display())),
            }
        }
        Err(DenoiseError::Library { tried })
    }

    /// An OIDN CPU device, with the library it came from (kept loaded while the device lives).
    pub(super) struct Device {
        api: Api,
        device: DeviceHandle,
        _lib: Library,
    }

    impl Device {
        pub(super) fn new(dir: Option<PathBuf>, system: bool) -> Result<Self, DenoiseError> {
            let lib = load(dir, system)?;
            /// The function `name` of the library, as the C signature `T` of `oidn.h`.
            ///
            /// SAFETY (callers): `T` must be the function's signature in OIDN 2's `oidn.h`,
            /// and the pointer must not be used after `lib` is unloaded.
            unsafe fn get<T: Copy>(lib: &Library, name: &str) -> Result<T, DenoiseError> {
                let symbol = format!("{name}\0");
                // SAFETY: as the function's contract.
                unsafe { lib.get::<T>(symbol.as_bytes()) }
                    .map(|f| *f)
                    .map_err(|e| {
                        DenoiseError::Oidn(format!("the library lacks {name} (not OIDN 2?): {e}"))
                    })
            }
            // SAFETY: each field's type is the function's signature in `oidn.h`; `Device`
            // keeps `lib` loaded for as long as `api` is used.
            let api = unsafe {
                Api {
                    new_device: get(&lib, "oidnNewDevice")?,
                    commit_device: get(&lib, "oidnCommitDevice")?,
                    release_device: get(&lib, "oidnReleaseDevice")?,
                    get_device_error: get(&lib, "oidnGetDeviceError")?,
                    new_filter: get(&lib, "oidnNewFilter")?,
                    set_shared_filter_image: get(&lib, "oidnSetSharedFilterImage")?,
                    set_filter_bool: get(&lib, "oidnSetFilterBool")?,
                    commit_filter: get(&lib, "oidnCommitFilter")?,
                    execute_filter: get(&lib, "oidnExecuteFilter")?,
                    release_filter: get(&lib, "oidnReleaseFilter")?,
                }
            };
            // SAFETY: plain calls of the C API; a null device is checked before use.
            let device = unsafe { (api.new_device)(DEVICE_TYPE_CPU) };
            if device.is_null() {
                return Err(DenoiseError::Oidn(
                    "no CPU device (is libOpenImageDenoise_device_cpu beside the library?)".into(),
                ));
            }
            let dev = Self {
                api,
                device,
                _lib: lib,
            };
            // SAFETY: `device` is a live device handle.
            unsafe { (dev.api.commit_device)(dev.device) };
            dev.check("creating the CPU device")?;
            Ok(dev)
        }

        /// The device's pending error, if any.
        fn check(&self, doing: &str) -> Result<(), DenoiseError> {
            let mut message: *const c_char = std::ptr::null();
            // SAFETY: `device` is live; OIDN sets `message` to null or to a C string that
            // stays valid until the next call on the device, and it is copied at once.
            let code = unsafe { (self.api.get_device_error)(self.device, &mut message) };
            if code == ERROR_NONE {
                return Ok(());
            }
            let text = if message.is_null() {
                String::new()
            } else {
                // SAFETY: see above.
                unsafe { CStr::from_ptr(message) }
                    .to_string_lossy()
                    .into_owned()
            };
            Err(DenoiseError::Oidn(format!("{doing}: error {code}: {text}")))
        }

        /// Run the `RT` filter on `color` (RGB f32, `size.0 x size.1`) with the guides given.
        pub(super) fn filter(
            &self,
            color: &[f32],
            albedo: Option<&[f32]>,
            normal: Option<&[f32]>,
            size: (usize, usize),
            clean_aux: bool,
        ) -> Result<Vec<f32>, DenoiseError> {
            let (w, h) = size;
            let n = 3 * w * h;
            assert!(
                color.len() == n
                    && albedo.is_none_or(|a| a.len() == n)
                    && normal.is_none_or(|a| a.len() == n),
                "image buffers of the stated size"
            );
            let mut out = vec![0.0f32; n];
            let api = &self.api;
            // SAFETY: `device` is live; the filter is released on every path below. The shared
            // images point into `color`, the guides and `out`, which outlive the filter's
            // execution (it runs synchronously and is released before they are dropped); the
            // inputs are only read by OIDN (the `*mut` of the C signature is not written
            // through for input images).
            unsafe {
                let filter = (api.new_filter)(self.device, c"RT".as_ptr());
                if filter.is_null() {
                    self.check("creating the RT filter")?;
                    return Err(DenoiseError::Oidn("no RT filter".into()));
                }
                let set = |name: &CStr, data: *const f32| {
                    (api.set_shared_filter_image)(
                        filter,
                        name.as_ptr(),
                        data as *mut c_void,
                        FORMAT_FLOAT3,
                        w,
                        h,
                        0,
                        0,
                        0,
                    );
                };
                set(c"color", color.as_ptr());
                if let Some(a) = albedo {
                    set(c"albedo", a.as_ptr());
                }
                if let Some(nrm) = normal {
                    set(c"normal", nrm.as_ptr());
                }
                set(c"output", out.as_mut_ptr());
                (api.set_filter_bool)(filter, c"hdr".as_ptr(), true);
                (api.set_filter_bool)(filter, c"cleanAux".as_ptr(), clean_aux && albedo.is_some());
                (api.commit_filter)(filter);
                let committed = self.check("setting up the RT filter");
                if committed.is_ok() {
                    (api.execute_filter)(filter);
                }
                (api.release_filter)(filter);
                committed?;
                self.check("denoising")?;
            }
            if out.iter().any(|v| !v.is_finite()) {
                return Err(DenoiseError::Oidn(
                    "the output has non-finite values".into(),
                ));
            }
            Ok(out)
        }
    }

    impl Drop for Device {
        fn drop(&mut self) {
            // SAFETY: the device is live and released once; the library outlives this call.
            unsafe { (self.api.release_device)(self.device) };
        }
    }
}
