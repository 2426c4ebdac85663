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
//!   piecewise-constant 2D distribution over the texels with weights `filtered luminance *
//!   sin(theta)`, so `pdf_li` is exact: `pdf(d) = p(u, v) / (2 pi^2 sin theta)`.
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
//! Each has an intensity `scale` and a rotation (map frame to world). Sample points for shadow
//! rays are placed beyond the scene's bounding sphere, whose radius also gives the power
//! estimate `Phi = pi R^2 * integral of L over the sphere` used to choose between the
//! environment and area lights.

use std::f32::consts::PI;
use std::fmt;

use glam::{Mat3, Vec2, Vec3};
use pt_accel::{Bounds3, Ray};

use crate::color::Rgb;
use crate::distribution::{Distribution1D, Distribution2D};
use crate::image::Image;
use crate::light::{Light, LightFlags, LightSample, LightSampleContext};
use crate::sampling::{sample_uniform_sphere, uniform_sphere_pdf};

/// A light (environment map, punctual light) that cannot be made from the given data.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum LightError {
    /// The image has no texels, or cube faces are not square or not all the same size.
    BadSize(String),
    /// A texel is negative or not finite (the first one found).
    BadTexel {
        /// Which image (face name for cube maps).
        image: &'static str,
        /// Column.
        x: u32,
        /// Row.
        y: u32,
    },
    /// The intensity scale or rotation is not usable.
    BadParameter(String),
}

impl fmt::Display for LightError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::BadSize(s) => write!(f, "environment map: {s}"),
            Self::BadTexel { image, x, y } => write!(
                f,
                "environment map: texel ({x}, {y}) of {image} is negative or not finite"
            ),
            Self::BadParameter(s) => write!(f, "light: {s}"),
        }
    }
}

impl std::error::Error for LightError {}

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

/// The part every environment light shares: orientation, scale and the scene's bounding sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Placement {
    /// Map frame to world.
    to_world: Mat3,
    /// World to map frame.
    to_map: Mat3,
    scale: f32,
    center: Vec3,
    radius: f32,
}

impl Placement {
    fn new() -> Self {
        Self {
            to_world: Mat3::IDENTITY,
            to_map: Mat3::IDENTITY,
            scale: 1.0,
            center: Vec3::ZERO,
            radius: 1.0,
        }
    }

    fn set_rotation(&mut self, rotation: Mat3) -> Result<(), LightError> {
        let orthonormal = (rotation.transpose() * rotation - Mat3::IDENTITY)
            .to_cols_array()
            .iter()
            .all(|v| v.abs() < 1e-4)
            && (rotation.determinant() - 1.0).abs() < 1e-4;
        if !orthonormal {
            return Err(LightError::BadParameter(format!(
                "rotation must be a proper rotation matrix, got {rotation}"
            )));
        }
        self.to_world = rotation;
        self.to_map = rotation.transpose();
        Ok(())
    }

    /// Set the scale of a map whose brightest radiance is `brightest`: refused when the scaled
    /// radiance would not be finite (`--env-intensity 3e38` made every lookup infinite).
    fn set_scale(&mut self, scale: f32, brightest: f32) -> Result<(), LightError> {
        if !(scale.is_finite() && scale >= 0.0) {
            return Err(LightError::BadParameter(format!(
                "intensity scale must be finite and >= 0, got {scale}"
            )));
        }
        if !(brightest * scale).is_finite() {
            return Err(LightError::BadParameter(format!(
                "intensity scale {scale} makes the brightest radiance of the map ({brightest}) \
                 overflow"
            )));
        }
        self.scale = scale;
        Ok(())
    }

    fn preprocess(&mut self, bounds: &Bounds3) {
        if bounds.min.is_finite() && bounds.max.is_finite() && bounds.min.cmple(bounds.max).all() {
            self.center = (bounds.min + bounds.max) * 0.5;
            self.radius = ((bounds.max - bounds.min).length() * 0.5).max(1e-3);
        }
    }

    /// A light sample toward world direction `wi` from `ctx`, with a target point beyond the
    /// scene.
    fn sample(&self, ctx: &LightSampleContext, wi: Vec3, li: Rgb, pdf: f32) -> LightSample {
        LightSample {
            li: li * self.scale,
            wi,
            pdf,
            point: ctx.point_beyond(wi, self.center, self.radius),
        }
    }

    /// Flux through the scene's bounding disk for a given integral of radiance over the sphere.
    fn power(&self, integral: Rgb) -> Rgb {
        // In f64 and capped: for a scene 1e18 across, R^2 alone overflows f32, and a light of
        // infinite power would be dropped by the light sampler.
        let k = f64::from(self.scale) * std::f64::consts::PI * f64::from(self.radius).powi(2);
        let cap = |c: f32| (f64::from(c) * k).min(f64::from(f32::MAX)) as f32;
        Rgb::new(cap(integral.r), cap(integral.g), cap(integral.b))
    }
}

/// Radiance `radiance` from every direction.
#[derive(Clone, Debug, PartialEq)]
pub struct UniformEnvironment {
    radiance: Rgb,
    place: Placement,
}

impl UniformEnvironment {
    /// A uniform environment. Fails unless every channel is finite and non-negative.
    pub fn new(radiance: Rgb) -> Result<Self, LightError> {
        if !radiance.is_valid_nonnegative() {
            return Err(LightError::BadParameter(format!(
                "radiance must be finite and >= 0, got {radiance:?}"
            )));
        }
        Ok(Self {
            radiance,
            place: Placement::new(),
        })
    }

    /// The radiance.
    #[must_use]
    pub fn radiance(&self) -> Rgb {
        self.radiance
    }
}

impl Light for UniformEnvironment {
    fn flags(&self) -> LightFlags {
        LightFlags::INFINITE
    }

    fn power(&self) -> Rgb {
        self.place.power(self.radiance * (4.0 * PI))
    }

    fn sample_li(&self, ctx: &LightSampleContext, u: Vec2) -> Option<LightSample> {
        if self.radiance.is_black() {
            return None;
        }
        let wi = sample_uniform_sphere(u);
        Some(
            self.place
                .sample(ctx, wi, self.radiance, uniform_sphere_pdf()),
        )
    }

    fn pdf_li(&self, _ctx: &LightSampleContext, _wi: Vec3) -> f32 {
        if self.radiance.is_black() {
            0.0
        } else {
            uniform_sphere_pdf()
        }
    }

    fn le(&self, _ray: &Ray) -> Rgb {
        self.radiance
    }

    fn preprocess(&mut self, scene_bounds: &Bounds3) {
        self.place.preprocess(scene_bounds);
    }
}

/// A latitude-longitude (equirectangular) environment map, importance sampled.
#[derive(Clone, Debug, PartialEq)]
pub struct EquirectEnvironment {
    image: Image,
    distribution: Option<Distribution2D>,
    /// Sample directions uniformly instead of by the map (for variance comparisons).
    uniform_sampling: bool,
    /// Integral of radiance over the sphere.
    integral: Rgb,
    place: Placement,
}

/// Map-frame direction to `(u, v)` in `[0, 1]^2`, and `sin theta`.
#[inline]
fn equirect_uv(d: Vec3) -> (Vec2, f32) {
    let u = 0.5 + d.x.atan2(-d.z) * (0.5 / PI);
    let v = d.y.clamp(-1.0, 1.0).acos() / PI;
    let sin_theta = (d.x * d.x + d.z * d.z).sqrt();
    (Vec2::new(u.rem_euclid(1.0), v), sin_theta)
}

/// `(u, v)` to a map-frame unit direction, and `sin theta`.
#[inline]
fn equirect_dir(uv: Vec2) -> (Vec3, f32) {
    let theta = PI * uv.y;
    let phi = 2.0 * PI * (uv.x - 0.5);
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    (Vec3::new(st * sp, ct, -st * cp), st)
}

/// The bilinear interpolation between texel centres at texel-space position `p` (texel `(x, y)`
/// covers `[x, x+1) x [y, y+1)`), `texel` giving any texel, also one beyond the edges.
#[inline]
fn bilinear(p: Vec2, texel: impl Fn(i64, i64) -> Rgb) -> Rgb {
    let f = p - Vec2::splat(0.5);
    let (x0, y0) = (f.x.floor(), f.y.floor());
    let (tx, ty) = (f.x - x0, f.y - y0);
    let (x, y) = (x0 as i64, y0 as i64);
    let top = texel(x, y) * (1.0 - tx) + texel(x + 1, y) * tx;
    let bottom = texel(x, y + 1) * (1.0 - tx) + texel(x + 1, y + 1) * tx;
    top * (1.0 - ty) + bottom * ty
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

impl EquirectEnvironment {
    /// An environment from a linear-RGB latitude-longitude image (any aspect ratio; 2:1 is
    /// usual). Fails on an empty image or a negative or non-finite texel. An all-black map is
    /// allowed and emits nothing.
    pub fn new(image: Image) -> Result<Self, LightError> {
        check_texels(&image, "the equirectangular map")?;
        let (w, h) = (image.width() as usize, image.height() as usize);
        let mut map = Self {
            distribution: None,
            uniform_sampling: false,
            image,
            integral: Rgb::BLACK,
            place: Placement::new(),
        };
        let mut weights = Vec::with_capacity(w * h);
        let mut integral = Rgb::BLACK;
        for y in 0..h {
            let theta = PI * (y as f32 + 0.5) / h as f32;
            let st = theta.sin();
            // Solid angle of a texel of this row.
            let omega = (2.0 * PI / w as f32) * (PI / h as f32) * st;
            for x in 0..w {
                let (xi, yi) = (x as i64, y as i64);
                let filtered = filter_3x3(|dx, dy| map.texel(xi + dx, yi + dy).luminance());
                weights.push(filtered * st);
                integral += map.texel(xi, yi) * omega;
            }
        }
        map.distribution = Distribution2D::new(&weights, w, h);
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
    #[inline]
    fn texel(&self, x: i64, y: i64) -> Rgb {
        let (w, h) = (
            i64::from(self.image.width()),
            i64::from(self.image.height()),
        );
        self.image
            .get(x.rem_euclid(w) as u32, y.clamp(0, h - 1) as u32)
    }

    /// Radiance at `uv`, interpolated bilinearly between texel centres.
    #[inline]
    fn lookup(&self, uv: Vec2) -> Rgb {
        let size = Vec2::new(self.image.width() as f32, self.image.height() as f32);
        bilinear(uv * size, |x, y| self.texel(x, y))
    }

    /// Radiance arriving from world direction `wi` (unit), scale included.
    #[must_use]
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

    fn sample_li(&self, ctx: &LightSampleContext, u: Vec2) -> Option<LightSample> {
        let dist = self.distribution.as_ref()?;
        if self.uniform_sampling {
            let wi = sample_uniform_sphere(u);
            let (uv, _) = equirect_uv(self.place.to_map * wi);
            let li = self.lookup(uv);
            return Some(self.place.sample(ctx, wi, li, uniform_sphere_pdf()));
        }
        let (uv, pdf_uv) = dist.sample_continuous(u);
        let (d, sin_theta) = equirect_dir(uv);
        if sin_theta <= 0.0 || pdf_uv <= 0.0 {
            return None;
        }
        let pdf = pdf_uv / (2.0 * PI * PI * sin_theta);
        let wi = (self.place.to_world * d).normalize();
        Some(self.place.sample(ctx, wi, self.lookup(uv), pdf))
    }

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
        dist.pdf(uv) / (2.0 * PI * PI * sin_theta)
    }

    fn le(&self, ray: &Ray) -> Rgb {
        self.radiance(ray.dir.normalize())
    }

    fn preprocess(&mut self, scene_bounds: &Bounds3) {
        self.place.preprocess(scene_bounds);
    }
}

/// Cube face names in storage order.
pub const CUBE_FACES: [&str; 6] = ["px", "nx", "py", "ny", "pz", "nz"];

/// A direction in the OpenGL cube-map frame to `(face, s, t)` with `s, t` in `[0, 1]`, and the
/// major-axis magnitude `|ma|` of the (not necessarily unit) direction.
#[must_use]
pub fn cube_face_st(d: Vec3) -> (usize, Vec2, f32) {
    let a = d.abs();
    let (face, ma, sc, tc) = if a.x >= a.y && a.x >= a.z {
        if d.x > 0.0 {
            (0, a.x, -d.z, -d.y)
        } else {
            (1, a.x, d.z, -d.y)
        }
    } else if a.y >= a.z {
        if d.y > 0.0 {
            (2, a.y, d.x, d.z)
        } else {
            (3, a.y, d.x, -d.z)
        }
    } else if d.z > 0.0 {
        (4, a.z, d.x, -d.y)
    } else {
        (5, a.z, -d.x, -d.y)
    };
    let st = Vec2::new(0.5 * (sc / ma + 1.0), 0.5 * (tc / ma + 1.0));
    (face, st.clamp(Vec2::ZERO, Vec2::ONE), ma)
}

/// `(face, s, t)` to the point on the cube `[-1, 1]^3` (OpenGL frame): the inverse of
/// [`cube_face_st`].
#[must_use]
pub fn cube_face_point(face: usize, st: Vec2) -> Vec3 {
    let sc = 2.0 * st.x - 1.0;
    let tc = 2.0 * st.y - 1.0;
    match face {
        0 => Vec3::new(1.0, -tc, -sc),
        1 => Vec3::new(-1.0, -tc, sc),
        2 => Vec3::new(sc, 1.0, tc),
        3 => Vec3::new(sc, -1.0, -tc),
        4 => Vec3::new(sc, -tc, 1.0),
        _ => Vec3::new(-sc, -tc, -1.0),
    }
}

/// Solid angle subtended by the rectangle `[x0, x1] x [y0, y1]` of the plane at distance 1.
fn rect_solid_angle(x0: f32, x1: f32, y0: f32, y1: f32) -> f32 {
    let f = |x: f32, y: f32| (x * y).atan2((x * x + y * y + 1.0).sqrt());
    f(x1, y1) - f(x0, y1) - f(x1, y0) + f(x0, y0)
}

/// A six-face cube map environment (the report's sky box), importance sampled.
#[derive(Clone, Debug, PartialEq)]
pub struct CubemapEnvironment {
    faces: [Image; 6],
    size: u32,
    distribution: Option<Distribution1D>,
    integral: Rgb,
    place: Placement,
}

/// World/map-frame direction to the OpenGL cube frame (x mirrored, see the module docs).
#[inline]
fn to_gl(d: Vec3) -> Vec3 {
    Vec3::new(-d.x, d.y, d.z)
}

impl CubemapEnvironment {
    /// A cube map from faces in the order `+x, -x, +y, -y, +z, -z` ([`CUBE_FACES`]), linear RGB,
    /// square and all the same size. Fails otherwise, or on a negative or non-finite texel.
    pub fn new(faces: [Image; 6]) -> Result<Self, LightError> {
        let size = faces[0].width();
        for (f, name) in faces.iter().zip(CUBE_FACES) {
            if f.width() != size || f.height() != size {
                return Err(LightError::BadSize(format!(
                    "cube faces must be square and the same size: {} is {}x{}, {} is {size}x{size}",
                    name,
                    f.width(),
                    f.height(),
                    CUBE_FACES[0]
                )));
            }
            check_texels(f, name)?;
        }
        let n = size as usize;
        let texel = 2.0 / size as f32;
        let mut omegas = Vec::with_capacity(n * n);
        for row in 0..n {
            for col in 0..n {
                let (x0, y0) = (-1.0 + col as f32 * texel, -1.0 + row as f32 * texel);
                omegas.push(rect_solid_angle(x0, x0 + texel, y0, y0 + texel));
            }
        }
        let mut map = Self {
            faces,
            size,
            distribution: None,
            integral: Rgb::BLACK,
            place: Placement::new(),
        };
        let mut weights = Vec::with_capacity(6 * n * n);
        let mut integral = Rgb::BLACK;
        for face in 0..6 {
            for row in 0..n {
                for col in 0..n {
                    let (c, r) = (col as i64, row as i64);
                    let filtered = filter_3x3(|dx, dy| map.fetch(face, c + dx, r + dy).luminance());
                    let omega = omegas[row * n + col];
                    weights.push(filtered * omega);
                    integral += map.faces[face].get(col as u32, row as u32) * omega;
                }
            }
        }
        map.distribution = Distribution1D::new(&weights);
        map.integral = integral;
        Ok(map)
    }

    /// Rotate the map: `rotation` takes map-frame directions to world directions.
    pub fn with_rotation(mut self, rotation: Mat3) -> Result<Self, LightError> {
        self.place.set_rotation(rotation)?;
        Ok(self)
    }

    /// Multiply the radiance by `scale` (finite, `>= 0`).
    pub fn with_scale(mut self, scale: f32) -> Result<Self, LightError> {
        let brightest = self
            .faces
            .iter()
            .flat_map(Image::pixels)
            .fold(0.0f32, |m, c| m.max(c.max_component()));
        self.place.set_scale(scale, brightest)?;
        Ok(self)
    }

    /// Face size in texels.
    #[must_use]
    pub fn size(&self) -> u32 {
        self.size
    }

    /// The texel `(face, column, row)` that world direction `wi` sees, and `|ma|`.
    #[inline]
    fn texel(&self, wi: Vec3) -> (usize, u32, u32, f32) {
        let (face, st, ma) = cube_face_st(to_gl(self.place.to_map * wi));
        let n = self.size;
        let col = ((st.x * n as f32) as u32).min(n - 1);
        let row = ((st.y * n as f32) as u32).min(n - 1);
        (face, col, row, ma)
    }

    /// Texel `(col, row)` of `face`, or, for a position up to one texel beyond the face's edge,
    /// the texel of the neighbouring face that its centre projects to (so that interpolation
    /// crosses the seams).
    #[inline]
    fn fetch(&self, face: usize, col: i64, row: i64) -> Rgb {
        let n = i64::from(self.size);
        if (0..n).contains(&col) && (0..n).contains(&row) {
            return self.faces[face].get(col as u32, row as u32);
        }
        let st = Vec2::new((col as f32 + 0.5) / n as f32, (row as f32 + 0.5) / n as f32);
        let (f, st, _) = cube_face_st(cube_face_point(face, st));
        let nf = n as f32;
        let c = ((st.x * nf) as i64).clamp(0, n - 1);
        let r = ((st.y * nf) as i64).clamp(0, n - 1);
        self.faces[f].get(c as u32, r as u32)
    }

    /// Radiance at `st` on `face`, interpolated bilinearly between texel centres.
    #[inline]
    fn lookup(&self, face: usize, st: Vec2) -> Rgb {
        let n = self.size as f32;
        bilinear(st * n, |x, y| self.fetch(face, x, y))
    }

    /// Radiance arriving from world direction `wi` (unit), scale included.
    #[must_use]
    pub fn radiance(&self, wi: Vec3) -> Rgb {
        let (face, st, _) = cube_face_st(to_gl(self.place.to_map * wi));
        self.lookup(face, st) * self.place.scale
    }
}

impl Light for CubemapEnvironment {
    fn flags(&self) -> LightFlags {
        LightFlags::INFINITE
    }

    fn power(&self) -> Rgb {
        self.place.power(self.integral)
    }

    fn sample_li(&self, ctx: &LightSampleContext, u: Vec2) -> Option<LightSample> {
        let dist = self.distribution.as_ref()?;
        let (index, pmf, ux) = dist.sample_discrete(u.x);
        if pmf <= 0.0 {
            return None;
        }
        let n = self.size as usize;
        let (face, row, col) = (index / (n * n), (index / n) % n, index % n);
        let st = Vec2::new((col as f32 + ux) / n as f32, (row as f32 + u.y) / n as f32);
        let p = cube_face_point(face, st);
        let r = p.length();
        // Uniform over the texel's area (2/n)^2 on the face, converted to solid angle.
        let texel_area = (2.0 / n as f32) * (2.0 / n as f32);
        let pdf = pmf / texel_area * r * r * r;
        let wi = (self.place.to_world * to_gl(p / r)).normalize();
        let li = self.lookup(face, st);
        Some(self.place.sample(ctx, wi, li, pdf))
    }

    fn pdf_li(&self, _ctx: &LightSampleContext, wi: Vec3) -> f32 {
        let Some(dist) = self.distribution.as_ref() else {
            return 0.0;
        };
        let (face, col, row, ma) = self.texel(wi.normalize());
        let n = self.size as usize;
        let pmf = dist.pmf(face * n * n + row as usize * n + col as usize);
        let r = 1.0 / ma;
        let texel_area = (2.0 / n as f32) * (2.0 / n as f32);
        pmf / texel_area * r * r * r
    }

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

    #[test]
    fn cube_faces_round_trip_and_tile() {
        for face in 0..6 {
            for st in [
                Vec2::new(0.1, 0.2),
                Vec2::new(0.5, 0.5),
                Vec2::new(0.9, 0.7),
            ] {
                let p = cube_face_point(face, st);
                let (f2, st2, ma) = cube_face_st(p * 3.0);
                assert_eq!(f2, face, "face of {p}");
                assert!((st2 - st).length() < 1e-6);
                assert!((ma - 3.0).abs() < 1e-5);
            }
        }
        // The OpenGL table: the centre of each face is its axis.
        let axes = [
            Vec3::X,
            Vec3::NEG_X,
            Vec3::Y,
            Vec3::NEG_Y,
            Vec3::Z,
            Vec3::NEG_Z,
        ];
        for (face, axis) in axes.iter().enumerate() {
            assert_eq!(cube_face_point(face, Vec2::splat(0.5)), *axis);
        }
        // Cross layout `nx pz px nz`: the right edge of pz meets the left edge of px, the right
        // edge of px the left edge of nz; py's bottom edge meets pz's top edge.
        let e = 1e-4;
        let pairs = [
            ((4, Vec2::new(1.0, 0.3)), (0, Vec2::new(0.0, 0.3))),
            ((0, Vec2::new(1.0, 0.6)), (5, Vec2::new(0.0, 0.6))),
            ((1, Vec2::new(1.0, 0.6)), (4, Vec2::new(0.0, 0.6))),
            ((2, Vec2::new(0.4, 1.0)), (4, Vec2::new(0.4, 0.0))),
            ((4, Vec2::new(0.4, 1.0)), (3, Vec2::new(0.4, 0.0))),
        ];
        for ((fa, a), (fb, b)) in pairs {
            let pa = cube_face_point(fa, a).normalize();
            let pb = cube_face_point(fb, b).normalize();
            assert!((pa - pb).length() < e, "faces {fa} and {fb} do not meet");
        }
        // Texel solid angles cover the sphere.
        let n = 64;
        let t = 2.0 / n as f32;
        let mut sum = 0.0f64;
        for r in 0..n {
            for c in 0..n {
                let x0 = -1.0 + c as f32 * t;
                let y0 = -1.0 + r as f32 * t;
                sum += f64::from(rect_solid_angle(x0, x0 + t, y0, y0 + t));
            }
        }
        assert!((6.0 * sum - 4.0 * std::f64::consts::PI).abs() < 1e-4);
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
}
