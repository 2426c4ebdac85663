//! Image textures: linear RGB images looked up by surface coordinates.

use glam::Vec2;

use crate::color::Rgb;
use crate::image::Image;

/// A linear-RGB image texture with bilinear filtering and repeat wrapping.
///
/// Coordinates follow glTF: `(0, 0)` is the top-left corner of the image, `v` grows downward.
/// [`Texture::flip_v`] makes `v` grow upward (OBJ, where `(0, 0)` is the bottom-left corner).
/// Colour images must be decoded from sRGB to linear before they become textures (pt-scene's
/// loaders do); data images (roughness, metalness) are used as stored.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    image: Image,
    flip_v: bool,
}

impl Texture {
    /// A texture from a linear image. An empty image evaluates to black.
    #[must_use]
    pub fn new(image: Image) -> Self {
        Self {
            image,
            flip_v: false,
        }
    }

    /// The same texture with `v` measured from the bottom of the image.
    #[must_use]
    pub fn flip_v(mut self) -> Self {
        self.flip_v = true;
        self
    }

    /// The image.
    #[must_use]
    pub fn image(&self) -> &Image {
        &self.image
    }

    /// The filtered value at `uv` (repeat wrapping, bilinear between texel centres).
    #[must_use]
    pub fn eval(&self, uv: Vec2) -> Rgb {
        let (w, h) = (self.image.width(), self.image.height());
        if w == 0 || h == 0 || !uv.is_finite() {
            return Rgb::BLACK;
        }
        let v = if self.flip_v { 1.0 - uv.y } else { uv.y };
        let x = uv.x.rem_euclid(1.0) * w as f32 - 0.5;
        let y = v.rem_euclid(1.0) * h as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let wrap = |i: f32, n: u32| (i as i64).rem_euclid(i64::from(n)) as u32;
        let (xa, xb) = (wrap(x0, w), wrap(x0 + 1.0, w));
        let (ya, yb) = (wrap(y0, h), wrap(y0 + 1.0, h));
        let top = self.image.get(xa, ya) * (1.0 - fx) + self.image.get(xb, ya) * fx;
        let bottom = self.image.get(xa, yb) * (1.0 - fx) + self.image.get(xb, yb) * fx;
        top * (1.0 - fy) + bottom * fy
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
}
