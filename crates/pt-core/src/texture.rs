//! Image textures: linear RGB(A) images looked up by surface coordinates, with glTF's wrap modes
//! and filters, and [`TextureMap`]: a texture as a material uses it (which coordinate set, what
//! transform).

use std::sync::Arc;

use glam::{Affine2, Vec2};

use crate::color::Rgb;
use crate::image::Image;
use crate::material::MaterialContext;

/// How coordinates outside `[0, 1)` map onto the image (glTF's sampler `wrapS`/`wrapT`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Wrap {
    /// The image tiles the plane (the default).
    #[default]
    Repeat,
    /// Coordinates are clamped to the image: the edge texels extend outward.
    ClampToEdge,
    /// The image tiles the plane, every other copy mirrored.
    MirroredRepeat,
}

impl Wrap {
    /// Texel index `i` (possibly outside `0..n`) wrapped into `0..n`.
    #[inline]
    fn texel(self, i: i64, n: u32) -> u32 {
        let n = i64::from(n);
        (match self {
            Self::Repeat => i.rem_euclid(n),
            Self::ClampToEdge => i.clamp(0, n - 1),
            Self::MirroredRepeat => {
                let k = i.rem_euclid(2 * n);
                if k < n { k } else { 2 * n - 1 - k }
            }
        }) as u32
    }
}

/// How a texture is filtered between texels.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Filter {
    /// The nearest texel.
    Nearest,
    /// Bilinear between the four nearest texel centres (the default).
    #[default]
    Linear,
}

/// How a texture is sampled: wrap mode per axis and filter.
///
/// A path tracer averages many samples per pixel, which filters minified textures at the pixel
/// (without mipmaps or ray differentials); the one filter here is what a texel looks like up
/// close. pt-scene maps glTF's `magFilter` to it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Sampling {
    /// Wrap mode along `u` (glTF's `wrapS`).
    pub wrap_u: Wrap,
    /// Wrap mode along `v` (glTF's `wrapT`).
    pub wrap_v: Wrap,
    /// Filter.
    pub filter: Filter,
}

/// A linear-RGB image texture with an optional alpha channel, sampled with a wrap mode per axis
/// and a filter ([`Sampling`]; by default repeat and bilinear).
///
/// Coordinates follow glTF: `(0, 0)` is the top-left corner of the image, `v` grows downward.
/// [`Texture::flip_v`] makes `v` grow upward (OBJ, where `(0, 0)` is the bottom-left corner).
/// Colour images must be decoded from sRGB to linear before they become textures (pt-scene's
/// loaders do); data images (roughness, metalness, normals) are used as stored.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    image: Image,
    alpha: Option<Box<[f32]>>,
    flip_v: bool,
    sampling: Sampling,
}

impl Texture {
    /// A texture from a linear image. An empty image evaluates to black.
    #[must_use]
    pub fn new(image: Image) -> Self {
        Self {
            image,
            alpha: None,
            flip_v: false,
            sampling: Sampling::default(),
        }
    }

    /// The same texture with `v` measured from the bottom of the image.
    #[must_use]
    pub fn flip_v(mut self) -> Self {
        self.flip_v = true;
        self
    }

    /// The same texture sampled as `sampling` says.
    #[must_use]
    pub fn with_sampling(mut self, sampling: Sampling) -> Self {
        self.sampling = sampling;
        self
    }

    /// The same texture with an alpha channel (coverage in `[0, 1]`, one value per texel, row
    /// by row like the image). `None` when the count does not match the image.
    #[must_use]
    pub fn with_alpha(mut self, alpha: Vec<f32>) -> Option<Self> {
        let n = self.image.width() as usize * self.image.height() as usize;
        if alpha.len() != n {
            return None;
        }
        self.alpha = Some(alpha.into_iter().map(|a| a.clamp(0.0, 1.0)).collect());
        Some(self)
    }

    /// The image.
    #[must_use]
    pub fn image(&self) -> &Image {
        &self.image
    }

    /// How the texture is sampled.
    #[must_use]
    pub fn sampling(&self) -> Sampling {
        self.sampling
    }

    /// True when the texture has an alpha channel.
    #[must_use]
    pub fn has_alpha(&self) -> bool {
        self.alpha.is_some()
    }

    /// The texels and weights that filtering at `uv` combines: up to four (index, weight).
    #[inline]
    fn footprint(&self, uv: Vec2) -> Option<[(usize, f32); 4]> {
        let (w, h) = (self.image.width(), self.image.height());
        if w == 0 || h == 0 || !uv.is_finite() {
            return None;
        }
        let v = if self.flip_v { 1.0 - uv.y } else { uv.y };
        let s = self.sampling;
        // Coordinates far outside [0, 1) lose their fraction in f32; reduce them first (the
        // period of every wrap mode divides 2).
        let reduce = |t: f32| {
            if t.abs() > 1024.0 {
                t.rem_euclid(2.0)
            } else {
                t
            }
        };
        let x = reduce(uv.x) * w as f32 - 0.5;
        let y = reduce(v) * h as f32 - 0.5;
        let at = |xi: i64, yi: i64| {
            let (tx, ty) = (s.wrap_u.texel(xi, w), s.wrap_v.texel(yi, h));
            ty as usize * w as usize + tx as usize
        };
        match s.filter {
            Filter::Nearest => {
                let (xi, yi) = ((x + 0.5).floor() as i64, (y + 0.5).floor() as i64);
                Some([(at(xi, yi), 1.0), (0, 0.0), (0, 0.0), (0, 0.0)])
            }
            Filter::Linear => {
                let (x0, y0) = (x.floor(), y.floor());
                let (fx, fy) = (x - x0, y - y0);
                let (xa, ya) = (x0 as i64, y0 as i64);
                Some([
                    (at(xa, ya), (1.0 - fx) * (1.0 - fy)),
                    (at(xa + 1, ya), fx * (1.0 - fy)),
                    (at(xa, ya + 1), (1.0 - fx) * fy),
                    (at(xa + 1, ya + 1), fx * fy),
                ])
            }
        }
    }

    /// The filtered colour at `uv`.
    #[must_use]
    pub fn eval(&self, uv: Vec2) -> Rgb {
        let Some(taps) = self.footprint(uv) else {
            return Rgb::BLACK;
        };
        let data = self.image.as_slice();
        let mut c = Rgb::BLACK;
        for (i, wt) in taps {
            if wt != 0.0 {
                c += Rgb::new(data[3 * i], data[3 * i + 1], data[3 * i + 2]) * wt;
            }
        }
        c
    }

    /// The filtered alpha at `uv`: 1 where the texture has no alpha channel.
    #[must_use]
    pub fn eval_alpha(&self, uv: Vec2) -> f32 {
        let Some(alpha) = &self.alpha else {
            return 1.0;
        };
        let Some(taps) = self.footprint(uv) else {
            return 1.0;
        };
        taps.iter().map(|&(i, wt)| alpha[i] * wt).sum()
    }
}

/// A texture as a material reads it: which texture-coordinate set, transformed how
/// (glTF's `texCoord` and `KHR_texture_transform`).
#[derive(Clone, Debug, PartialEq)]
pub struct TextureMap {
    /// The texture.
    pub texture: Arc<Texture>,
    /// The texture-coordinate set (glTF's `TEXCOORD_<n>`); sets other than 0 are read from
    /// [`MaterialContext::attributes`].
    pub uv_set: usize,
    /// Applied to the coordinates before the lookup (identity by default).
    pub transform: Affine2,
}

impl TextureMap {
    /// The texture on coordinate set 0, untransformed.
    #[must_use]
    pub fn new(texture: Arc<Texture>) -> Self {
        Self {
            texture,
            uv_set: 0,
            transform: Affine2::IDENTITY,
        }
    }

    /// The same map on coordinate set `set`.
    #[must_use]
    pub fn with_uv_set(mut self, set: usize) -> Self {
        self.uv_set = set;
        self
    }

    /// The same map with the coordinates transformed by `transform`.
    #[must_use]
    pub fn with_transform(mut self, transform: Affine2) -> Self {
        self.transform = transform;
        self
    }

    /// True when evaluating it reads [`MaterialContext::attributes`] (a set other than 0).
    #[must_use]
    pub fn reads_attributes(&self) -> bool {
        self.uv_set != 0
    }

    /// The coordinates this map looks up at `ctx`.
    #[inline]
    #[must_use]
    pub fn uv(&self, ctx: &MaterialContext) -> Vec2 {
        let uv = if self.uv_set == 0 {
            ctx.uv
        } else {
            ctx.attributes
                .uv
                .get(self.uv_set)
                .copied()
                .unwrap_or(Vec2::ZERO)
        };
        if self.transform == Affine2::IDENTITY {
            uv
        } else {
            self.transform.transform_point2(uv)
        }
    }

    /// The filtered colour at `ctx`.
    #[inline]
    #[must_use]
    pub fn eval(&self, ctx: &MaterialContext) -> Rgb {
        self.texture.eval(self.uv(ctx))
    }

    /// The filtered alpha at `ctx` (1 without an alpha channel).
    #[inline]
    #[must_use]
    pub fn eval_alpha(&self, ctx: &MaterialContext) -> f32 {
        self.texture.eval_alpha(self.uv(ctx))
    }
}

impl From<Arc<Texture>> for TextureMap {
    fn from(texture: Arc<Texture>) -> Self {
        Self::new(texture)
    }
}

impl From<Texture> for TextureMap {
    fn from(texture: Texture) -> Self {
        Self::new(Arc::new(texture))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bilinear_repeat_and_flip() {
        let mut img = Image::new(2, 2);
        img.set(0, 0, Rgb::splat(1.0));
        img.set(1, 0, Rgb::splat(2.0));
        img.set(0, 1, Rgb::splat(3.0));
        img.set(1, 1, Rgb::splat(4.0));
        let t = Texture::new(img);
        // Texel centres return the texel.
        assert_eq!(t.eval(Vec2::new(0.25, 0.25)), Rgb::splat(1.0));
        assert_eq!(t.eval(Vec2::new(0.75, 0.75)), Rgb::splat(4.0));
        // Half way between all four centres: the mean.
        assert_eq!(t.eval(Vec2::new(0.5, 0.5)), Rgb::splat(2.5));
        // Repeat: one period later is the same.
        assert_eq!(t.eval(Vec2::new(1.25, -0.75)), Rgb::splat(1.0));
        // Flipped: v = 0.25 is now the bottom row.
        assert_eq!(
            t.clone().flip_v().eval(Vec2::new(0.25, 0.25)),
            Rgb::splat(3.0)
        );
        assert_eq!(Texture::new(Image::new(0, 0)).eval(Vec2::ZERO), Rgb::BLACK);
        assert_eq!(t.eval(Vec2::new(f32::NAN, 0.0)), Rgb::BLACK);
    }

    /// A 4x1 ramp 0, 1, 2, 3 sampled at texel centres beyond the right edge.
    #[test]
    fn wrap_modes_and_nearest_filter() {
        let mut img = Image::new(4, 1);
        for x in 0..4 {
            img.set(x, 0, Rgb::splat(x as f32));
        }
        let at = |wrap, u: f32| {
            let s = Sampling {
                wrap_u: wrap,
                wrap_v: Wrap::Repeat,
                filter: Filter::Nearest,
            };
            Texture::new(img.clone())
                .with_sampling(s)
                .eval(Vec2::new(u, 0.5))
                .r
        };
        // Texel centres of the next period: 1.125, 1.375, ...
        let next: Vec<f32> = (0..4).map(|i| 1.125 + 0.25 * i as f32).collect();
        let values = |w| next.iter().map(|&u| at(w, u)).collect::<Vec<_>>();
        assert_eq!(values(Wrap::Repeat), [0.0, 1.0, 2.0, 3.0]);
        assert_eq!(values(Wrap::MirroredRepeat), [3.0, 2.0, 1.0, 0.0]);
        assert_eq!(values(Wrap::ClampToEdge), [3.0, 3.0, 3.0, 3.0]);
        assert_eq!(at(Wrap::ClampToEdge, -5.0), 0.0);
        // Nearest: no blending between centres.
        assert_eq!(at(Wrap::Repeat, 0.3), 1.0);
        // Bilinear with clamping at the edge: the edge texel, not a blend with the far side.
        let clamp = Sampling {
            wrap_u: Wrap::ClampToEdge,
            ..Sampling::default()
        };
        let t = Texture::new(img.clone()).with_sampling(clamp);
        assert_eq!(t.eval(Vec2::new(0.999, 0.5)).r, 3.0);
        let t = Texture::new(img.clone());
        assert!((t.eval(Vec2::new(0.999, 0.5)).r - 1.5).abs() < 0.1);
        // Huge coordinates keep their place in the period.
        assert_eq!(at(Wrap::Repeat, 1e6 + 0.125), 0.0);
    }

    #[test]
    fn alpha_channel_and_maps() {
        let t = Texture::new(Image::new(2, 1))
            .with_alpha(vec![0.0, 1.0])
            .unwrap();
        assert_eq!(t.eval_alpha(Vec2::new(0.25, 0.5)), 0.0);
        assert_eq!(t.eval_alpha(Vec2::new(0.75, 0.5)), 1.0);
        assert!(
            Texture::new(Image::new(2, 1))
                .with_alpha(vec![1.0])
                .is_none()
        );
        assert_eq!(Texture::new(Image::new(2, 1)).eval_alpha(Vec2::ZERO), 1.0);
        // A map on set 1 with a transform that shifts u by half the image.
        let map = TextureMap::from(t)
            .with_uv_set(1)
            .with_transform(Affine2::from_translation(Vec2::new(0.5, 0.0)));
        assert!(map.reads_attributes());
        let mut ctx = MaterialContext::new(
            glam::Vec3::ZERO,
            glam::Vec3::Z,
            glam::Vec3::Z,
            glam::Vec3::Z,
            Vec2::new(0.75, 0.5),
        );
        ctx.attributes.uv[1] = Vec2::new(0.25, 0.5);
        assert_eq!(map.eval_alpha(&ctx), 1.0);
    }
}
