//! Linear RGB color with sRGB / Rec. 709 primaries.

use std::ops::{Add, AddAssign, Div, DivAssign, Index, Mul, MulAssign, Sub};

/// A linear RGB triple (sRGB / Rec. 709 primaries, no transfer curve). Used for radiance,
/// reflectance and throughput alike.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Rgb {
    /// Red.
    pub r: f32,
    /// Green.
    pub g: f32,
    /// Blue.
    pub b: f32,
}

impl Rgb {
    /// All zero.
    pub const BLACK: Self = Self::splat(0.0);
    /// All one.
    pub const WHITE: Self = Self::splat(1.0);

    /// A color from its three channels.
    #[inline]
    #[must_use]
    pub const fn new(r: f32, g: f32, b: f32) -> Self {
        Self { r, g, b }
    }

    /// The same value in every channel.
    #[inline]
    #[must_use]
    pub const fn splat(v: f32) -> Self {
        Self { r: v, g: v, b: v }
    }

    /// Relative luminance Y (Rec. 709 weights).
    #[inline]
    #[must_use]
    pub fn luminance(self) -> f32 {
        0.2126 * self.r + 0.7152 * self.g + 0.0722 * self.b
    }

    /// Largest channel.
    #[inline]
    #[must_use]
    pub fn max_component(self) -> f32 {
        self.r.max(self.g).max(self.b)
    }

    /// Smallest channel.
    #[inline]
    #[must_use]
    pub fn min_component(self) -> f32 {
        self.r.min(self.g).min(self.b)
    }

    /// Mean of the channels.
    #[inline]
    #[must_use]
    pub fn average(self) -> f32 {
        (self.r + self.g + self.b) / 3.0
    }

    /// True when every channel is exactly zero.
    #[inline]
    #[must_use]
    pub fn is_black(self) -> bool {
        // `&` rather than `&&`: three compares and no branches (this runs several times per
        // bounce, on values whose outcome the branch predictor cannot guess).
        (self.r == 0.0) & (self.g == 0.0) & (self.b == 0.0)
    }

    /// True when no channel is NaN or infinite.
    #[inline]
    #[must_use]
    pub fn is_finite(self) -> bool {
        self.r.is_finite() && self.g.is_finite() && self.b.is_finite()
    }

    /// True when every channel is finite and not negative.
    #[inline]
    #[must_use]
    pub fn is_valid_nonnegative(self) -> bool {
        self.is_finite() && self.min_component() >= 0.0
    }

    /// Channel-wise map.
    #[inline]
    #[must_use]
    pub fn map(self, f: impl Fn(f32) -> f32) -> Self {
        Self::new(f(self.r), f(self.g), f(self.b))
    }

    /// Channel-wise division that returns 0 where the divisor is 0.
    #[inline]
    #[must_use]
    pub fn safe_div(self, d: Self) -> Self {
        let q = |a: f32, b: f32| if b == 0.0 { 0.0 } else { a / b };
        Self::new(q(self.r, d.r), q(self.g, d.g), q(self.b, d.b))
    }

    /// The channels as an array.
    #[inline]
    #[must_use]
    pub fn to_array(self) -> [f32; 3] {
        [self.r, self.g, self.b]
    }

    /// Decode an 8-bit-style sRGB-encoded value in `[0, 1]` per channel to linear.
    #[must_use]
    pub fn from_srgb(r: f32, g: f32, b: f32) -> Self {
        Self::new(srgb_to_linear(r), srgb_to_linear(g), srgb_to_linear(b))
    }
}

impl From<[f32; 3]> for Rgb {
    #[inline]
    fn from(v: [f32; 3]) -> Self {
        Self::new(v[0], v[1], v[2])
    }
}

impl Index<usize> for Rgb {
    type Output = f32;
    #[inline]
    fn index(&self, i: usize) -> &f32 {
        match i {
            0 => &self.r,
            1 => &self.g,
            2 => &self.b,
            _ => panic!("Rgb channel index {i} out of range"),
        }
    }
}

macro_rules! channelwise {
    ($tr:ident, $f:ident, $op:tt, $tra:ident, $fa:ident) => {
        impl $tr for Rgb {
            type Output = Rgb;
            #[inline]
            fn $f(self, o: Rgb) -> Rgb {
                Rgb::new(self.r $op o.r, self.g $op o.g, self.b $op o.b)
            }
        }
        impl $tr<f32> for Rgb {
            type Output = Rgb;
            #[inline]
            fn $f(self, o: f32) -> Rgb {
                Rgb::new(self.r $op o, self.g $op o, self.b $op o)
            }
        }
        impl $tra for Rgb {
            #[inline]
            fn $fa(&mut self, o: Rgb) {
                *self = *self $op o;
            }
        }
        impl $tra<f32> for Rgb {
            #[inline]
            fn $fa(&mut self, o: f32) {
                *self = *self $op o;
            }
        }
    };
}

channelwise!(Add, add, +, AddAssign, add_assign);
channelwise!(Mul, mul, *, MulAssign, mul_assign);
channelwise!(Div, div, /, DivAssign, div_assign);

impl Sub for Rgb {
    type Output = Rgb;
    #[inline]
    fn sub(self, o: Rgb) -> Rgb {
        Rgb::new(self.r - o.r, self.g - o.g, self.b - o.b)
    }
}

impl Mul<Rgb> for f32 {
    type Output = Rgb;
    #[inline]
    fn mul(self, c: Rgb) -> Rgb {
        c * self
    }
}

/// The sRGB transfer function's inverse (encoded `[0, 1]` to linear).
#[inline]
#[must_use]
pub fn srgb_to_linear(v: f32) -> f32 {
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

/// [`srgb_to_linear`] of an 8-bit value `v / 255`, from a table (texture loading decodes
/// millions of them).
#[inline]
#[must_use]
pub fn srgb8_to_linear(v: u8) -> f32 {
    static TABLE: std::sync::OnceLock<[f32; 256]> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| std::array::from_fn(|i| srgb_to_linear(i as f32 / 255.0)))[v as usize]
}

/// The sRGB transfer function (linear to encoded `[0, 1]`; input clamped to `[0, 1]`).
#[inline]
#[must_use]
pub fn linear_to_srgb(v: f32) -> f32 {
    let v = v.clamp(0.0, 1.0);
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_eight_bit_table_is_the_transfer_function() {
        for v in 0..=255u8 {
            assert_eq!(srgb8_to_linear(v), srgb_to_linear(f32::from(v) / 255.0));
        }
    }

    #[test]
    fn arithmetic_and_luminance() {
        let a = Rgb::new(1.0, 2.0, 3.0);
        assert_eq!(a * 2.0, Rgb::new(2.0, 4.0, 6.0));
        assert_eq!(a * a, Rgb::new(1.0, 4.0, 9.0));
        assert_eq!(a - a, Rgb::BLACK);
        assert!((Rgb::WHITE.luminance() - 1.0).abs() < 1e-6);
        assert_eq!(a.max_component(), 3.0);
        assert!(!Rgb::new(f32::NAN, 0.0, 0.0).is_finite());
        assert_eq!(
            Rgb::new(1.0, 0.0, 2.0).safe_div(Rgb::new(2.0, 0.0, 4.0)),
            Rgb::new(0.5, 0.0, 0.5)
        );
    }

    #[test]
    fn srgb_round_trip() {
        for i in 0..=255 {
            let v = i as f32 / 255.0;
            assert!((linear_to_srgb(srgb_to_linear(v)) - v).abs() < 1e-5);
        }
        assert!((linear_to_srgb(2.0) - 1.0).abs() < 1e-6);
        assert_eq!(linear_to_srgb(-1.0), 0.0);
    }
}
