//! The figures of a finished render and the summary line printed from them.

use std::fmt;
use std::ops::Range;
use std::time::Duration;

#[cfg(doc)]
use crate::{Film, RenderOptions};

/// Figures of a finished render.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct RenderStats {
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Samples per pixel taken by this render (the length of [`RenderStats::sample_range`]).
    pub spp: u32,
    /// The sample indices taken, out of `0..total_spp`.
    pub sample_range: Range<u32>,
    /// Samples per pixel of the complete render.
    pub total_spp: u32,
    /// The seed of the render.
    pub seed: u64,
    /// Wall time of the render (not of scene building).
    pub elapsed: Duration,
    /// Camera samples taken (with adaptive sampling, fewer than width x height x spp).
    pub samples: u64,
    /// With adaptive sampling, the fraction of the `width x height x spp` samples that pixels
    /// did not need (0 without it).
    pub adaptive_saved: f64,
    /// Rays traced: camera, continuation and shadow rays.
    pub rays: u64,
    /// Samples dropped because their value was NaN or infinite.
    pub non_finite_samples: u64,
    /// Samples scaled down by [`RenderOptions::sample_clamp`].
    pub clamped_samples: u64,
    /// Samples that reached the film's fixed-point limit (a channel of about 4.6e18 or more):
    /// their pixels are capped. See [`Film::saturated_samples`].
    pub saturated_samples: u64,
    /// The work this render left out because the scene does not need it, each with its reason
    /// (from [`SceneFeatures::skipped`](crate::SceneFeatures::skipped), plus the lens
    /// sample of cameras that do not use it).
    pub skipped: Vec<&'static str>,
    /// The lane path tracer rendered (eight paths at once, [`RenderOptions::lanes`](crate::RenderOptions::lanes)).
    pub lanes: bool,
}

impl RenderStats {
    /// Millions of camera samples per second.
    #[must_use]
    pub fn msamples_per_second(&self) -> f64 {
        self.samples as f64 / self.elapsed.as_secs_f64().max(1e-9) / 1e6
    }

    /// Millions of rays per second.
    #[must_use]
    pub fn mrays_per_second(&self) -> f64 {
        self.rays as f64 / self.elapsed.as_secs_f64().max(1e-9) / 1e6
    }
}

impl fmt::Display for RenderStats {
    /// The summary line of DESIGN.md section 8, without the leading name.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}x{}, {} spp", self.width, self.height, self.spp)?;
        if self.spp != self.total_spp {
            write!(
                f,
                " (samples {}..{} of {})",
                self.sample_range.start, self.sample_range.end, self.total_spp
            )?;
        }
        write!(
            f,
            ", {:.2} s, {} Msamples/s, {} Mrays/s, {} non-finite samples dropped",
            self.elapsed.as_secs_f64(),
            Sig3(self.msamples_per_second()),
            Sig3(self.mrays_per_second()),
            self.non_finite_samples
        )?;
        if self.saturated_samples > 0 {
            write!(
                f,
                ", {} samples saturated the film (radiance of 4.6e18 or more: those pixels are capped)",
                self.saturated_samples
            )?;
        }
        if self.clamped_samples > 0 {
            write!(f, ", {} samples clamped", self.clamped_samples)?;
        }
        if self.adaptive_saved > 0.0 {
            write!(
                f,
                ", adaptive: {:.1}% of samples saved",
                100.0 * self.adaptive_saved
            )?;
        }
        if !self.skipped.is_empty() {
            write!(f, ", skipped: {}", self.skipped.join(", "))?;
        }
        Ok(())
    }
}

/// A rate printed with three significant figures (at least two decimals).
struct Sig3(f64);

impl fmt::Display for Sig3 {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let digits = if self.0 > 0.0 && self.0.is_finite() {
            (2 - self.0.log10().floor() as i32).max(2)
        } else {
            2
        };
        write!(f, "{:.*}", digits as usize, self.0)
    }
}
