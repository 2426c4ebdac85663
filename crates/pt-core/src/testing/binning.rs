//! Cells over the sphere of directions (or the cube), and the quadrature of a density over them.

use std::f64::consts::PI;

use glam::Vec3;

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

impl Binning {
    pub(crate) fn cells(&self) -> usize {
        match *self {
            Self::Sphere {
                theta_bins,
                phi_bins,
            } => theta_bins * phi_bins,
            Self::Cube { cells } => 6 * cells * cells,
        }
    }

    /// The cell of a direction.
    pub(crate) fn cell_of(&self, w: Vec3) -> usize {
        match *self {
            Self::Sphere {
                theta_bins: nt,
                phi_bins: np,
            } => {
                // Single precision and a polynomial arctangent (error below 4e-7 rad): a
                // sample within 1e-6 of a cell edge may land in its neighbour, which no test at
                // a million samples can tell. Both angles are arctangents of ratios, so `w`
                // needs no normalising; libm's `acosf` and `atan2f` took a third of a
                // histogram's time.
                let theta = atan2_fast((w.x * w.x + w.y * w.y).sqrt(), w.z);
                let mut phi = atan2_fast(w.y, w.x);
                if phi < 0.0 {
                    phi += std::f32::consts::TAU;
                }
                let i = ((theta * (1.0 / std::f32::consts::PI) * nt as f32) as usize).min(nt - 1);
                let j = ((phi * (1.0 / std::f32::consts::TAU) * np as f32) as usize).min(np - 1);
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
    pub(crate) fn integrate(
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
                    // theta's sine and cosine once per inner integral, not per point.
                    let (st, ct) = theta.sin_cos();
                    let mut inner = |phi: f64| pdf(direction_sc(st, ct, phi));
                    adaptive_simpson(
                        &mut inner,
                        p0,
                        p0 + dp,
                        abs_tol / dt,
                        rel_tol,
                        min_depth,
                        10,
                    ) * st
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

/// `y.atan2(x)` within 4e-7 rad (0 for the origin): the arctangent of the smaller over the
/// larger magnitude by a degree-15 odd polynomial (least-squares minimax fit on `[0, 1]`,
/// 4e-8 in real arithmetic, 1.4e-7 evaluated in f32), then reflected into the right octant.
#[inline]
fn atan2_fast(y: f32, x: f32) -> f32 {
    use std::f32::consts::{FRAC_PI_2, PI};
    const C: [f32; 8] = [
        0.999_999_34,
        -0.333_298_6,
        0.199_465_66,
        -0.139_086_3,
        0.096_421_97,
        -0.055_912_33,
        0.021_862_96,
        -0.004_054_57,
    ];
    let (ax, ay) = (x.abs(), y.abs());
    let (lo, hi) = (ax.min(ay), ax.max(ay));
    if hi == 0.0 {
        return 0.0;
    }
    let t = lo / hi;
    let s = t * t;
    let p = C.iter().rev().fold(0.0, |acc, &c| acc * s + c);
    let mut r = t * p;
    if ay > ax {
        r = FRAC_PI_2 - r;
    }
    if x < 0.0 {
        r = PI - r;
    }
    if y < 0.0 { -r } else { r }
}

/// Direction of spherical coordinates (theta from `+z`, phi from `+x`).
#[inline]
pub(crate) fn direction(theta: f64, phi: f64) -> Vec3 {
    let (st, ct) = theta.sin_cos();
    direction_sc(st, ct, phi)
}

/// [`direction`] from theta's sine and cosine.
#[inline]
fn direction_sc(st: f64, ct: f64, phi: f64) -> Vec3 {
    // In single precision, as the direction is returned: the argument's rounding (below 5e-7
    // rad) is far below anything a cell's integral can tell, and f32's sine and cosine cost
    // half of f64's (they were a tenth of a chi-square test's time).
    let (sp, cp) = (phi as f32).sin_cos();
    Vec3::new(st as f32 * cp, st as f32 * sp, ct as f32)
}

/// Adaptive Simpson quadrature of `f` over `[a, b]`: subdivides at least `min_depth` times, and
/// until the Richardson error estimate is below `max(abs_tol, rel_tol * |estimate|)`, or at
/// `max_depth`.
pub(crate) fn adaptive_simpson(
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The polynomial arctangent against f64's on a grid over all four quadrants, the axes and
    /// the diagonals, and the cells it picks against cells from f64 angles: different only for
    /// directions within 1e-6 rad of a cell edge.
    #[test]
    fn fast_atan2_and_cells_match_f64() {
        let mut worst = 0.0f64;
        for i in -200..=200 {
            for j in -200..=200 {
                let (y, x) = (i as f32 * 0.37, j as f32 * 0.41);
                let want = f64::from(y).atan2(f64::from(x));
                let want = if i == 0 && j == 0 { 0.0 } else { want };
                worst = worst.max((f64::from(atan2_fast(y, x)) - want).abs());
            }
        }
        assert!(worst < 4e-7, "largest error {worst}");
        let binning = Binning::Sphere {
            theta_bins: 80,
            phi_bins: 160,
        };
        let (mut state, mut moved) = (0x2545_f491_4f6c_dd1du64, 0);
        for _ in 0..200_000 {
            let mut next = || {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
            };
            let v = [next(), next(), next()];
            let w = Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32);
            let (x, y, z) = (f64::from(w.x), f64::from(w.y), f64::from(w.z));
            let theta = (x * x + y * y).sqrt().atan2(z);
            let phi = y.atan2(x).rem_euclid(2.0 * PI);
            let (ft, fp) = (theta / PI * 80.0, phi / (2.0 * PI) * 160.0);
            let want = (ft as usize).min(79) * 160 + (fp as usize).min(159);
            if binning.cell_of(w) != want {
                let near_edge = |f: f64, width: f64| (f - f.round()).abs() * width < 1e-6;
                assert!(
                    near_edge(ft, PI / 80.0) || near_edge(fp, 2.0 * PI / 160.0),
                    "{w} binned far from an edge"
                );
                moved += 1;
            }
        }
        assert!(moved < 20, "{moved} directions moved");
    }
}
