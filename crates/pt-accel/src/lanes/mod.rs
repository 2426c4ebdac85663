//! Eight lanes of `f32` and `u32`, for code that runs eight of something at once (pt-core's
//! lane path tracer), with the instruction set chosen when the program runs.
//!
//! Code generic over [`Simd`] is written once with ordinary operators (`a * b + c` on
//! [`Simd::F`]) and run through [`dispatch`]: on an x86-64 CPU with AVX2 and FMA it is compiled
//! for them (and for AVX-512 where the CPU has it), elsewhere for the baseline (the
//! [`Portable`] lanes, plain arrays the compiler vectorises as it can). A program built for
//! baseline x86-64 therefore gets the AVX2 code on a CPU that has it.
//!
//! The lane types can only be made through a [`Simd`] token, and the AVX2 token only by
//! [`dispatch`] on a CPU that has the instructions: holding a lane value proves the instruction
//! set is there, which is what makes the operators' intrinsics sound. All of pt's `unsafe` code
//! for this lives in this module's `avx2` file and in [`dispatch`]; users of the lanes write
//! none.
//!
//! ```
//! use pt_accel::lanes::{dispatch, FloatLanes, Simd, WithSimd};
//!
//! /// `x * x + 1` for eight values at once.
//! struct SquarePlusOne([f32; 8]);
//! impl WithSimd for SquarePlusOne {
//!     type Output = [f32; 8];
//!     #[inline(always)]
//!     fn with_simd<S: Simd>(self, s: S) -> [f32; 8] {
//!         let x = s.load(self.0);
//!         (x * x + s.splat(1.0)).to_array()
//!     }
//! }
//! let y = dispatch(SquarePlusOne([0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0]));
//! assert_eq!(y, [1.0, 2.0, 5.0, 10.0, 17.0, 26.0, 37.0, 50.0]);
//! ```
//!
//! Rounding: every operation rounds as the scalar one does, except [`FloatLanes::mul_add`],
//! which is fused (one rounding) where the CPU has FMA and two roundings elsewhere. Results are
//! therefore the same on every run of one machine, not across machines.

mod portable;

#[cfg(target_arch = "x86_64")]
mod avx2;

use std::fmt::Debug;
use std::ops::{Add, BitAnd, BitOr, BitXor, Div, Mul, Neg, Not, Shl, Shr, Sub};

pub use crate::simd::prefetch;
pub use portable::Portable;

/// Lanes per vector.
pub const WIDTH: usize = 8;

/// The lanes whose bits are set in `mask`, in increasing order.
///
/// ```
/// let lanes: Vec<usize> = pt_accel::lanes::bits(0b1010_0001).collect();
/// assert_eq!(lanes, [0, 5, 7]);
/// ```
#[inline(always)]
pub fn bits(mut mask: u32) -> impl Iterator<Item = usize> {
    std::iter::from_fn(move || {
        (mask != 0).then(|| {
            let lane = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            lane
        })
    })
}

/// The mask of the lanes of `mask` for which `f` holds (each asked once, in increasing order).
#[inline(always)]
pub fn mask_where(mask: u32, mut f: impl FnMut(usize) -> bool) -> u32 {
    bits(mask)
        .filter(|&lane| f(lane))
        .fold(0, |m, lane| m | (1 << lane))
}

/// An instruction set for eight lanes: makes lane values from scalars and arrays.
pub trait Simd: Copy + Send + Sync + Debug + 'static {
    /// Eight `f32`.
    type F: FloatLanes<M = Self::M, U = Self::U>;
    /// Eight `u32`.
    type U: UintLanes<M = Self::M, F = Self::F>;
    /// Eight lane flags.
    type M: MaskLanes;

    /// Run `work` with these lanes, compiled for their instruction set: what [`dispatch`]
    /// does, without asking the CPU again. Code that already runs with a token calls a
    /// kernel through this rather than through `dispatch`, whose checks and entry would run
    /// as the program's baseline code (a build for baseline x86-64: no AVX); from such code
    /// the compiler may also inline the kernel into the caller.
    fn run<W: WithSimd>(self, work: W) -> W::Output;

    /// `v` in every lane.
    fn splat(self, v: f32) -> Self::F;
    /// Lane `i` holds `a[i]`.
    fn load(self, a: [f32; WIDTH]) -> Self::F;
    /// `v` in every lane.
    fn splat_u(self, v: u32) -> Self::U;
    /// Lane `i` holds `a[i]`.
    fn load_u(self, a: [u32; WIDTH]) -> Self::U;
    /// Lane `i` set where bit `i` of `bits` is.
    fn mask(self, bits: u32) -> Self::M;
    /// The coordinates of eight vectors as three lane values: lane `i` of the first holds
    /// `v[i].x`, and so on. Read by three whole-register loads and shuffles instead of 24
    /// scalar copies. Those loads wait for any recent smaller stores they overlap: for an
    /// array written a lane at a time just before, copying coordinate by coordinate (or
    /// keeping the coordinates in separate arrays) can be faster; measure both (pt's lane
    /// tracer uses this for its colours only, docs/performance-log.md).
    fn load_vec3(self, v: &[glam::Vec3; WIDTH]) -> [Self::F; 3];
    /// The eight lane values transposed: lane `j` of the `i`-th result is lane `i` of the
    /// `j`-th argument (eight arrays of eight values by coordinate become eight records of
    /// eight values, and back). In registers, by shuffles.
    fn transpose(self, rows: [Self::F; WIDTH]) -> [Self::F; WIDTH];
    /// Lane `i` holds `v[k_i]`: one of four values chosen per lane (only the low two bits of
    /// each `k_i` are read). By one in-register permutation of `v` loaded once, where a choice
    /// among three by masks takes three broadcasts and two blends per value.
    fn pick(self, v: &[f32; 4], k: Self::U) -> Self::F;
}

/// Eight `f32` lanes: arithmetic by operators, the rest by methods.
pub trait FloatLanes:
    Copy
    + Debug
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// The lane flags comparisons give.
    type M: MaskLanes;
    /// The matching integer lanes.
    type U: UintLanes;

    /// `v` in every lane (an existing value stands for the token).
    fn splat_like(self, v: f32) -> Self;
    /// `self * b + c`, fused where the CPU has FMA.
    fn mul_add(self, b: Self, c: Self) -> Self;
    /// Square root.
    fn sqrt(self) -> Self;
    /// Absolute value.
    fn abs(self) -> Self;
    /// The smaller of the two, or `o` where either is NaN.
    fn min(self, o: Self) -> Self;
    /// The larger of the two, or `o` where either is NaN.
    fn max(self, o: Self) -> Self;
    /// Largest integer not above.
    fn floor(self) -> Self;
    /// The smallest of the eight lanes (none may be NaN; of a `0.0` and a `-0.0` either may
    /// come).
    fn reduce_min(self) -> f32;
    /// `self < o` (false for NaN).
    fn lt(self, o: Self) -> Self::M;
    /// `self <= o`.
    fn le(self, o: Self) -> Self::M;
    /// `self > o`.
    fn gt(self, o: Self) -> Self::M;
    /// `self >= o`.
    fn ge(self, o: Self) -> Self::M;
    /// `self == o`.
    fn eq(self, o: Self) -> Self::M;
    /// Lanes whose value is finite (not infinite, not NaN).
    fn is_finite(self) -> Self::M;
    /// `a` where `m` is set, `b` elsewhere.
    fn select(m: Self::M, a: Self, b: Self) -> Self;
    /// The lanes as an array.
    fn to_array(self) -> [f32; WIDTH];
    /// The bits of each lane.
    fn to_bits(self) -> Self::U;
    /// Truncate toward zero to an integer (lanes must hold values in `0..2^31`).
    fn to_u32(self) -> Self::U;
}

/// Eight `u32` lanes: wrapping arithmetic and bit operations.
pub trait UintLanes:
    Copy
    + Debug
    + BitAnd<Output = Self>
    + BitOr<Output = Self>
    + BitXor<Output = Self>
    + Shl<u32, Output = Self>
    + Shr<u32, Output = Self>
{
    /// The lane flags comparisons give.
    type M: MaskLanes;
    /// The matching float lanes.
    type F: FloatLanes;

    /// `v` in every lane.
    fn splat_like(self, v: u32) -> Self;
    /// Wrapping addition.
    fn wrapping_add(self, o: Self) -> Self;
    /// Wrapping multiplication (the low 32 bits of the product).
    fn wrapping_mul(self, o: Self) -> Self;
    /// The bits of each lane in reverse order.
    fn reverse_bits(self) -> Self;
    /// `self == o`.
    fn eq(self, o: Self) -> Self::M;
    /// `a` where `m` is set, `b` elsewhere.
    fn select(m: Self::M, a: Self, b: Self) -> Self;
    /// Each lane converted to the nearest `f32` (exact below `2^24`; lanes must be below
    /// `2^31`).
    fn to_f32(self) -> Self::F;
    /// Each lane's bits as a float.
    fn to_bits_f32(self) -> Self::F;
    /// The lanes as an array.
    fn to_array(self) -> [u32; WIDTH];
}

/// Eight lane flags.
pub trait MaskLanes:
    Copy + Debug + BitAnd<Output = Self> + BitOr<Output = Self> + Not<Output = Self>
{
    /// Bit `i` set where lane `i` is.
    fn bits(self) -> u32;
    /// Whether any lane is set.
    fn any(self) -> bool {
        self.bits() != 0
    }
    /// Whether every lane is set.
    fn all(self) -> bool {
        self.bits() == 0xff
    }
}

/// Work that runs with the lanes of whatever instruction set [`dispatch`] picks.
///
/// Mark the implementation `#[inline(always)]`, and the functions it calls too, so that they
/// are compiled inside the instruction set's entry point. Do not hold or make lane values in
/// closures there: a closure cannot be marked so, and a build for baseline x86-64 may compile
/// it outside the entry, where every lane operation becomes a function call (several times
/// slower); use a function or a macro instead.
pub trait WithSimd {
    /// What the work returns.
    type Output;
    /// Do the work with the lanes of `s`.
    fn with_simd<S: Simd>(self, s: S) -> Self::Output;
}

/// The instruction sets [`dispatch`] chooses from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum Isa {
    /// Plain arrays, compiled for the build's baseline.
    Portable,
    /// AVX2 with FMA.
    Avx2,
    /// The AVX2 lanes compiled for AVX-512 (more registers, mask registers).
    Avx512,
}

/// The instruction set [`dispatch`] runs on this CPU.
#[must_use]
pub fn detected() -> Isa {
    #[cfg(target_arch = "x86_64")]
    if let Some(t) = avx2::Avx2Lanes::detect() {
        return if t.has_avx512() {
            Isa::Avx512
        } else {
            Isa::Avx2
        };
    }
    Isa::Portable
}

/// Run `work` with the best lanes this CPU has (see [`detected`]).
#[inline]
pub fn dispatch<W: WithSimd>(work: W) -> W::Output {
    Found::detect().run(work)
}

/// The lanes [`dispatch`] runs on this CPU, asked for once and kept: a kernel entered many
/// times (the BVH's packet kernels, once per lane query) runs through this instead of
/// [`dispatch`], whose questions to the CPU a build for baseline x86-64 asks again on every
/// call (about 2% of Mitsuba's box in such a build; docs/performance-log.md).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Found {
    #[cfg(target_arch = "x86_64")]
    avx2: Option<avx2::Avx2Lanes>,
}

impl Found {
    /// Ask the CPU.
    #[inline]
    pub(crate) fn detect() -> Self {
        Self {
            #[cfg(target_arch = "x86_64")]
            avx2: avx2::Avx2Lanes::detect(),
        }
    }

    /// Run `work` with these lanes, as [`dispatch`] would.
    ///
    /// A build whose target features include the AVX2 lanes' (pt's own on such a CPU) runs
    /// only on CPUs that have them, so the portable lanes are left out of it: `work` is then
    /// compiled for two instruction sets, not three (each user type's lane tracer is a large
    /// instantiation; CI's clean build spent about a third of it on the unreachable one).
    #[inline(always)]
    pub(crate) fn run<W: WithSimd>(self, work: W) -> W::Output {
        #[cfg(pt_avx2_build)]
        {
            self.avx2
                .unwrap_or_else(avx2::Avx2Lanes::compiled_in)
                .run(work)
        }
        #[cfg(not(pt_avx2_build))]
        {
            // A build for a CPU with AVX-512 knows the answer without the stored one.
            #[cfg(target_arch = "x86_64")]
            if let Some(t) = avx2::Avx2Lanes::known().or(self.avx2) {
                return t.run(work);
            }
            run_portable(work)
        }
    }
}

/// `work` with the portable lanes; out of line on x86-64, where it is the rare case: inlined
/// into an entry like [`Found::run`]'s caller, its kernel's stack frame (probed page by page
/// on every call) and registers would be the AVX2 path's too.
#[cfg_attr(target_arch = "x86_64", inline(never))]
#[cfg(not(pt_avx2_build))]
fn run_portable<W: WithSimd>(work: W) -> W::Output {
    work.with_simd(Portable)
}

/// Run `work` with the portable lanes, whatever the CPU (for tests and comparisons).
#[inline]
pub fn dispatch_portable<W: WithSimd>(work: W) -> W::Output {
    work.with_simd(Portable)
}

#[cfg(test)]
mod tests;
