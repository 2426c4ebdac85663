//! The light registry: every built-in light in a configuration whose sampling can be checked,
//! with the point it is sampled from.
//!
//! Adding a built-in light means adding its cases here; the crate's `tests/registry.rs` fails
//! while a variant of [`BuiltinLight`] has none, and `tests/light_stats.rs` checks each case
//! (`sample_li` against `pdf_li` by chi-square, and the pdf integral).

use glam::{Mat3, Vec3};

use crate::color::Rgb;
use crate::image::Image;
use crate::interaction::SurfacePoint;
use crate::light::{
    BuiltinLight, CubemapEnvironment, DirectionalLight, EquirectEnvironment, LightSampleContext,
    PointLight, SpotLight, TexturedTriangleLight, TriangleLight, UniformEnvironment,
};
use crate::testing::{Binning, HistogramConfig, Quadrature};

/// A built-in light and the receiving point its samples are drawn for.
#[derive(Clone, Debug)]
#[non_exhaustive]
pub struct LightCase {
    /// What the case is.
    pub name: &'static str,
    /// The light.
    pub light: BuiltinLight,
    /// The receiving point (with no shading normal: every direction counts).
    pub ctx: LightSampleContext,
    /// Rotates world directions into the histogram's frame (aligning map texels with cells).
    pub frame: Mat3,
    /// The histogram that checks the case: cells aligned with the light's texels where it has
    /// them, so that the midpoint rule integrates its piecewise-constant pdf exactly.
    pub config: HistogramConfig,
}

/// A small synthetic map: a gradient, a dark band and one bright texel, so importance sampling
/// has structure to follow.
fn synthetic(w: u32, h: u32, seed: f32) -> Image {
    let mut img = Image::new(w, h);
    for y in 0..h {
        for x in 0..w {
            let v = 0.2 + seed + x as f32 / w as f32 + if y == h / 3 { 0.0 } else { 0.5 };
            img.set(x, y, Rgb::new(v, 0.5 * v, 0.1));
        }
    }
    img.set(w / 3, h / 4, Rgb::splat(50.0));
    img
}

/// Every built-in light: a triangle by area and by solid angle, a textured triangle by its
/// cells and as one cell, the uniform, equirectangular
/// and cube-map environments, and the point, spot and directional lights (delta lights: their
/// samples must all be delta). Sampled from the origin.
///
/// # Panics
///
/// Never: the parameters are valid constants.
#[must_use]
pub fn builtin_light_cases() -> Vec<LightCase> {
    let ctx = LightSampleContext::new(SurfacePoint::exact(Vec3::ZERO), Vec3::ZERO);
    let tri = [
        Vec3::new(-1.0, 0.5, -1.0),
        Vec3::new(1.5, 0.7, -1.2),
        Vec3::new(0.2, 0.6, 1.3),
    ];
    let triangle = TriangleLight::new(tri, Rgb::splat(3.0), true).expect("valid triangle");
    let faces = std::array::from_fn(|i| synthetic(16, 16, i as f32 * 0.3));
    let smooth = HistogramConfig {
        samples: 200_000,
        binning: Binning::Sphere {
            theta_bins: 40,
            phi_bins: 80,
        },
        ..HistogramConfig::default()
    };
    let case = |name, light: BuiltinLight| LightCase {
        name,
        light,
        ctx,
        frame: Mat3::IDENTITY,
        config: smooth,
    };
    // The equirectangular map's frame (+y up, u from atan2(x, -z)) turned into the histogram's
    // (+z up, phi from +x), so texel rows and columns are cell edges: 2 x 2 texels per cell.
    let equirect = LightCase {
        frame: Mat3::from_cols(Vec3::Y, Vec3::Z, Vec3::NEG_X),
        config: HistogramConfig {
            binning: Binning::Sphere {
                theta_bins: 16,
                phi_bins: 32,
            },
            quadrature: Quadrature::Midpoint(2),
            ..smooth
        },
        ..case(
            "equirectangular environment",
            EquirectEnvironment::new(synthetic(64, 32, 0.0))
                .expect("valid")
                .into(),
        )
    };
    // The cube binning is in the OpenGL frame, which mirrors x: 2 x 2 texels per cell.
    let cube = LightCase {
        frame: Mat3::from_diagonal(Vec3::new(-1.0, 1.0, 1.0)),
        config: HistogramConfig {
            binning: Binning::Cube { cells: 8 },
            quadrature: Quadrature::Midpoint(2),
            ..smooth
        },
        ..case(
            "cube-map environment",
            CubemapEnvironment::new(faces).expect("valid").into(),
        )
    };
    // Textured: a 32x32 map over the triangle (12 x 12 sampling cells), and the same map at a
    // budget of one cell (sampled as the untextured triangle, here by solid angle).
    let texture = std::sync::Arc::new(crate::texture::Texture::new(synthetic(32, 32, 0.1)));
    let uv = [glam::Vec2::ZERO, glam::Vec2::X, glam::Vec2::Y];
    let textured = |shape: TriangleLight, budget: usize| {
        TexturedTriangleLight::new(shape, uv, glam::Affine2::IDENTITY, texture.clone(), &mut {
            budget
        })
        .expect("not black")
    };
    vec![
        case(
            "textured triangle (cells)",
            textured(triangle, 1 << 20).into(),
        ),
        case(
            "textured triangle (one cell, solid-angle sampling)",
            textured(triangle.with_solid_angle_sampling(true), 0).into(),
        ),
        case(
            "triangle (area sampling)",
            triangle.with_solid_angle_sampling(false).into(),
        ),
        case(
            "triangle (solid-angle sampling)",
            triangle.with_solid_angle_sampling(true).into(),
        ),
        case(
            "uniform environment",
            UniformEnvironment::new(Rgb::splat(0.7))
                .expect("valid")
                .into(),
        ),
        equirect,
        cube,
        case(
            "point light",
            PointLight::new(Vec3::new(0.0, 2.0, 0.0), Rgb::splat(5.0))
                .expect("valid")
                .into(),
        ),
        case(
            "spot light",
            SpotLight::new(Vec3::Y * 2.0, Vec3::NEG_Y, Rgb::splat(5.0), 0.2, 0.5)
                .expect("valid")
                .into(),
        ),
        case(
            "directional light",
            DirectionalLight::new(Vec3::new(0.3, -1.0, 0.2), Rgb::splat(2.0))
                .expect("valid")
                .into(),
        ),
    ]
}
