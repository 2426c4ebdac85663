//! A light defined outside pt: a sky dome whose radiance goes from a horizon colour to a zenith
//! colour, over a uniform ground colour, importance-sampled (cosine-weighted about the zenith
//! above the horizon). It joins the built-in lights through `light_enum!`, so next-event
//! estimation and MIS use it with static dispatch; its sampling is checked with pt's
//! statistical harness (chi-square of `sample_li` against `pdf_li`, and `pdf_li` integrating to
//! 1), then it lights a mirror, a glass and a diffuse sphere on a floor.
//!
//! ```text
//! cargo run --release --example custom_light
//! cargo run --release --example custom_light -- --skip-checks --spp 256
//! ```

use std::f32::consts::PI;

use clap::Parser;
use pt::pt_accel::{Bounds3, Ray, TriangleMesh};
use pt::pt_core::glam::{Mat3, Vec2, Vec3};
use pt::pt_core::light::{Light, LightFlags, LightSample, LightSampleContext};
use pt::pt_core::sampling::{sample_cosine_hemisphere, sample_uniform_sphere};
use pt::pt_core::testing::{
    HistogramConfig, check_chi2_named, check_pdf_integral_named, light_histogram,
};
use pt::pt_core::{
    BuiltinLight, BuiltinMaterial, Glass, Mesh, Mirror, Object, PinholeCamera, Rgb, SceneBuilder,
    light_enum,
};
use pt_cli::{Defaults, Failure, Job, RenderArgs};

const NAME: &str = "custom_light";

/// A sky: `horizon` to `zenith` radiance with the sine of elevation above the horizon (`+y` is
/// up), `ground` below it.
#[derive(Clone, Copy, Debug)]
pub struct SkyDome {
    zenith: Rgb,
    horizon: Rgb,
    ground: Rgb,
    /// Probability of sampling the upper hemisphere (by its share of the power).
    p_up: f32,
    /// The scene's bounding sphere, for shadow-ray targets and the power estimate.
    center: Vec3,
    radius: f32,
}

impl SkyDome {
    /// A sky; every colour must be finite and non-negative.
    pub fn new(zenith: Rgb, horizon: Rgb, ground: Rgb) -> Result<Self, String> {
        for (name, c) in [("zenith", zenith), ("horizon", horizon), ("ground", ground)] {
            if !c.is_valid_nonnegative() {
                return Err(format!(
                    "{name} radiance must be finite and >= 0, got {c:?}"
                ));
            }
        }
        let (up, down) = Self::hemisphere_integrals(zenith, horizon, ground);
        let total = up.luminance() + down.luminance();
        let p_up = if total > 0.0 {
            up.luminance() / total
        } else {
            1.0
        };
        Ok(Self {
            zenith,
            horizon,
            ground,
            p_up,
            center: Vec3::ZERO,
            radius: 1.0,
        })
    }

    /// Integrals of radiance over the upper and lower hemispheres: with `L = h + (z - h) y`
    /// above, `integral of y dw = pi`.
    fn hemisphere_integrals(zenith: Rgb, horizon: Rgb, ground: Rgb) -> (Rgb, Rgb) {
        (
            horizon * (2.0 * PI) + (zenith - horizon) * PI,
            ground * (2.0 * PI),
        )
    }

    fn radiance(&self, w: Vec3) -> Rgb {
        if w.y >= 0.0 {
            self.horizon + (self.zenith - self.horizon) * w.y
        } else {
            self.ground
        }
    }
}

impl Light for SkyDome {
    fn flags(&self) -> LightFlags {
        LightFlags::INFINITE
    }

    fn power(&self) -> Rgb {
        let (up, down) = Self::hemisphere_integrals(self.zenith, self.horizon, self.ground);
        (up + down) * (PI * self.radius * self.radius)
    }

    fn sample_li(&self, ctx: &LightSampleContext, u: Vec2) -> Option<LightSample> {
        // Choose a hemisphere with u.x, then reuse the rescaled u.x within it.
        let wi = if u.x < self.p_up {
            let v = sample_cosine_hemisphere(Vec2::new(u.x / self.p_up, u.y));
            Vec3::new(v.x, v.z, v.y) // local z (the lobe's axis) becomes world y
        } else {
            let v = sample_uniform_sphere(Vec2::new((u.x - self.p_up) / (1.0 - self.p_up), u.y));
            Vec3::new(v.x, -v.y.abs(), v.z)
        };
        let pdf = self.pdf_li(ctx, wi);
        if pdf <= 0.0 {
            return None;
        }
        Some(LightSample {
            li: self.radiance(wi),
            wi,
            pdf,
            // The shadow-ray target: beyond everything in the scene.
            point: ctx.point_beyond(wi, self.center, self.radius),
        })
    }

    fn pdf_li(&self, _ctx: &LightSampleContext, wi: Vec3) -> f32 {
        if wi.y > 0.0 {
            self.p_up * wi.y / PI
        } else {
            (1.0 - self.p_up) / (2.0 * PI)
        }
    }

    fn le(&self, ray: &Ray) -> Rgb {
        self.radiance(ray.dir.normalize())
    }

    fn preprocess(&mut self, bounds: &Bounds3) {
        if !bounds.is_empty() && bounds.min.is_finite() && bounds.max.is_finite() {
            self.center = (bounds.min + bounds.max) * 0.5;
            self.radius = (bounds.max - bounds.min).length() * 0.5;
        }
    }
}

light_enum! {
    /// The built-in lights plus the sky dome.
    #[derive(Clone, Debug)]
    pub enum MyLight {
        Builtin(BuiltinLight),
        Sky(SkyDome),
    }
}

/// `sample_li` against `pdf_li` by chi-square (significance 0.01) over the whole sphere, and
/// `pdf_li` integrating to 1, for a sky with and without ground light.
fn check_light(sky: &SkyDome) -> Result<(), String> {
    let ctx = LightSampleContext::default();
    let h = light_histogram(sky, &ctx, Mat3::IDENTITY, &HistogramConfig::default());
    let chi2 = check_chi2_named("sky dome", &h, 0.01).map_err(|f| f.to_string())?;
    let integral = check_pdf_integral_named("sky dome", &h, 1e-3).map_err(|f| f.to_string())?;
    println!(
        "{NAME}: sky dome: chi-square p = {:.3} ({} dof), pdf integral {integral:.5}",
        chi2.p_value, chi2.dof
    );
    Ok(())
}

/// An importance-sampled sky defined outside the crates, checked and rendered.
#[derive(Parser)]
struct Cli {
    #[command(flatten)]
    render: RenderArgs,
    /// Render without running the statistical checks first
    #[arg(long)]
    skip_checks: bool,
}

const DEFAULTS: Defaults = Defaults {
    width: 640,
    height: 360,
    spp: 64,
    max_depth: 16,
    out: "out/custom_light.png",
};

fn die(e: impl std::fmt::Display) -> ! {
    Failure::run(e).exit()
}

fn main() {
    let cli: Cli = pt_cli::parse(NAME, DEFAULTS);
    let job = Job::new(NAME, &cli.render, &DEFAULTS, "").unwrap_or_else(|f| f.exit());
    let sky = SkyDome::new(
        Rgb::new(0.25, 0.45, 1.2),
        Rgb::new(1.0, 0.95, 0.85),
        Rgb::new(0.08, 0.07, 0.06),
    )
    .unwrap_or_else(|e| die(e));
    if !cli.skip_checks {
        check_light(&sky).unwrap_or_else(|e| die(e));
    }

    // The scene is built for the extended light type; materials stay the built-in ones.
    let mut b = SceneBuilder::<BuiltinMaterial, MyLight>::default();
    let floor = b.add_mesh(Mesh::new(
        TriangleMesh::new(
            vec![
                Vec3::new(-20.0, 0.0, -20.0),
                Vec3::new(20.0, 0.0, -20.0),
                Vec3::new(20.0, 0.0, 20.0),
                Vec3::new(-20.0, 0.0, 20.0),
            ],
            vec![[0, 2, 1], [0, 3, 2]],
        )
        .unwrap_or_else(|e| die(e)),
    ));
    let grey = b.add_material(BuiltinMaterial::diffuse(Rgb::splat(0.5)));
    b.add_object(Object::new(floor, grey));
    let ball = b.add_mesh(pt::pt_scene::shapes::sphere(1.0, 48, 96));
    let materials = [
        b.add_material(Mirror::new(Rgb::splat(0.95))),
        b.add_material(Glass::new(1.5).unwrap_or_else(|e| die(e))),
        b.add_material(BuiltinMaterial::diffuse(Rgb::new(0.8, 0.3, 0.2))),
    ];
    for (i, m) in materials.into_iter().enumerate() {
        let at = Vec3::new(-2.4 + 2.4 * i as f32, 1.0, 0.0);
        b.add_object(
            Object::new(ball, m).with_transform(pt::pt_core::glam::Affine3A::from_translation(at)),
        );
    }
    b.add_light(sky);
    let scene = b.build().unwrap_or_else(|e| die(e));
    let camera = PinholeCamera::look_at(
        Vec3::new(0.0, 2.5, 8.0),
        Vec3::new(0.0, 0.8, 0.0),
        Vec3::Y,
        40.0,
    )
    .unwrap_or_else(|e| die(e));
    let out = job.render(&scene, &camera);
    job.finish(&out, ", lit by a user-defined sky dome");
}
