//! Sampled directions binned over the sphere next to the probability the claimed pdf gives
//! each cell: the measurement behind the chi-square and pdf-integral checks.

use glam::Vec3;

use crate::bsdf::{Bsdf, TransportMode};
use crate::testing::stats::chi2_survival;
use crate::testing::{Binning, BsdfCase, Chi2Outcome, Quadrature, TestRng};

/// Settings of the histogram behind [`check_chi2`] and [`check_pdf_integral`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HistogramConfig {
    /// Number of `sample` calls.
    pub samples: usize,
    /// The cells.
    pub binning: Binning,
    /// How cell integrals are computed.
    pub quadrature: Quadrature,
    /// Cells expecting fewer samples are pooled.
    pub min_expected: f64,
    /// Seed of the sample values.
    pub seed: u64,
}

impl Default for HistogramConfig {
    /// 1,000,000 samples, 80 x 160 (theta, phi) cells, adaptive quadrature, pooling below 5
    /// expected (pbrt-v4's settings).
    fn default() -> Self {
        Self {
            samples: 1_000_000,
            binning: Binning::Sphere {
                theta_bins: 80,
                phi_bins: 160,
            },
            quadrature: Quadrature::Adaptive,
            min_expected: 5.0,
            seed: 1,
        }
    }
}

/// One draw of a sampling routine under test.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Draw {
    /// No direction.
    Failed,
    /// A delta lobe (not binned).
    Delta,
    /// A direction with a density.
    Direction(Vec3),
}

/// Sampled directions binned over the sphere, next to the probability `pdf` gives each cell.
#[derive(Clone, Debug)]
pub struct Histogram {
    pub(crate) config: HistogramConfig,
    /// Samples that landed in each cell (theta-major).
    observed: Vec<u64>,
    /// Integral of `pdf` over each cell.
    probability: Vec<f64>,
    /// `sample` returned a non-delta direction.
    non_delta: u64,
    /// `sample` returned a delta lobe.
    delta: u64,
    /// `sample` returned `None`.
    failed: u64,
}

impl Histogram {
    /// Integral of `pdf` over the sphere.
    #[must_use]
    pub fn pdf_integral(&self) -> f64 {
        self.probability.iter().sum()
    }

    /// Fraction of `sample` calls that returned a non-delta direction.
    #[must_use]
    pub fn non_delta_fraction(&self) -> f64 {
        self.non_delta as f64 / self.config.samples as f64
    }

    /// Fraction of `sample` calls that returned a delta lobe.
    #[must_use]
    pub fn delta_fraction(&self) -> f64 {
        self.delta as f64 / self.config.samples as f64
    }

    /// Fraction of `sample` calls that returned `None`.
    #[must_use]
    pub fn failed_fraction(&self) -> f64 {
        self.failed as f64 / self.config.samples as f64
    }

    /// The chi-square statistic: one bin per cell expecting at least `min_expected` samples, one
    /// for the pooled rest, and one for "no non-delta direction" (failures and delta samples).
    #[must_use]
    pub fn chi2(&self) -> Chi2Outcome {
        let n = self.config.samples as f64;
        let min = self.config.min_expected;
        let mut bins: Vec<(f64, f64)> = Vec::new();
        let mut pooled = (0.0, 0.0);
        let mut impossible = 0u64;
        let mut push = |observed: f64, expected: f64| {
            if expected >= min {
                bins.push((observed, expected));
            } else {
                pooled.0 += observed;
                pooled.1 += expected.max(0.0);
            }
        };
        for (&o, &p) in self.observed.iter().zip(&self.probability) {
            if p <= 0.0 && o > 0 {
                impossible += o;
            }
            push(o as f64, n * p);
        }
        push(
            (self.delta + self.failed) as f64,
            n * (1.0 - self.pdf_integral()),
        );
        if pooled.1 >= min || bins.is_empty() {
            bins.push(pooled);
        } else if let Some(smallest) = bins
            .iter_mut()
            .min_by(|a, b| a.1.partial_cmp(&b.1).unwrap_or(std::cmp::Ordering::Equal))
        {
            smallest.0 += pooled.0;
            smallest.1 += pooled.1;
        }
        let chi2: f64 = bins
            .iter()
            .filter(|b| b.1 > 0.0)
            .map(|&(o, e)| (o - e) * (o - e) / e)
            .sum();
        let dof = bins.len().saturating_sub(1);
        let p_value = if dof == 0 {
            1.0
        } else {
            chi2_survival(chi2, dof)
        };
        Chi2Outcome {
            chi2,
            dof,
            p_value,
            impossible_samples: impossible,
        }
    }
}

/// Draw `config.samples` directions from `case.bsdf.sample` (radiance mode) and integrate
/// `case.bsdf.pdf` over every cell of the grid.
///
/// With [`Quadrature::Adaptive`] each cell is integrated by nested adaptive Simpson quadrature
/// (theta outside, phi inside). Cells that received samples start from a finer subdivision
/// (9 x 9 points instead of 5 x 5), so that narrow lobes are resolved wherever sampling puts
/// them; refinement then continues until the cell's integral is known to `1e-6` relative
/// (`1e-10` absolute), far below the statistical noise of a million samples.
pub fn histogram<B: Bsdf>(case: &BsdfCase<B>, config: &HistogramConfig) -> Histogram {
    let mode = TransportMode::Radiance;
    histogram_of(
        config,
        |rng| {
            let uc = rng.uniform();
            let u = rng.uniform2();
            match case.bsdf.sample(case.wo, uc, u, mode) {
                None => Draw::Failed,
                Some(s) if s.flags.is_specular() => Draw::Delta,
                Some(s) => Draw::Direction(s.wi),
            }
        },
        |wi| f64::from(case.bsdf.pdf(case.wo, wi, mode)),
        case.bsdf.flags().is_non_specular(),
    )
}

/// The histogram of any direction sampler: `draw` is called `config.samples` times, and `pdf`
/// (its claimed solid-angle density) is integrated over each cell unless `has_density` is false
/// (only delta lobes), in which case every cell expects zero.
pub fn histogram_of(
    config: &HistogramConfig,
    mut draw: impl FnMut(&mut TestRng) -> Draw,
    pdf: impl Fn(Vec3) -> f64,
    has_density: bool,
) -> Histogram {
    let cells = config.binning.cells();
    let mut observed = vec![0u64; cells];
    let (mut non_delta, mut delta, mut failed) = (0u64, 0u64, 0u64);
    let mut rng = TestRng::new(config.seed);
    for _ in 0..config.samples {
        match draw(&mut rng) {
            Draw::Failed => failed += 1,
            Draw::Delta => delta += 1,
            Draw::Direction(w) => {
                non_delta += 1;
                observed[config.binning.cell_of(w)] += 1;
            }
        }
    }
    let mut probability = vec![0.0f64; cells];
    if has_density {
        for (cell, p) in probability.iter_mut().enumerate() {
            *p = config
                .binning
                .integrate(cell, config.quadrature, observed[cell] > 0, &pdf);
        }
    }
    Histogram {
        config: *config,
        observed,
        probability,
        non_delta,
        delta,
        failed,
    }
}
