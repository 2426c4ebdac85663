//! The statistical test harness for BSDFs (feature `testing`).
//!
//! Every check takes a [`BsdfCase`] (a BSDF, an outgoing direction and what is known about it)
//! and returns `Ok` with its measurements or a [`Failure`] that names the case, the check and the
//! numbers. The checks, their tolerances and the reasons for them are described in
//! `docs/testing.md`; in short:
//!
//! 1. [`check_chi2`]: `sample` against `pdf` by a chi-square goodness-of-fit test over a
//!    (theta, phi) grid of the whole sphere, with expected counts from adaptive quadrature of
//!    `pdf` and low-count cells pooled (pbrt-v4's `bsdfs_test`, Mitsuba 3's `chi2` are the
//!    models).
//! 2. [`check_pdf_integral`]: the integral of `pdf` over the sphere equals the measured
//!    probability that `sample` returns a non-delta direction.
//! 3. [`check_consistency`]: `sample` returns the `f` and `pdf` that `eval` and `pdf` give for its
//!    direction, with valid flags.
//! 4. [`check_reciprocity`]: `f(wo, wi) / n_o^2 = f(wi, wo) / n_i^2` (Veach's generalized
//!    reciprocity; plain symmetry for reflection) and radiance mode is the adjoint of importance
//!    mode.
//! 5. [`check_energy`]: the directional albedo `E[f |cos| / pdf]` (importance mode) is at most 1,
//!    and equals the known value for lossless models.
//! 6. [`check_delta`]: delta lobes go where the law of reflection and Snell's law say, with the
//!    Fresnel split and weights of an independent `f64` implementation of the Fresnel equations.
//!
//! The registry ([`builtin_bsdf_cases`], [`builtin_bsdf_models`],
//! [`builtin_material_furnace_cases`]) is the one list of built-in models that the checks, the
//! benchmarks and the furnace tests iterate.
//!
//! ```
//! use pt_core::testing::{builtin_bsdf_cases, check_consistency};
//!
//! let cases = builtin_bsdf_cases();
//! assert!(cases.len() > 100);
//! check_consistency(&cases[0], 1000, 7).unwrap();
//! ```

mod binning;
mod case;
mod chi2;
mod delta;
mod histogram;
mod invariants;
mod light;
mod lights;
mod registry;
pub mod stats;

use std::fmt;

pub use binning::{Binning, Quadrature};
pub use case::{BsdfCase, DeltaExpectation};
pub use chi2::{
    Chi2Outcome, check_chi2, check_chi2_named, check_pdf_integral, check_pdf_integral_named,
};
pub use delta::{check_delta, fresnel_reference};
use glam::Vec2;
pub use histogram::{Draw, Histogram, HistogramConfig, histogram, histogram_of};
pub use invariants::{check_consistency, check_energy, check_reciprocity};
pub use light::light_histogram;
pub use lights::{LightCase, builtin_light_cases};
use rand_pcg::Pcg32;
use rand_pcg::rand_core::RngCore;
pub use registry::{
    FurnaceCase, FurnaceExpectation, builtin_bsdf_cases, builtin_bsdf_models,
    builtin_material_furnace_cases,
};

/// A check that did not pass: which case, which check, and what was measured.
#[derive(Clone, Debug, PartialEq)]
pub struct Failure {
    /// Name of the case.
    pub case: String,
    /// Name of the check.
    pub check: &'static str,
    /// What was measured against what was expected.
    pub message: String,
}

impl fmt::Display for Failure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} failed for {}: {}",
            self.check, self.case, self.message
        )
    }
}

impl std::error::Error for Failure {}

/// Uniform random numbers for the checks (PCG32, fixed seed per check and case).
#[derive(Clone, Debug)]
pub struct TestRng(Pcg32);

impl TestRng {
    /// A generator for `seed`.
    #[must_use]
    pub fn new(seed: u64) -> Self {
        Self(Pcg32::new(
            seed ^ 0x853c_49e6_748f_ea9b,
            0xda3e_39cb_94b9_5bdb,
        ))
    }

    /// Uniform in `[0, 1)`.
    pub fn uniform(&mut self) -> f32 {
        (self.0.next_u32() >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
    }

    /// Two uniforms in `[0, 1)`.
    pub fn uniform2(&mut self) -> Vec2 {
        Vec2::new(self.uniform(), self.uniform())
    }
}
