//! An emitting triangle whose radiance a texture modulates: [`TexturedTriangleLight`].

use std::sync::Arc;

use glam::{Affine2, Vec2, Vec3};

use crate::color::Rgb;
use crate::light::{Light, LightFlags, LightSample, LightSampleContext, TriangleLight};
use crate::texture::Texture;

/// An emitting triangle whose radiance a texture modulates (glTF's emissive texture).
///
/// The radiance at a point is the light's base radiance times the texture at the point's
/// texture coordinates, evaluated where a ray hits the light and where a light sample lands:
/// detail smaller than the triangle is kept (text on an emissive label, a screen).
///
/// Sampling follows the texture. The triangle is cut into `n x n` congruent cells (barycentric
/// subdivision, `n` chosen so that a cell covers a few texels, at most
/// [`MAX_SUBDIVISION`](TexturedTriangleLight::MAX_SUBDIVISION) and within the scene's budget
/// of cells); each cell's mean texture luminance, from stratified lookups, makes a discrete
/// distribution, mixed with a uniform one (weight [`UNIFORM_SHARE`](TexturedTriangleLight::UNIFORM_SHARE))
/// so every cell where the texture could be non-zero keeps a positive density: the estimator
/// stays unbiased whatever the lookups missed. A sample picks a cell from the distribution and
/// a point uniformly in it. Dark parts of a label then cost few samples. The light's power
/// (what the light sampler selects by) is the base radiance times the texture's mean over the
/// triangle, from the same lookups: per-triangle power from the texels it covers.
///
/// With one cell (`n = 1`, a triangle that covers few texels) the light samples as a
/// [`TriangleLight`] does, solid-angle sampling included.
#[derive(Clone, Debug, PartialEq)]
pub struct TexturedTriangleLight {
    shape: TriangleLight,
    /// Texture coordinates of the corners (transformed), in the shape's corner order.
    uv: [Vec2; 3],
    texture: Arc<Texture>,
    /// Mean of the texture over the triangle.
    mean: Rgb,
    /// `c / |c|^2` with `c = (p1 - p0) x (p2 - p0)`: barycentric coordinates of a point.
    bary: Vec3,
    /// Cells per edge.
    n: u32,
    /// Cumulative probabilities of the `2 n^2` cells (upward cell `2 (a n + b)`, downward
    /// `2 (a n + b) + 1`; the ones outside the triangle have zero probability); empty when
    /// `n == 1`.
    cdf: Box<[f32]>,
}

impl TexturedTriangleLight {
    /// The most cells per edge (`n^2` cells).
    pub const MAX_SUBDIVISION: u32 = 32;
    /// The share of the sampling density spread uniformly over the triangle.
    pub const UNIFORM_SHARE: f32 = 0.1;
    /// Texels a cell should cover.
    const TEXELS_PER_CELL: f32 = 4.0;

    /// A textured emitting triangle: `shape` with its radiance as the base, `uv` the texture
    /// coordinates of its corners (in the order of [`TriangleLight::corners`], `transform`
    /// applied to them), and at most `*cell_budget` cells, which it takes from the budget.
    /// `None` when the texture is black over the triangle (as far as its lookups see) or not
    /// finite.
    #[must_use]
    pub fn new(
        shape: TriangleLight,
        uv: [Vec2; 3],
        transform: Affine2,
        texture: Arc<Texture>,
        cell_budget: &mut usize,
    ) -> Option<Self> {
        let uv = uv.map(|t| transform.transform_point2(t));
        if !uv.iter().all(|t| t.is_finite()) {
            return None;
        }
        let (w, h) = (texture.image().width(), texture.image().height());
        let texels = 0.5 * (uv[1] - uv[0]).perp_dot(uv[2] - uv[0]).abs() * w as f32 * h as f32;
        let mut n =
            ((texels / Self::TEXELS_PER_CELL).sqrt().ceil() as u32).clamp(1, Self::MAX_SUBDIVISION);
        if (n * n) as usize > *cell_budget {
            n = 1;
        }
        // Lookups per cell edge: about one per texel, at most 8 (64) for a lone cell and 4 (16)
        // for subdivided ones, so a scene's build does at most 16 lookups per budgeted cell
        // (2^25 in all) however large the texture coordinates of a hostile file.
        let per_cell = texels / (n * n) as f32;
        let k = (per_cell.sqrt().ceil() as u32).clamp(2, if n > 1 { 4 } else { 8 });
        let at = |b: Vec2| uv[0] * (1.0 - b.x - b.y) + uv[1] * b.x + uv[2] * b.y;
        let mut means = vec![0.0f32; if n > 1 { 2 * (n * n) as usize } else { 0 }];
        let mut total = Rgb::BLACK;
        for (slot, corners) in cells(n) {
            let m = triangle_mean(&texture, corners.map(at), k);
            if !m.is_valid_nonnegative() {
                return None;
            }
            total += m;
            if n > 1 {
                means[slot] = m.luminance().max(0.0);
            }
        }
        let mean = total / (n * n) as f32;
        if mean.is_black() {
            return None;
        }
        let cdf: Box<[f32]> = if n > 1 {
            *cell_budget -= (n * n) as usize;
            let sum: f32 = means.iter().sum();
            let uniform = Self::UNIFORM_SHARE / (n * n) as f32;
            let mut acc = 0.0;
            let mut cdf: Vec<f32> = (0..means.len())
                .map(|slot| {
                    if is_cell(n, slot) {
                        let learnt = if sum > 0.0 {
                            means[slot] / sum
                        } else {
                            1.0 / (n * n) as f32
                        };
                        acc += (1.0 - Self::UNIFORM_SHARE) * learnt + uniform;
                    }
                    acc
                })
                .collect();
            let last = acc;
            for c in &mut cdf {
                *c /= last;
            }
            cdf.into()
        } else {
            Box::default()
        };
        let p = shape.corners();
        let c = (p[1] - p[0]).cross(p[2] - p[0]);
        Some(Self {
            shape,
            uv,
            texture,
            mean,
            bary: c / c.length_squared(),
            n,
            cdf,
        })
    }

    /// The untextured triangle (its radiance is the base radiance).
    #[must_use]
    pub fn shape(&self) -> &TriangleLight {
        &self.shape
    }

    /// The texture's mean over the triangle.
    #[must_use]
    pub fn mean(&self) -> Rgb {
        self.mean
    }

    /// Cells per edge of the sampling distribution (1: sampled as an untextured triangle).
    #[must_use]
    pub fn subdivision(&self) -> u32 {
        self.n
    }

    /// The radiance at barycentric coordinates `b`.
    #[inline]
    fn radiance_at(&self, b: [f32; 3]) -> Rgb {
        let uv = self.uv[0] * b[0] + self.uv[1] * b[1] + self.uv[2] * b[2];
        self.shape.radiance() * self.texture.eval(uv)
    }

    /// The probability of cell `slot` (0 outside the table).
    #[inline]
    fn pmf(&self, slot: usize) -> f32 {
        let hi = self.cdf.get(slot).copied().unwrap_or(0.0);
        let lo = if slot == 0 { 0.0 } else { self.cdf[slot - 1] };
        hi - lo
    }

    /// The cell holding barycentric coordinates `(b1, b2)`.
    #[inline]
    fn slot_of(&self, b: Vec2) -> usize {
        let n = self.n as f32;
        let (x, y) = (b.x.clamp(0.0, 1.0) * n, b.y.clamp(0.0, 1.0) * n);
        let a = (x.floor() as u32).min(self.n - 1);
        let c = (y.floor() as u32).min(self.n - 1);
        let down = (x - a as f32) + (y - c as f32) > 1.0 && a + c + 1 < self.n;
        let slot = 2 * (a * self.n + c) as usize + usize::from(down);
        if is_cell(self.n, slot) {
            slot
        } else {
            // Rounding put the point just outside the triangle's last row: its upward cell.
            2 * (a * self.n + c.min(self.n - 1 - a.min(self.n - 1))) as usize
        }
    }

    /// Barycentric coordinates sampled from the cell distribution, with the density relative
    /// to uniform.
    #[inline]
    fn sample_cells(&self, u: Vec2) -> ([f32; 3], f32) {
        let slot = self
            .cdf
            .partition_point(|&c| c <= u.x)
            .min(self.cdf.len() - 1);
        let lo = if slot == 0 { 0.0 } else { self.cdf[slot - 1] };
        let pmf = self.cdf[slot] - lo;
        let ux = ((u.x - lo) / pmf).clamp(0.0, 1.0 - f32::EPSILON / 2.0);
        let corners = cell_corners(self.n, slot);
        let t = crate::sampling::sample_uniform_triangle(Vec2::new(ux, u.y));
        let b = corners[0] * t[0] + corners[1] * t[1] + corners[2] * t[2];
        ([1.0 - b.x - b.y, b.x, b.y], pmf * (self.n * self.n) as f32)
    }
}

impl Light for TexturedTriangleLight {
    #[inline]
    fn flags(&self) -> LightFlags {
        LightFlags::AREA
    }

    fn power(&self) -> Rgb {
        self.shape.power() * self.mean
    }

    #[inline]
    fn sample_li(&self, ctx: &LightSampleContext, u: Vec2) -> Option<LightSample> {
        let radiance = |b| self.radiance_at(b);
        if self.n == 1 {
            self.shape
                .sample_point(ctx, u, None::<fn(Vec2) -> ([f32; 3], f32)>, radiance)
        } else {
            self.shape
                .sample_point(ctx, u, Some(|u| self.sample_cells(u)), radiance)
        }
    }

    #[inline]
    fn pdf_li(&self, ctx: &LightSampleContext, wi: Vec3) -> f32 {
        if self.n == 1 {
            self.shape.pdf_li(ctx, wi)
        } else {
            let n2 = (self.n * self.n) as f32;
            self.shape
                .pdf_area_weighted(ctx, wi, |b| self.pmf(self.slot_of(b)) * n2)
        }
    }

    /// The base radiance times the texture at `p`'s texture coordinates (from its barycentric
    /// coordinates on the light, so `uv` is not used), on the emitting side.
    #[inline]
    fn l(&self, p: Vec3, n: Vec3, uv: Vec2, w: Vec3) -> Rgb {
        if self.shape.l(p, n, uv, w).is_black() {
            return Rgb::BLACK;
        }
        let p0 = self.shape.corners();
        let d = p - p0[0];
        let b1 = d.cross(p0[2] - p0[0]).dot(self.bary);
        let b2 = (p0[1] - p0[0]).cross(d).dot(self.bary);
        self.radiance_at([1.0 - b1 - b2, b1, b2])
    }
}

/// Whether `slot` is a cell of the `n`-subdivision.
#[inline]
fn is_cell(n: u32, slot: usize) -> bool {
    let (i, down) = ((slot / 2) as u32, slot % 2 == 1);
    let (a, b) = (i / n, i % n);
    if down { a + b + 2 <= n } else { a + b < n }
}

/// Barycentric `(b1, b2)` corners of cell `slot` of the `n`-subdivision.
#[inline]
fn cell_corners(n: u32, slot: usize) -> [Vec2; 3] {
    let i = (slot / 2) as u32;
    let (a, b) = ((i / n) as f32, (i % n) as f32);
    let s = 1.0 / n as f32;
    if slot.is_multiple_of(2) {
        [
            Vec2::new(a, b) * s,
            Vec2::new(a + 1.0, b) * s,
            Vec2::new(a, b + 1.0) * s,
        ]
    } else {
        [
            Vec2::new(a + 1.0, b + 1.0) * s,
            Vec2::new(a, b + 1.0) * s,
            Vec2::new(a + 1.0, b) * s,
        ]
    }
}

/// The cells of the `n`-subdivision with their corners.
fn cells(n: u32) -> impl Iterator<Item = (usize, [Vec2; 3])> {
    (0..2 * (n * n) as usize)
        .filter(move |&s| is_cell(n, s))
        .map(move |s| (s, cell_corners(n, s)))
}

/// The mean of `texture` over the texture-coordinate triangle `t`: the average at the
/// centroids of the `k^2` cells of its `k`-subdivision.
fn triangle_mean(texture: &Texture, t: [Vec2; 3], k: u32) -> Rgb {
    let mut sum = Rgb::BLACK;
    for (_, c) in cells(k) {
        let b = (c[0] + c[1] + c[2]) / 3.0;
        sum += texture.eval(t[0] * (1.0 - b.x - b.y) + t[1] * b.x + t[2] * b.y);
    }
    sum / (k * k) as f32
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::image::Image;
    use crate::interaction::SurfacePoint;

    fn ctx(p: Vec3) -> LightSampleContext {
        LightSampleContext {
            point: SurfacePoint::exact(p),
            ns: Vec3::ZERO,
        }
    }

    /// A 64x64 texture, black but for a bright 8x8 block.
    fn block_texture() -> Arc<Texture> {
        let mut img = Image::new(64, 64);
        for y in 40..48 {
            for x in 8..16 {
                img.set(x, y, Rgb::new(10.0, 5.0, 2.0));
            }
        }
        Arc::new(Texture::new(img))
    }

    fn light(budget: &mut usize) -> TexturedTriangleLight {
        let shape =
            TriangleLight::new([Vec3::ZERO, Vec3::X, Vec3::Y], Rgb::splat(2.0), false).unwrap();
        TexturedTriangleLight::new(
            shape,
            [Vec2::ZERO, Vec2::X, Vec2::Y],
            Affine2::IDENTITY,
            block_texture(),
            budget,
        )
        .unwrap()
    }

    #[test]
    fn cells_tile_the_triangle() {
        for n in [1, 2, 3, 7] {
            assert_eq!(cells(n).count(), (n * n) as usize);
            // Each cell's centroid maps back to it.
            let l = TexturedTriangleLight { n, ..light(&mut 0) };
            for (slot, c) in cells(n) {
                assert_eq!(l.slot_of((c[0] + c[1] + c[2]) / 3.0), slot, "n {n}");
            }
        }
    }

    #[test]
    fn subdivision_follows_the_texels_and_the_budget() {
        let mut budget = 10_000;
        let l = light(&mut budget);
        // 2048 texels / 4 per cell: n = 23.
        assert_eq!(l.subdivision(), 23);
        assert_eq!(budget, 10_000 - 23 * 23);
        let mut small = 100;
        assert_eq!(light(&mut small).subdivision(), 1);
        assert_eq!(small, 100);
    }

    #[test]
    fn radiance_follows_the_texture_where_rays_hit_and_samples_land() {
        let l = light(&mut 10_000);
        // Texel (12, 44) is in the block: uv (12.5/64, 44.5/64) is point (u, v) on the light.
        let p = Vec3::new(12.5 / 64.0, 44.5 / 64.0, 0.0);
        let d = l.l(p, Vec3::Z, Vec2::ZERO, Vec3::Z) - Rgb::new(20.0, 10.0, 4.0);
        assert!(d.r.abs().max(d.g.abs()).max(d.b.abs()) < 1e-3, "{d:?}");
        let dark = Vec3::new(0.4, 0.1, 0.0);
        assert!(l.l(dark, Vec3::Z, Vec2::ZERO, Vec3::Z).is_black());
        // The back face does not emit.
        assert!(l.l(p, Vec3::Z, Vec2::ZERO, -Vec3::Z).is_black());
        // Light samples land mostly on the block, each with its own radiance, and their pdf
        // agrees with pdf_li.
        let c = ctx(Vec3::new(0.3, 0.3, 1.0));
        let mut on_block = 0;
        let m = 4096;
        for i in 0..m {
            let u = Vec2::new(
                (i as f32 + 0.5) / m as f32,
                ((i * 37) % m) as f32 / m as f32,
            );
            let Some(s) = l.sample_li(&c, u) else {
                continue;
            };
            if s.li.r > 1.0 {
                on_block += 1;
            }
            let pdf = l.pdf_li(&c, s.wi);
            assert!((pdf - s.pdf).abs() <= 1e-3 * s.pdf, "{pdf} != {}", s.pdf);
        }
        // The block is 1/32 of the triangle's area; with the learnt distribution most samples
        // land on it.
        assert!(on_block > m / 2, "{on_block} of {m} on the block");
    }

    #[test]
    fn the_estimate_of_irradiance_is_unbiased() {
        // Irradiance at a point above the light, by light sampling, against brute-force
        // integration over the texels.
        let l = light(&mut 10_000);
        let c = ctx(Vec3::new(0.2, 0.4, 0.5));
        let m = 1 << 16;
        let mut est = Rgb::BLACK;
        let mut rng = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            rng ^= rng << 13;
            rng ^= rng >> 7;
            rng ^= rng << 17;
            (rng >> 40) as f32 / (1u64 << 24) as f32
        };
        for _ in 0..m {
            if let Some(s) = l.sample_li(&c, Vec2::new(next(), next())) {
                // Cosine at a receiver facing down.
                est += s.li * (s.wi.dot(-Vec3::Z).max(0.0) / s.pdf);
            }
        }
        est /= m as f32;
        // Reference: midpoint rule on a fine grid of the triangle (area 1/2).
        let g = 1024;
        let mut reference = Rgb::BLACK;
        for i in 0..g {
            for j in 0..g - i {
                let (u, v) = ((i as f32 + 0.5) / g as f32, (j as f32 + 0.5) / g as f32);
                let p = Vec3::new(u, v, 0.0);
                let d = p - c.p();
                let r2 = d.length_squared();
                let w = d / r2.sqrt();
                let cos_r = w.dot(-Vec3::Z).max(0.0);
                let cos_l = (-w).dot(Vec3::Z).max(0.0);
                reference += l.l(p, Vec3::Z, Vec2::ZERO, -w) * (cos_r * cos_l / r2);
            }
        }
        reference /= (g * g) as f32;
        let rel = (est.r - reference.r).abs() / reference.r;
        assert!(rel < 0.02, "{est:?} against {reference:?}");
    }
}
