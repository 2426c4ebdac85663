//! The tests' random numbers: a xorshift64 generator, reproducible and dependency-free.

/// Uniform floats in `[0, 1)` with 24 random bits each, from `seed` (which must not be 0).
pub(crate) fn uniform(seed: u64) -> impl FnMut() -> f32 {
    let mut state = seed;
    move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 40) as f32 / 16_777_216.0
    }
}
