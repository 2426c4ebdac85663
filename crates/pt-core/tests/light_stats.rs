//! Every light of the registry (`pt_core::testing::builtin_light_cases`): `sample_li` follows
//! `pdf_li` (chi-square at a family-wise significance of 0.01, Šidák over the cases) and the pdf
//! integrates to 1 over the sphere within 1e-3; delta lights return only delta samples.
//! 200,000 samples each, over 40 x 80 (theta, phi) cells or, for the maps, cells aligned with
//! 2 x 2 texels (the case's histogram).

use pt_core::Light;
use pt_core::testing::stats::sidak;
use pt_core::testing::{
    builtin_light_cases, check_chi2_named, check_pdf_integral_named, light_histogram,
};

#[test]
fn every_light_samples_its_pdf() {
    let cases = builtin_light_cases();
    let alpha = sidak(0.01, cases.len());
    for case in &cases {
        let h = light_histogram(&case.light, &case.ctx, case.frame, &case.config);
        if case.light.flags().is_delta() {
            assert_eq!(
                h.delta_fraction(),
                1.0,
                "{}: a delta light returned a non-delta sample or failed",
                case.name
            );
            continue;
        }
        let c = check_chi2_named(case.name, &h, alpha).unwrap_or_else(|e| panic!("{e}"));
        let integral =
            check_pdf_integral_named(case.name, &h, 1e-3).unwrap_or_else(|e| panic!("{e}"));
        println!(
            "{}: chi2 {:.1}, dof {}, p {:.3}, pdf integral {integral:.5}",
            case.name, c.chi2, c.dof, c.p_value
        );
    }
}
