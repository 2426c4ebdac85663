//! The Owen-scrambled Sobol sampler: low-discrepancy points with hash-based nested uniform
//! scrambling, randomised per pixel, with padded dimensions.
//!
//! Every draw (`next_1d`, `next_2d`, `pixel_2d`) is its own *padded* dimension: it takes the
//! first one or two dimensions of the Sobol sequence, with the sample index shuffled and the
//! values scrambled by seeds hashed from (seed, pixel, dimension). Within a draw the points of
//! a pixel are a scrambled (0, m, 2)-net for `2^m` samples (every elementary interval of area
//! `2^-m` holds exactly one point); across draws the shuffles differ, so bounces stay
//! decorrelated even though every draw reuses the best two Sobol dimensions. This is the padding
//! scheme of pbrt-v4's `PaddedSobolSampler` with the scrambling of B. Burley, "Practical
//! Hash-based Owen Scrambling", JCGT 9(4), 2020.

use glam::{UVec2, Vec2};

use crate::sampler::Sampler;
use crate::sampler::scramble::{fixed_to_unit, lk_hash};

/// Owen-scrambled Sobol points, deterministic per (seed, pixel, sample index, dimension).
///
/// Best with a power-of-two number of samples per pixel (the points of each draw are then
/// stratified in every elementary interval); any count works.
#[derive(Clone, Debug)]
pub struct SobolSampler {
    seed: u64,
    /// The pixel whose key is kept, and its key ([`pixel_key`]).
    pixel: Option<UVec2>,
    key: u32,
    /// The sample index with its bits reversed (what the index shuffle works on).
    reversed_index: u32,
    dimension: u32,
}

impl SobolSampler {
    /// A sampler for the given global seed.
    #[must_use]
    pub fn new(seed: u64) -> Self {
        Self {
            seed,
            pixel: None,
            key: 0,
            reversed_index: 0,
            dimension: 0,
        }
    }

    /// The per-draw seeds (one for the index shuffle, one per coordinate), and the first Sobol
    /// coordinate of the shuffled index, which is also the shuffled index with its bits
    /// reversed.
    ///
    /// With `r` the reversed index, the shuffled index is `i = reverse(lk(r))` (a nested
    /// uniform scramble), and Sobol dimension 0 of `i` is `reverse(i) = lk(r)`; working on
    /// reversed bits throughout saves four of the seven bit reversals a direct transcription
    /// would take for a 2D draw.
    #[inline]
    fn draw(&mut self) -> (u32, u32, u32) {
        let (s_index, s_x, s_y) = draw_seeds(draw_input(self.key, self.dimension));
        self.dimension += 1;
        let sobol0_of_shuffled = lk_hash(self.reversed_index, s_index);
        (sobol0_of_shuffled, s_x, s_y)
    }
}

/// The 32-bit key of a pixel from which its draws' seeds are hashed (shared with the lane
/// sampler).
#[inline]
pub(crate) fn pixel_key(seed: u64, pixel: UVec2) -> u32 {
    crate::hash::hash_words(&[
        seed,
        u64::from(pixel.x) | (u64::from(pixel.y) << 32),
        SOBOL_TAG,
    ]) as u32
}

/// Added to a draw's hash input per dimension: `key + dimension * DIMENSION_STEP` is the
/// input of draw `dimension` (the lane sampler adds it as lanes move on, instead of
/// multiplying).
pub(crate) const DIMENSION_STEP: u32 = 0x9e37_79b9;

/// The hash input of draw `dimension` of the pixel with `key`.
#[inline(always)]
pub(crate) fn draw_input(key: u32, dimension: u32) -> u32 {
    key.wrapping_add(dimension.wrapping_mul(DIMENSION_STEP))
}

/// The xor constants that tell the two value seeds apart ([`draw_seeds`]).
pub(crate) const VALUE_SEED_TAGS: [u32; 2] = [0x85eb_ca6b, 0xc2b2_ae35];

/// A draw's three seeds from its hash input ([`draw_input`]): the index shuffle's, the first
/// value's and the second value's.
///
/// Three 32-bit hashes ([`mix32`]): the lane sampler computes them for eight lanes at once
/// with the same operations, without a table or a per-lane step (the seeds of a pixel's draws
/// used to be 64-bit hashes cached per pixel, looked up lane by lane: 6% of Mitsuba's box).
#[inline(always)]
pub(crate) fn draw_seeds(input: u32) -> (u32, u32, u32) {
    let h = mix32(input);
    (
        h,
        mix32(h ^ VALUE_SEED_TAGS[0]),
        mix32(h ^ VALUE_SEED_TAGS[1]),
    )
}

/// The multipliers of [`mix32`].
pub(crate) const MIX32_MULTIPLIERS: [u32; 2] = [0x21f0_aaad, 0x735a_2d97];

/// A bijective 32-bit hash with full avalanche: xor-shifts and two odd multiplies (the
/// constants of C. Wellons' "lowbias32", from his hash-prospector search).
#[inline(always)]
pub(crate) fn mix32(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(MIX32_MULTIPLIERS[0]);
    x ^= x >> 15;
    x = x.wrapping_mul(MIX32_MULTIPLIERS[1]);
    x ^ (x >> 15)
}

/// The generator matrix of the second Sobol dimension (primitive polynomial `x + 1`, initial
/// direction number 1), column `j` for bit `j` of the index, as 32-bit fixed point.
#[cfg(test)]
const fn sobol1_columns() -> [u32; 32] {
    let mut v = [0u32; 32];
    let mut m = 1u32; // direction numbers m_k: m_1 = 1, m_k = (2 m_{k-1}) xor m_{k-1}
    let mut k = 0;
    while k < 32 {
        v[k] = m << (31 - k);
        m = (m << 1) ^ m;
        k += 1;
    }
    v
}

/// The second Sobol dimension of each byte of the index, for the four bytes: the matrix-vector
/// product over GF(2) is the xor of four table entries.
#[cfg(test)]
const SOBOL1_BYTES: [[u32; 256]; 4] = byte_tables(sobol1_columns());

/// Like [`SOBOL1_BYTES`] for the bit-reversed values: `reverse(sobol1(i))` (the tables
/// [`sobol1_reversed`] is checked against).
#[cfg(test)]
const SOBOL1_REVERSED_BYTES: [[u32; 256]; 4] = {
    let mut cols = sobol1_columns();
    let mut k = 0;
    while k < 32 {
        cols[k] = cols[k].reverse_bits();
        k += 1;
    }
    byte_tables(cols)
};

/// Per-byte tables of a GF(2) matrix given by its 32 columns.
#[cfg(test)]
const fn byte_tables(cols: [u32; 32]) -> [[u32; 256]; 4] {
    let mut t = [[0u32; 256]; 4];
    let mut byte = 0;
    while byte < 4 {
        let mut value = 0;
        while value < 256 {
            let mut x = 0u32;
            let mut bit = 0;
            while bit < 8 {
                if value & (1 << bit) != 0 {
                    x ^= cols[byte * 8 + bit];
                }
                bit += 1;
            }
            t[byte][value] = x;
            value += 1;
        }
        byte += 1;
    }
    t
}

/// Dimension 0 of the Sobol sequence (the van der Corput sequence), 32-bit fixed point.
#[cfg(test)]
#[inline]
#[must_use]
pub(crate) fn sobol0(index: u32) -> u32 {
    index.reverse_bits()
}

/// Dimension 1 of the Sobol sequence, 32-bit fixed point.
#[cfg(test)]
#[inline]
#[must_use]
pub(crate) fn sobol1(index: u32) -> u32 {
    apply(&SOBOL1_BYTES, index)
}

/// `sobol1(index).reverse_bits()`, without the reversal and without tables: the generator
/// matrix is Pascal's triangle mod 2 (column `k` holds the coefficients of `(x + 1)^k`), so bit
/// `d` of the reversed value is the xor of the index bits `k >= d` with `C(k, d)` odd. By
/// Lucas' theorem the matrix on `2n` bits is `[[P, P], [0, P]]` with `P` the matrix on `n`
/// bits: fold each block's upper half into its lower half, halving the block each step (five
/// shift-xor steps, the same in SIMD lanes).
#[inline]
#[must_use]
pub(crate) fn sobol1_reversed(index: u32) -> u32 {
    sobol1_reversed_in(index, SOBOL1_MASKS)
}

/// The masks of [`sobol1_reversed_in`]'s shift-xor steps.
pub(crate) const SOBOL1_MASKS: [u32; 4] = [0x00ff_00ff, 0x0f0f_0f0f, 0x3333_3333, 0x5555_5555];

/// [`sobol1_reversed`] for any `u32`-like lanes, `masks` being [`SOBOL1_MASKS`] in them (made
/// by the caller: no closure, which a baseline build may compile outside the lanes' entry).
#[inline(always)]
pub(crate) fn sobol1_reversed_in<U>(mut x: U, masks: [U; 4]) -> U
where
    U: Copy
        + std::ops::Shr<u32, Output = U>
        + std::ops::BitAnd<Output = U>
        + std::ops::BitXor<Output = U>,
{
    x = x ^ (x >> 16);
    x = x ^ ((x >> 8) & masks[0]);
    x = x ^ ((x >> 4) & masks[1]);
    x = x ^ ((x >> 2) & masks[2]);
    x ^ ((x >> 1) & masks[3])
}

#[cfg(test)]
#[inline]
fn apply(t: &[[u32; 256]; 4], index: u32) -> u32 {
    t[0][(index & 0xff) as usize]
        ^ t[1][((index >> 8) & 0xff) as usize]
        ^ t[2][((index >> 16) & 0xff) as usize]
        ^ t[3][(index >> 24) as usize]
}

/// "Sobol" in ASCII: the tag that keeps this sampler's streams apart from the others'.
pub(crate) const SOBOL_TAG: u64 = 0x536f_626f_6c00;

impl Sampler for SobolSampler {
    #[inline]
    fn start_pixel_sample(&mut self, pixel: UVec2, index: u32) {
        if self.pixel != Some(pixel) {
            self.pixel = Some(pixel);
            self.key = pixel_key(self.seed, pixel);
        }
        self.reversed_index = index.reverse_bits();
        self.dimension = 0;
    }

    #[inline(always)]
    fn next_1d(&mut self) -> f32 {
        let (x0, s_x, _) = self.draw();
        value_1d(x0, s_x)
    }

    #[inline(always)]
    fn next_2d(&mut self) -> Vec2 {
        let (x0, s_x, s_y) = self.draw();
        let (x, y) = values_2d(x0, s_x, s_y);
        Vec2::new(x, y)
    }
}

/// A 1D draw's value from `x0`, the first Sobol coordinate of the shuffled index, and the
/// value's seed (shared with the lane sampler's one-lane draws, which must give the same bits).
#[inline(always)]
pub(crate) fn value_1d(x0: u32, s_x: u32) -> f32 {
    // nested_uniform_scramble(x0, s_x), written out: x0 reversed is the shuffled index.
    fixed_to_unit(lk_hash(x0.reverse_bits(), s_x).reverse_bits())
}

/// A 2D draw's values from `x0` and the two values' seeds, as [`value_1d`].
#[inline(always)]
pub(crate) fn values_2d(x0: u32, s_x: u32, s_y: u32) -> (f32, f32) {
    let i = x0.reverse_bits();
    // Both scrambled values are bit-reversed by one 64-bit reversal (which costs what one
    // 32-bit reversal does): the first ends in the low half, the second in the high half.
    let pair = (u64::from(lk_hash(i, s_x)) << 32) | u64::from(lk_hash(sobol1_reversed(i), s_y));
    let pair = pair.reverse_bits();
    (
        fixed_to_unit(pair as u32),
        fixed_to_unit((pair >> 32) as u32),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sobol_dimensions_are_the_classic_ones() {
        // The first points of the 2D Sobol sequence (as Joe and Kuo's generator and scipy give
        // them): (0,0), (1/2,1/2), (3/4,1/4), (1/4,3/4), (3/8,3/8), (7/8,7/8), (5/8,1/8),
        // (1/8,5/8).
        let expect = [
            (0.0, 0.0),
            (0.5, 0.5),
            (0.75, 0.25),
            (0.25, 0.75),
            (0.375, 0.375),
            (0.875, 0.875),
            (0.625, 0.125),
            (0.125, 0.625),
        ];
        // The sequence index i is the Gray-code order's i-th point; without Gray code the
        // points are the same set in a different order. Compare as sets.
        let mut got: Vec<(f64, f64)> = (0..8u32)
            .map(|i| {
                (
                    f64::from(sobol0(i)) / 4_294_967_296.0,
                    f64::from(sobol1(i)) / 4_294_967_296.0,
                )
            })
            .collect();
        let mut want = expect.to_vec();
        got.sort_by(|a, b| a.partial_cmp(b).unwrap());
        want.sort_by(|a, b| a.partial_cmp(b).unwrap());
        assert_eq!(got, want);
        // The byte tables agree with the bit-by-bit product.
        let cols = sobol1_columns();
        for i in [1u32, 0x80, 0x1234_5678, 0xffff_ffff, 0x8000_0001] {
            let mut x = 0;
            for (bit, c) in cols.iter().enumerate() {
                if i & (1 << bit) != 0 {
                    x ^= c;
                }
            }
            assert_eq!(sobol1(i), x, "{i:#x}");
            assert_eq!(sobol1_reversed(i), x.reverse_bits(), "{i:#x}");
        }
        // The shift-xor form equals the matrix product (by tables) everywhere: every single
        // bit, and a million other indices.
        let mut x = 0x2545_f491u32;
        for i in (0..32).map(|b| 1u32 << b).chain((0..1_000_000).map(|_| {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            x
        })) {
            assert_eq!(
                sobol1_reversed(i),
                apply(&SOBOL1_REVERSED_BYTES, i),
                "{i:#x}"
            );
        }
    }

    /// The draws equal the direct transcription of the method: shuffle the index by a nested
    /// uniform scramble, take Sobol dimensions 0 and 1, scramble each value.
    #[test]
    fn draws_equal_the_direct_transcription() {
        use crate::sampler::scramble::nested_uniform_scramble as owen;
        let mut s = SobolSampler::new(99);
        let key = pixel_key(99, UVec2::new(7, 3));
        for index in [0u32, 1, 5, 255, 4096, 0xdead_beef] {
            s.start_pixel_sample(UVec2::new(7, 3), index);
            for draw in 0..60u32 {
                let h = mix32(key.wrapping_add(draw.wrapping_mul(0x9e37_79b9)));
                let s_index = h;
                let (s_x, s_y) = (mix32(h ^ 0x85eb_ca6b), mix32(h ^ 0xc2b2_ae35));
                let i = owen(index, s_index);
                let want_x = fixed_to_unit(owen(sobol0(i), s_x));
                if draw % 2 == 0 {
                    assert_eq!(s.next_1d(), want_x);
                } else {
                    let want_y = fixed_to_unit(owen(sobol1(i), s_y));
                    assert_eq!(s.next_2d(), Vec2::new(want_x, want_y));
                }
            }
        }
    }
}
