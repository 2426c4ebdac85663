//! Pointwise invariants of a BSDF: sample/eval/pdf consistency, reciprocity, energy.

use glam::Vec3;

use crate::bsdf::{Bsdf, TransportMode};
use crate::color::Rgb;
use crate::sampling::sample_uniform_sphere;
use crate::testing::stats::normal_two_sided_p;
use crate::testing::{BsdfCase, Failure, TestRng};

pub(crate) fn close(a: f32, b: f32, rel: f32, abs: f32) -> bool {
    (a - b).abs() <= abs + rel * a.abs().max(b.abs())
}

pub(crate) fn close_rgb(a: Rgb, b: Rgb, rel: f32, abs: f32) -> bool {
    (0..3).all(|i| close(a[i], b[i], rel, abs))
}

/// Relative size of the direction perturbations that measure how ill-conditioned a value is.
pub(crate) const PERTURBATION: f32 = 1e-5;

/// Two unit vectors orthogonal to `w`.
pub(crate) fn tangents(w: Vec3) -> (Vec3, Vec3) {
    let f = crate::frame::Frame::from_z(w.normalize());
    (f.s(), f.t())
}

/// How much `g(wo, wi)` moves when either direction is turned by [`PERTURBATION`] radians:
/// the largest change per channel over eight perturbations.
///
/// Some values are ill-conditioned in `f32` (Fresnel near the critical angle, very sharp lobes,
/// half vectors of nearly opposite directions): rounding the inputs to `f32` alone changes them
/// by more than any fixed relative tolerance. Differences within a few times this spread are
/// rounding; a planted bug (wrong factor, swapped arguments) is orders of magnitude larger.
pub(crate) fn spread(g: impl Fn(Vec3, Vec3) -> Rgb, wo: Vec3, wi: Vec3) -> Rgb {
    let base = g(wo, wi);
    let mut out = Rgb::BLACK;
    let (so, to) = tangents(wo);
    let (si, ti) = tangents(wi);
    for (o, i) in [
        (so, Vec3::ZERO),
        (-so, Vec3::ZERO),
        (to, Vec3::ZERO),
        (-to, Vec3::ZERO),
        (Vec3::ZERO, si),
        (Vec3::ZERO, -si),
        (Vec3::ZERO, ti),
        (Vec3::ZERO, -ti),
    ] {
        let v = g(
            (wo + o * PERTURBATION).normalize(),
            (wi + i * PERTURBATION).normalize(),
        );
        for c in 0..3 {
            let d = (v[c] - base[c]).abs();
            if d.is_finite() && d > out[c] {
                match c {
                    0 => out.r = d,
                    1 => out.g = d,
                    _ => out.b = d,
                }
            }
        }
    }
    out
}

/// `a` and `b` agree within `1e-3` relative (`1e-5` absolute) plus twice the `spread`.
pub(crate) fn agree(a: Rgb, b: Rgb, spread: Rgb) -> bool {
    (0..3).all(|c| close(a[c], b[c], 1e-3, 1e-5 + 2.0 * spread[c]))
}

/// `n` samples (both transport modes): finite values, a unit `wi`, a positive `pdf`, flags that
/// name exactly one of reflection/transmission, agree with the side of `wi` and belong to the
/// BSDF's flags; for non-delta samples `f` and `pdf` equal `eval` and `pdf` within `1e-3`
/// relative or the rounding spread of [`check_reciprocity`]; delta samples are invisible to `eval` and `pdf` when the BSDF has no other lobe.
/// A number that [`Bsdf::sample_inputs`] declares unread changes no sample (each sample is
/// drawn again with that number changed).
pub fn check_consistency<B: Bsdf>(case: &BsdfCase<B>, n: usize, seed: u64) -> Result<(), Failure> {
    let mut rng = TestRng::new(seed);
    let all = case.bsdf.flags();
    let inputs = case.bsdf.sample_inputs();
    let wo = case.wo;
    for k in 0..n {
        let mode = if k % 2 == 0 {
            TransportMode::Radiance
        } else {
            TransportMode::Importance
        };
        let uc = rng.uniform();
        let u = rng.uniform2();
        let sample = case.bsdf.sample(wo, uc, u, mode);
        let (other_uc, other_u) = (rng.uniform(), rng.uniform2());
        for (what, read, again) in [
            ("uc", inputs.uc, case.bsdf.sample(wo, other_uc, u, mode)),
            ("u", inputs.u, case.bsdf.sample(wo, uc, other_u, mode)),
        ] {
            if !read && again != sample {
                return Err(case.fail(
                    "consistency",
                    format!(
                        "sample {k}: `sample_inputs` says {what} is not read, but another {what} \
                         changes the sample from {sample:?} to {again:?}"
                    ),
                ));
            }
        }
        let Some(s) = sample else {
            continue;
        };
        let fail = |m: String| Err(case.fail("consistency", format!("sample {k}: {m}: {s:?}")));
        if !s.f.is_valid_nonnegative() || !s.pdf.is_finite() || s.pdf <= 0.0 {
            return fail("non-finite or negative value, or pdf <= 0".into());
        }
        if (s.wi.length() - 1.0).abs() > 1e-4 || s.wi.z == 0.0 {
            return fail("wi is not a unit vector off the surface".into());
        }
        if s.flags.is_reflective() == s.flags.is_transmissive() {
            return fail("flags must name exactly one of reflection and transmission".into());
        }
        if !all.contains(s.flags) {
            return fail(format!("sampled flags are not among the BSDF's {all:?}"));
        }
        let crosses = s.wi.z * wo.z < 0.0;
        if crosses != s.flags.is_transmissive() {
            return fail("transmission flag disagrees with the side of wi".into());
        }
        let f = case.bsdf.eval(wo, s.wi, mode);
        let pdf = case.bsdf.pdf(wo, s.wi, mode);
        if s.flags.is_specular() {
            if !all.is_non_specular() && (!f.is_black() || pdf != 0.0) {
                return fail(format!(
                    "a delta lobe is visible to eval ({f:?}) or pdf ({pdf})"
                ));
            }
        } else {
            let eval = |o: Vec3, i: Vec3| case.bsdf.eval(o, i, mode);
            if !close_rgb(f, s.f, 1e-3, 1e-6) && !agree(f, s.f, spread(eval, wo, s.wi)) {
                return fail(format!("eval gives {f:?}"));
            }
            let pdf_rgb = |o: Vec3, i: Vec3| Rgb::splat(case.bsdf.pdf(o, i, mode));
            if !close(pdf, s.pdf, 1e-3, 1e-6)
                && !agree(
                    Rgb::splat(pdf),
                    Rgb::splat(s.pdf),
                    spread(pdf_rgb, wo, s.wi),
                )
            {
                return fail(format!("pdf gives {pdf}"));
            }
        }
    }
    Ok(())
}

/// Generalized reciprocity `f(wo, wi) / n_o^2 = f(wi, wo) / n_i^2` in radiance mode, and
/// `f_radiance(wo, wi) = f_importance(wi, wo)`, for `n` pairs: a quarter with `wo = case.wo` and
/// `wi` drawn by `sample` (so narrow lobes are tested where they are), the others with one or
/// both directions uniform on the sphere. Values agree within `1e-3` relative, or within twice
/// the change that turning either direction by `1e-5` radians makes (rounding in ill-conditioned
/// places, such as Fresnel at the critical angle).
pub fn check_reciprocity<B: Bsdf>(case: &BsdfCase<B>, n: usize, seed: u64) -> Result<(), Failure> {
    let mut rng = TestRng::new(seed);
    let (r, i) = (TransportMode::Radiance, TransportMode::Importance);
    for k in 0..n {
        let wo = if k % 4 < 2 {
            case.wo
        } else {
            sample_uniform_sphere(rng.uniform2())
        };
        let wi = if k % 2 == 0 {
            match case.bsdf.sample(wo, rng.uniform(), rng.uniform2(), r) {
                Some(s) if !s.flags.is_specular() => s.wi,
                _ => continue,
            }
        } else {
            sample_uniform_sphere(rng.uniform2())
        };
        if wo.z.abs() < 1e-4 || wi.z.abs() < 1e-4 {
            continue;
        }
        let f_oi = case.bsdf.eval(wo, wi, r);
        let f_io = case.bsdf.eval(wi, wo, r);
        if !f_oi.is_valid_nonnegative() || !f_io.is_valid_nonnegative() {
            return Err(case.fail(
                "reciprocity",
                format!("eval is negative or not finite at wo {wo}, wi {wi}: {f_oi:?}, {f_io:?}"),
            ));
        }
        let (no, ni) = (case.ior(wo), case.ior(wi));
        let a = f_oi / (no * no);
        let b = f_io / (ni * ni);
        let eval_r = |o: Vec3, i: Vec3| case.bsdf.eval(o, i, r);
        let cond = || spread(eval_r, wo, wi) / (no * no) + spread(eval_r, wi, wo) / (ni * ni);
        if !close_rgb(a, b, 1e-3, 1e-6) && !agree(a, b, cond()) {
            return Err(case.fail(
                "reciprocity",
                format!(
                    "f(wo, wi) / n_o^2 = {a:?} but f(wi, wo) / n_i^2 = {b:?} for wo {wo}, wi {wi}"
                ),
            ));
        }
        let adj = case.bsdf.eval(wi, wo, i);
        if !close_rgb(f_oi, adj, 1e-3, 1e-6) && !agree(f_oi, adj, cond() * (no * no)) {
            return Err(case.fail(
                "reciprocity",
                format!(
                    "radiance f(wo, wi) = {f_oi:?} but importance f(wi, wo) = {adj:?} for wo {wo}, wi {wi}"
                ),
            ));
        }
    }
    Ok(())
}

/// Directional albedo `E[f |cos| / pdf]` over `n` importance-mode samples (failures count as
/// zero): per channel at most 1, and equal to `case.albedo` when given, each within `1e-3` plus
/// the deviation a normal test at significance `alpha` allows. Returns the estimate.
///
/// Importance mode is used because it carries energy: in radiance mode refraction scales by
/// `1 / eta^2`, which is not a gain or loss of energy.
pub fn check_energy<B: Bsdf>(
    case: &BsdfCase<B>,
    n: usize,
    seed: u64,
    alpha: f64,
) -> Result<Rgb, Failure> {
    let mut rng = TestRng::new(seed);
    let mut sum = [0.0f64; 3];
    let mut sum2 = [0.0f64; 3];
    for _ in 0..n {
        let uc = rng.uniform();
        let u = rng.uniform2();
        let Some(s) = case.bsdf.sample(case.wo, uc, u, TransportMode::Importance) else {
            continue;
        };
        let w = s.f * (s.wi.z.abs() / s.pdf);
        if !w.is_valid_nonnegative() {
            return Err(case.fail("energy", format!("sample weight {w:?} from {s:?}")));
        }
        for c in 0..3 {
            let v = f64::from(w[c]);
            sum[c] += v;
            sum2[c] += v * v;
        }
    }
    let nf = n as f64;
    // Normal quantile for the corrected alpha, found by bisection on the two-sided p-value.
    let z = {
        let (mut lo, mut hi) = (0.0f64, 40.0f64);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if normal_two_sided_p(mid) > alpha {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        hi
    };
    let mut mean = [0.0f32; 3];
    for c in 0..3 {
        let m = sum[c] / nf;
        let var = (sum2[c] / nf - m * m).max(0.0);
        let se = (var / nf).sqrt();
        let allowed = 1e-3 + z * se;
        mean[c] = m as f32;
        if m > 1.0 + allowed {
            return Err(case.fail(
                "energy",
                format!("albedo {m:.5} > 1 in channel {c} (allowed {allowed:.2e} above)"),
            ));
        }
        if let Some(expected) = case.albedo {
            let e = f64::from(expected[c]);
            if (m - e).abs() > allowed {
                return Err(case.fail(
                    "energy",
                    format!("albedo {m:.5} in channel {c}, expected {e:.5} within {allowed:.2e}"),
                ));
            }
        }
    }
    Ok(Rgb::new(mean[0], mean[1], mean[2]))
}
