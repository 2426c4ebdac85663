//! Why a render could not run, and which option was out of range.

use std::fmt;
use std::ops::Range;

#[cfg(doc)]
use crate::render::{MAX_PIXELS, RenderOptions};
use crate::render::{MAX_RR_THRESHOLD, MAX_THREADS};

/// Why a render could not run.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum RenderError {
    /// An option is out of range ([`crate::RenderOptions::validate`]).
    InvalidOptions(OptionsError),
    /// The worker thread pool could not be created.
    ThreadPool(String),
    /// The caller's cancellation flag was set ([`crate::RenderControl::cancel`]).
    Cancelled,
}

impl fmt::Display for RenderError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::InvalidOptions(e) => write!(f, "invalid render options: {e}"),
            Self::ThreadPool(r) => write!(f, "could not create worker threads: {r}"),
            Self::Cancelled => write!(f, "render cancelled"),
        }
    }
}

impl std::error::Error for RenderError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Self::InvalidOptions(e) => Some(e),
            _ => None,
        }
    }
}

impl From<OptionsError> for RenderError {
    fn from(e: OptionsError) -> Self {
        Self::InvalidOptions(e)
    }
}

/// Why [`RenderOptions`] cannot be rendered: which option is out of range, with its value.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum OptionsError {
    /// The image has no pixels.
    EmptyImage {
        /// The width asked for.
        width: u32,
        /// The height asked for.
        height: u32,
    },
    /// The image has more than [`MAX_PIXELS`] pixels.
    TooManyPixels {
        /// The width asked for.
        width: u32,
        /// The height asked for.
        height: u32,
    },
    /// `spp` is 0.
    NoSamples,
    /// `tile_size` is 0.
    EmptyTiles,
    /// `spp_range` is empty or not within `0..spp`.
    SampleRange {
        /// The range asked for.
        range: Range<u32>,
        /// The samples per pixel of the complete render.
        spp: u32,
    },
    /// `sample_clamp` is not positive and finite.
    SampleClamp(f32),
    /// `rr_threshold` is not positive, or above [`MAX_RR_THRESHOLD`].
    RouletteThreshold(f32),
    /// `threads` is 0 or above [`MAX_THREADS`].
    Threads(usize),
    /// The film would take more than `max_film_bytes`.
    FilmTooLarge {
        /// The width asked for.
        width: u32,
        /// The height asked for.
        height: u32,
        /// What the film would take.
        bytes: u64,
        /// [`RenderOptions::max_film_bytes`](struct.RenderOptions.html#structfield.max_film_bytes).
        max_bytes: u64,
    },
    /// The adaptive threshold is not positive and finite.
    AdaptiveThreshold(f32),
    /// The adaptive minimum is below 2 or above `spp`.
    AdaptiveMinSpp {
        /// The minimum asked for.
        min_spp: u32,
        /// The samples per pixel (the most a pixel takes).
        spp: u32,
    },
    /// Adaptive sampling was combined with a sample range.
    AdaptiveWithSampleRange,
}

impl fmt::Display for OptionsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let gib = |b: u64| b as f64 / f64::from(1u32 << 30);
        match self {
            Self::EmptyImage { width, height } => write!(f, "image size {width}x{height} is empty"),
            Self::TooManyPixels { width, height } => {
                write!(f, "image size {width}x{height} exceeds 2^28 pixels")
            }
            Self::NoSamples => write!(f, "spp must be at least 1"),
            Self::EmptyTiles => write!(f, "tile size must be at least 1"),
            Self::SampleRange { range, spp } => write!(
                f,
                "sample range {}..{} is empty or not within 0..{spp} (the spp)",
                range.start, range.end
            ),
            Self::SampleClamp(c) => {
                write!(f, "sample clamp must be positive and finite, got {c}")
            }
            Self::RouletteThreshold(t) => write!(
                f,
                "Russian roulette threshold must be positive and at most {MAX_RR_THRESHOLD}, \
                 got {t}"
            ),
            Self::Threads(0) => write!(f, "thread count must be at least 1"),
            Self::Threads(t) => write!(
                f,
                "{t} threads is above the most a render takes ({MAX_THREADS})"
            ),
            Self::FilmTooLarge {
                width,
                height,
                bytes,
                max_bytes,
            } => write!(
                f,
                "a {width}x{height} film needs {:.1} GiB ({} bytes per pixel while tiles are \
                 merged), above max_film_bytes = {:.1} GiB (raise \
                 RenderOptions::max_film_bytes)",
                gib(*bytes),
                bytes / (u64::from(*width) * u64::from(*height)).max(1),
                gib(*max_bytes)
            ),
            Self::AdaptiveThreshold(t) => {
                write!(f, "adaptive threshold must be positive and finite, got {t}")
            }
            Self::AdaptiveMinSpp { min_spp, spp } => write!(
                f,
                "adaptive minimum spp must be in 2..={spp} (the spp), got {min_spp}"
            ),
            Self::AdaptiveWithSampleRange => write!(
                f,
                "adaptive sampling cannot be split into sample ranges: a pixel's stopping point \
                 depends on all its samples"
            ),
        }
    }
}

impl std::error::Error for OptionsError {}
