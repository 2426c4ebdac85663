//! Integer hashing used to derive independent random streams from (seed, pixel, sample index).

/// A strong 64-bit finaliser (Stafford's variant 13 of the MurmurHash3 mixer, as in splitmix64).
#[inline]
#[must_use]
pub const fn mix_bits(mut v: u64) -> u64 {
    v ^= v >> 31;
    v = v.wrapping_mul(0x7fb5_d329_728e_a185);
    v ^= v >> 27;
    v = v.wrapping_mul(0x81da_def4_bc2d_d44d);
    v ^= v >> 33;
    v
}

/// Hash a sequence of words into 64 bits; order matters.
#[inline]
#[must_use]
pub fn hash_words(words: &[u64]) -> u64 {
    let mut h = 0x9e37_79b9_7f4a_7c15u64;
    for &w in words {
        h = mix_bits(h ^ w.wrapping_add(0x9e37_79b9_7f4a_7c15));
    }
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distinct_inputs_give_distinct_hashes() {
        let mut seen = std::collections::HashSet::new();
        for a in 0..64u64 {
            for b in 0..64u64 {
                assert!(seen.insert(hash_words(&[a, b])));
            }
        }
        assert_ne!(hash_words(&[1, 2]), hash_words(&[2, 1]));
    }
}
