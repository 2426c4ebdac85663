//! The latitude-longitude (equirectangular) environment map, importance sampled.

use std::f32::consts::PI;

use glam::{Mat3, Vec2, Vec3};
use pt_accel::{Bounds3, Ray};

use crate::color::Rgb;
use crate::image::Image;
use crate::light::environment::placement::Placement;
use crate::light::environment::{Cells, TexelDistribution, bilinear, check_texels, filter_3x3};
use crate::light::{Light, LightError, LightFlags, LightSample, LightSampleContext};
use crate::sampling::{ONE_MINUS_EPSILON, sample_uniform_sphere, uniform_sphere_pdf};

/// A latitude-longitude (equirectangular) environment map, importance sampled.
///
/// Texels are chosen with probability proportional to their filtered luminance times `sin
/// theta`, a cell of 8x8 texels first (from a distribution over the cells, small enough to stay
/// in the cache), then the texel within the cell; the direction is uniform in `(u, v)` within
/// the texel.
#[derive(Clone, Debug, PartialEq)]
pub struct EquirectEnvironment {
    image: Image,
    /// The image's texels as sampling cells.
    cells: Cells,
    distribution: Option<TexelDistribution>,
    /// Sample directions uniformly instead of by the map (for variance comparisons).
    uniform_sampling: bool,
    /// Integral of radiance over the sphere.
    integral: Rgb,
    place: Placement,
}

/// Map-frame direction to `(u, v)` in `[0, 1]^2`, and `sin theta`.
#[inline]
pub(crate) fn equirect_uv(d: Vec3) -> (Vec2, f32) {
    let u = 0.5 + d.x.atan2(-d.z) * (0.5 / PI);
    let v = d.y.clamp(-1.0, 1.0).acos() / PI;
    let sin_theta = (d.x * d.x + d.z * d.z).sqrt();
    (Vec2::new(u.rem_euclid(1.0), v), sin_theta)
}

/// `(u, v)` to a map-frame unit direction, and `sin theta`.
#[inline]
pub(crate) fn equirect_dir(uv: Vec2) -> (Vec3, f32) {
    let theta = PI * uv.y;
    let phi = 2.0 * PI * (uv.x - 0.5);
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    (Vec3::new(st * sp, ct, -st * cp), st)
}

impl EquirectEnvironment {
    /// An environment from a linear-RGB latitude-longitude image (any aspect ratio; 2:1 is
    /// usual). Fails on an empty image or a negative or non-finite texel. An all-black map is
    /// allowed and emits nothing.
    pub fn new(image: Image) -> Result<Self, LightError> {
        check_texels(&image, "the equirectangular map")?;
        let (w, h) = (image.width() as usize, image.height() as usize);
        let cells = Cells::new(w, h);
        let mut map = Self {
            cells,
            distribution: None,
            uniform_sampling: false,
            image,
            integral: Rgb::BLACK,
            place: Placement::new(),
        };
        let mut weights = vec![0.0f32; cells.items()];
        let mut integral = Rgb::BLACK;
        for y in 0..h {
            let theta = PI * (y as f32 + 0.5) / h as f32;
            let st = theta.sin();
            // Solid angle of a texel of this row.
            let omega = (2.0 * PI / w as f32) * (PI / h as f32) * st;
            for x in 0..w {
                let (xi, yi) = (x as i64, y as i64);
                let filtered = filter_3x3(|dx, dy| map.texel(xi + dx, yi + dy).luminance());
                weights[cells.item(0, x, y)] = filtered * st;
                integral += map.texel(xi, yi) * omega;
            }
        }
        map.distribution = TexelDistribution::new(&weights);
        map.integral = integral;
        Ok(map)
    }

    /// Rotate the map: `rotation` takes map-frame directions to world directions. Fails unless
    /// it is a proper rotation.
    pub fn with_rotation(mut self, rotation: Mat3) -> Result<Self, LightError> {
        self.place.set_rotation(rotation)?;
        Ok(self)
    }

    /// Multiply the radiance by `scale` (finite, `>= 0`).
    pub fn with_scale(mut self, scale: f32) -> Result<Self, LightError> {
        let brightest = self
            .image
            .pixels()
            .fold(0.0f32, |m, c| m.max(c.max_component()));
        self.place.set_scale(scale, brightest)?;
        Ok(self)
    }

    /// Sample directions uniformly over the sphere instead of in proportion to the map: worse in
    /// every case, here to measure what importance sampling gains (the variance check).
    #[must_use]
    pub fn with_uniform_sampling(mut self) -> Self {
        self.uniform_sampling = true;
        self
    }

    /// The image.
    #[must_use]
    pub fn image(&self) -> &Image {
        &self.image
    }

    /// Texel `(x, y)` with `x` wrapping around and `y` clamped to the poles.
    // Here and below: always inlined without AVX2 (see the module's docs).
    #[cfg_attr(target_feature = "avx2", inline)]
    #[cfg_attr(not(target_feature = "avx2"), inline(always))]
    fn texel(&self, x: i64, y: i64) -> Rgb {
        let (w, h) = (
            i64::from(self.image.width()),
            i64::from(self.image.height()),
        );
        self.image
            .get(x.rem_euclid(w) as u32, y.clamp(0, h - 1) as u32)
    }

    /// Radiance at `uv`, interpolated bilinearly between texel centres.
    #[cfg_attr(target_feature = "avx2", inline)]
    #[cfg_attr(not(target_feature = "avx2"), inline(always))]
    fn lookup(&self, uv: Vec2) -> Rgb {
        let size = Vec2::new(self.image.width() as f32, self.image.height() as f32);
        bilinear(uv * size, |x, y| self.texel(x, y))
    }

    /// Radiance arriving from world direction `wi` (unit), scale included.
    #[must_use]
    #[cfg_attr(not(target_feature = "avx2"), inline(always))]
    pub fn radiance(&self, wi: Vec3) -> Rgb {
        let (uv, _) = equirect_uv(self.place.to_map * wi);
        self.lookup(uv) * self.place.scale
    }
}

impl Light for EquirectEnvironment {
    fn flags(&self) -> LightFlags {
        LightFlags::INFINITE
    }

    fn power(&self) -> Rgb {
        self.place.power(self.integral)
    }

    #[cfg_attr(not(target_feature = "avx2"), inline(always))]
    fn sample_li(&self, ctx: &LightSampleContext, u: Vec2) -> Option<LightSample> {
        let dist = self.distribution.as_ref()?;
        if self.uniform_sampling {
            let wi = sample_uniform_sphere(u);
            let (uv, _) = equirect_uv(self.place.to_map * wi);
            let li = self.lookup(uv);
            return Some(self.place.sample(ctx, wi, li, uniform_sphere_pdf()));
        }
        let (index, pmf, ux) = dist.sample_discrete(u.x);
        let (_, x, y) = self.cells.texel(index);
        let (w, h) = (self.image.width() as f32, self.image.height() as f32);
        let uv = Vec2::new(
            ((x as f32 + ux) / w).min(ONE_MINUS_EPSILON),
            ((y as f32 + u.y) / h).min(ONE_MINUS_EPSILON),
        );
        // The texel's probability over its area in (u, v).
        let pdf_uv = pmf * w * h;
        let (d, sin_theta) = equirect_dir(uv);
        if sin_theta <= 0.0 || pdf_uv <= 0.0 {
            return None;
        }
        let pdf = pdf_uv / (2.0 * PI * PI * sin_theta);
        let wi = (self.place.to_world * d).normalize();
        Some(self.place.sample(ctx, wi, self.lookup(uv), pdf))
    }

    #[cfg_attr(not(target_feature = "avx2"), inline(always))]
    fn prefetch_sample_li(&self, u: Vec2, step: u32) {
        let Some(dist) = &self.distribution else {
            return;
        };
        if self.uniform_sampling {
            return;
        }
        if step == 0 {
            dist.prefetch(u.x);
        } else if step == 1 {
            // The rows of the bilinear lookup's texels (the column wrapped, the rows clamped).
            let (index, _, ux) = dist.sample_discrete(u.x);
            let (_, x, y) = self.cells.texel(index);
            let (w, h) = (self.image.width(), self.image.height());
            let p = Vec2::new(x as f32 + ux, y as f32 + u.y) - 0.5;
            // `-0.5 <= p.x < w`: a negative column is -1, wrapped to the last; otherwise
            // truncation is the floor (and needs no `floorf` call).
            let x = if p.x < 0.0 {
                w - 1
            } else {
                (p.x as u32).min(w - 1)
            };
            let y = p.y.max(0.0) as u32;
            for row in [y.min(h - 1), (y + 1).min(h - 1)] {
                self.image.prefetch_pair(x, row);
            }
        }
    }

    #[cfg_attr(not(target_feature = "avx2"), inline(always))]
    fn pdf_li(&self, _ctx: &LightSampleContext, wi: Vec3) -> f32 {
        let Some(dist) = self.distribution.as_ref() else {
            return 0.0;
        };
        if self.uniform_sampling {
            return uniform_sphere_pdf();
        }
        let (uv, sin_theta) = equirect_uv(self.place.to_map * wi.normalize());
        if sin_theta <= 0.0 {
            return 0.0;
        }
        let (w, h) = (self.image.width(), self.image.height());
        let x = ((uv.x * w as f32) as u32).min(w - 1) as usize;
        let y = ((uv.y * h as f32) as u32).min(h - 1) as usize;
        let pdf_uv = dist.pmf(self.cells.item(0, x, y)) * w as f32 * h as f32;
        pdf_uv / (2.0 * PI * PI * sin_theta)
    }

    #[cfg_attr(not(target_feature = "avx2"), inline(always))]
    fn le(&self, ray: &Ray) -> Rgb {
        self.radiance(ray.dir.normalize())
    }

    fn preprocess(&mut self, scene_bounds: &Bounds3) {
        self.place.preprocess(scene_bounds);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn equirect_mapping_round_trips() {
        for uv in [
            Vec2::new(0.1, 0.2),
            Vec2::new(0.5, 0.5),
            Vec2::new(0.75, 0.9),
            Vec2::new(0.999, 0.01),
        ] {
            let (d, st) = equirect_dir(uv);
            assert!((d.length() - 1.0).abs() < 1e-6);
            let (back, st2) = equirect_uv(d);
            assert!((back - uv).length() < 1e-5, "{uv} -> {d} -> {back}");
            assert!((st - st2).abs() < 1e-5);
        }
        // The centre column looks toward -z; u = 0.75 toward +x; row 0 is up.
        assert!((equirect_dir(Vec2::new(0.5, 0.5)).0 - Vec3::NEG_Z).length() < 1e-6);
        assert!((equirect_dir(Vec2::new(0.75, 0.5)).0 - Vec3::X).length() < 1e-6);
        assert!(equirect_dir(Vec2::new(0.3, 0.0)).0.y > 0.999);
    }
}
