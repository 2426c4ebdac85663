//! Environment lights: radiance arriving from infinitely far away, seen by rays that escape the
//! scene and sampled for next-event estimation.
//!
//! Three models share the same conventions:
//!
//! - [`UniformEnvironment`]: the same radiance from every direction (furnace tests, ambient).
//! - [`EquirectEnvironment`]: a latitude-longitude map (Radiance `.hdr`, OpenEXR). For a unit
//!   direction `d` in the map's frame (`+y` up), `u = 1/2 + atan2(d.x, -d.z) / (2 pi)` and
//!   `v = acos(d.y) / pi`: the image's centre column looks toward `-z`, its left edge toward
//!   `+z` through `-x`, row 0 is straight up. Radiance is interpolated bilinearly between texel
//!   centres (wrapping in `u`, clamped at the poles), and directions are sampled from a
//!   piecewise-constant distribution over the texels with weights `filtered luminance *
//!   sin(theta)` (a texel, then a point uniformly in `(u, v)` within it), so `pdf_li` is
//!   exact: `pdf(d) = p(u, v) / (2 pi^2 sin theta)`.
//! - [`CubemapEnvironment`]: six square faces in the OpenGL layout (`+x, -x, +y, -y, +z, -z`;
//!   on face `+z`, `s` grows with `x` and `t` with `-y`; row 0 at the top of each image). That
//!   layout reads correctly from inside a *left-handed* frame, so pt mirrors `x` before the
//!   lookup (as three.js does): looking along `+z` with `+y` up, the `px` face is on the right,
//!   as in the usual cross layout `nx pz px nz`. Radiance is interpolated bilinearly between
//!   texel centres, across the seams too (a tap beyond a face's edge is the texel of the
//!   neighbouring face that its centre projects to). Texels are chosen with probability
//!   proportional to `filtered luminance * solid angle`, then a point uniformly within the
//!   texel on the face, so `pdf(d) = P(texel) / A_texel * r^3` with `r` the distance to the
//!   face point.
//!
//! Why the sampling can stay piecewise constant while the radiance is bilinear: next-event
//! estimation divides the interpolated radiance of the sampled direction by the exact density
//! of that direction, `L(d) f cos / pdf(d)`, whose expectation is the integral of `L f cos`
//! wherever `pdf > 0`. It is unbiased as long as `pdf > 0` wherever the interpolated `L > 0`.
//! Interpolation spreads a bright texel into its neighbours, so a texel's weight is its
//! luminance filtered with `(1/8, 3/4, 1/8)` in each direction: the mean of the bilinear
//! radiance over the texel, positive wherever the interpolated radiance is. Light sampling and
//! rays that escape see the same (interpolated) radiance, so MIS combines estimates of one
//! function.
//!
//! Both maps choose a texel in two steps that together give each texel its weight's share: a
//! cell of 8x8 texels from a distribution over the cells (a 1024-texel cube face has 16,384
//! cells, a 4096x2048 map 131,072: small enough to stay in the cache), then the texel from the
//! cell's running sums, which lie together in four cache lines. A map of millions of texels
//! is far larger than the caches, so what a light sample costs is its cache misses: one for the
//! cell's sums, one or two for the texels of the bilinear lookup. The lane path tracer asks
//! for every lane's cell, then for every lane's texels
//! ([`Light::prefetch_sample_li`](crate::Light::prefetch_sample_li) steps 0 and 1), before the
//! first lane samples, so that the lanes wait for their misses together.
//!
//! In a build without AVX2 (a program built for baseline x86-64) the maps' lookups and
//! sampling are always inlined, as are `light_enum!`'s forwarding methods and the tracers'
//! emission weight: they then compile inside the lane tracer's entry for the CPU's AVX2 or
//! AVX-512 (with its rounding and fused instructions), not as SSE2 code out of line (the
//! cube-map figure +5.7% and the sunset +5.2% in such a build). pt's own builds for the host
//! CPU leave the choice to the compiler.
//!
//! Each has an intensity `scale` and a rotation (map frame to world). Sample points for shadow
//! rays are placed beyond the scene's bounding sphere, whose radius also gives the power
//! estimate `Phi = pi R^2 * integral of L over the sphere` used to choose between the
//! environment and area lights.

mod cubemap;
mod equirect;
mod placement;
mod uniform;

pub use cubemap::{CUBE_FACES, CubemapEnvironment, cube_face_point, cube_face_st};
pub use equirect::EquirectEnvironment;
pub use uniform::UniformEnvironment;

use glam::Vec2;

use crate::color::Rgb;
use crate::distribution::BlockDistribution;
use crate::image::Image;
use crate::light::LightError;

/// Side of the square cells of texels whose sampling weights are kept together: one block of
/// a [`BlockDistribution`], 64 floats in four cache lines.
const CELL: usize = 8;
/// Texels per cell.
const CELL_TEXELS: usize = CELL * CELL;

/// How a map samples its texels: first a cell of 8x8 texels, by a distribution over the cells
/// small enough to stay in the cache, then a texel within the cell from the cell's own sums,
/// which lie together (see [`BlockDistribution`]). Each choice costs at most one cache miss
/// before the texel is read (a search of one distribution over every texel costs two: its
/// guide table, then its cumulative sums).
type TexelDistribution = BlockDistribution<CELL_TEXELS>;

/// A `width x height` texel grid as cells of [`CELL_TEXELS`] texels, and the index of each texel
/// in a [`TexelDistribution`] over one or more such grids (cell by cell, row-major in each cell;
/// texels beyond the grid's edge in its last cells have weight 0). Cells are [`CELL`] x
/// [`CELL`] texels, or, for a grid narrower or lower than that, as narrow or as low as the grid
/// (to the next power of two) and longer the other way, so that the padding stays within a few
/// times the texels for any shape (with 8x8 cells a 1 x 2^28 map would pad to 2^31 items).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Cells {
    /// Cells per row and per column.
    cols: usize,
    rows: usize,
    /// A cell's width and height in texels: powers of two whose product is `CELL_TEXELS`,
    /// kept as their logarithms (shifts and masks, not divisions, on the sampling path).
    width_log2: u32,
    height_log2: u32,
}

impl Cells {
    fn new(width: usize, height: usize) -> Self {
        let (cw, ch) = if width >= CELL && height >= CELL {
            (CELL, CELL)
        } else if width < height {
            let cw = width.max(1).next_power_of_two();
            (cw, CELL_TEXELS / cw)
        } else {
            let ch = height.max(1).next_power_of_two();
            (CELL_TEXELS / ch, ch)
        };
        Self {
            cols: width.div_ceil(cw),
            rows: height.div_ceil(ch),
            width_log2: cw.ilog2(),
            height_log2: ch.ilog2(),
        }
    }

    /// Items of one grid (texels and the padding of its last cells).
    fn items(self) -> usize {
        self.cols * self.rows * CELL_TEXELS
    }

    /// Index of texel `(x, y)` of grid `plane` (a cube face; 0 for a single image).
    #[inline]
    fn item(self, plane: usize, x: usize, y: usize) -> usize {
        let (wl, hl) = (self.width_log2, self.height_log2);
        let cell = (plane * self.rows + (y >> hl)) * self.cols + (x >> wl);
        cell * CELL_TEXELS + ((y & ((1 << hl) - 1)) << wl) + (x & ((1 << wl) - 1))
    }

    /// The grid and texel `(plane, x, y)` of index `item` (the inverse of [`Self::item`]).
    #[inline]
    fn texel(self, item: usize) -> (usize, usize, usize) {
        let (cell, k) = (item / CELL_TEXELS, item % CELL_TEXELS);
        let per_plane = self.cols * self.rows;
        let (plane, cell) = (cell / per_plane, cell % per_plane);
        let (wl, hl) = (self.width_log2, self.height_log2);
        let y = ((cell / self.cols) << hl) + (k >> wl);
        let x = ((cell % self.cols) << wl) + (k & ((1 << wl) - 1));
        (plane, x, y)
    }
}

/// Fails on an empty image or a negative or non-finite texel, naming the image and the texel.
fn check_texels(image: &Image, name: &'static str) -> Result<(), LightError> {
    if image.width() == 0 || image.height() == 0 {
        return Err(LightError::BadSize(format!("{name} has no texels")));
    }
    for y in 0..image.height() {
        for x in 0..image.width() {
            let c = image.get(x, y);
            if !c.is_valid_nonnegative() {
                return Err(LightError::BadTexel { image: name, x, y });
            }
        }
    }
    Ok(())
}

/// The bilinear interpolation between texel centres at texel-space position `p >= 0` (texel
/// `(x, y)` covers `[x, x+1) x [y, y+1)`), `texel` giving any texel, also one beyond the edges.
#[cfg_attr(target_feature = "avx2", inline)]
#[cfg_attr(not(target_feature = "avx2"), inline(always))]
fn bilinear(p: Vec2, texel: impl Fn(i64, i64) -> Rgb) -> Rgb {
    let f = p - Vec2::splat(0.5);
    let ((x, tx), (y, ty)) = (floor_above_minus_one(f.x), floor_above_minus_one(f.y));
    let top = texel(x, y) * (1.0 - tx) + texel(x + 1, y) * tx;
    let bottom = texel(x, y + 1) * (1.0 - tx) + texel(x + 1, y + 1) * tx;
    top * (1.0 - ty) + bottom * ty
}

/// `(floor(x), x - floor(x))` for `x > -1` (NaN gives `(0, NaN)`; -0.0, which `p - 0.5` never
/// is, may give the fraction -0.0). A build for baseline x86-64 has no rounding instruction
/// (SSE4.1's `roundss`) and calls the C library for `floor`; above -1, truncation and a step
/// down below zero give the same integer and fraction.
#[inline(always)]
fn floor_above_minus_one(x: f32) -> (i64, f32) {
    debug_assert!(x > -1.0 || x.is_nan(), "{x}");
    if cfg!(any(target_feature = "sse4.1", not(target_arch = "x86_64"))) {
        let x0 = x.floor();
        (x0 as i64, x - x0)
    } else {
        floor_by_truncation(x)
    }
}

/// [`floor_above_minus_one`] without `floor`.
#[inline(always)]
fn floor_by_truncation(x: f32) -> (i64, f32) {
    let x0 = x as i64 - i64::from(x < 0.0);
    (x0, x - x0 as f32)
}

/// `sum k(dx) k(dy) f(dx, dy)` over the 3x3 neighbourhood with `k = (1/8, 3/4, 1/8)`: the mean
/// over a texel of the bilinear interpolation of `f` between texel centres.
fn filter_3x3(f: impl Fn(i64, i64) -> f32) -> f32 {
    const K: [f32; 3] = [0.125, 0.75, 0.125];
    let mut sum = 0.0;
    for (j, ky) in K.iter().enumerate() {
        for (i, kx) in K.iter().enumerate() {
            sum += kx * ky * f(i as i64 - 1, j as i64 - 1);
        }
    }
    sum
}

#[cfg(test)]
mod tests {
    use glam::{Mat3, Vec3};

    use super::*;

    #[test]
    fn floor_by_truncation_is_floor_above_minus_one() {
        let check = |x: f32| {
            let (x0, t) = floor_by_truncation(x);
            let want = x.floor();
            // Bits equal, but for -0.0's fraction (-0.0 against 0.0).
            let same = t.to_bits() == (x - want).to_bits() || (t == 0.0 && x == 0.0);
            assert!(x0 == want as i64 && same, "{x:e}: ({x0}, {t:e})");
        };
        for x in [
            -0.999_999_94,
            -0.5,
            -1e-45,
            -0.0,
            0.0,
            1e-45,
            0.5,
            0.999_999_94,
            1.0,
            3.5,
        ] {
            check(x);
        }
        // Every f32 from -1 (excluded) to 2^24, by a spread of bit patterns.
        let top = 16_777_216.0f32.to_bits();
        for bits in (0..top).step_by(97) {
            check(f32::from_bits(bits));
        }
        for bits in (0..(-1.0f32).to_bits() - (1 << 31)).step_by(97) {
            check(-f32::from_bits(bits));
        }
        let (x0, t) = floor_by_truncation(f32::NAN);
        assert!(x0 == 0 && t.is_nan());
    }

    #[test]
    fn bad_maps_are_errors() {
        let mut img = Image::new(4, 2);
        img.set(1, 1, Rgb::new(f32::NAN, 0.0, 0.0));
        let e = EquirectEnvironment::new(img).unwrap_err();
        assert_eq!(
            e,
            LightError::BadTexel {
                image: "the equirectangular map",
                x: 1,
                y: 1
            }
        );
        assert!(EquirectEnvironment::new(Image::new(0, 0)).is_err());
        let faces = std::array::from_fn(|i| Image::new(4, if i == 3 { 5 } else { 4 }));
        assert!(
            CubemapEnvironment::new(faces)
                .unwrap_err()
                .to_string()
                .contains("ny is 4x5")
        );
        assert!(UniformEnvironment::new(Rgb::splat(-1.0)).is_err());
        let ok = EquirectEnvironment::new(Image::new(4, 2)).unwrap();
        assert!(ok.clone().with_scale(f32::NAN).is_err());
        assert!(
            ok.with_rotation(Mat3::from_diagonal(Vec3::splat(2.0)))
                .is_err()
        );
    }

    /// Every texel has its own item and comes back from it, for square, wide, tall and tiny
    /// grids; the padding stays within four times the texels (plus two cells), which cells of
    /// 8x8 alone would break for thin grids (1x300: 2,432 items).
    #[test]
    fn cells_index_every_texel_once_with_bounded_padding() {
        for (w, h) in [
            (16, 16),
            (17, 9),
            (1, 1),
            (1, 300),
            (300, 1),
            (3, 40),
            (40, 5),
            (7, 7),
        ] {
            let cells = Cells::new(w, h);
            assert_eq!(1 << (cells.width_log2 + cells.height_log2), CELL_TEXELS);
            let items = cells.items();
            assert!(
                items <= 4 * w * h + 2 * CELL_TEXELS,
                "{w}x{h}: {items} items"
            );
            let mut seen = vec![false; 2 * items];
            for plane in 0..2 {
                for y in 0..h {
                    for x in 0..w {
                        let i = cells.item(plane, x, y);
                        assert!(!seen[i], "{w}x{h}: item {i} twice");
                        seen[i] = true;
                        assert_eq!(cells.texel(i), (plane, x, y));
                    }
                }
            }
        }
    }
}
