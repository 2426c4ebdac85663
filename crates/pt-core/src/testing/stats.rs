//! Distribution functions for the statistical tests: the chi-square survival function (through
//! the regularised incomplete gamma function) and the Šidák correction.
//!
//! Written from the textbook definitions (series for small `x`, Lentz's continued fraction for
//! large `x`, Lanczos' approximation of `ln Gamma`), in `f64`, accurate to about 1e-12 relative
//! over the range the tests use.

/// `ln Gamma(x)` for `x > 0` (Lanczos, g = 7, n = 9).
#[must_use]
pub fn ln_gamma(x: f64) -> f64 {
    const G: f64 = 7.0;
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        // Reflection: Gamma(x) Gamma(1 - x) = pi / sin(pi x).
        let pi = std::f64::consts::PI;
        return (pi / (pi * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut a = C[0];
    let t = x + G + 0.5;
    for (i, c) in C.iter().enumerate().skip(1) {
        a += c / (x + i as f64);
    }
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

/// Regularised upper incomplete gamma function `Q(a, x) = Gamma(a, x) / Gamma(a)`.
#[must_use]
pub fn gamma_q(a: f64, x: f64) -> f64 {
    assert!(a > 0.0, "gamma_q needs a > 0, got {a}");
    if x <= 0.0 {
        return 1.0;
    }
    let log_prefactor = -x + a * x.ln() - ln_gamma(a);
    if x < a + 1.0 {
        // Series for P(a, x).
        let mut term = 1.0 / a;
        let mut sum = term;
        for n in 1..10_000 {
            term *= x / (a + f64::from(n));
            sum += term;
            if term.abs() < sum.abs() * 1e-16 {
                break;
            }
        }
        (1.0 - sum * log_prefactor.exp()).clamp(0.0, 1.0)
    } else {
        // Continued fraction for Q(a, x) (modified Lentz).
        const TINY: f64 = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / TINY;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..10_000 {
            let an = -f64::from(i) * (f64::from(i) - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < TINY {
                d = TINY;
            }
            c = b + an / c;
            if c.abs() < TINY {
                c = TINY;
            }
            d = 1.0 / d;
            let delta = d * c;
            h *= delta;
            if (delta - 1.0).abs() < 1e-16 {
                break;
            }
        }
        (log_prefactor.exp() * h).clamp(0.0, 1.0)
    }
}

/// Probability that a chi-square variable with `dof` degrees of freedom exceeds `chi2`
/// (the p-value of a chi-square test).
#[must_use]
pub fn chi2_survival(chi2: f64, dof: usize) -> f64 {
    assert!(
        dof > 0,
        "a chi-square test needs at least one degree of freedom"
    );
    gamma_q(dof as f64 / 2.0, chi2 / 2.0)
}

/// Two-sided p-value of a standard normal deviate `z` (`erfc(|z| / sqrt 2)`).
#[must_use]
pub fn normal_two_sided_p(z: f64) -> f64 {
    chi2_survival(z * z, 1)
}

/// Šidák-corrected significance level for one of `tests` independent tests, so that the chance
/// of any false rejection among them is `alpha`: `1 - (1 - alpha)^(1 / tests)`.
#[must_use]
pub fn sidak(alpha: f64, tests: usize) -> f64 {
    1.0 - (1.0 - alpha).powf(1.0 / tests.max(1) as f64)
}

/// The Kolmogorov-Smirnov test of `values` against the uniform distribution on `[0, 1)`:
/// returns `(D, p)`, the largest distance between the empirical and the uniform distribution
/// function, and the asymptotic p-value with Stephens' small-sample correction
/// (`lambda = (sqrt n + 0.12 + 0.11 / sqrt n) D`, `p = 2 sum (-1)^(k-1) exp(-2 k^2 lambda^2)`),
/// accurate to a few percent from `n = 5` on. Sorts `values`.
#[must_use]
pub fn ks_uniform(values: &mut [f64]) -> (f64, f64) {
    assert!(!values.is_empty(), "a KS test needs values");
    values.sort_by(f64::total_cmp);
    let n = values.len() as f64;
    let mut d = 0.0f64;
    for (i, &v) in values.iter().enumerate() {
        let v = v.clamp(0.0, 1.0);
        d = d.max((i + 1) as f64 / n - v).max(v - i as f64 / n);
    }
    let lambda = (n.sqrt() + 0.12 + 0.11 / n.sqrt()) * d;
    (d, kolmogorov_survival(lambda))
}

/// `P(K > lambda)` for the Kolmogorov distribution.
fn kolmogorov_survival(lambda: f64) -> f64 {
    if lambda < 0.2 {
        return 1.0; // the series converges slowly here, and the value is 1 to 1e-20
    }
    let mut sum = 0.0;
    let mut sign = 1.0;
    for k in 1..=100 {
        let term = (-2.0 * f64::from(k * k) * lambda * lambda).exp();
        sum += sign * term;
        if term < 1e-16 {
            break;
        }
        sign = -sign;
    }
    (2.0 * sum).clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kolmogorov_smirnov_quantiles() {
        // Asymptotic critical values: P(K > 1.3581) = 0.05, P(K > 1.6276) = 0.01.
        assert!((kolmogorov_survival(1.358_1) - 0.05).abs() < 1e-4);
        assert!((kolmogorov_survival(1.627_6) - 0.01).abs() < 1e-4);
        // A perfectly even sample has D = 1/(2n); a sample squeezed into [0, 1/2) has D = 1/2.
        let mut even: Vec<f64> = (0..1000).map(|i| (i as f64 + 0.5) / 1000.0).collect();
        let (d, p) = ks_uniform(&mut even);
        assert!((d - 0.0005).abs() < 1e-12 && p > 0.999);
        let mut half: Vec<f64> = (0..1000).map(|i| i as f64 / 2000.0).collect();
        let (d, p) = ks_uniform(&mut half);
        assert!((d - 0.5).abs() < 1e-3 && p < 1e-100);
    }

    #[test]
    fn known_quantiles() {
        // Table values: the 0.05 and 0.01 critical points of chi-square.
        assert!((chi2_survival(3.841_458_820_694_124, 1) - 0.05).abs() < 1e-9);
        assert!((chi2_survival(23.209_251_158_954_36, 10) - 0.01).abs() < 1e-9);
        assert!((normal_two_sided_p(1.959_963_984_540_054) - 0.05).abs() < 1e-9);
        assert!((ln_gamma(5.0) - 24f64.ln()).abs() < 1e-12);
        assert!((ln_gamma(0.5) - std::f64::consts::PI.sqrt().ln()).abs() < 1e-12);
    }

    #[test]
    fn sidak_correction() {
        let a = sidak(0.01, 100);
        assert!((1.0 - (1.0 - a).powi(100) - 0.01).abs() < 1e-12);
        assert!((sidak(0.01, 1) - 0.01).abs() < 1e-15);
    }
}
