//! The chi-square goodness-of-fit check and the pdf-integral check on a histogram.

use crate::bsdf::Bsdf;
use crate::testing::{BsdfCase, Failure, Histogram};

/// Result of the chi-square test.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Chi2Outcome {
    /// The statistic.
    pub chi2: f64,
    /// Degrees of freedom (bins - 1).
    pub dof: usize,
    /// Probability of a statistic at least this large if `sample` follows `pdf`.
    pub p_value: f64,
    /// Samples that landed in cells where `pdf` integrates to zero.
    pub impossible_samples: u64,
}

/// Chi-square goodness of fit of `sample` against `pdf`, rejected below significance `alpha`
/// (already corrected for the number of tests) or when any sample lands where `pdf` integrates
/// to zero.
pub fn check_chi2<B: Bsdf>(
    case: &BsdfCase<B>,
    h: &Histogram,
    alpha: f64,
) -> Result<Chi2Outcome, Failure> {
    check_chi2_named(&case.name, h, alpha)
}

/// [`check_chi2`] for any histogram, failures named `name`.
pub fn check_chi2_named(name: &str, h: &Histogram, alpha: f64) -> Result<Chi2Outcome, Failure> {
    let fail = |check: &'static str, message: String| Failure {
        case: name.to_string(),
        check,
        message,
    };
    let c = h.chi2();
    if c.impossible_samples > 0 {
        return Err(fail(
            "chi-square",
            format!(
                "{} samples landed in cells where pdf integrates to 0",
                c.impossible_samples
            ),
        ));
    }
    if c.p_value < alpha {
        return Err(fail(
            "chi-square",
            format!(
                "chi2 = {:.1} with {} dof, p = {:.3e} < alpha = {alpha:.3e}",
                c.chi2, c.dof, c.p_value
            ),
        ));
    }
    Ok(c)
}

/// The integral of `pdf` over the sphere must equal the measured fraction of `sample` calls
/// that return a non-delta direction, within `tolerance` plus four standard errors of that
/// fraction.
pub fn check_pdf_integral<B: Bsdf>(
    case: &BsdfCase<B>,
    h: &Histogram,
    tolerance: f64,
) -> Result<f64, Failure> {
    check_pdf_integral_named(&case.name, h, tolerance)
}

/// [`check_pdf_integral`] for any histogram, failures named `name`.
pub fn check_pdf_integral_named(name: &str, h: &Histogram, tolerance: f64) -> Result<f64, Failure> {
    let integral = h.pdf_integral();
    let p = h.non_delta_fraction();
    let se = (p * (1.0 - p) / h.config.samples as f64).sqrt();
    let err = (integral - p).abs();
    if !integral.is_finite() || err > tolerance + 4.0 * se {
        return Err(Failure {
            case: name.to_string(),
            check: "pdf integral",
            message: format!(
                "pdf integrates to {integral:.6} but sample returned a non-delta direction {p:.6} \
                 of the time (delta {:.6}, failed {:.6}); |difference| {err:.2e} > {:.2e}",
                h.delta_fraction(),
                h.failed_fraction(),
                tolerance + 4.0 * se
            ),
        });
    }
    Ok(integral)
}
