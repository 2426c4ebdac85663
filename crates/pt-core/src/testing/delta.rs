//! Delta lobes against the law of reflection, Snell's law and an independent Fresnel.

use glam::Vec3;

use crate::bsdf::{Bsdf, BsdfFlags, TransportMode};
use crate::color::Rgb;
use crate::testing::invariants::{close, close_rgb};
use crate::testing::stats::normal_two_sided_p;
use crate::testing::{BsdfCase, DeltaExpectation, Failure, TestRng};

/// Fresnel reflectance of a smooth dielectric for light arriving at `cos_o` (positive outside),
/// `eta = n_inside / n_outside`, written from Snell's law and the s/p amplitude coefficients in
/// `f64`: an implementation independent of [`crate::bsdf::fresnel`].
#[must_use]
pub fn fresnel_reference(cos_o: f64, eta: f64) -> f64 {
    let (n1, n2) = if cos_o >= 0.0 { (1.0, eta) } else { (eta, 1.0) };
    let ci = cos_o.abs().min(1.0);
    let si = (1.0 - ci * ci).sqrt();
    let st = si * n1 / n2;
    if st >= 1.0 {
        return 1.0;
    }
    let ct = (1.0 - st * st).sqrt();
    let rs = (n1 * ci - n2 * ct) / (n1 * ci + n2 * ct);
    let rp = (n2 * ci - n1 * ct) / (n2 * ci + n1 * ct);
    0.5 * (rs * rs + rp * rp)
}

/// Delta lobes of `n` samples (alternating transport modes) against the case's
/// [`DeltaExpectation`]: mirror directions, Snell's law, the sample's `eta`, the throughput of
/// each lobe, and for a dielectric the fraction of reflections against the Fresnel reflectance
/// (a binomial test at significance `alpha`; exact when the reflectance is 0 or 1).
pub fn check_delta<B: Bsdf>(
    case: &BsdfCase<B>,
    n: usize,
    seed: u64,
    alpha: f64,
) -> Result<(), Failure> {
    if case.delta == DeltaExpectation::None {
        return Ok(());
    }
    let mut rng = TestRng::new(seed);
    let wo = case.wo;
    let mirror = Vec3::new(-wo.x, -wo.y, wo.z);
    let (mut reflections, mut total) = (0u64, 0u64);
    for k in 0..n {
        let mode = if k % 2 == 0 {
            TransportMode::Radiance
        } else {
            TransportMode::Importance
        };
        let Some(s) = case.bsdf.sample(wo, rng.uniform(), rng.uniform2(), mode) else {
            return Err(case.fail("delta", format!("sample {k} failed")));
        };
        let fail = |m: String| Err(case.fail("delta", format!("sample {k}: {m}: {s:?}")));
        if !s.flags.is_specular() {
            return fail("expected a delta lobe".into());
        }
        total += 1;
        let weight = s.f * (s.wi.z.abs() / s.pdf);
        if s.flags.contains(BsdfFlags::SPECULAR_REFLECTION) {
            reflections += 1;
            if (s.wi - mirror).length() > 1e-5 {
                return fail(format!("reflection is not the mirror direction {mirror}"));
            }
        }
        match case.delta {
            DeltaExpectation::None => {}
            DeltaExpectation::Reflection { weight: expected } => {
                if !s.flags.contains(BsdfFlags::SPECULAR_REFLECTION) {
                    return fail("expected a specular reflection".into());
                }
                if let Some(e) = expected
                    && !close_rgb(weight, e, 1e-4, 1e-6)
                {
                    return fail(format!("throughput {weight:?}, expected {e:?}"));
                }
            }
            DeltaExpectation::Dielectric { eta, tint } => {
                let f = fresnel_reference(f64::from(wo.z), f64::from(eta)) as f32;
                if s.flags.is_reflective() {
                    if !close(s.pdf, f, 1e-4, 1e-6) {
                        return fail(format!("reflection probability, expected Fresnel {f}"));
                    }
                    if !close_rgb(weight, Rgb::WHITE, 1e-4, 1e-6) {
                        return fail("reflection throughput is not 1".into());
                    }
                    continue;
                }
                // Snell: n_o sin_o = n_t sin_t, azimuth reversed, other side.
                let (no, nt) = if wo.z > 0.0 { (1.0, eta) } else { (eta, 1.0) };
                let txy = -glam::Vec2::new(wo.x, wo.y) * (no / nt);
                let tz = -wo.z.signum() * (1.0 - txy.length_squared()).max(0.0).sqrt();
                let expected = Vec3::new(txy.x, txy.y, tz);
                if (s.wi - expected).length() > 1e-4 {
                    return fail(format!("refraction is not Snell's direction {expected}"));
                }
                if !close(s.eta, nt / no, 1e-5, 0.0) {
                    return fail(format!("sample eta should be n_t / n_o = {}", nt / no));
                }
                if !close(s.pdf, 1.0 - f, 1e-4, 1e-6) {
                    return fail(format!(
                        "refraction probability, expected 1 - Fresnel {}",
                        1.0 - f
                    ));
                }
                let etap = nt / no;
                let expected_w = match mode {
                    TransportMode::Radiance => tint / (etap * etap),
                    TransportMode::Importance => tint,
                };
                if !close_rgb(weight, expected_w, 1e-4, 1e-6) {
                    return fail(format!("refraction throughput, expected {expected_w:?}"));
                }
            }
        }
    }
    if let DeltaExpectation::Dielectric { eta, .. } = case.delta {
        let f = fresnel_reference(f64::from(wo.z), f64::from(eta));
        let nf = total as f64;
        let k = reflections as f64;
        let ok = if f >= 1.0 {
            reflections == total
        } else if f <= 0.0 {
            reflections == 0
        } else {
            let z = (k - nf * f) / (nf * f * (1.0 - f)).sqrt();
            normal_two_sided_p(z) >= alpha
        };
        if !ok {
            return Err(case.fail(
                "delta",
                format!(
                    "{reflections} reflections in {total} samples ({:.5}), Fresnel says {f:.5}",
                    k / nf
                ),
            ));
        }
    }
    Ok(())
}
