//! Every lane operation of the instruction set this CPU runs agrees with the portable lanes, bit
//! for bit (fused multiply-add within one rounding).

use super::*;

/// Every operation applied to two float and two integer inputs, as bits.
struct AllOps {
    a: [f32; WIDTH],
    b: [f32; WIDTH],
    x: [u32; WIDTH],
    y: [u32; WIDTH],
}

impl WithSimd for AllOps {
    type Output = Vec<[u32; WIDTH]>;

    #[inline(always)]
    fn with_simd<S: Simd>(self, s: S) -> Vec<[u32; WIDTH]> {
        let (a, b) = (s.load(self.a), s.load(self.b));
        let (x, y) = (s.load_u(self.x), s.load_u(self.y));
        let bits = |v: S::F| v.to_bits().to_array();
        let m = |m: S::M| [m.bits(), 0, 0, 0, 0, 0, 0, 0];
        // Keep inputs of the integer conversions in their documented range.
        let small = s.load(
            self.a
                .map(|v| if v.is_finite() { v.abs().min(1e9) } else { 3.0 }),
        );
        // Vectors whose coordinates are all different: a, b and the integers as floats.
        let v: [glam::Vec3; WIDTH] = std::array::from_fn(|i| {
            glam::Vec3::new(
                self.a[i],
                self.b[i],
                f32::from_bits(self.x[i] & 0x7f7f_ffff),
            )
        });
        let [vx, vy, vz] = s.load_vec3(&v);
        vec![
            bits(vx),
            bits(vy),
            bits(vz),
            bits(a + b),
            bits(a - b),
            bits(a * b),
            bits(a / b),
            bits(-a),
            bits(a.sqrt()),
            bits(a.abs()),
            bits(a.min(b)),
            bits(a.max(b)),
            bits(a.floor()),
            m(a.lt(b)),
            m(a.le(b)),
            m(a.gt(b)),
            m(a.ge(b)),
            m(a.eq(b)),
            m(a.is_finite()),
            bits(S::F::select(a.lt(b), a, b)),
            small.to_u32().to_array(),
            (x & y).to_array(),
            (x | y).to_array(),
            (x ^ y).to_array(),
            (x << 7).to_array(),
            (x >> 13).to_array(),
            (x << 40).to_array(),
            x.wrapping_add(y).to_array(),
            x.wrapping_mul(y).to_array(),
            x.reverse_bits().to_array(),
            m(x.eq(y)),
            S::U::select(x.eq(y), x, y).to_array(),
            (x >> 1).to_f32().to_bits().to_array(),
            x.to_bits_f32().to_bits().to_array(),
            m(s.mask(0b1010_0110)),
            m(!a.lt(b) & a.eq(a) | s.mask(1)),
            bits(s.splat(2.5)),
            s.splat_u(77).to_array(),
            bits(a.splat_like(-1.0)),
            x.splat_like(9).to_array(),
            bits(s.pick(&[self.a[0], self.b[1], self.a[2], self.b[3]], x)),
            [
                small.reduce_min().to_bits(),
                (-small).reduce_min().to_bits(),
                0,
                0,
                0,
                0,
                0,
                0,
            ],
        ]
    }
}

#[test]
fn the_detected_lanes_agree_with_the_portable_ones() {
    let mut state = 0x853c_49e6_748f_ea9bu64;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    let specials = [
        0.0,
        -0.0,
        1.0,
        -2.5,
        f32::INFINITY,
        f32::NEG_INFINITY,
        f32::NAN,
        1e-40,
        3.4e38,
        0.5,
    ];
    for round in 0..2000 {
        let mut f = || {
            let r = next();
            if round % 3 == 0 {
                specials[(r % specials.len() as u64) as usize]
            } else {
                f32::from_bits((r >> 32) as u32 & 0x7fff_ffff) * if r & 1 == 0 { 1.0 } else { -1.0 }
            }
        };
        let a: [f32; WIDTH] = std::array::from_fn(|_| f());
        let b: [f32; WIDTH] = std::array::from_fn(|_| f());
        let x: [u32; WIDTH] = std::array::from_fn(|_| next() as u32);
        let y: [u32; WIDTH] =
            std::array::from_fn(|i| if i % 3 == 0 { x[i] } else { next() as u32 });
        let want = dispatch_portable(AllOps { a, b, x, y });
        let got = dispatch(AllOps { a, b, x, y });
        // `Simd::run` from inside a dispatch runs the same lanes.
        assert_eq!(
            dispatch(Rerun(AllOps { a, b, x, y })),
            got,
            "round {round}: `run`"
        );
        for (k, (g, w)) in got.iter().zip(&want).enumerate() {
            // NaN payloads may differ between instruction sets; compare NaN as NaN.
            let same = g.iter().zip(w).all(|(&g, &w)| {
                g == w || (f32::from_bits(g).is_nan() && f32::from_bits(w).is_nan())
            });
            assert!(
                same,
                "operation {k}, round {round}: {g:x?} against {w:x?} for {a:?} {b:?}"
            );
        }
    }
}

/// `work` run again through [`Simd::run`] by the lanes it is dispatched to.
struct Rerun<W>(W);

impl<W: WithSimd> WithSimd for Rerun<W> {
    type Output = W::Output;
    #[inline(always)]
    fn with_simd<S: Simd>(self, s: S) -> W::Output {
        s.run(self.0)
    }
}

#[test]
fn fused_multiply_add_rounds_once_where_the_cpu_fuses() {
    struct Fma;
    impl WithSimd for Fma {
        type Output = [f32; WIDTH];
        #[inline(always)]
        fn with_simd<S: Simd>(self, s: S) -> [f32; WIDTH] {
            let a = s.load([0.1, 3.0, -2.0, 0.7, 1e10, 7.0, 0.0, 5.5]);
            // a * a - round(a * a): the rounding error of the product when fused, 0 when not.
            a.mul_add(a, -(a * a)).to_array()
        }
    }
    let (f, p) = (dispatch(Fma), dispatch_portable(Fma));
    assert_eq!(p, [0.0; WIDTH]);
    if detected() != Isa::Portable {
        // 0.1 and 0.7 squared are not floats: the fused result is the (tiny) rounding error.
        assert!(f[0] != 0.0 && f[0].abs() < 1e-9, "{f:?}");
        assert!(f[3] != 0.0 && f[3].abs() < 1e-8, "{f:?}");
        assert_eq!(f[1], 0.0);
    }
}

/// Which instruction set a job runs with, read from the token it is given.
struct Which;

impl WithSimd for Which {
    type Output = Isa;

    fn with_simd<S: Simd>(self, s: S) -> Isa {
        #[cfg(target_arch = "x86_64")]
        if let Some(t) = (&s as &dyn std::any::Any).downcast_ref::<avx2::Avx2Lanes>() {
            return if t.has_avx512() {
                Isa::Avx512
            } else {
                Isa::Avx2
            };
        }
        let _ = s;
        Isa::Portable
    }
}

/// `dispatch` and a stored `Found` (the BVH's packet kernels) run the instruction set the CPU
/// has, whatever the build's own target features: a build for x86-64-v3 knows AVX2 at compile
/// time but must still ask the CPU for AVX-512 (a shortcut that took the build's answer ran the
/// AVX2 entry there).
#[test]
fn found_and_dispatch_run_what_the_cpu_has() {
    assert_eq!(dispatch(Which), detected());
    assert_eq!(Found::detect().run(Which), detected());
}

/// The build script's names (`build.rs`) stand for exactly the target features the lane
/// dispatch relies on: a name set without its features would leave out the only entry a CPU
/// can take, a feature set without its name would compile the unreachable ones again.
#[test]
fn build_script_names_match_the_target_features() {
    let avx2 = cfg!(all(
        target_arch = "x86_64",
        target_feature = "avx2",
        target_feature = "fma",
        target_feature = "bmi1",
        target_feature = "bmi2",
        target_feature = "lzcnt",
        target_feature = "popcnt"
    ));
    let avx512 = avx2
        && cfg!(all(
            target_feature = "avx512f",
            target_feature = "avx512vl",
            target_feature = "avx512bw",
            target_feature = "avx512dq"
        ));
    assert_eq!(cfg!(pt_avx2_build), avx2);
    assert_eq!(cfg!(pt_avx512_build), avx512);
    if avx2 {
        assert_ne!(detected(), Isa::Portable);
    }
}
