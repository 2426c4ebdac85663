//! Eight-lane float vectors for the eight-wide node test and the eight-triangle leaf test, chosen
//! at run time by CPU feature.
//!
//! The traversal kernels are written once, generic over [`Simd8`], and instantiated for each
//! instruction set: [`Portable`] (two four-lane glam vectors: SSE2 on x86-64, NEON on ARM, or
//! scalar code) and, on x86-64, [`Avx2`] (one 256-bit register, fused multiply-add). An
//! instruction set is represented by a token, a zero-sized value that only
//! [`Avx2::detect`] can make, and only on a CPU that has the instructions; a kernel takes the
//! token by value, so a kernel for an instruction set the CPU lacks cannot be called. Kernels
//! that use a token are compiled inside functions marked `#[target_feature]` (see
//! `bvh8::traverse`), so that the intrinsics below are inlined as single instructions.
//!
//! This module and the `#[target_feature]` entry points of the kernels are the only places in
//! pt where `unsafe` appears: calling an intrinsic outside a function compiled for its
//! instruction set, and aligned loads from `&Lanes8` (always valid: the reference guarantees 32
//! readable, 32-byte-aligned bytes). Each use is sound because the token proves the CPU has the
//! instruction set.
//!
//! Why `std::arch` and not a SIMD crate: the robust node test depends on the exact NaN rules of
//! `maxps`/`minps` (a NaN candidate must leave the running bound unchanged) and on the bit mask
//! of a comparison in one instruction, which the intrinsics give directly; nothing else here
//! needs more than a dozen operations.

use glam::Vec4;

/// Eight floats aligned for one 256-bit load: the unit the node planes are stored in.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub(crate) struct Lanes8(pub [f32; 8]);

/// Which of a node's six planes (`[Lanes8; 6]`), kept as its byte offset, so that a kernel
/// loads a plane chosen per ray with one instruction (the base address plus a register), as
/// Embree's node test does, instead of recomputing the address from the index at every node.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Plane(usize);

impl Plane {
    /// Plane `i` (in `0..6`).
    #[inline(always)]
    pub fn new(i: usize) -> Self {
        assert!(i < 6, "a node has six planes");
        Self(i * size_of::<Lanes8>())
    }

    /// The plane's index.
    #[inline(always)]
    fn index(self) -> usize {
        self.0 / size_of::<Lanes8>()
    }
}

/// Eight-lane float arithmetic as the node test needs it.
///
/// `max_or(candidate, acc)` returns `candidate` where it is greater than `acc` and `acc`
/// elsewhere, in particular where `candidate` is NaN (likewise `min_or`): the rule of x86's
/// `maxps(candidate, acc)`, which the robust slab test relies on to ignore the slab of an axis
/// the ray runs inside of.
pub(crate) trait Simd8: Copy {
    /// Eight floats.
    type F: Copy;
    fn load(self, a: &Lanes8) -> Self::F;
    /// `load(&planes[p])`, addressed by the plane's byte offset.
    fn load_plane(self, planes: &[Lanes8; 6], p: Plane) -> Self::F;
    fn splat(self, v: f32) -> Self::F;
    fn sub(self, a: Self::F, b: Self::F) -> Self::F;
    fn mul(self, a: Self::F, b: Self::F) -> Self::F;
    /// `a * b - c`, rounded once where the instruction set has fused multiply-add ([`Avx2`]).
    fn mul_sub(self, a: Self::F, b: Self::F, c: Self::F) -> Self::F;
    /// `a * b + c`, rounded once where the instruction set has fused multiply-add.
    fn mul_add(self, a: Self::F, b: Self::F, c: Self::F) -> Self::F;
    /// `a + b`.
    fn add(self, a: Self::F, b: Self::F) -> Self::F;
    /// `a / b`, correctly rounded.
    fn div(self, a: Self::F, b: Self::F) -> Self::F;
    /// `|a|` (the sign bit cleared).
    fn abs(self, a: Self::F) -> Self::F;
    /// Lanes 0-3 from `lo`, 4-7 from `hi`.
    fn load_pair(self, lo: &Vec4, hi: &Vec4) -> Self::F;
    fn max_or(self, candidate: Self::F, acc: Self::F) -> Self::F;
    fn min_or(self, candidate: Self::F, acc: Self::F) -> Self::F;
    /// Bit `i` set where `a[i] <= b[i]`.
    fn le_mask(self, a: Self::F, b: Self::F) -> u32;
    /// Bit `i` set where `a[i] < b[i]`.
    fn lt_mask(self, a: Self::F, b: Self::F) -> u32;
    /// Bit `i` set where `a[i] != b[i]` (also where either is NaN).
    fn ne_mask(self, a: Self::F, b: Self::F) -> u32;
    fn to_array(self, v: Self::F) -> [f32; 8];
    /// Ask for the cache lines holding `*p` (a hint; no effect where the ISA has none).
    #[inline(always)]
    fn prefetch<T>(self, p: &T) {
        self.prefetch_at(p as *const T);
    }
    /// Ask for the cache lines a `T` at address `p` would occupy: `p` may point anywhere (a
    /// prefetch never faults), so callers need no bounds check.
    fn prefetch_at<T>(self, p: *const T);
}

/// Any CPU: two four-lane glam vectors (SSE2 on x86-64, NEON on AArch64, scalar elsewhere).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Portable;

impl Simd8 for Portable {
    type F = [Vec4; 2];

    #[inline(always)]
    fn load(self, a: &Lanes8) -> Self::F {
        [Vec4::from_slice(&a.0[..4]), Vec4::from_slice(&a.0[4..])]
    }
    #[inline(always)]
    fn load_plane(self, planes: &[Lanes8; 6], p: Plane) -> Self::F {
        self.load(&planes[p.index()])
    }
    #[inline(always)]
    fn splat(self, v: f32) -> Self::F {
        [Vec4::splat(v); 2]
    }
    #[inline(always)]
    fn sub(self, a: Self::F, b: Self::F) -> Self::F {
        [a[0] - b[0], a[1] - b[1]]
    }
    #[inline(always)]
    fn mul(self, a: Self::F, b: Self::F) -> Self::F {
        [a[0] * b[0], a[1] * b[1]]
    }
    #[inline(always)]
    fn mul_sub(self, a: Self::F, b: Self::F, c: Self::F) -> Self::F {
        [a[0] * b[0] - c[0], a[1] * b[1] - c[1]]
    }
    #[inline(always)]
    fn mul_add(self, a: Self::F, b: Self::F, c: Self::F) -> Self::F {
        [a[0] * b[0] + c[0], a[1] * b[1] + c[1]]
    }
    #[inline(always)]
    fn add(self, a: Self::F, b: Self::F) -> Self::F {
        [a[0] + b[0], a[1] + b[1]]
    }
    #[inline(always)]
    fn div(self, a: Self::F, b: Self::F) -> Self::F {
        [a[0] / b[0], a[1] / b[1]]
    }
    #[inline(always)]
    fn abs(self, a: Self::F) -> Self::F {
        [a[0].abs(), a[1].abs()]
    }
    #[inline(always)]
    fn load_pair(self, lo: &Vec4, hi: &Vec4) -> Self::F {
        [*lo, *hi]
    }
    #[inline(always)]
    fn max_or(self, candidate: Self::F, acc: Self::F) -> Self::F {
        let pick = |c: Vec4, a: Vec4| Vec4::select(c.cmpgt(a), c, a);
        [pick(candidate[0], acc[0]), pick(candidate[1], acc[1])]
    }
    #[inline(always)]
    fn min_or(self, candidate: Self::F, acc: Self::F) -> Self::F {
        let pick = |c: Vec4, a: Vec4| Vec4::select(c.cmplt(a), c, a);
        [pick(candidate[0], acc[0]), pick(candidate[1], acc[1])]
    }
    #[inline(always)]
    fn le_mask(self, a: Self::F, b: Self::F) -> u32 {
        a[0].cmple(b[0]).bitmask() | a[1].cmple(b[1]).bitmask() << 4
    }
    #[inline(always)]
    fn lt_mask(self, a: Self::F, b: Self::F) -> u32 {
        a[0].cmplt(b[0]).bitmask() | a[1].cmplt(b[1]).bitmask() << 4
    }
    #[inline(always)]
    fn ne_mask(self, a: Self::F, b: Self::F) -> u32 {
        a[0].cmpne(b[0]).bitmask() | a[1].cmpne(b[1]).bitmask() << 4
    }
    #[inline(always)]
    fn to_array(self, v: Self::F) -> [f32; 8] {
        let (lo, hi) = (v[0].to_array(), v[1].to_array());
        [lo[0], lo[1], lo[2], lo[3], hi[0], hi[1], hi[2], hi[3]]
    }
    #[inline(always)]
    fn prefetch_at<T>(self, _p: *const T) {}
}

#[cfg(target_arch = "x86_64")]
pub(crate) use x86::Avx2;

/// Whether this CPU runs the AVX2 kernels.
pub(crate) fn has_avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        Avx2::detect().is_some()
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

#[cfg(target_arch = "x86_64")]
mod x86 {
    use std::arch::x86_64::{
        __m128, __m256, _CMP_LE_OQ, _CMP_LT_OQ, _CMP_NEQ_UQ, _mm256_add_ps, _mm256_andnot_ps,
        _mm256_castps128_ps256, _mm256_cmp_ps, _mm256_div_ps, _mm256_fmadd_ps, _mm256_fmsub_ps,
        _mm256_insertf128_ps, _mm256_load_ps, _mm256_max_ps, _mm256_min_ps, _mm256_movemask_ps,
        _mm256_mul_ps, _mm256_set1_ps, _mm256_storeu_ps, _mm256_sub_ps,
    };

    use glam::Vec4;

    use super::{Lanes8, Plane, Simd8};

    /// Proof that the CPU has AVX2, FMA, BMI1, BMI2, LZCNT and POPCNT (every x86-64 CPU since
    /// 2013-2015 that has AVX2 has the others). Only [`Avx2::detect`] makes one.
    #[derive(Clone, Copy, Debug)]
    pub(crate) struct Avx2 {
        _private: (),
    }

    impl Avx2 {
        /// The token, when this CPU has the instructions.
        #[must_use]
        pub fn detect() -> Option<Self> {
            let ok = is_x86_feature_detected!("avx2")
                && is_x86_feature_detected!("fma")
                && is_x86_feature_detected!("bmi1")
                && is_x86_feature_detected!("bmi2")
                && is_x86_feature_detected!("lzcnt")
                && is_x86_feature_detected!("popcnt");
            ok.then_some(Self { _private: () })
        }

        /// Whether this CPU also has AVX-512 (F, VL, BW, DQ): the same kernels compiled for it
        /// use 32 vector registers and mask registers.
        #[must_use]
        pub fn has_avx512(self) -> bool {
            is_x86_feature_detected!("avx512f")
                && is_x86_feature_detected!("avx512vl")
                && is_x86_feature_detected!("avx512bw")
                && is_x86_feature_detected!("avx512dq")
        }
    }

    // SAFETY (every method): `self` is an `Avx2` token, which exists only when the CPU has AVX2
    // and FMA (`Avx2::detect`); loads read a `&Lanes8`, 32 valid bytes aligned to 32.
    impl Simd8 for Avx2 {
        type F = __m256;

        #[inline(always)]
        fn load(self, a: &Lanes8) -> __m256 {
            unsafe { _mm256_load_ps(a.0.as_ptr()) }
        }
        #[inline(always)]
        fn load_plane(self, planes: &[Lanes8; 6], p: Plane) -> __m256 {
            // SAFETY: in bounds, as `Plane::new` admits offsets of planes 0 to 5 only, each
            // 32 bytes from the array's start, which is aligned to 32.
            unsafe { _mm256_load_ps(planes.as_ptr().cast::<u8>().add(p.0).cast::<f32>()) }
        }
        #[inline(always)]
        fn splat(self, v: f32) -> __m256 {
            unsafe { _mm256_set1_ps(v) }
        }
        #[inline(always)]
        fn sub(self, a: __m256, b: __m256) -> __m256 {
            unsafe { _mm256_sub_ps(a, b) }
        }
        #[inline(always)]
        fn mul(self, a: __m256, b: __m256) -> __m256 {
            unsafe { _mm256_mul_ps(a, b) }
        }
        #[inline(always)]
        fn mul_sub(self, a: __m256, b: __m256, c: __m256) -> __m256 {
            unsafe { _mm256_fmsub_ps(a, b, c) }
        }
        #[inline(always)]
        fn mul_add(self, a: __m256, b: __m256, c: __m256) -> __m256 {
            unsafe { _mm256_fmadd_ps(a, b, c) }
        }
        #[inline(always)]
        fn add(self, a: __m256, b: __m256) -> __m256 {
            unsafe { _mm256_add_ps(a, b) }
        }
        #[inline(always)]
        fn div(self, a: __m256, b: __m256) -> __m256 {
            unsafe { _mm256_div_ps(a, b) }
        }
        #[inline(always)]
        fn abs(self, a: __m256) -> __m256 {
            unsafe { _mm256_andnot_ps(_mm256_set1_ps(-0.0), a) }
        }
        #[inline(always)]
        fn load_pair(self, lo: &Vec4, hi: &Vec4) -> __m256 {
            let (lo, hi) = (__m128::from(*lo), __m128::from(*hi));
            unsafe { _mm256_insertf128_ps::<1>(_mm256_castps128_ps256(lo), hi) }
        }
        #[inline(always)]
        fn max_or(self, candidate: __m256, acc: __m256) -> __m256 {
            unsafe { _mm256_max_ps(candidate, acc) }
        }
        #[inline(always)]
        fn min_or(self, candidate: __m256, acc: __m256) -> __m256 {
            unsafe { _mm256_min_ps(candidate, acc) }
        }
        #[inline(always)]
        fn le_mask(self, a: __m256, b: __m256) -> u32 {
            unsafe { _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(a, b)) as u32 }
        }
        #[inline(always)]
        fn lt_mask(self, a: __m256, b: __m256) -> u32 {
            unsafe { _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LT_OQ>(a, b)) as u32 }
        }
        #[inline(always)]
        fn ne_mask(self, a: __m256, b: __m256) -> u32 {
            unsafe { _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_NEQ_UQ>(a, b)) as u32 }
        }
        #[inline(always)]
        fn to_array(self, v: __m256) -> [f32; 8] {
            let mut out = [0.0; 8];
            unsafe { _mm256_storeu_ps(out.as_mut_ptr(), v) };
            out
        }
        #[inline(always)]
        fn prefetch_at<T>(self, p: *const T) {
            let first = p.cast::<u8>();
            let mut offset = 0;
            while offset < size_of::<T>() {
                super::prefetch_line(first.wrapping_add(offset));
                offset += 64;
            }
        }
    }
}

/// Ask for the cache line holding `*p` ahead of its use (a hint: no effect where the CPU has no
/// prefetch instruction; never faults).
///
/// ```
/// let indices = vec![[0u32, 1, 2]; 1000];
/// pt_accel::lanes::prefetch(&indices[500]);
/// ```
#[inline(always)]
pub fn prefetch<T>(p: &T) {
    prefetch_line((p as *const T).cast::<u8>());
}

/// Ask for the cache line holding address `p`, which may point anywhere: a prefetch never
/// faults. The one prefetch instruction of the crate ([`prefetch`] and the kernels'
/// [`Simd8::prefetch`]).
#[inline(always)]
fn prefetch_line(p: *const u8) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: `_mm_prefetch` (SSE, part of x86-64) only hints the cache and never faults,
    // whatever the address.
    unsafe {
        std::arch::x86_64::_mm_prefetch::<{ std::arch::x86_64::_MM_HINT_T0 }>(p.cast::<i8>());
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = p;
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every operation of every instruction set this CPU has agrees with the portable one, NaN
    /// rules included.
    #[test]
    fn instruction_sets_agree() {
        let a = Lanes8([
            1.0,
            -2.0,
            f32::NAN,
            4.0,
            f32::INFINITY,
            -0.0,
            7.5,
            f32::NEG_INFINITY,
        ]);
        let b = Lanes8([0.5, 3.0, 1.0, f32::NAN, 2.0, 0.0, 7.5, -1.0]);
        let c = Lanes8([0.25; 8]);
        fn all<S: Simd8>(s: S, a: &Lanes8, b: &Lanes8, c: &Lanes8) -> Vec<[u32; 8]> {
            let (x, y, z) = (s.load(a), s.load(b), s.load(c));
            let bits = |v: S::F| s.to_array(v).map(f32::to_bits);
            vec![
                bits(s.sub(x, y)),
                bits(s.mul(x, y)),
                bits(s.max_or(x, y)),
                bits(s.min_or(x, y)),
                bits(s.max_or(y, x)),
                bits(s.min_or(y, x)),
                bits(s.splat(3.0)),
                [s.le_mask(x, y), s.le_mask(y, x), 0, 0, 0, 0, 0, 0],
                bits(s.mul_sub(s.load(c), y, z)),
                bits(s.add(x, y)),
                bits(s.div(x, y)),
                bits(s.abs(x)),
                [
                    s.lt_mask(x, y),
                    s.lt_mask(y, x),
                    s.ne_mask(x, y),
                    s.ne_mask(x, x),
                    0,
                    0,
                    0,
                    0,
                ],
                bits(s.load_pair(&Vec4::from_slice(&b.0[4..]), &Vec4::from_slice(&a.0[..4]))),
            ]
        }
        let portable = all(Portable, &a, &b, &c);
        // NaN candidates leave the accumulator: lane 2 of max_or(a, b) is b's 1.0.
        assert_eq!(f32::from_bits(portable[2][2]), 1.0);
        assert_eq!(f32::from_bits(portable[4][3]), 4.0);
        #[cfg(target_arch = "x86_64")]
        if let Some(avx2) = Avx2::detect() {
            // 0.25 * b - 0.25 is exact in both (no rounding for these values).
            assert_eq!(all(avx2, &a, &b, &c), portable);
        }
    }
}
