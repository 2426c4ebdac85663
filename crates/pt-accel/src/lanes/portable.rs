//! The portable lanes: plain arrays, each operation a loop the compiler may vectorise.

use std::ops::{Add, BitAnd, BitOr, BitXor, Div, Mul, Neg, Not, Shl, Shr, Sub};

use super::{FloatLanes, MaskLanes, Simd, UintLanes, WIDTH, WithSimd};

/// The instruction set every CPU has.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Portable;

/// Eight `f32` lanes as an array.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PF([f32; WIDTH]);

/// Eight `u32` lanes as an array.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PU([u32; WIDTH]);

/// Eight lane flags as a bit mask.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PM(u32);

#[inline(always)]
fn map<T: Copy, R: Copy + Default>(a: [T; WIDTH], f: impl Fn(T) -> R) -> [R; WIDTH] {
    let mut out = [R::default(); WIDTH];
    for i in 0..WIDTH {
        out[i] = f(a[i]);
    }
    out
}

#[inline(always)]
fn zip<T: Copy, R: Copy + Default>(
    a: [T; WIDTH],
    b: [T; WIDTH],
    f: impl Fn(T, T) -> R,
) -> [R; WIDTH] {
    let mut out = [R::default(); WIDTH];
    for i in 0..WIDTH {
        out[i] = f(a[i], b[i]);
    }
    out
}

#[inline(always)]
fn flags<T: Copy>(a: [T; WIDTH], b: [T; WIDTH], f: impl Fn(T, T) -> bool) -> PM {
    let mut m = 0;
    for i in 0..WIDTH {
        m |= u32::from(f(a[i], b[i])) << i;
    }
    PM(m)
}

impl Simd for Portable {
    type F = PF;
    type U = PU;
    type M = PM;

    #[inline(always)]
    fn run<W: WithSimd>(self, work: W) -> W::Output {
        work.with_simd(self)
    }
    #[inline(always)]
    fn splat(self, v: f32) -> PF {
        PF([v; WIDTH])
    }
    #[inline(always)]
    fn load(self, a: [f32; WIDTH]) -> PF {
        PF(a)
    }
    #[inline(always)]
    fn splat_u(self, v: u32) -> PU {
        PU([v; WIDTH])
    }
    #[inline(always)]
    fn load_u(self, a: [u32; WIDTH]) -> PU {
        PU(a)
    }
    #[inline(always)]
    fn mask(self, bits: u32) -> PM {
        PM(bits & 0xff)
    }
    #[inline(always)]
    fn transpose(self, rows: [PF; WIDTH]) -> [PF; WIDTH] {
        let mut out = [PF([0.0; WIDTH]); WIDTH];
        for (i, row) in out.iter_mut().enumerate() {
            for (j, v) in row.0.iter_mut().enumerate() {
                *v = rows[j].0[i];
            }
        }
        out
    }
    #[inline(always)]
    fn pick(self, v: &[f32; 4], k: PU) -> PF {
        PF(map(k.0, |k| v[(k & 3) as usize]))
    }
    #[inline(always)]
    fn load_vec3(self, v: &[glam::Vec3; WIDTH]) -> [PF; 3] {
        let (mut x, mut y, mut z) = ([0.0; WIDTH], [0.0; WIDTH], [0.0; WIDTH]);
        for i in 0..WIDTH {
            (x[i], y[i], z[i]) = (v[i].x, v[i].y, v[i].z);
        }
        [PF(x), PF(y), PF(z)]
    }
}

macro_rules! float_op {
    ($tr:ident, $f:ident, $op:tt) => {
        impl $tr for PF {
            type Output = PF;
            #[inline(always)]
            fn $f(self, o: PF) -> PF {
                PF(zip(self.0, o.0, |a, b| a $op b))
            }
        }
    };
}
float_op!(Add, add, +);
float_op!(Sub, sub, -);
float_op!(Mul, mul, *);
float_op!(Div, div, /);

impl Neg for PF {
    type Output = PF;
    #[inline(always)]
    fn neg(self) -> PF {
        PF(map(self.0, |a| -a))
    }
}

impl FloatLanes for PF {
    type M = PM;
    type U = PU;

    #[inline(always)]
    fn splat_like(self, v: f32) -> PF {
        PF([v; WIDTH])
    }
    #[inline(always)]
    fn mul_add(self, b: PF, c: PF) -> PF {
        let p = self * b;
        p + c
    }
    #[inline(always)]
    fn sqrt(self) -> PF {
        PF(map(self.0, f32::sqrt))
    }
    #[inline(always)]
    fn abs(self) -> PF {
        PF(map(self.0, f32::abs))
    }
    #[inline(always)]
    fn min(self, o: PF) -> PF {
        // x86's rule: `o` unless `self < o` (so NaN in either gives `o`).
        PF(zip(self.0, o.0, |a, b| if a < b { a } else { b }))
    }
    #[inline(always)]
    fn max(self, o: PF) -> PF {
        PF(zip(self.0, o.0, |a, b| if a > b { a } else { b }))
    }
    #[inline(always)]
    fn floor(self) -> PF {
        PF(map(self.0, f32::floor))
    }
    #[inline(always)]
    fn reduce_min(self) -> f32 {
        let mut m = self.0[0];
        for &v in &self.0[1..] {
            if v < m {
                m = v;
            }
        }
        m
    }
    #[inline(always)]
    fn lt(self, o: PF) -> PM {
        flags(self.0, o.0, |a, b| a < b)
    }
    #[inline(always)]
    fn le(self, o: PF) -> PM {
        flags(self.0, o.0, |a, b| a <= b)
    }
    #[inline(always)]
    fn gt(self, o: PF) -> PM {
        flags(self.0, o.0, |a, b| a > b)
    }
    #[inline(always)]
    fn ge(self, o: PF) -> PM {
        flags(self.0, o.0, |a, b| a >= b)
    }
    #[inline(always)]
    fn eq(self, o: PF) -> PM {
        flags(self.0, o.0, |a, b| a == b)
    }
    #[inline(always)]
    fn is_finite(self) -> PM {
        flags(self.0, self.0, |a, _| a.is_finite())
    }
    #[inline(always)]
    fn select(m: PM, a: PF, b: PF) -> PF {
        let mut out = b.0;
        for i in 0..WIDTH {
            if m.0 & (1 << i) != 0 {
                out[i] = a.0[i];
            }
        }
        PF(out)
    }
    #[inline(always)]
    fn to_array(self) -> [f32; WIDTH] {
        self.0
    }
    #[inline(always)]
    fn to_bits(self) -> PU {
        PU(map(self.0, f32::to_bits))
    }
    #[inline(always)]
    fn to_u32(self) -> PU {
        PU(map(self.0, |a| a as i32 as u32))
    }
}

macro_rules! uint_op {
    ($tr:ident, $f:ident, $op:tt) => {
        impl $tr for PU {
            type Output = PU;
            #[inline(always)]
            fn $f(self, o: PU) -> PU {
                PU(zip(self.0, o.0, |a, b| a $op b))
            }
        }
    };
}
uint_op!(BitAnd, bitand, &);
uint_op!(BitOr, bitor, |);
uint_op!(BitXor, bitxor, ^);

impl Shl<u32> for PU {
    type Output = PU;
    #[inline(always)]
    fn shl(self, n: u32) -> PU {
        PU(map(self.0, |a| a.checked_shl(n).unwrap_or(0)))
    }
}

impl Shr<u32> for PU {
    type Output = PU;
    #[inline(always)]
    fn shr(self, n: u32) -> PU {
        PU(map(self.0, |a| a.checked_shr(n).unwrap_or(0)))
    }
}

impl UintLanes for PU {
    type M = PM;
    type F = PF;

    #[inline(always)]
    fn splat_like(self, v: u32) -> PU {
        PU([v; WIDTH])
    }
    #[inline(always)]
    fn wrapping_add(self, o: PU) -> PU {
        PU(zip(self.0, o.0, u32::wrapping_add))
    }
    #[inline(always)]
    fn wrapping_mul(self, o: PU) -> PU {
        PU(zip(self.0, o.0, u32::wrapping_mul))
    }
    #[inline(always)]
    fn reverse_bits(self) -> PU {
        PU(map(self.0, u32::reverse_bits))
    }
    #[inline(always)]
    fn eq(self, o: PU) -> PM {
        flags(self.0, o.0, |a, b| a == b)
    }
    #[inline(always)]
    fn select(m: PM, a: PU, b: PU) -> PU {
        let mut out = b.0;
        for i in 0..WIDTH {
            if m.0 & (1 << i) != 0 {
                out[i] = a.0[i];
            }
        }
        PU(out)
    }
    #[inline(always)]
    fn to_f32(self) -> PF {
        PF(map(self.0, |a| a as i32 as f32))
    }
    #[inline(always)]
    fn to_bits_f32(self) -> PF {
        PF(map(self.0, f32::from_bits))
    }
    #[inline(always)]
    fn to_array(self) -> [u32; WIDTH] {
        self.0
    }
}

impl BitAnd for PM {
    type Output = PM;
    #[inline(always)]
    fn bitand(self, o: PM) -> PM {
        PM(self.0 & o.0)
    }
}

impl BitOr for PM {
    type Output = PM;
    #[inline(always)]
    fn bitor(self, o: PM) -> PM {
        PM(self.0 | o.0)
    }
}

impl Not for PM {
    type Output = PM;
    #[inline(always)]
    fn not(self) -> PM {
        PM(!self.0 & 0xff)
    }
}

impl MaskLanes for PM {
    #[inline(always)]
    fn bits(self) -> u32 {
        self.0
    }
}
