//! A BSDF defined outside pt: Oren-Nayar rough diffuse reflection, added next to the built-in
//! models with `bsdf_enum!`/`material_enum!` (the path tracer stays statically dispatched),
//! checked with pt's statistical harness (feature `testing`), then rendered: the Cornell box with
//! both blocks in a rough matte material.
//!
//! ```text
//! cargo run --release --example custom_bsdf
//! cargo run --release --example custom_bsdf -- --sigma 40 --skip-checks
//! ```
//!
//! Reference: M. Oren and S. K. Nayar, *Generalization of Lambert's Reflectance Model*,
//! SIGGRAPH 1994 (the qualitative model, as in *Physically Based Rendering*, 3rd ed., 8.4.2).

use clap::Parser;
use pt::pt_core::bsdf::{
    Bsdf, BsdfFlags, BsdfSample, SampleInputs, TransportMode, same_hemisphere,
};
use pt::pt_core::glam::{Vec2, Vec3};
use pt::pt_core::material::{Material, MaterialContext};
use pt::pt_core::sampling::{cosine_hemisphere_pdf, sample_cosine_hemisphere};
use pt::pt_core::testing::{
    BsdfCase, HistogramConfig, check_chi2, check_consistency, check_energy, check_pdf_integral,
    check_reciprocity, histogram,
};
use pt::pt_core::{BuiltinBsdf, BuiltinMaterial, Rgb, bsdf_enum, material_enum};
use pt::pt_scene::presets::CornellBox;
use pt_cli::{Defaults, Failure, Job, RenderArgs};

const NAME: &str = "custom_bsdf";

/// Oren-Nayar reflection: a Lambertian surface made of V-shaped facets whose slopes have standard
/// deviation `sigma`. Brighter than Lambert toward the light at grazing view (backscatter).
#[derive(Clone, Copy, Debug)]
pub struct OrenNayar {
    reflectance: Rgb,
    a: f32,
    b: f32,
}

impl OrenNayar {
    /// `sigma` in radians; 0 gives Lambert.
    pub fn new(reflectance: Rgb, sigma: f32) -> Self {
        let s2 = sigma * sigma;
        Self {
            reflectance,
            a: 1.0 - s2 / (2.0 * (s2 + 0.33)),
            b: 0.45 * s2 / (s2 + 0.09),
        }
    }
}

impl Bsdf for OrenNayar {
    fn flags(&self) -> BsdfFlags {
        BsdfFlags::DIFFUSE_REFLECTION
    }

    fn eval(&self, wo: Vec3, wi: Vec3, _mode: TransportMode) -> Rgb {
        if !same_hemisphere(wo, wi) {
            return Rgb::BLACK;
        }
        let sin_o = (1.0 - wo.z * wo.z).max(0.0).sqrt();
        let sin_i = (1.0 - wi.z * wi.z).max(0.0).sqrt();
        // cos(phi_i - phi_o), from the projections onto the tangent plane.
        let max_cos = if sin_o > 1e-4 && sin_i > 1e-4 {
            ((wi.x * wo.x + wi.y * wo.y) / (sin_i * sin_o)).max(0.0)
        } else {
            0.0
        };
        // sin(alpha) tan(beta) with alpha = max(theta_i, theta_o), beta = min.
        let (sin_alpha, tan_beta) = if wi.z.abs() > wo.z.abs() {
            (sin_o, sin_i / wi.z.abs())
        } else {
            (sin_i, sin_o / wo.z.abs())
        };
        self.reflectance
            * (std::f32::consts::FRAC_1_PI * (self.a + self.b * max_cos * sin_alpha * tan_beta))
    }

    fn pdf(&self, wo: Vec3, wi: Vec3, _mode: TransportMode) -> f32 {
        if same_hemisphere(wo, wi) {
            cosine_hemisphere_pdf(wi.z.abs())
        } else {
            0.0
        }
    }

    fn sample(&self, wo: Vec3, _uc: f32, u: Vec2, mode: TransportMode) -> Option<BsdfSample> {
        if wo.z == 0.0 {
            return None;
        }
        let mut wi = sample_cosine_hemisphere(u);
        if wo.z < 0.0 {
            wi.z = -wi.z;
        }
        let pdf = self.pdf(wo, wi, mode);
        (pdf > 0.0).then(|| BsdfSample {
            wi,
            f: self.eval(wo, wi, mode),
            pdf,
            flags: BsdfFlags::DIFFUSE_REFLECTION,
            eta: 1.0,
        })
    }

    /// One lobe: the lobe choice `uc` is never read, so the path tracer need not draw it
    /// (the default, both numbers, would be correct too; `check_consistency` holds a model to
    /// what it declares here).
    fn sample_inputs(&self) -> SampleInputs {
        SampleInputs::DIRECTION
    }
}

/// A rough matte material producing [`OrenNayar`].
#[derive(Clone, Copy, Debug)]
pub struct RoughMatte {
    /// Albedo-like colour.
    pub reflectance: Rgb,
    /// Facet slope deviation, radians.
    pub sigma: f32,
}

impl Material for RoughMatte {
    type Bsdf = OrenNayar;
    fn bsdf(&self, _ctx: &MaterialContext) -> OrenNayar {
        OrenNayar::new(self.reflectance, self.sigma)
    }
}

bsdf_enum! {
    /// The built-in BSDFs plus Oren-Nayar.
    #[derive(Clone, Debug)]
    pub enum MyBsdf {
        Builtin(BuiltinBsdf),
        OrenNayar(OrenNayar),
    }
}

material_enum! {
    /// The built-in materials plus the rough matte one.
    #[derive(Clone, Debug)]
    pub enum MyMaterial -> MyBsdf {
        Builtin(BuiltinMaterial),
        RoughMatte(RoughMatte),
    }
}

/// Run the harness on the new model: chi-square of `sample` against `pdf` (significance 0.01),
/// `pdf` integrating to 1, `sample` agreeing with `eval`/`pdf`, reciprocity, and an albedo of at
/// most 1, at normal, oblique and grazing outgoing directions.
fn check_model(sigma: f32) -> Result<(), String> {
    let bsdf = OrenNayar::new(Rgb::new(0.8, 0.6, 0.4), sigma);
    for (label, wo) in [
        ("normal", Vec3::Z),
        ("oblique", Vec3::new(0.6, 0.2, 0.77)),
        ("grazing", Vec3::new(0.999, 0.0, 0.04)),
    ] {
        let case = BsdfCase::new(format!("oren-nayar sigma {sigma:.2}, {label}"), bsdf, wo);
        let h = histogram(&case, &HistogramConfig::default());
        let chi2 = check_chi2(&case, &h, 0.01).map_err(|f| f.to_string())?;
        let integral = check_pdf_integral(&case, &h, 1e-3).map_err(|f| f.to_string())?;
        check_consistency(&case, 10_000, 1).map_err(|f| f.to_string())?;
        check_reciprocity(&case, 10_000, 2).map_err(|f| f.to_string())?;
        let albedo = check_energy(&case, 100_000, 3, 0.01).map_err(|f| f.to_string())?;
        println!(
            "{NAME}: {}: chi-square p = {:.3}, pdf integral {integral:.5}, albedo {:.3}",
            case.name, chi2.p_value, albedo.g
        );
    }
    Ok(())
}

/// An Oren-Nayar BSDF defined outside the crates, checked and rendered.
#[derive(Parser)]
struct Cli {
    #[command(flatten)]
    render: RenderArgs,
    /// Facet slope deviation of the rough matte blocks, in degrees
    #[arg(long, value_name = "DEGREES", default_value_t = 30.0)]
    sigma: f32,
    /// Render without running the statistical checks first
    #[arg(long)]
    skip_checks: bool,
}

const DEFAULTS: Defaults = Defaults {
    width: 512,
    height: 512,
    spp: 64,
    max_depth: 16,
    out: "out/custom_bsdf.png",
};

fn die(e: impl std::fmt::Display) -> ! {
    Failure::run(e).exit()
}

fn main() {
    let cli: Cli = pt_cli::parse(NAME, DEFAULTS);
    let extra = format!("sigma {}", cli.sigma);
    let job = Job::new(NAME, &cli.render, &DEFAULTS, &extra).unwrap_or_else(|f| f.exit());
    let sigma = cli.sigma.to_radians();
    if !cli.skip_checks {
        check_model(sigma).unwrap_or_else(|e| die(e));
    }

    // The classic room, built for the extended material type, with rough matte blocks.
    let mut cb = CornellBox::<MyMaterial>::empty_with();
    let matte = cb.builder().add_material(RoughMatte {
        reflectance: CornellBox::white_albedo(),
        sigma,
    });
    cb.add_short_block(matte).add_tall_block(matte);
    let bundle = cb.build().unwrap_or_else(|e| die(e));
    let out = job.render(&bundle.scene, &bundle.camera);
    job.finish(
        &out,
        &format!(
            ", blocks: Oren-Nayar, sigma {:.0} degrees",
            sigma.to_degrees()
        ),
    );
}
