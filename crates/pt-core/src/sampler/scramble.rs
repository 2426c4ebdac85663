//! Hash-based scrambling and permutation: the randomisation behind the stratified and Sobol
//! samplers.
//!
//! - `nested_uniform_scramble` (compiled for the tests): Owen scrambling of a 32-bit
//!   fixed-point value in base 2, as a hash in the style of Laine and Karras (2011) applied
//!   to the bit-reversed value. Every operation of [`lk_hash`] is a bijection in which output
//!   bit `k` depends only on input bits `<= k`; on reversed bits that is exactly the structure
//!   of a nested uniform scramble (each digit is flipped by a function of the digits above
//!   it). The constants are those of the
//!   improved hash of N. Vegdahl (2021), adopted by B. Burley, "Practical Hash-based Owen
//!   Scrambling", JCGT 9(4), 2020.
//! - [`permute`]: a pseudo-random permutation of `0..n` for any `n`: a keyed Feistel network
//!   over the next even power of two, restricted to `0..n` by cycle walking (the restriction
//!   of A. Kensler, "Correlated Multi-Jittered Sampling", 2013; the network is the classic
//!   format-preserving construction).

/// A 32-bit hash in which output bit `k` depends only on input bits `0..=k` (and the seed), and
/// which is a bijection for every seed.
#[inline]
#[must_use]
pub(crate) fn lk_hash(mut x: u32, seed: u32) -> u32 {
    x ^= x.wrapping_mul(0x3d20_adea);
    x = x.wrapping_add(seed);
    x = x.wrapping_mul((seed >> 16) | 1);
    x ^= x.wrapping_mul(0x0552_6c56);
    x ^= x.wrapping_mul(0x53a2_2864);
    x
}

/// Owen-scramble the binary digits of `x` (most significant first) with `seed`: digit `k` is
/// flipped by a function of the seed and the digits above it. Applied to a value in fixed point
/// this keeps every elementary interval's count; applied to a sample index it shuffles the
/// indices of every aligned block of `2^m` samples among themselves.
#[cfg(test)]
#[inline]
#[must_use]
pub(crate) fn nested_uniform_scramble(x: u32, seed: u32) -> u32 {
    lk_hash(x.reverse_bits(), seed).reverse_bits()
}

/// A 64-bit hash of a per-pixel seed and a dimension, for per-dimension scramble seeds.
#[inline]
#[must_use]
pub(crate) fn dimension_hash(pixel_seed: u64, dimension: u32) -> u64 {
    crate::hash::mix_bits(pixel_seed ^ u64::from(dimension).wrapping_mul(0x9e37_79b9_7f4a_7c15))
}

/// How many dimensions' seeds [`PixelSeeds`] keeps (a path of 9 bounces takes about 45 draws;
/// deeper draws hash their seed each time).
const CACHED_DIMENSIONS: usize = 48;

/// The per-pixel seed and the per-dimension seeds hashed from it, kept while the renderer takes
/// the samples of one pixel. Every sample of a pixel uses the same seed for a dimension, so it
/// is hashed once per pixel instead of once per draw. A pure cache: values never depend on it.
#[derive(Clone, Debug)]
pub(crate) struct PixelSeeds {
    pixel: Option<glam::UVec2>,
    pixel_seed: u64,
    filled: u32,
    seeds: [u64; CACHED_DIMENSIONS],
}

impl PixelSeeds {
    pub(crate) fn new() -> Self {
        Self {
            pixel: None,
            pixel_seed: 0,
            filled: 0,
            seeds: [0; CACHED_DIMENSIONS],
        }
    }

    /// Switch to `pixel` of a render with `seed`; `tag` tells samplers apart, so that two
    /// samplers given the same seed draw unrelated values. The pixel's seed is hashed only when
    /// the pixel changes.
    #[inline]
    pub(crate) fn start_pixel(&mut self, pixel: glam::UVec2, seed: u64, tag: u64) {
        if self.pixel != Some(pixel) {
            self.pixel = Some(pixel);
            self.pixel_seed = crate::hash::hash_words(&[
                seed,
                u64::from(pixel.x) | (u64::from(pixel.y) << 32),
                tag,
            ]);
            self.filled = 0;
        }
    }

    /// The seed of the current pixel.
    #[inline]
    pub(crate) fn pixel_seed(&self) -> u64 {
        self.pixel_seed
    }

    /// `dimension_hash(pixel_seed, dimension)`, from the cache when it can.
    #[inline]
    pub(crate) fn dimension(&mut self, dimension: u32) -> u64 {
        let d = dimension as usize;
        if d >= CACHED_DIMENSIONS {
            return dimension_hash(self.pixel_seed, dimension);
        }
        while self.filled <= dimension {
            self.seeds[self.filled as usize] = dimension_hash(self.pixel_seed, self.filled);
            self.filled += 1;
        }
        self.seeds[d]
    }
}

/// Element `i` of a pseudo-random permutation of `0..n` selected by `seed` (`i < n`).
///
/// A four-round Feistel network keyed by the seed permutes the `2^(2h)` values of the smallest
/// even bit width that holds `n`; walking the cycle until the value falls below `n` makes it a
/// permutation of `0..n` (on average fewer than four steps).
#[inline]
#[must_use]
pub(crate) fn permute(mut i: u32, n: u32, seed: u32) -> u32 {
    debug_assert!(i < n);
    if n <= 1 {
        return 0;
    }
    let bits = 32 - (n - 1).leading_zeros();
    let half = bits.div_ceil(2);
    let half_mask = (1u32 << half) - 1;
    // Round keys: the seed and three odd multiples of it, rotated apart.
    let keys = [
        seed,
        seed.wrapping_mul(0x9e37_79b9).rotate_left(11),
        seed.wrapping_mul(0x85eb_ca6b).rotate_left(19),
        seed.wrapping_mul(0xc2b2_ae35).rotate_left(5),
    ];
    loop {
        let (mut left, mut right) = (i >> half, i & half_mask);
        for key in keys {
            // Round function: a multiplicative hash of the right half and the key, top bits.
            let f = ((right ^ key).wrapping_mul(0x2c1b_3c6d) ^ key).wrapping_mul(0x297a_2d39)
                >> (32 - half);
            (left, right) = (right, left ^ f);
        }
        i = (left << half) | right;
        if i < n {
            return i;
        }
    }
}

/// Map 32 bits of fixed point to a float in `[0, 1)` (24 bits kept, so it never rounds to 1).
#[inline]
#[must_use]
pub(crate) fn fixed_to_unit(v: u32) -> f32 {
    (v >> 8) as f32 * (1.0 / 16_777_216.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn permute_is_a_bijection_for_every_size() {
        for n in 1..=300u32 {
            for seed in [0u32, 1, 0xdead_beef, 0x1234_5678] {
                let mut seen = vec![false; n as usize];
                for i in 0..n {
                    let p = permute(i, n, seed);
                    assert!(p < n, "n {n}: {i} -> {p}");
                    assert!(!seen[p as usize], "n {n} seed {seed}: {p} twice");
                    seen[p as usize] = true;
                }
            }
        }
        // Different seeds give different permutations.
        let a: Vec<u32> = (0..64).map(|i| permute(i, 64, 1)).collect();
        let b: Vec<u32> = (0..64).map(|i| permute(i, 64, 2)).collect();
        assert_ne!(a, b);
    }

    #[test]
    fn nested_scramble_permutes_aligned_blocks() {
        // Owen scrambling maps every aligned block of 2^m values onto an aligned block of 2^m
        // (for the index shuffle: the first 2^m samples stay one Sobol block).
        for seed in [3u32, 0x9e37_79b9, 0xffff_ffff] {
            for m in 0..8u32 {
                let block = 1u32 << m;
                for start in [0u32, block * 5] {
                    let out: Vec<u32> = (start..start + block)
                        .map(|i| nested_uniform_scramble(i, seed))
                        .collect();
                    let base = out[0] & !(block - 1);
                    let mut seen = vec![false; block as usize];
                    for v in out {
                        assert_eq!(v & !(block - 1), base, "seed {seed} m {m}");
                        assert!(!seen[(v & (block - 1)) as usize]);
                        seen[(v & (block - 1)) as usize] = true;
                    }
                }
            }
        }
    }

    #[test]
    fn scrambled_digits_depend_only_on_higher_digits() {
        // Changing a low digit of the input never changes a higher digit of the output.
        for seed in [7u32, 0xabcd_ef01] {
            for x in [0u32, 0x8000_0000, 0x1234_5678, 0xffff_ffff] {
                for bit in 0..32 {
                    let a = nested_uniform_scramble(x, seed);
                    let b = nested_uniform_scramble(x ^ (1 << bit), seed);
                    let above = !((2u64 << bit) - 1) as u32;
                    assert_eq!(a & above, b & above, "bit {bit}");
                    assert_ne!(a, b);
                }
            }
        }
    }
}
