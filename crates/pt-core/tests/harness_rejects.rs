//! Every check of the statistical harness fails on a planted bug: each test-only BSDF below
//! wraps a correct model and breaks one thing, and the matching check must reject it. Without
//! these, a check that could never fail would look like a passing test.

use std::f32::consts::FRAC_1_PI;

use pt_core::bsdf::fresnel::reflect;
use pt_core::glam::{Vec2, Vec3};
use pt_core::testing::{
    BsdfCase, DeltaExpectation, HistogramConfig, check_chi2, check_consistency, check_delta,
    check_energy, check_pdf_integral, check_reciprocity, histogram,
};
use pt_core::{
    Bsdf, BsdfFlags, BsdfSample, ConductorFresnel, Lambertian, Rgb, RoughConductor,
    RoughDielectric, SampleInputs, SmoothDielectric, TransportMode, TrowbridgeReitz,
};

/// The significance level of one test alone (no correction: a planted bug must be caught even
/// at the strictest per-test level the real suite uses, which is smaller still).
const ALPHA: f64 = 1e-6;

fn wo(cos_theta: f32) -> Vec3 {
    Vec3::new((1.0 - cos_theta * cos_theta).sqrt(), 0.0, cos_theta)
}

fn config() -> HistogramConfig {
    HistogramConfig {
        samples: 200_000,
        ..HistogramConfig::default()
    }
}

/// A correct model `B` with a planted bug `X`: every method is the model's own except those the
/// bug changes.
struct Planted<B, X>(B, X);

/// How a planted bug changes a model `b`: each method is `b`'s own unless the bug overrides it.
trait Bug<B: Bsdf> {
    fn eval(&self, b: &B, wo: Vec3, wi: Vec3, mode: TransportMode) -> Rgb {
        b.eval(wo, wi, mode)
    }
    fn pdf(&self, b: &B, wo: Vec3, wi: Vec3, mode: TransportMode) -> f32 {
        b.pdf(wo, wi, mode)
    }
    /// The sample `b` drew for `wo`, as the bug changes it.
    fn sampled(&self, _b: &B, _wo: Vec3, s: BsdfSample, _mode: TransportMode) -> BsdfSample {
        s
    }
    fn sample_inputs(&self, b: &B) -> SampleInputs {
        b.sample_inputs()
    }
}

impl<B: Bsdf, X: Bug<B>> Bsdf for Planted<B, X> {
    fn flags(&self) -> BsdfFlags {
        self.0.flags()
    }
    fn eval(&self, wo: Vec3, wi: Vec3, mode: TransportMode) -> Rgb {
        self.1.eval(&self.0, wo, wi, mode)
    }
    fn pdf(&self, wo: Vec3, wi: Vec3, mode: TransportMode) -> f32 {
        self.1.pdf(&self.0, wo, wi, mode)
    }
    fn sample(&self, wo: Vec3, uc: f32, u: Vec2, mode: TransportMode) -> Option<BsdfSample> {
        let s = self.0.sample(wo, uc, u, mode)?;
        Some(self.1.sampled(&self.0, wo, s, mode))
    }
    fn sample_inputs(&self) -> SampleInputs {
        self.1.sample_inputs(&self.0)
    }
}

/// Bug: `pdf` evaluates with its arguments swapped.
struct SwappedPdf;

impl Bug<RoughConductor> for SwappedPdf {
    fn pdf(&self, b: &RoughConductor, wo: Vec3, wi: Vec3, mode: TransportMode) -> f32 {
        b.pdf(wi, wo, mode)
    }
}

fn gold(alpha: f32) -> RoughConductor {
    RoughConductor::new(TrowbridgeReitz::isotropic(alpha), ConductorFresnel::GOLD)
}

#[test]
fn chi2_rejects_a_pdf_with_swapped_arguments() {
    let good = BsdfCase::new("conductor", gold(0.3), wo(0.3));
    let h = histogram(&good, &config());
    check_chi2(&good, &h, ALPHA).expect("the correct model passes");

    let bad = BsdfCase::new("swapped pdf", Planted(gold(0.3), SwappedPdf), wo(0.3));
    let h = histogram(&bad, &config());
    let err = check_chi2(&bad, &h, ALPHA).expect_err("chi-square must reject a wrong pdf");
    assert_eq!(err.check, "chi-square");
}

/// Bug: the Lambertian pdf forgets the cosine (`1 / pi` instead of `cos / pi`).
struct NoCosinePdf;

impl Bug<Lambertian> for NoCosinePdf {
    fn pdf(&self, b: &Lambertian, wo: Vec3, wi: Vec3, mode: TransportMode) -> f32 {
        if b.pdf(wo, wi, mode) > 0.0 {
            FRAC_1_PI
        } else {
            0.0
        }
    }
}

#[test]
fn pdf_integral_rejects_a_dropped_cosine() {
    let good = BsdfCase::new("lambertian", Lambertian::new(Rgb::splat(0.5)), wo(0.7));
    let h = histogram(&good, &config());
    check_pdf_integral(&good, &h, 1e-3).expect("the correct model passes");

    let bad = BsdfCase::new(
        "no cosine",
        Planted(Lambertian::new(Rgb::splat(0.5)), NoCosinePdf),
        wo(0.7),
    );
    let h = histogram(&bad, &config());
    let err = check_pdf_integral(&bad, &h, 1e-3).expect_err("the integral is 2, not 1");
    assert_eq!(err.check, "pdf integral");
}

/// Bug: `sample` returns the albedo as `f`, forgetting the `1 / pi`.
struct SampleWithoutPi;

impl Bug<Lambertian> for SampleWithoutPi {
    fn sampled(&self, b: &Lambertian, _: Vec3, s: BsdfSample, _: TransportMode) -> BsdfSample {
        BsdfSample {
            f: b.reflectance(),
            ..s
        }
    }
}

#[test]
fn consistency_rejects_a_sample_value_that_eval_disagrees_with() {
    let r = Lambertian::new(Rgb::splat(0.5));
    check_consistency(&BsdfCase::new("lambertian", r, wo(0.7)), 1000, 1)
        .expect("the correct model passes");
    let err = check_consistency(
        &BsdfCase::new("sample without pi", Planted(r, SampleWithoutPi), wo(0.7)),
        1000,
        1,
    )
    .expect_err("sample and eval disagree");
    assert_eq!(err.check, "consistency");
}

/// Bug: declares that `sample` reads none of its numbers (as a mirror), but the model reads
/// the lobe choice (smooth glass) or the direction (Lambertian): the path tracers would pass it
/// constants.
struct ReadsUndeclared;

impl<B: Bsdf> Bug<B> for ReadsUndeclared {
    fn sample_inputs(&self, _: &B) -> SampleInputs {
        SampleInputs::NONE
    }
}

#[test]
fn consistency_rejects_a_number_read_though_declared_unread() {
    let glass = SmoothDielectric::new(1.5, Rgb::WHITE);
    let lambert = Lambertian::new(Rgb::splat(0.5));
    check_consistency(&BsdfCase::new("glass", glass, wo(0.7)), 1000, 1)
        .expect("the correct glass passes");
    check_consistency(&BsdfCase::new("lambertian", lambert, wo(0.7)), 1000, 1)
        .expect("the correct Lambertian passes");
    for (name, err) in [
        (
            "glass",
            check_consistency(
                &BsdfCase::new("g", Planted(glass, ReadsUndeclared), wo(0.7)),
                1000,
                1,
            ),
        ),
        (
            "lambertian",
            check_consistency(
                &BsdfCase::new("l", Planted(lambert, ReadsUndeclared), wo(0.7)),
                1000,
                1,
            ),
        ),
    ] {
        let err = err.expect_err(name);
        assert_eq!(err.check, "consistency", "{name}");
        assert!(
            err.message.contains("sample_inputs"),
            "{name}: {}",
            err.message
        );
    }
}

/// Bug: radiance-mode refraction scales by `etap^2` instead of `1 / etap^2` (the wrong eta ratio).
struct WrongEtaRatio;

impl Bug<RoughDielectric> for WrongEtaRatio {
    fn eval(&self, b: &RoughDielectric, wo: Vec3, wi: Vec3, mode: TransportMode) -> Rgb {
        let f = b.eval(wo, wi, TransportMode::Importance);
        if mode == TransportMode::Radiance && wo.z * wi.z < 0.0 {
            let etap = if wo.z > 0.0 { b.eta() } else { 1.0 / b.eta() };
            f * (etap * etap)
        } else {
            f
        }
    }
    fn sampled(
        &self,
        b: &RoughDielectric,
        wo: Vec3,
        s: BsdfSample,
        mode: TransportMode,
    ) -> BsdfSample {
        BsdfSample {
            f: self.eval(b, wo, s.wi, mode),
            ..s
        }
    }
}

#[test]
fn reciprocity_rejects_the_wrong_eta_ratio() {
    let glass = RoughDielectric::new(TrowbridgeReitz::isotropic(0.3), 1.5, Rgb::WHITE);
    let mut good = BsdfCase::new("rough glass", glass, wo(0.6));
    good.eta = 1.5;
    check_reciprocity(&good, 5000, 3).expect("the correct model passes");

    let mut bad = BsdfCase::new("wrong eta ratio", Planted(glass, WrongEtaRatio), wo(0.6));
    bad.eta = 1.5;
    let err = check_reciprocity(&bad, 5000, 3).expect_err("generalized reciprocity is broken");
    assert_eq!(err.check, "reciprocity");
}

/// Bug: a GGX conductor without the masking-shadowing term `G` (it creates energy at grazing
/// angles).
struct NoMasking(TrowbridgeReitz);

impl Bsdf for NoMasking {
    fn flags(&self) -> BsdfFlags {
        BsdfFlags::GLOSSY_REFLECTION
    }
    fn eval(&self, wo: Vec3, wi: Vec3, _mode: TransportMode) -> Rgb {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::BLACK;
        }
        let wm = (wo + wi).normalize();
        Rgb::splat(self.0.d(wm) / (4.0 * wo.z * wi.z))
    }
    fn pdf(&self, wo: Vec3, wi: Vec3, _mode: TransportMode) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let wm = (wo + wi).normalize();
        self.0.pdf(wo, wm) / (4.0 * wo.dot(wm))
    }
    fn sample(&self, wo: Vec3, _uc: f32, u: Vec2, mode: TransportMode) -> Option<BsdfSample> {
        let wm = self.0.sample_wm(wo, u);
        let wi = reflect(wo, wm);
        if wi.z <= 0.0 {
            return None;
        }
        Some(BsdfSample {
            wi,
            f: self.eval(wo, wi, mode),
            pdf: self.pdf(wo, wi, mode),
            flags: BsdfFlags::GLOSSY_REFLECTION,
            eta: 1.0,
        })
    }
}

#[test]
fn energy_rejects_a_model_without_masking() {
    let white = RoughConductor::new(
        TrowbridgeReitz::isotropic(0.6),
        ConductorFresnel::Schlick(Rgb::WHITE),
    );
    check_energy(
        &BsdfCase::new("white conductor", white, wo(0.1)),
        50_000,
        5,
        ALPHA,
    )
    .expect("the correct model passes");
    let bad = BsdfCase::new(
        "no masking",
        NoMasking(TrowbridgeReitz::isotropic(0.6)),
        wo(0.1),
    );
    let err = check_energy(&bad, 50_000, 5, ALPHA).expect_err("albedo above 1");
    assert_eq!(err.check, "energy");
}

/// Bug: the refraction uses `1 / eta` where `eta` belongs (a model built for the wrong side).
#[test]
fn delta_check_rejects_the_wrong_refraction_ratio() {
    let case = |bsdf: SmoothDielectric| BsdfCase {
        name: "glass".into(),
        bsdf,
        wo: wo(0.6),
        eta: 1.5,
        delta: DeltaExpectation::Dielectric {
            eta: 1.5,
            tint: Rgb::WHITE,
        },
        albedo: None,
    };
    check_delta(
        &case(SmoothDielectric::new(1.5, Rgb::WHITE)),
        20_000,
        9,
        ALPHA,
    )
    .expect("the correct model passes");
    let err = check_delta(
        &case(SmoothDielectric::new(1.0 / 1.5, Rgb::WHITE)),
        20_000,
        9,
        ALPHA,
    )
    .expect_err("Snell's law is broken");
    assert_eq!(err.check, "delta");
}

/// Bug: the reflect/refract choice uses Schlick's approximation, not the Fresnel equations,
/// while every direction and weight is right: only the measured split can tell.
struct SchlickSplit(f32);

impl Bsdf for SchlickSplit {
    fn flags(&self) -> BsdfFlags {
        BsdfFlags::SPECULAR_REFLECTION | BsdfFlags::SPECULAR_TRANSMISSION
    }
    fn eval(&self, _: Vec3, _: Vec3, _: TransportMode) -> Rgb {
        Rgb::BLACK
    }
    fn pdf(&self, _: Vec3, _: Vec3, _: TransportMode) -> f32 {
        0.0
    }
    fn sample(&self, wo: Vec3, uc: f32, u: Vec2, mode: TransportMode) -> Option<BsdfSample> {
        let exact = pt_core::bsdf::fresnel::fresnel_dielectric(wo.z, self.0);
        let f0 = ((self.0 - 1.0) / (self.0 + 1.0)).powi(2);
        let schlick = f0 + (1.0 - f0) * (1.0 - wo.z.abs()).powi(5);
        // Remap uc so the real model reflects with probability `schlick` while reporting the
        // exact Fresnel probability and weights.
        let uc = if uc < schlick {
            uc / schlick * exact
        } else {
            exact + (uc - schlick) / (1.0 - schlick) * (1.0 - exact)
        };
        SmoothDielectric::new(self.0, Rgb::WHITE).sample(wo, uc, u, mode)
    }
}

#[test]
fn delta_check_rejects_a_wrong_fresnel_split() {
    // At 70 degrees Schlick is off by about 0.03 for eta 1.5: detectable with 100,000 samples.
    let bad = BsdfCase {
        name: "schlick split".into(),
        bsdf: SchlickSplit(1.5),
        wo: wo(0.34),
        eta: 1.5,
        delta: DeltaExpectation::Dielectric {
            eta: 1.5,
            tint: Rgb::WHITE,
        },
        albedo: None,
    };
    let err = check_delta(&bad, 100_000, 11, ALPHA).expect_err("the split is not Fresnel's");
    assert_eq!(err.check, "delta");
    assert!(err.message.contains("Fresnel says"), "{err}");
}
