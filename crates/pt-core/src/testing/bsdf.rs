//! The BSDF checks. See the [module documentation](super) and `docs/testing.md`.

use std::f64::consts::PI;

use glam::Vec3;

use crate::bsdf::{Bsdf, BsdfFlags, TransportMode};
use crate::color::Rgb;
use crate::sampling::sample_uniform_sphere;
use crate::testing::stats::{chi2_survival, normal_two_sided_p};
use crate::testing::{Failure, TestRng};

/// What the delta lobes of a case must do, for [`check_delta`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum DeltaExpectation {
    /// The case has no delta lobe.
    None,
    /// Every sample is a delta reflection in the mirror direction, with throughput
    /// `f |cos| / pdf` equal to `weight` when it is given.
    Reflection {
        /// Expected throughput of each sample, if known.
        weight: Option<Rgb>,
    },
    /// A smooth dielectric boundary: reflection with the probability of the Fresnel equations,
    /// refraction by Snell's law otherwise.
    Dielectric {
        /// Relative IOR `n_inside / n_outside` (outside is `z > 0`).
        eta: f32,
        /// Transmission tint.
        tint: Rgb,
    },
}

/// One BSDF under test at one outgoing direction.
#[derive(Clone, Debug)]
pub struct BsdfCase<B> {
    /// A readable name: model, parameters and direction.
    pub name: String,
    /// The BSDF.
    pub bsdf: B,
    /// The outgoing direction (local frame, unit).
    pub wo: Vec3,
    /// Relative IOR `n_inside / n_outside` for models that transmit (used by the reciprocity
    /// check), 1 otherwise.
    pub eta: f32,
    /// What the delta lobes must do.
    pub delta: DeltaExpectation,
    /// The exact directional albedo in importance mode, when known (lossless models).
    pub albedo: Option<Rgb>,
}

impl<B: Bsdf> BsdfCase<B> {
    /// A case with no delta expectation and no known albedo, `eta = 1`.
    pub fn new(name: impl Into<String>, bsdf: B, wo: Vec3) -> Self {
        Self {
            name: name.into(),
            bsdf,
            wo: wo.normalize(),
            eta: 1.0,
            delta: DeltaExpectation::None,
            albedo: None,
        }
    }

    fn fail(&self, check: &'static str, message: String) -> Failure {
        Failure {
            case: self.name.clone(),
            check,
            message,
        }
    }

    /// Index of refraction on the side of `w` (outside, `z > 0`, is 1).
    fn ior(&self, w: Vec3) -> f32 {
        if w.z > 0.0 { 1.0 } else { self.eta }
    }
}

/// How the sphere of directions is cut into cells for the chi-square test.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Binning {
    /// `theta_bins` cells in theta over `[0, pi]` (from `+z`) times `phi_bins` in phi over
    /// `[0, 2 pi)` (from `+x` toward `+y`). Use an even `theta_bins` so the horizon is an edge.
    Sphere {
        /// Cells in theta.
        theta_bins: usize,
        /// Cells in phi.
        phi_bins: usize,
    },
    /// The faces of the cube `[-1, 1]^3` (OpenGL layout, see
    /// [`cube_face_st`](crate::light::cube_face_st)), each cut into `cells x cells` squares.
    Cube {
        /// Cells along each side of a face.
        cells: usize,
    },
}

/// How the integral of `pdf` over each cell is computed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Quadrature {
    /// Nested adaptive Simpson (sphere binning only): for smooth densities and sharp lobes.
    Adaptive,
    /// The midpoint rule on `n x n` points per cell: exact for densities that are constant on
    /// sub-cells aligned with the grid (texels of an environment map), when `n` is the number of
    /// texels per cell side.
    Midpoint(usize),
}

/// Settings of the histogram behind [`check_chi2`] and [`check_pdf_integral`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HistogramConfig {
    /// Number of `sample` calls.
    pub samples: usize,
    /// The cells.
    pub binning: Binning,
    /// How cell integrals are computed.
    pub quadrature: Quadrature,
    /// Cells expecting fewer samples are pooled.
    pub min_expected: f64,
    /// Seed of the sample values.
    pub seed: u64,
}

impl Default for HistogramConfig {
    /// 1,000,000 samples, 80 x 160 (theta, phi) cells, adaptive quadrature, pooling below 5
    /// expected (pbrt-v4's settings).
    fn default() -> Self {
        Self {
            samples: 1_000_000,
            binning: Binning::Sphere {
                theta_bins: 80,
                phi_bins: 160,
            },
            quadrature: Quadrature::Adaptive,
            min_expected: 5.0,
            seed: 1,
        }
    }
}

impl Binning {
    fn cells(&self) -> usize {
        match *self {
            Self::Sphere {
                theta_bins,
                phi_bins,
            } => theta_bins * phi_bins,
            Self::Cube { cells } => 6 * cells * cells,
        }
    }

    /// The cell of a direction.
    fn cell_of(&self, w: Vec3) -> usize {
        match *self {
            Self::Sphere {
                theta_bins: nt,
                phi_bins: np,
            } => {
                let w = w.as_dvec3().normalize();
                let theta = w.z.clamp(-1.0, 1.0).acos();
                let mut phi = w.y.atan2(w.x);
                if phi < 0.0 {
                    phi += 2.0 * PI;
                }
                let i = ((theta / PI * nt as f64) as usize).min(nt - 1);
                let j = ((phi / (2.0 * PI) * np as f64) as usize).min(np - 1);
                i * np + j
            }
            Self::Cube { cells: n } => {
                let (face, st, _) = crate::light::cube_face_st(w);
                let col = ((st.x * n as f32) as usize).min(n - 1);
                let row = ((st.y * n as f32) as usize).min(n - 1);
                (face * n + row) * n + col
            }
        }
    }

    /// Integral of `pdf` (solid-angle density) over `cell`.
    fn integrate(
        &self,
        cell: usize,
        quadrature: Quadrature,
        occupied: bool,
        pdf: &impl Fn(Vec3) -> f64,
    ) -> f64 {
        match (*self, quadrature) {
            (
                Self::Sphere {
                    theta_bins: nt,
                    phi_bins: np,
                },
                Quadrature::Adaptive,
            ) => {
                let (dt, dp) = (PI / nt as f64, 2.0 * PI / np as f64);
                let (i, j) = (cell / np, cell % np);
                let min_depth = if occupied { 2 } else { 1 };
                let (t0, p0) = (i as f64 * dt, j as f64 * dp);
                let abs_tol = 1e-10;
                let rel_tol = 1e-6;
                let mut outer = |theta: f64| {
                    let mut inner = |phi: f64| pdf(direction(theta, phi));
                    adaptive_simpson(
                        &mut inner,
                        p0,
                        p0 + dp,
                        abs_tol / dt,
                        rel_tol,
                        min_depth,
                        10,
                    ) * theta.sin()
                };
                adaptive_simpson(&mut outer, t0, t0 + dt, abs_tol, rel_tol, min_depth, 10)
            }
            (
                Self::Sphere {
                    theta_bins: nt,
                    phi_bins: np,
                },
                Quadrature::Midpoint(m),
            ) => {
                let (dt, dp) = (PI / nt as f64, 2.0 * PI / np as f64);
                let (i, j) = (cell / np, cell % np);
                let (ht, hp) = (dt / m as f64, dp / m as f64);
                let mut sum = 0.0;
                for a in 0..m {
                    let theta = i as f64 * dt + (a as f64 + 0.5) * ht;
                    for b in 0..m {
                        let phi = j as f64 * dp + (b as f64 + 0.5) * hp;
                        sum += pdf(direction(theta, phi)) * theta.sin();
                    }
                }
                sum * ht * hp
            }
            (Self::Cube { cells: n }, q) => {
                let m = match q {
                    Quadrature::Midpoint(m) => m,
                    Quadrature::Adaptive => 16,
                };
                let face = cell / (n * n);
                let (row, col) = ((cell / n) % n, cell % n);
                let h = 1.0 / (n * m) as f64;
                let mut sum = 0.0;
                for a in 0..m {
                    let t = (row * m + a) as f64 * h + 0.5 * h;
                    for b in 0..m {
                        let s = (col * m + b) as f64 * h + 0.5 * h;
                        let p = crate::light::cube_face_point(
                            face,
                            glam::Vec2::new(s as f32, t as f32),
                        );
                        let r = f64::from(p.length());
                        // dA on the face in [-1, 1] coordinates is (2h)^2; d(omega) = dA / r^3.
                        sum += pdf(p / p.length()) / (r * r * r);
                    }
                }
                sum * (2.0 * h) * (2.0 * h)
            }
        }
    }
}

/// One draw of a sampling routine under test.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Draw {
    /// No direction.
    Failed,
    /// A delta lobe (not binned).
    Delta,
    /// A direction with a density.
    Direction(Vec3),
}

/// Sampled directions binned over the sphere, next to the probability `pdf` gives each cell.
#[derive(Clone, Debug)]
pub struct Histogram {
    config: HistogramConfig,
    /// Samples that landed in each cell (theta-major).
    observed: Vec<u64>,
    /// Integral of `pdf` over each cell.
    probability: Vec<f64>,
    /// `sample` returned a non-delta direction.
    non_delta: u64,
    /// `sample` returned a delta lobe.
    delta: u64,
    /// `sample` returned `None`.
    failed: u64,
}

impl Histogram {
    /// Integral of `pdf` over the sphere.
    #[must_use]
    pub fn pdf_integral(&self) -> f64 {
        self.probability.iter().sum()
    }

    /// Fraction of `sample` calls that returned a non-delta direction.
    #[must_use]
    pub fn non_delta_fraction(&self) -> f64 {
        self.non_delta as f64 / self.config.samples as f64
    }

    /// Fraction of `sample` calls that returned a delta lobe.
    #[must_use]
    pub fn delta_fraction(&self) -> f64 {
        self.delta as f64 / self.config.samples as f64
    }

    /// Fraction of `sample` calls that returned `None`.
    #[must_use]
    pub fn failed_fraction(&self) -> f64 {
        self.failed as f64 / self.config.samples as f64
    }

    /// The chi-square statistic: one bin per cell expecting at least `min_expected` samples, one
    /// for the pooled rest, and one for "no non-delta direction" (failures and delta samples).
    #[must_use]
    pub fn chi2(&self) -> Chi2Outcome {
        let n = self.config.samples as f64;
        let min = self.config.min_expected;
        let mut bins: Vec<(f64, f64)> = Vec::new();
        let mut pooled = (0.0, 0.0);
        let mut impossible = 0u64;
        let mut push = |observed: f64, expected: f64| {
            if expected >= min {
                bins.push((observed, expected));
            } else {
                pooled.0 += observed;
                pooled.1 += expected.max(0.0);
            }
        };
        for (&o, &p) in self.observed.iter().zip(&self.probability) {
            if p <= 0.0 && o > 0 {
                impossible += o;
            }
            push(o as f64, n * p);
        }
        push(
            (self.delta + self.failed) as f64,
            n * (1.0 - self.pdf_integral()),
        );
        if pooled.1 >= min || bins.is_empty() {
            bins.push(pooled);
        } else if let Some(smallest) = bins
            .iter_mut()
            .min_by(|a, b| a.1.partial_cmp(&b.1).unwrap_or(std::cmp::Ordering::Equal))
        {
            smallest.0 += pooled.0;
            smallest.1 += pooled.1;
        }
        let chi2: f64 = bins
            .iter()
            .filter(|b| b.1 > 0.0)
            .map(|&(o, e)| (o - e) * (o - e) / e)
            .sum();
        let dof = bins.len().saturating_sub(1);
        let p_value = if dof == 0 {
            1.0
        } else {
            chi2_survival(chi2, dof)
        };
        Chi2Outcome {
            chi2,
            dof,
            p_value,
            impossible_samples: impossible,
        }
    }
}

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

/// Direction of spherical coordinates (theta from `+z`, phi from `+x`).
#[inline]
fn direction(theta: f64, phi: f64) -> Vec3 {
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    Vec3::new((st * cp) as f32, (st * sp) as f32, ct as f32)
}

/// Adaptive Simpson quadrature of `f` over `[a, b]`: subdivides at least `min_depth` times, and
/// until the Richardson error estimate is below `max(abs_tol, rel_tol * |estimate|)`, or at
/// `max_depth`.
fn adaptive_simpson(
    f: &mut impl FnMut(f64) -> f64,
    a: f64,
    b: f64,
    abs_tol: f64,
    rel_tol: f64,
    min_depth: u32,
    max_depth: u32,
) -> f64 {
    struct Ctx {
        rel_tol: f64,
        min_depth: u32,
        max_depth: u32,
    }
    #[allow(clippy::too_many_arguments)]
    fn rec(
        f: &mut impl FnMut(f64) -> f64,
        c: &Ctx,
        a: f64,
        b: f64,
        fa: f64,
        fm: f64,
        fb: f64,
        whole: f64,
        tol: f64,
        depth: u32,
    ) -> f64 {
        let m = 0.5 * (a + b);
        let (lm, rm) = (0.5 * (a + m), 0.5 * (m + b));
        let (flm, frm) = (f(lm), f(rm));
        let left = (m - a) / 6.0 * (fa + 4.0 * flm + fm);
        let right = (b - m) / 6.0 * (fm + 4.0 * frm + fb);
        let delta = left + right - whole;
        let limit = tol.max(c.rel_tol * (left + right).abs());
        if depth >= c.max_depth || (depth >= c.min_depth && delta.abs() <= 15.0 * limit) {
            return left + right + delta / 15.0;
        }
        rec(f, c, a, m, fa, flm, fm, left, 0.5 * tol, depth + 1)
            + rec(f, c, m, b, fm, frm, fb, right, 0.5 * tol, depth + 1)
    }
    let (fa, fm, fb) = (f(a), f(0.5 * (a + b)), f(b));
    let whole = (b - a) / 6.0 * (fa + 4.0 * fm + fb);
    let c = Ctx {
        rel_tol,
        min_depth,
        max_depth,
    };
    rec(f, &c, a, b, fa, fm, fb, whole, abs_tol, 0)
}

/// Draw `config.samples` directions from `case.bsdf.sample` (radiance mode) and integrate
/// `case.bsdf.pdf` over every cell of the grid.
///
/// With [`Quadrature::Adaptive`] each cell is integrated by nested adaptive Simpson quadrature
/// (theta outside, phi inside). Cells that received samples start from a finer subdivision
/// (9 x 9 points instead of 5 x 5), so that narrow lobes are resolved wherever sampling puts
/// them; refinement then continues until the cell's integral is known to `1e-6` relative
/// (`1e-10` absolute), far below the statistical noise of a million samples.
pub fn histogram<B: Bsdf>(case: &BsdfCase<B>, config: &HistogramConfig) -> Histogram {
    let mode = TransportMode::Radiance;
    histogram_of(
        config,
        |rng| {
            let uc = rng.uniform();
            let u = rng.uniform2();
            match case.bsdf.sample(case.wo, uc, u, mode) {
                None => Draw::Failed,
                Some(s) if s.flags.is_specular() => Draw::Delta,
                Some(s) => Draw::Direction(s.wi),
            }
        },
        |wi| f64::from(case.bsdf.pdf(case.wo, wi, mode)),
        case.bsdf.flags().is_non_specular(),
    )
}

/// The histogram of any direction sampler: `draw` is called `config.samples` times, and `pdf`
/// (its claimed solid-angle density) is integrated over each cell unless `has_density` is false
/// (only delta lobes), in which case every cell expects zero.
pub fn histogram_of(
    config: &HistogramConfig,
    mut draw: impl FnMut(&mut TestRng) -> Draw,
    pdf: impl Fn(Vec3) -> f64,
    has_density: bool,
) -> Histogram {
    let cells = config.binning.cells();
    let mut observed = vec![0u64; cells];
    let (mut non_delta, mut delta, mut failed) = (0u64, 0u64, 0u64);
    let mut rng = TestRng::new(config.seed);
    for _ in 0..config.samples {
        match draw(&mut rng) {
            Draw::Failed => failed += 1,
            Draw::Delta => delta += 1,
            Draw::Direction(w) => {
                non_delta += 1;
                observed[config.binning.cell_of(w)] += 1;
            }
        }
    }
    let mut probability = vec![0.0f64; cells];
    if has_density {
        for (cell, p) in probability.iter_mut().enumerate() {
            *p = config
                .binning
                .integrate(cell, config.quadrature, observed[cell] > 0, &pdf);
        }
    }
    Histogram {
        config: *config,
        observed,
        probability,
        non_delta,
        delta,
        failed,
    }
}

/// The histogram of a light's `sample_li` from `ctx`, with `pdf_li` integrated over the cells.
/// `frame` rotates world directions into the frame the cells are laid out in (so that, for
/// example, an equirectangular map's texels align with the cells).
pub fn light_histogram<L: crate::light::Light>(
    light: &L,
    ctx: &crate::light::LightSampleContext,
    frame: glam::Mat3,
    config: &HistogramConfig,
) -> Histogram {
    let back = frame.transpose();
    histogram_of(
        config,
        |rng| match light.sample_li(ctx, rng.uniform2()) {
            None => Draw::Failed,
            Some(s) if light.flags().is_delta() => {
                let _ = s;
                Draw::Delta
            }
            Some(s) => Draw::Direction(frame * s.wi),
        },
        |w| f64::from(light.pdf_li(ctx, back * w)),
        !light.flags().is_delta(),
    )
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

fn close(a: f32, b: f32, rel: f32, abs: f32) -> bool {
    (a - b).abs() <= abs + rel * a.abs().max(b.abs())
}

fn close_rgb(a: Rgb, b: Rgb, rel: f32, abs: f32) -> bool {
    (0..3).all(|i| close(a[i], b[i], rel, abs))
}

/// Relative size of the direction perturbations that measure how ill-conditioned a value is.
const PERTURBATION: f32 = 1e-5;

/// Two unit vectors orthogonal to `w`.
fn tangents(w: Vec3) -> (Vec3, Vec3) {
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
fn spread(g: impl Fn(Vec3, Vec3) -> Rgb, wo: Vec3, wi: Vec3) -> Rgb {
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
fn agree(a: Rgb, b: Rgb, spread: Rgb) -> bool {
    (0..3).all(|c| close(a[c], b[c], 1e-3, 1e-5 + 2.0 * spread[c]))
}

/// `n` samples (both transport modes): finite values, a unit `wi`, a positive `pdf`, flags that
/// name exactly one of reflection/transmission, agree with the side of `wi` and belong to the
/// BSDF's flags; for non-delta samples `f` and `pdf` equal `eval` and `pdf` within `1e-3`
/// relative or the rounding spread of [`check_reciprocity`]; delta samples are invisible to `eval` and `pdf` when the BSDF has no other lobe.
pub fn check_consistency<B: Bsdf>(case: &BsdfCase<B>, n: usize, seed: u64) -> Result<(), Failure> {
    let mut rng = TestRng::new(seed);
    let all = case.bsdf.flags();
    let wo = case.wo;
    for k in 0..n {
        let mode = if k % 2 == 0 {
            TransportMode::Radiance
        } else {
            TransportMode::Importance
        };
        let uc = rng.uniform();
        let u = rng.uniform2();
        let Some(s) = case.bsdf.sample(wo, uc, u, mode) else {
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
