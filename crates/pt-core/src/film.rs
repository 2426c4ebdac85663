//! The film: per-pixel accumulation of radiance samples.
//!
//! Each sample is added with a box filter (it counts for the pixel it was taken in only), so a
//! pixel's value is exactly the mean of its samples and no filter can bias analytic tests.
//!
//! Sums are kept in **fixed point**: each f32 channel is converted exactly to an `i128` with 64
//! fractional bits and added as an integer. Integer addition is associative, so a render split
//! into sample ranges and merged gives bit for bit the same sums, in any order, as one render over
//! all samples: the basis of [`Film::merge`]. Values below 2^-64 (5e-20) are truncated and a
//! pixel's sum saturates at 2^63 (9.2e18), far outside any radiance a scene produces.
//!
//! Samples with a NaN or infinite channel are **dropped** and counted: they still count as a
//! sample of the pixel (with zero value, as pbrt does, so that dropping cannot brighten a pixel)
//! but never reach the sums or any output file.

use glam::Vec3;

use crate::color::Rgb;
use crate::image::Image;

/// Fractional bits of the fixed-point sums.
const FRAC_BITS: i32 = 64;

/// Convert an f32 exactly (up to truncation below 2^-64) to fixed point, saturating.
#[inline]
fn to_fixed(v: f32) -> i128 {
    let bits = v.to_bits();
    let biased = ((bits >> 23) & 0xff) as i32;
    let frac = i128::from(bits & 0x7f_ffff);
    // value = mantissa * 2^(exponent - 150) for normals, mantissa * 2^-149 for subnormals.
    let (mantissa, exp) = if biased == 0 {
        (frac, 1)
    } else {
        (frac | 0x80_0000, biased)
    };
    let shift = exp - 150 + FRAC_BITS;
    let magnitude = if shift >= 0 {
        if shift > 102 {
            SATURATED
        } else {
            mantissa << shift
        }
    } else if shift <= -24 {
        0
    } else {
        mantissa >> -shift
    };
    if bits >> 31 == 1 {
        -magnitude
    } else {
        magnitude
    }
}

/// What [`to_fixed`] returns for values beyond the fixed-point range.
const SATURATED: i128 = i128::MAX >> 1;

/// What adding a sample did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Added {
    Ok,
    NonFinite,
    Saturated,
}

/// Convert a fixed-point sum back to f64.
#[inline]
fn from_fixed(v: i128) -> f64 {
    v as f64 * (-FRAC_BITS as f64).exp2()
}

/// The accumulated samples of one pixel.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct PixelSum {
    sum: [i128; 3],
    count: u32,
}

impl PixelSum {
    /// Add one sample. Returns false (and adds only to the count) when it is not finite.
    #[inline]
    pub fn add(&mut self, l: Rgb) -> bool {
        self.add_reporting(l) != Added::NonFinite
    }

    /// Add one sample, saying whether it was dropped (not finite) or reached the fixed-point
    /// limit (a channel of about 4.6e18 or more, or a sum that saturated).
    #[inline]
    pub(crate) fn add_reporting(&mut self, l: Rgb) -> Added {
        self.count += 1;
        if !l.is_finite() {
            return Added::NonFinite;
        }
        let mut saturated = false;
        for (s, v) in self.sum.iter_mut().zip(l.to_array()) {
            let f = to_fixed(v);
            let (sum, overflow) = s.overflowing_add(f);
            saturated |= overflow || f.abs() >= SATURATED;
            *s = if overflow { s.saturating_add(f) } else { sum };
        }
        if saturated {
            Added::Saturated
        } else {
            Added::Ok
        }
    }

    /// Mean of the samples (black when there are none).
    #[inline]
    #[must_use]
    pub fn mean(&self) -> Rgb {
        if self.count == 0 {
            return Rgb::BLACK;
        }
        let n = f64::from(self.count);
        Rgb::new(
            (from_fixed(self.sum[0]) / n) as f32,
            (from_fixed(self.sum[1]) / n) as f32,
            (from_fixed(self.sum[2]) / n) as f32,
        )
    }

    /// Number of samples taken in this pixel.
    #[inline]
    #[must_use]
    pub fn count(&self) -> u32 {
        self.count
    }

    /// The fixed-point sums (64 fractional bits) and the count, for serialisation.
    #[cfg_attr(not(feature = "exr"), allow(dead_code))]
    pub(crate) fn raw(&self) -> ([i128; 3], u32) {
        (self.sum, self.count)
    }

    /// A pixel from [`PixelSum::raw`]'s parts.
    #[cfg_attr(not(feature = "exr"), allow(dead_code))]
    pub(crate) fn from_raw(sum: [i128; 3], count: u32) -> Self {
        Self { sum, count }
    }

    /// Combine with the samples of another render of the same pixel (exact).
    #[inline]
    pub fn merge(&mut self, other: &PixelSum) {
        for k in 0..3 {
            self.sum[k] = self.sum[k].saturating_add(other.sum[k]);
        }
        // Counts from files (partial renders) may be anything: saturate rather than wrap.
        self.count = self.count.saturating_add(other.count);
    }
}

/// Fractional bits of the auxiliary sums: their values lie in [-1, 1], so a sum of up to 2^31
/// samples fits an `i64`.
const AUX_FRAC_BITS: i32 = 32;

/// `v` (in [-1, 1], or clamped to it) in the fixed point of the auxiliary sums. The product
/// with a power of two is exact and the rounding deterministic, so the sums are exact too.
#[inline]
fn aux_fixed(v: f32) -> i64 {
    let v = if v.is_finite() {
        v.clamp(-1.0, 1.0)
    } else {
        0.0
    };
    (f64::from(v) * f64::from(AUX_FRAC_BITS).exp2()).round() as i64
}

/// The accumulated auxiliary outputs of one pixel: albedo and normal of each sample's first
/// non-specular hit (see [`crate::aov`]), in exact fixed point like the colour, so partial
/// renders merge bit for bit. Their means divide by the colour's sample count.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct AuxSum {
    albedo: [i64; 3],
    normal: [i64; 3],
}

impl AuxSum {
    /// Add one sample's albedo (each channel clamped to [0, 1]) and normal (components clamped
    /// to [-1, 1]; zero where the path hit nothing).
    #[inline]
    pub fn add(&mut self, albedo: Rgb, normal: Vec3) {
        for (s, v) in self.albedo.iter_mut().zip(albedo.to_array()) {
            *s = s.saturating_add(aux_fixed(v.max(0.0)));
        }
        for (s, v) in self.normal.iter_mut().zip(normal.to_array()) {
            *s = s.saturating_add(aux_fixed(v));
        }
    }

    /// Combine with another render's sums of the same pixel (exact).
    #[inline]
    pub fn merge(&mut self, other: &AuxSum) {
        for k in 0..3 {
            self.albedo[k] = self.albedo[k].saturating_add(other.albedo[k]);
            self.normal[k] = self.normal[k].saturating_add(other.normal[k]);
        }
    }

    /// Mean albedo over `count` samples (black for none).
    #[must_use]
    pub fn albedo(&self, count: u32) -> Rgb {
        let [r, g, b] = mean3(&self.albedo, count);
        Rgb::new(r, g, b)
    }

    /// Mean normal over `count` samples (not renormalised: shorter where samples disagree,
    /// zero for none).
    #[must_use]
    pub fn normal(&self, count: u32) -> Vec3 {
        Vec3::from_array(mean3(&self.normal, count))
    }

    /// The raw sums, albedo then normal (32 fractional bits), for serialisation.
    #[cfg_attr(not(feature = "exr"), allow(dead_code))]
    pub(crate) fn raw(&self) -> [i64; 6] {
        let (a, n) = (self.albedo, self.normal);
        [a[0], a[1], a[2], n[0], n[1], n[2]]
    }

    /// Sums from [`AuxSum::raw`]'s order.
    #[cfg_attr(not(feature = "exr"), allow(dead_code))]
    pub(crate) fn from_raw(v: [i64; 6]) -> Self {
        Self {
            albedo: [v[0], v[1], v[2]],
            normal: [v[3], v[4], v[5]],
        }
    }
}

fn mean3(sum: &[i64; 3], count: u32) -> [f32; 3] {
    if count == 0 {
        return [0.0; 3];
    }
    let scale = (-f64::from(AUX_FRAC_BITS)).exp2() / f64::from(count);
    sum.map(|s| (s as f64 * scale) as f32)
}

/// A rectangle of pixel sums: the whole image, or one tile of it.
#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    width: u32,
    height: u32,
    pixels: Vec<PixelSum>,
    /// The auxiliary sums, one per pixel, or empty when the render has no AOVs.
    aux: Vec<AuxSum>,
    non_finite: u64,
    clamped: u64,
    saturated: u64,
}

impl Film {
    /// An empty film.
    #[must_use]
    pub fn new(width: u32, height: u32) -> Self {
        Self {
            width,
            height,
            pixels: vec![PixelSum::default(); width as usize * height as usize],
            aux: Vec::new(),
            non_finite: 0,
            clamped: 0,
            saturated: 0,
        }
    }

    /// An empty film that also accumulates the auxiliary outputs (albedo and normal).
    #[must_use]
    pub fn with_aux(width: u32, height: u32) -> Self {
        Self {
            aux: vec![AuxSum::default(); width as usize * height as usize],
            ..Self::new(width, height)
        }
    }

    /// An empty film, with the auxiliary sums when `aux` ([`Film::with_aux`]) or without.
    #[must_use]
    pub fn new_with(width: u32, height: u32, aux: bool) -> Self {
        if aux {
            Self::with_aux(width, height)
        } else {
            Self::new(width, height)
        }
    }

    /// Whether the film accumulates the auxiliary outputs.
    #[must_use]
    pub fn has_aux(&self) -> bool {
        !self.aux.is_empty()
    }

    /// The auxiliary sums, row by row (empty without AOVs).
    #[cfg_attr(not(feature = "exr"), allow(dead_code))]
    pub(crate) fn aux(&self) -> &[AuxSum] {
        &self.aux
    }

    /// Set the auxiliary sums (read back from a partial render file).
    #[cfg_attr(not(feature = "exr"), allow(dead_code))]
    pub(crate) fn set_aux(&mut self, aux: Vec<AuxSum>) {
        debug_assert_eq!(aux.len(), self.pixels.len());
        self.aux = aux;
    }

    /// Add a sample's albedo and normal to pixel `(x, y)` (its colour goes through
    /// [`Film::add_sample`]; the means divide by that count).
    ///
    /// # Panics
    /// If the film has no auxiliary sums ([`Film::with_aux`]).
    #[inline]
    pub fn add_aux(&mut self, x: u32, y: u32, albedo: Rgb, normal: Vec3) {
        let i = y as usize * self.width as usize + x as usize;
        self.aux[i].add(albedo, normal);
    }

    /// The mean albedo of each pixel's samples, if the film has AOVs.
    #[must_use]
    pub fn albedo_image(&self) -> Option<Image> {
        self.aux_image(|a, n| a.albedo(n).to_array())
    }

    /// The mean shading normal of each pixel's samples (world space, components in [-1, 1],
    /// zero where every sample missed), if the film has AOVs.
    #[must_use]
    pub fn normal_image(&self) -> Option<Image> {
        self.aux_image(|a, n| a.normal(n).to_array())
    }

    fn aux_image(&self, f: impl Fn(&AuxSum, u32) -> [f32; 3]) -> Option<Image> {
        if !self.has_aux() {
            return None;
        }
        let data = self
            .aux
            .iter()
            .zip(&self.pixels)
            .flat_map(|(a, p)| f(a, p.count()))
            .collect();
        Some(Image::from_rgb(self.width, self.height, data).expect("film and image sizes agree"))
    }

    /// A film from its parts (for reading partial renders back).
    #[cfg_attr(not(feature = "exr"), allow(dead_code))]
    pub(crate) fn from_parts(
        width: u32,
        height: u32,
        pixels: Vec<PixelSum>,
        non_finite: u64,
        clamped: u64,
    ) -> Self {
        debug_assert_eq!(pixels.len(), width as usize * height as usize);
        Self {
            width,
            height,
            pixels,
            aux: Vec::new(),
            non_finite,
            clamped,
            saturated: 0,
        }
    }

    /// The pixel sums, row by row.
    #[cfg_attr(not(feature = "exr"), allow(dead_code))]
    pub(crate) fn pixels(&self) -> &[PixelSum] {
        &self.pixels
    }

    /// Width in pixels.
    #[must_use]
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    #[must_use]
    pub fn height(&self) -> u32 {
        self.height
    }

    /// The number of samples taken in pixel `(x, y)` (all pixels take the same number unless
    /// the render sampled adaptively).
    #[must_use]
    pub fn sample_count(&self, x: u32, y: u32) -> u32 {
        self.pixels[y as usize * self.width as usize + x as usize].count()
    }

    /// Samples taken over all pixels.
    #[must_use]
    pub fn total_samples(&self) -> u64 {
        self.pixels.iter().map(|p| u64::from(p.count())).sum()
    }

    /// Add a radiance sample to pixel `(x, y)`. Non-finite samples are dropped and counted.
    #[inline]
    pub fn add_sample(&mut self, x: u32, y: u32, l: Rgb) {
        let i = y as usize * self.width as usize + x as usize;
        match self.pixels[i].add_reporting(l) {
            Added::Ok => {}
            Added::NonFinite => self.non_finite += 1,
            Added::Saturated => self.saturated += 1,
        }
    }

    /// Add a sample after scaling it so that its largest component is at most `max` (the
    /// firefly clamp of [`crate::RenderOptions::sample_clamp`]); counts the samples it scaled.
    #[inline]
    pub fn add_sample_clamped(&mut self, x: u32, y: u32, l: Rgb, max: f32) {
        let m = l.max_component();
        let l = if l.is_finite() && m > max {
            self.clamped += 1;
            l * (max / m)
        } else {
            l
        };
        self.add_sample(x, y, l);
    }

    /// Number of samples that reached the fixed-point limit of the sums (a channel of about
    /// 4.6e18 or more): their pixels are capped, not exact. A scene whose radiance is that large
    /// (an emitter of `Ke 1e30`, an environment scaled by 3e38) is reported, never silent.
    #[must_use]
    pub fn saturated_samples(&self) -> u64 {
        self.saturated
    }

    /// Set the saturated-sample count (read back from a partial render file).
    #[cfg_attr(not(feature = "exr"), allow(dead_code))]
    pub(crate) fn set_saturated(&mut self, n: u64) {
        self.saturated = n;
    }

    /// Number of samples scaled down by the firefly clamp.
    #[must_use]
    pub fn clamped_samples(&self) -> u64 {
        self.clamped
    }

    /// The sums of pixel `(x, y)`.
    #[must_use]
    pub fn pixel(&self, x: u32, y: u32) -> &PixelSum {
        &self.pixels[y as usize * self.width as usize + x as usize]
    }

    /// The auxiliary sums of pixel `(x, y)`, if the film has AOVs.
    #[must_use]
    pub fn aux_pixel(&self, x: u32, y: u32) -> Option<&AuxSum> {
        self.aux.get(y as usize * self.width as usize + x as usize)
    }

    /// Number of samples dropped because they were NaN or infinite.
    #[must_use]
    pub fn non_finite_samples(&self) -> u64 {
        self.non_finite
    }

    /// Copy a tile film into this film with its top-left corner at `(x0, y0)`, adding to what is
    /// there.
    ///
    /// # Panics
    /// If the tile does not fit, or one of the films has AOVs and the other not.
    pub fn add_tile(&mut self, x0: u32, y0: u32, tile: &Film) {
        assert!(
            x0 + tile.width <= self.width && y0 + tile.height <= self.height,
            "tile outside film"
        );
        assert_eq!(
            self.has_aux(),
            tile.has_aux(),
            "films with and without AOVs"
        );
        for ty in 0..tile.height {
            let row = (ty * tile.width) as usize..((ty + 1) * tile.width) as usize;
            let start = ((y0 + ty) * self.width + x0) as usize;
            let dst = start..start + tile.width as usize;
            for (d, s) in self.pixels[dst.clone()]
                .iter_mut()
                .zip(&tile.pixels[row.clone()])
            {
                d.merge(s);
            }
            if tile.has_aux() {
                for (d, s) in self.aux[dst].iter_mut().zip(&tile.aux[row]) {
                    d.merge(s);
                }
            }
        }
        self.non_finite += tile.non_finite;
        self.saturated += tile.saturated;
        self.clamped += tile.clamped;
    }

    /// Add another render of the same image (for example another range of sample indices).
    /// Because sums are fixed point, merging is exact and order-independent.
    ///
    /// # Panics
    /// If the sizes differ, or one film has AOVs and the other not.
    pub fn merge(&mut self, other: &Film) {
        assert_eq!(
            (self.width, self.height),
            (other.width, other.height),
            "films of different sizes"
        );
        assert_eq!(
            self.has_aux(),
            other.has_aux(),
            "films with and without AOVs"
        );
        for (d, s) in self.pixels.iter_mut().zip(&other.pixels) {
            d.merge(s);
        }
        for (d, s) in self.aux.iter_mut().zip(&other.aux) {
            d.merge(s);
        }
        self.non_finite = self.non_finite.saturating_add(other.non_finite);
        self.saturated = self.saturated.saturating_add(other.saturated);
        self.clamped = self.clamped.saturating_add(other.clamped);
    }

    /// The mean of each pixel's samples.
    #[must_use]
    pub fn to_image(&self) -> Image {
        let data = self
            .pixels
            .iter()
            .flat_map(|p| p.mean().to_array())
            .collect();
        Image::from_rgb(self.width, self.height, data).expect("film and image sizes agree")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fixed_point_is_exact_for_ordinary_values() {
        for v in [
            0.0f32,
            1.0,
            -1.0,
            0.1,
            3.0e7,
            1.5e-12,
            -7.25,
            65504.0,
            f32::MIN_POSITIVE,
        ] {
            let back = from_fixed(to_fixed(v));
            let expected = if v.abs() < 2f32.powi(-41) {
                (back - v as f64).abs() < 2f64.powi(-64)
            } else {
                back == v as f64
            };
            assert!(expected, "{v} -> {back}");
        }
        assert_eq!(to_fixed(-0.0), 0);
        assert_eq!(to_fixed(1e30), i128::MAX >> 1);
        assert_eq!(to_fixed(-1e30), -(i128::MAX >> 1));
    }

    #[test]
    fn merging_ranges_equals_one_pass() {
        let samples: Vec<Rgb> = (0..100)
            .map(|i| Rgb::new(0.1 * i as f32, 1.0 / (i + 1) as f32, 1e3 / (i as f32 + 0.3)))
            .collect();
        let mut all = Film::new(1, 1);
        for s in &samples {
            all.add_sample(0, 0, *s);
        }
        let (mut a, mut b) = (Film::new(1, 1), Film::new(1, 1));
        for s in &samples[..37] {
            a.add_sample(0, 0, *s);
        }
        for s in &samples[37..] {
            b.add_sample(0, 0, *s);
        }
        b.merge(&a);
        assert_eq!(all, b);
        assert_eq!(all.to_image(), b.to_image());
    }

    #[test]
    fn saturating_samples_are_counted() {
        let mut f = Film::new(2, 1);
        f.add_sample(0, 0, Rgb::splat(1e18));
        assert_eq!(f.saturated_samples(), 0, "1e18 fits the fixed-point sums");
        f.add_sample(0, 0, Rgb::new(1e30, 0.0, 0.0));
        f.add_sample(1, 0, Rgb::splat(f32::MAX));
        assert_eq!(f.saturated_samples(), 2);
        let mut g = Film::new(2, 1);
        g.merge(&f);
        g.merge(&f);
        assert_eq!(g.saturated_samples(), 4, "merges add the counts");
        // Counters read from files may be anything: they saturate instead of wrapping.
        let huge = Film::from_parts(1, 1, vec![PixelSum::default()], u64::MAX, u64::MAX);
        let mut h = huge.clone();
        h.merge(&huge);
        assert_eq!(
            (h.non_finite_samples(), h.clamped_samples()),
            (u64::MAX, u64::MAX)
        );
    }

    #[test]
    fn non_finite_samples_are_dropped_and_counted() {
        let mut f = Film::new(2, 1);
        f.add_sample(0, 0, Rgb::splat(1.0));
        f.add_sample(0, 0, Rgb::new(f32::NAN, 0.0, 0.0));
        f.add_sample(1, 0, Rgb::new(0.0, f32::INFINITY, 0.0));
        assert_eq!(f.non_finite_samples(), 2);
        assert_eq!(f.pixel(0, 0).count(), 2);
        let img = f.to_image();
        assert_eq!(img.get(0, 0), Rgb::splat(0.5));
        assert_eq!(img.get(1, 0), Rgb::BLACK);
    }

    #[test]
    fn aux_sums_are_exact_and_merge_like_the_colour() {
        let samples: Vec<(Rgb, Vec3)> = (0..50)
            .map(|i| {
                let t = i as f32 * 0.37;
                (
                    Rgb::new(t.sin().abs(), 0.3, 2.0),
                    Vec3::new(t.cos(), -t.sin(), 0.0),
                )
            })
            .collect();
        let add = |film: &mut Film, range: std::ops::Range<usize>| {
            for &(a, n) in &samples[range] {
                film.add_sample(0, 0, Rgb::WHITE);
                film.add_aux(0, 0, a, n);
            }
        };
        let mut all = Film::with_aux(1, 1);
        add(&mut all, 0..50);
        let (mut a, mut b) = (Film::with_aux(1, 1), Film::with_aux(1, 1));
        add(&mut a, 0..13);
        add(&mut b, 13..50);
        b.merge(&a);
        assert_eq!(all, b);
        let albedo = all.albedo_image().unwrap().get(0, 0);
        let normal = all.normal_image().unwrap().get(0, 0);
        let mean = |f: &dyn Fn(&(Rgb, Vec3)) -> f32| samples.iter().map(f).sum::<f32>() / 50.0;
        assert!((albedo.r - mean(&|s| s.0.r)).abs() < 1e-6);
        assert_eq!(albedo.b, 1.0, "albedo is clamped to 1");
        assert!((normal.r - mean(&|s| s.1.x)).abs() < 1e-6);
        assert!((normal.g - mean(&|s| s.1.y)).abs() < 1e-6);
        assert!(Film::new(1, 1).albedo_image().is_none());
    }

    #[test]
    fn tiles_land_where_they_belong() {
        let mut film = Film::new(4, 4);
        let mut tile = Film::new(2, 2);
        tile.add_sample(1, 0, Rgb::splat(3.0));
        film.add_tile(2, 1, &tile);
        assert_eq!(film.to_image().get(3, 1), Rgb::splat(3.0));
        assert_eq!(film.pixel(3, 1).count(), 1);
        assert_eq!(film.pixel(2, 1).count(), 0);
    }
}
