//! The AVX2 lanes: one 256-bit register per value.
//!
//! SAFETY (every `unsafe` block of this file): the intrinsics are compiled for AVX2 and FMA but
//! called from functions that may not be; that is sound only on a CPU that has them. A value of
//! [`AF`], [`AU`] or [`AM`] can only be made from an [`Avx2Lanes`] token or from another such
//! value, and the token only by [`Avx2Lanes::detect`] on a CPU that has AVX2, FMA, BMI1, BMI2,
//! LZCNT and POPCNT, or by `known` and `compiled_in` in a build whose target features include
//! them (which runs on no other CPU). Loads and stores go through arrays owned by the caller;
//! `load_vec3` reads an array of `glam::Vec3` as floats, which glam's `#[repr(C)]` of three
//! `f32` allows.

#![allow(unsafe_code)]

use std::arch::x86_64::*;
use std::ops::{Add, BitAnd, BitOr, BitXor, Div, Mul, Neg, Not, Shl, Shr, Sub};

use super::{FloatLanes, MaskLanes, Simd, UintLanes, WIDTH, WithSimd};

/// Proof that the CPU has AVX2 and FMA (and BMI1, BMI2, LZCNT, POPCNT), and whether it has
/// AVX-512 too.
#[derive(Clone, Copy, Debug)]
pub struct Avx2Lanes {
    avx512: bool,
}

impl Avx2Lanes {
    /// The token, when this CPU has the instructions.
    pub(super) fn detect() -> Option<Self> {
        let ok = is_x86_feature_detected!("avx2")
            && is_x86_feature_detected!("fma")
            && is_x86_feature_detected!("bmi1")
            && is_x86_feature_detected!("bmi2")
            && is_x86_feature_detected!("lzcnt")
            && is_x86_feature_detected!("popcnt");
        let avx512 = is_x86_feature_detected!("avx512f")
            && is_x86_feature_detected!("avx512vl")
            && is_x86_feature_detected!("avx512bw")
            && is_x86_feature_detected!("avx512dq");
        ok.then_some(Self { avx512 })
    }

    /// The token without asking the CPU, in a build whose target features include all of
    /// these instructions and AVX-512 (pt's own on such a CPU): the answer [`Self::detect`]
    /// gives there. `None` elsewhere, including builds with AVX2 but not AVX-512, where
    /// whether the CPU has AVX-512 is still a question for run time.
    #[inline(always)]
    pub(super) fn known() -> Option<Self> {
        // `pt_avx512_build`: the build script's name for those features (build.rs).
        cfg!(pt_avx512_build).then_some(Self { avx512: true })
    }

    /// The token in a build whose target features include AVX2, FMA, BMI1, BMI2, LZCNT and
    /// POPCNT: such a program runs only on CPUs that have them. [`Self::detect`] gives the same
    /// there (the feature macros answer from the build's features); this is its answer should
    /// it ever give none, claiming no AVX-512.
    #[cfg(pt_avx2_build)]
    pub(super) fn compiled_in() -> Self {
        Self::known().unwrap_or(Self { avx512: false })
    }

    /// Whether the CPU also has AVX-512 F, VL, BW and DQ.
    #[inline(always)]
    pub(super) fn has_avx512(self) -> bool {
        self.avx512
    }
}

/// `work` compiled for AVX2 and FMA (not in builds for AVX-512, where it could never run).
#[inline]
#[cfg(not(pt_avx512_build))]
pub(super) fn run_avx2<W: WithSimd>(work: W, t: Avx2Lanes) -> W::Output {
    #[target_feature(enable = "avx2,fma,bmi1,bmi2,lzcnt,popcnt")]
    fn go<W: WithSimd>(work: W, t: Avx2Lanes) -> W::Output {
        work.with_simd(t)
    }
    // SAFETY: `t` proves the CPU has these features.
    unsafe { go(work, t) }
}

/// `work` compiled for AVX-512 (the AVX2 lanes with 32 registers and mask registers).
#[inline]
pub(super) fn run_avx512<W: WithSimd>(work: W, t: Avx2Lanes) -> W::Output {
    #[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq,avx2,fma,bmi1,bmi2,lzcnt,popcnt")]
    fn go<W: WithSimd>(work: W, t: Avx2Lanes) -> W::Output {
        work.with_simd(t)
    }
    // SAFETY: `t` proves AVX2 and FMA, and the caller checked `has_avx512` (which `t` holds).
    unsafe { go(work, t) }
}

/// `a` where `m` is set, `b` elsewhere, with `b` hidden from the optimiser.
///
/// A blend whose `b` was loaded from where its result is stored (`x = select(m, v, x)`, the lane
/// tracer's way of updating some lanes of an array) is otherwise compiled to a masked store,
/// `vmaskmovps`, which AMD's Zen 3 runs slowly (3.8 ns a store, measured, against 0.9 for a load, a
/// blend and a store; the lane tracer had 25 of them in its loop, Mitsuba's box ran 3% faster
/// without them). An empty `asm!` on `b` keeps the compiler from knowing that `b` is what memory
/// holds; it emits no instruction. (The same blend written as `and`, `andnot` and `or` was turned
/// back into a masked store.)
///
/// A build for AVX-512 (pt's own on such a CPU) keeps the plain blend: there the masked store
/// is a fast `vmovups` with a mask register, and hiding `b` cost the lane tracer 1% more
/// instructions (a `target-cpu=znver5` build, counted by `objdump`).
#[inline(always)]
unsafe fn blend(m: __m256, a: __m256, b: __m256) -> __m256 {
    let b = if cfg!(pt_avx512_build) {
        b
    } else {
        unsafe { opaque(b) }
    };
    unsafe { _mm256_blendv_ps(b, a, m) }
}

/// `v`, as a value the compiler cannot see through.
///
/// Compiled for AVX (to name a 256-bit register) and inlined into the AVX2 kernels, whose
/// features include it.
#[target_feature(enable = "avx")]
#[inline]
unsafe fn opaque(mut v: __m256) -> __m256 {
    unsafe {
        std::arch::asm!(
            "/* {0} */",
            inout(ymm_reg) v,
            options(pure, nomem, nostack, preserves_flags)
        )
    };
    v
}

/// Eight `f32` in a 256-bit register.
#[derive(Clone, Copy, Debug)]
pub struct AF(__m256);

/// Eight `u32` in a 256-bit register.
#[derive(Clone, Copy, Debug)]
pub struct AU(__m256i);

/// Eight lane flags (all ones or all zeros per lane).
#[derive(Clone, Copy, Debug)]
pub struct AM(__m256);

impl Simd for Avx2Lanes {
    type F = AF;
    type U = AU;
    type M = AM;

    #[inline(always)]
    fn run<W: WithSimd>(self, work: W) -> W::Output {
        // A build for AVX-512 (pt's own, for the host CPU) knows the answer, and leaves the
        // AVX2-only entry out (it could never run).
        #[cfg(pt_avx512_build)]
        {
            run_avx512(work, self)
        }
        #[cfg(not(pt_avx512_build))]
        {
            if Self::known().is_some() || self.avx512 {
                run_avx512(work, self)
            } else {
                run_avx2(work, self)
            }
        }
    }

    #[inline(always)]
    fn splat(self, v: f32) -> AF {
        AF(unsafe { _mm256_set1_ps(v) })
    }
    #[inline(always)]
    fn load(self, a: [f32; WIDTH]) -> AF {
        AF(unsafe { _mm256_loadu_ps(a.as_ptr()) })
    }
    #[inline(always)]
    fn splat_u(self, v: u32) -> AU {
        AU(unsafe { _mm256_set1_epi32(v as i32) })
    }
    #[inline(always)]
    fn load_u(self, a: [u32; WIDTH]) -> AU {
        AU(unsafe { _mm256_loadu_si256(a.as_ptr().cast()) })
    }
    #[inline(always)]
    fn pick(self, v: &[f32; 4], k: AU) -> AF {
        // SAFETY: `v` is four readable floats (an unaligned load); the rest is in registers.
        unsafe {
            let four = _mm_loadu_ps(v.as_ptr());
            AF(_mm256_permutevar_ps(_mm256_set_m128(four, four), k.0))
        }
    }
    #[inline(always)]
    fn mask(self, bits: u32) -> AM {
        unsafe {
            let lane_bits = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
            let b = _mm256_set1_epi32(bits as i32);
            let hit = _mm256_cmpeq_epi32(_mm256_and_si256(b, lane_bits), lane_bits);
            AM(_mm256_castsi256_ps(hit))
        }
    }
    #[inline(always)]
    fn transpose(self, rows: [AF; WIDTH]) -> [AF; WIDTH] {
        let r = rows.map(|f| f.0);
        // SAFETY: `self` exists only on CPUs with AVX2 (shuffles only, no memory access).
        unsafe {
            // Pairs of rows interleaved, then pairs of pairs, then the halves swapped.
            let t0 = _mm256_unpacklo_ps(r[0], r[1]);
            let t1 = _mm256_unpackhi_ps(r[0], r[1]);
            let t2 = _mm256_unpacklo_ps(r[2], r[3]);
            let t3 = _mm256_unpackhi_ps(r[2], r[3]);
            let t4 = _mm256_unpacklo_ps(r[4], r[5]);
            let t5 = _mm256_unpackhi_ps(r[4], r[5]);
            let t6 = _mm256_unpacklo_ps(r[6], r[7]);
            let t7 = _mm256_unpackhi_ps(r[6], r[7]);
            let s0 = _mm256_shuffle_ps::<0x44>(t0, t2);
            let s1 = _mm256_shuffle_ps::<0xee>(t0, t2);
            let s2 = _mm256_shuffle_ps::<0x44>(t1, t3);
            let s3 = _mm256_shuffle_ps::<0xee>(t1, t3);
            let s4 = _mm256_shuffle_ps::<0x44>(t4, t6);
            let s5 = _mm256_shuffle_ps::<0xee>(t4, t6);
            let s6 = _mm256_shuffle_ps::<0x44>(t5, t7);
            let s7 = _mm256_shuffle_ps::<0xee>(t5, t7);
            [
                AF(_mm256_permute2f128_ps::<0x20>(s0, s4)),
                AF(_mm256_permute2f128_ps::<0x20>(s1, s5)),
                AF(_mm256_permute2f128_ps::<0x20>(s2, s6)),
                AF(_mm256_permute2f128_ps::<0x20>(s3, s7)),
                AF(_mm256_permute2f128_ps::<0x31>(s0, s4)),
                AF(_mm256_permute2f128_ps::<0x31>(s1, s5)),
                AF(_mm256_permute2f128_ps::<0x31>(s2, s6)),
                AF(_mm256_permute2f128_ps::<0x31>(s3, s7)),
            ]
        }
    }
    #[inline(always)]
    fn load_vec3(self, v: &[glam::Vec3; WIDTH]) -> [AF; 3] {
        // `Vec3` is `repr(C)` of three `f32`: the 24 floats x0 y0 z0 x1 ... z7 lie in three
        // registers a, b, c. Each coordinate takes its lanes from all three (x: a at 0, 3, 6,
        // b at 1, 4, 7, c at 2, 5), put in order by one permute.
        unsafe {
            let p = v.as_ptr().cast::<f32>();
            let (a, b, c) = (
                _mm256_loadu_ps(p),
                _mm256_loadu_ps(p.add(8)),
                _mm256_loadu_ps(p.add(16)),
            );
            let x = _mm256_blend_ps::<0x24>(_mm256_blend_ps::<0x92>(a, b), c);
            let y = _mm256_blend_ps::<0x49>(_mm256_blend_ps::<0x24>(a, b), c);
            let z = _mm256_blend_ps::<0x92>(_mm256_blend_ps::<0x49>(a, b), c);
            [
                AF(_mm256_permutevar8x32_ps(
                    x,
                    _mm256_setr_epi32(0, 3, 6, 1, 4, 7, 2, 5),
                )),
                AF(_mm256_permutevar8x32_ps(
                    y,
                    _mm256_setr_epi32(1, 4, 7, 2, 5, 0, 3, 6),
                )),
                AF(_mm256_permutevar8x32_ps(
                    z,
                    _mm256_setr_epi32(2, 5, 0, 3, 6, 1, 4, 7),
                )),
            ]
        }
    }
}

macro_rules! float_op {
    ($tr:ident, $f:ident, $intr:ident) => {
        impl $tr for AF {
            type Output = AF;
            #[inline(always)]
            fn $f(self, o: AF) -> AF {
                AF(unsafe { $intr(self.0, o.0) })
            }
        }
    };
}
float_op!(Add, add, _mm256_add_ps);
float_op!(Sub, sub, _mm256_sub_ps);
float_op!(Mul, mul, _mm256_mul_ps);
float_op!(Div, div, _mm256_div_ps);

impl Neg for AF {
    type Output = AF;
    #[inline(always)]
    fn neg(self) -> AF {
        AF(unsafe { _mm256_xor_ps(self.0, _mm256_set1_ps(-0.0)) })
    }
}

impl FloatLanes for AF {
    type M = AM;
    type U = AU;

    #[inline(always)]
    fn splat_like(self, v: f32) -> AF {
        AF(unsafe { _mm256_set1_ps(v) })
    }
    #[inline(always)]
    fn mul_add(self, b: AF, c: AF) -> AF {
        AF(unsafe { _mm256_fmadd_ps(self.0, b.0, c.0) })
    }
    #[inline(always)]
    fn sqrt(self) -> AF {
        AF(unsafe { _mm256_sqrt_ps(self.0) })
    }
    #[inline(always)]
    fn abs(self) -> AF {
        AF(unsafe { _mm256_andnot_ps(_mm256_set1_ps(-0.0), self.0) })
    }
    #[inline(always)]
    fn min(self, o: AF) -> AF {
        AF(unsafe { _mm256_min_ps(self.0, o.0) })
    }
    #[inline(always)]
    fn max(self, o: AF) -> AF {
        AF(unsafe { _mm256_max_ps(self.0, o.0) })
    }
    #[inline(always)]
    fn floor(self) -> AF {
        AF(unsafe { _mm256_floor_ps(self.0) })
    }
    #[inline(always)]
    fn reduce_min(self) -> f32 {
        unsafe {
            // Halves, then pairs, then neighbours.
            let m = _mm_min_ps(
                _mm256_castps256_ps128(self.0),
                _mm256_extractf128_ps::<1>(self.0),
            );
            let m = _mm_min_ps(m, _mm_movehl_ps(m, m));
            let m = _mm_min_ss(m, _mm_shuffle_ps::<0b01>(m, m));
            _mm_cvtss_f32(m)
        }
    }
    #[inline(always)]
    fn lt(self, o: AF) -> AM {
        AM(unsafe { _mm256_cmp_ps::<_CMP_LT_OQ>(self.0, o.0) })
    }
    #[inline(always)]
    fn le(self, o: AF) -> AM {
        AM(unsafe { _mm256_cmp_ps::<_CMP_LE_OQ>(self.0, o.0) })
    }
    #[inline(always)]
    fn gt(self, o: AF) -> AM {
        AM(unsafe { _mm256_cmp_ps::<_CMP_GT_OQ>(self.0, o.0) })
    }
    #[inline(always)]
    fn ge(self, o: AF) -> AM {
        AM(unsafe { _mm256_cmp_ps::<_CMP_GE_OQ>(self.0, o.0) })
    }
    #[inline(always)]
    fn eq(self, o: AF) -> AM {
        AM(unsafe { _mm256_cmp_ps::<_CMP_EQ_OQ>(self.0, o.0) })
    }
    #[inline(always)]
    fn is_finite(self) -> AM {
        // |x| < inf is false for infinities and NaN.
        self.abs().lt(self.splat_like(f32::INFINITY))
    }
    #[inline(always)]
    fn select(m: AM, a: AF, b: AF) -> AF {
        AF(unsafe { blend(m.0, a.0, b.0) })
    }
    #[inline(always)]
    fn to_array(self) -> [f32; WIDTH] {
        let mut out = [0.0; WIDTH];
        unsafe { _mm256_storeu_ps(out.as_mut_ptr(), self.0) };
        out
    }
    #[inline(always)]
    fn to_bits(self) -> AU {
        AU(unsafe { _mm256_castps_si256(self.0) })
    }
    #[inline(always)]
    fn to_u32(self) -> AU {
        AU(unsafe { _mm256_cvttps_epi32(self.0) })
    }
}

macro_rules! uint_op {
    ($tr:ident, $f:ident, $intr:ident) => {
        impl $tr for AU {
            type Output = AU;
            #[inline(always)]
            fn $f(self, o: AU) -> AU {
                AU(unsafe { $intr(self.0, o.0) })
            }
        }
    };
}
uint_op!(BitAnd, bitand, _mm256_and_si256);
uint_op!(BitOr, bitor, _mm256_or_si256);
uint_op!(BitXor, bitxor, _mm256_xor_si256);

impl Shl<u32> for AU {
    type Output = AU;
    #[inline(always)]
    fn shl(self, n: u32) -> AU {
        AU(unsafe { _mm256_sll_epi32(self.0, _mm_cvtsi32_si128(n as i32)) })
    }
}

impl Shr<u32> for AU {
    type Output = AU;
    #[inline(always)]
    fn shr(self, n: u32) -> AU {
        AU(unsafe { _mm256_srl_epi32(self.0, _mm_cvtsi32_si128(n as i32)) })
    }
}

impl UintLanes for AU {
    type M = AM;
    type F = AF;

    #[inline(always)]
    fn splat_like(self, v: u32) -> AU {
        AU(unsafe { _mm256_set1_epi32(v as i32) })
    }
    #[inline(always)]
    fn wrapping_add(self, o: AU) -> AU {
        AU(unsafe { _mm256_add_epi32(self.0, o.0) })
    }
    #[inline(always)]
    fn wrapping_mul(self, o: AU) -> AU {
        AU(unsafe { _mm256_mullo_epi32(self.0, o.0) })
    }
    #[inline(always)]
    fn reverse_bits(self) -> AU {
        // Where the whole build may use GFNI (pt's own builds on a CPU that has it), each
        // byte's bits are reversed by one affine transformation over GF(2).
        #[cfg(target_feature = "gfni")]
        unsafe {
            let bytes = _mm256_setr_epi8(
                3, 2, 1, 0, 7, 6, 5, 4, 11, 10, 9, 8, 15, 14, 13, 12, 3, 2, 1, 0, 7, 6, 5, 4, 11,
                10, 9, 8, 15, 14, 13, 12,
            );
            let x = _mm256_shuffle_epi8(self.0, bytes);
            let reverse = _mm256_set1_epi64x(0x8040_2010_0804_0201_u64 as i64);
            AU(_mm256_gf2p8affine_epi64_epi8::<0>(x, reverse))
        }
        #[cfg(not(target_feature = "gfni"))]
        unsafe {
            // Reverse the bytes of each lane, then the bits of each byte by two nibble tables.
            let bytes = _mm256_setr_epi8(
                3, 2, 1, 0, 7, 6, 5, 4, 11, 10, 9, 8, 15, 14, 13, 12, 3, 2, 1, 0, 7, 6, 5, 4, 11,
                10, 9, 8, 15, 14, 13, 12,
            );
            let x = _mm256_shuffle_epi8(self.0, bytes);
            // Nibble n reversed, as the low and as the high nibble of a byte.
            let rev = _mm256_setr_epi8(
                0x0, 0x8, 0x4, 0xc, 0x2, 0xa, 0x6, 0xe, 0x1, 0x9, 0x5, 0xd, 0x3, 0xb, 0x7, 0xf,
                0x0, 0x8, 0x4, 0xc, 0x2, 0xa, 0x6, 0xe, 0x1, 0x9, 0x5, 0xd, 0x3, 0xb, 0x7, 0xf,
            );
            let low = _mm256_set1_epi8(0x0f);
            let lo = _mm256_and_si256(x, low);
            let hi = _mm256_and_si256(_mm256_srli_epi16::<4>(x), low);
            let lo_rev_high = _mm256_slli_epi16::<4>(_mm256_shuffle_epi8(rev, lo));
            let hi_rev_low = _mm256_shuffle_epi8(rev, hi);
            AU(_mm256_or_si256(lo_rev_high, hi_rev_low))
        }
    }
    #[inline(always)]
    fn eq(self, o: AU) -> AM {
        AM(unsafe { _mm256_castsi256_ps(_mm256_cmpeq_epi32(self.0, o.0)) })
    }
    #[inline(always)]
    fn select(m: AM, a: AU, b: AU) -> AU {
        AU(unsafe {
            _mm256_castps_si256(blend(
                m.0,
                _mm256_castsi256_ps(a.0),
                _mm256_castsi256_ps(b.0),
            ))
        })
    }
    #[inline(always)]
    fn to_f32(self) -> AF {
        AF(unsafe { _mm256_cvtepi32_ps(self.0) })
    }
    #[inline(always)]
    fn to_bits_f32(self) -> AF {
        AF(unsafe { _mm256_castsi256_ps(self.0) })
    }
    #[inline(always)]
    fn to_array(self) -> [u32; WIDTH] {
        let mut out = [0u32; WIDTH];
        unsafe { _mm256_storeu_si256(out.as_mut_ptr().cast(), self.0) };
        out
    }
}

impl BitAnd for AM {
    type Output = AM;
    #[inline(always)]
    fn bitand(self, o: AM) -> AM {
        AM(unsafe { _mm256_and_ps(self.0, o.0) })
    }
}

impl BitOr for AM {
    type Output = AM;
    #[inline(always)]
    fn bitor(self, o: AM) -> AM {
        AM(unsafe { _mm256_or_ps(self.0, o.0) })
    }
}

impl Not for AM {
    type Output = AM;
    #[inline(always)]
    fn not(self) -> AM {
        AM(unsafe { _mm256_xor_ps(self.0, _mm256_castsi256_ps(_mm256_set1_epi32(-1))) })
    }
}

impl MaskLanes for AM {
    #[inline(always)]
    fn bits(self) -> u32 {
        (unsafe { _mm256_movemask_ps(self.0) }) as u32
    }
}
