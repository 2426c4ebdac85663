//! The tile scheduler: the image in square tiles on the thread pool, each pixel's samples in
//! index order by one thread, and adaptive stopping per pixel.

use glam::{UVec2, Vec2};

use crate::aov::{AovRecord, AovSample, NoAov};
use crate::camera::{Camera, CameraSample};
use crate::film::Film;
use crate::integrator::Integrator;
use crate::light::Light;
use crate::material::Material;
use crate::render::{RenderControl, RenderError, RenderOptions};
use crate::sampler::Sampler;
use crate::scene::Scene;

/// A rectangle of pixels rendered as one unit of work.
#[derive(Clone, Copy, Debug)]
pub(super) struct Tile {
    pub x0: u32,
    pub y0: u32,
    pub w: u32,
    pub h: u32,
}

/// The tiles of a `width x height` image, row by row.
pub(super) fn tiles(width: u32, height: u32, size: u32) -> Vec<Tile> {
    let mut out = Vec::new();
    for y0 in (0..height).step_by(size as usize) {
        for x0 in (0..width).step_by(size as usize) {
            out.push(Tile {
                x0,
                y0,
                w: size.min(width - x0),
                h: size.min(height - y0),
            });
        }
    }
    out
}

#[cfg(feature = "parallel")]
pub(super) fn run_tiles<R: Send>(
    tiles: &[Tile],
    threads: Option<usize>,
    job: impl Fn(&Tile) -> R + Sync,
) -> Result<Vec<R>, RenderError> {
    use rayon::prelude::*;
    let work = || tiles.par_iter().map(&job).collect();
    match threads {
        None => Ok(work()),
        Some(n) => {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .map_err(|e| RenderError::ThreadPool(e.to_string()))?;
            Ok(pool.install(work))
        }
    }
}

#[cfg(not(feature = "parallel"))]
pub(super) fn run_tiles<R: Send>(
    tiles: &[Tile],
    _threads: Option<usize>,
    job: impl Fn(&Tile) -> R + Sync,
) -> Result<Vec<R>, RenderError> {
    Ok(tiles.iter().map(job).collect())
}

/// Render one tile; `A` is the AOV recorder ([`AovSample`] when the options ask for AOVs, else
/// [`NoAov`], which compiles to nothing).
pub(super) fn render_tile<
    M: Material,
    L: Light,
    C: Camera,
    S: Sampler,
    I: Integrator<M, L>,
    K,
    A: AovRecord + AovFilm,
>(
    scene: &Scene<M, L>,
    camera: &C,
    options: &RenderOptions<K>,
    integrator: &I,
    mut sampler: S,
    tile: &Tile,
    control: &RenderControl<'_>,
) -> (Film, u64) {
    let mut film = Film::new_with(tile.w, tile.h, A::ON);
    let mut rays = 0u64;
    let inv = Vec2::new(1.0 / options.width as f32, 1.0 / options.height as f32);
    let aspect = options.width as f32 / options.height as f32;
    let range = options.samples();
    let uses_lens = camera.uses_lens();
    for ty in 0..tile.h {
        for tx in 0..tile.w {
            if control.cancelled() {
                return (film, rays);
            }
            let pixel = UVec2::new(tile.x0 + tx, tile.y0 + ty);
            // Running sums of the samples' luminance, for adaptive sampling's error estimate.
            let (mut taken, mut sum, mut sum_sq) = (0u32, 0.0f64, 0.0f64);
            let mut next_check = options.adaptive.map_or(u32::MAX, |a| a.min_spp);
            for index in range.clone() {
                sampler.start_pixel_sample(pixel, index);
                let film_pos = (pixel.as_vec2() + sampler.pixel_2d()) * inv;
                let lens = if uses_lens {
                    sampler.next_2d()
                } else {
                    Vec2::splat(0.5)
                };
                let ray = camera.generate_ray(&CameraSample {
                    film: film_pos,
                    aspect,
                    lens,
                });
                let mut aov = A::default();
                let l = integrator.radiance(scene, ray, &mut sampler, &mut rays, &mut aov);
                match options.sample_clamp {
                    Some(max) => film.add_sample_clamped(tx, ty, l, max),
                    None => film.add_sample(tx, ty, l),
                }
                aov.add_to(&mut film, tx, ty);
                if let Some(adaptive) = &options.adaptive {
                    let y = f64::from(l.luminance());
                    if y.is_finite() {
                        sum += y;
                        sum_sq += y * y;
                    }
                    taken += 1;
                    if taken == next_check {
                        if converged(taken, sum, sum_sq, adaptive.threshold) {
                            break;
                        }
                        next_check = next_check.saturating_mul(2);
                    }
                }
            }
        }
    }
    (film, rays)
}

/// How a sample's AOVs reach the film.
pub(super) trait AovFilm {
    fn add_to(&self, film: &mut Film, x: u32, y: u32);
}

impl AovFilm for NoAov {
    #[inline(always)]
    fn add_to(&self, _: &mut Film, _: u32, _: u32) {}
}

impl AovFilm for AovSample {
    #[inline]
    fn add_to(&self, film: &mut Film, x: u32, y: u32) {
        film.add_aux(x, y, self.albedo, self.normal);
    }
}

/// Whether a pixel's mean, from `n` samples with luminance sum `sum` and sum of squares
/// `sum_sq`, has a relative standard error below `threshold` (relative to the mean plus 0.01).
#[inline]
fn converged(n: u32, sum: f64, sum_sq: f64, threshold: f32) -> bool {
    let n = f64::from(n);
    let mean = sum / n;
    let variance = ((sum_sq - sum * mean) / (n - 1.0)).max(0.0);
    let standard_error = (variance / n).sqrt();
    standard_error < f64::from(threshold) * (mean.abs() + 0.01)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn adaptive_error_estimate() {
        // Constant samples have no error; 1% noise on a mean of 1 with 100 samples has a
        // standard error of 0.1%.
        assert!(converged(16, 16.0, 16.0, 1e-6));
        let (n, mean, sd) = (100.0f64, 1.0f64, 0.01f64);
        let sum = n * mean;
        let sum_sq = (n - 1.0) * sd * sd + n * mean * mean;
        assert!(converged(100, sum, sum_sq, 0.0011));
        assert!(!converged(100, sum, sum_sq, 0.0009));
        // A dark pixel is judged against the floor of 0.01.
        assert!(!converged(4, 0.0, 0.01, 0.5));
    }

    #[test]
    fn tiles_cover_the_image_exactly_once() {
        let t = tiles(37, 20, 16);
        let area: u32 = t.iter().map(|t| t.w * t.h).sum();
        assert_eq!(area, 37 * 20);
        assert_eq!(t.len(), 3 * 2);
    }
}
