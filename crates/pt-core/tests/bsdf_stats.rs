//! Statistical tests of every built-in BSDF, through the `testing` harness and its registry.
//!
//! Significance: 0.01 for the whole binary, split over the tests of each kind by the Šidák
//! correction. Seeds are fixed, so a run is reproducible. `docs/testing.md` explains each check
//! and its tolerance; `harness_rejects.rs` shows each check failing on a planted bug.

use pt_core::Bsdf;
use pt_core::testing::stats::sidak;
use pt_core::testing::{
    BsdfCase, HistogramConfig, builtin_bsdf_cases, check_chi2, check_consistency, check_delta,
    check_energy, check_pdf_integral, check_reciprocity, histogram,
};

/// Family-wise significance level of the binary.
const ALPHA: f64 = 0.01;
/// Tolerance of the pdf integral beyond its sampling error (quadrature error is ~1e-6).
const INTEGRAL_TOLERANCE: f64 = 1e-3;
/// The chi-square cases are spread over this many test functions, to run in parallel.
const SHARDS: usize = 4;

fn chi2_cases() -> Vec<(usize, BsdfCase<pt_core::BuiltinBsdf>)> {
    builtin_bsdf_cases()
        .into_iter()
        .enumerate()
        .filter(|(_, c)| c.bsdf.flags().is_non_specular())
        .collect()
}

fn run_chi2_shard(shard: usize) {
    let cases = chi2_cases();
    // Two tests per case (chi-square and the integral), one family for the whole registry.
    let alpha = sidak(ALPHA, 2 * cases.len());
    let mut failures = Vec::new();
    for (i, case) in cases.iter().filter(|(i, _)| i % SHARDS == shard) {
        let config = HistogramConfig {
            seed: *i as u64 + 1,
            ..HistogramConfig::default()
        };
        let h = histogram(case, &config);
        match check_chi2(case, &h, alpha) {
            Ok(c) => eprintln!(
                "{}: chi2 {:.1}, dof {}, p {:.3}",
                case.name, c.chi2, c.dof, c.p_value
            ),
            Err(e) => failures.push(e.to_string()),
        }
        if let Err(e) = check_pdf_integral(case, &h, INTEGRAL_TOLERANCE) {
            failures.push(e.to_string());
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn chi2_and_pdf_integral_shard_0() {
    run_chi2_shard(0);
}

#[test]
fn chi2_and_pdf_integral_shard_1() {
    run_chi2_shard(1);
}

#[test]
fn chi2_and_pdf_integral_shard_2() {
    run_chi2_shard(2);
}

#[test]
fn chi2_and_pdf_integral_shard_3() {
    run_chi2_shard(3);
}

#[test]
fn sample_eval_pdf_consistency() {
    let failures: Vec<String> = builtin_bsdf_cases()
        .iter()
        .enumerate()
        .filter_map(|(i, c)| check_consistency(c, 20_000, i as u64).err())
        .map(|e| e.to_string())
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn reciprocity() {
    let failures: Vec<String> = builtin_bsdf_cases()
        .iter()
        .enumerate()
        .filter_map(|(i, c)| check_reciprocity(c, 20_000, i as u64).err())
        .map(|e| e.to_string())
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn energy_conservation() {
    let cases = builtin_bsdf_cases();
    let alpha = sidak(ALPHA, cases.len());
    let failures: Vec<String> = cases
        .iter()
        .enumerate()
        .filter_map(|(i, c)| check_energy(c, 100_000, i as u64, alpha).err())
        .map(|e| e.to_string())
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn delta_lobes() {
    let cases = builtin_bsdf_cases();
    let n_delta = cases
        .iter()
        .filter(|c| c.delta != pt_core::testing::DeltaExpectation::None)
        .count();
    assert!(n_delta >= 50, "the registry has delta cases");
    let alpha = sidak(ALPHA, n_delta);
    let failures: Vec<String> = cases
        .iter()
        .enumerate()
        .filter_map(|(i, c)| check_delta(c, 100_000, i as u64, alpha).err())
        .map(|e| e.to_string())
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
