//! The Sobol sampler for eight samples at once, one per SIMD lane: each lane draws exactly (bit
//! for bit) what a [`SobolSampler`](super::SobolSampler) draws for the same seed, pixel, sample
//! index and dimension, whatever the other lanes hold; the lanes' dimensions advance
//! independently (paths in different lanes bounce at different depths).

use glam::UVec2;
use pt_accel::lanes::{Simd, UintLanes, WIDTH};

use crate::sampler::scramble::lk_hash as lk_hash_one;
use crate::sampler::sobol::{
    DIMENSION_STEP, MIX32_MULTIPLIERS, SOBOL1_MASKS, VALUE_SEED_TAGS, draw_input, draw_seeds,
    pixel_key, sobol1_reversed_in, value_1d,
};

/// Eight Sobol samplers in lanes.
///
/// A draw's seeds are hashed from the lane's pixel key and dimension in lanes, with the scalar
/// sampler's operations ([`draw_seeds`]); the lanes keep each one's next hash input
/// ([`draw_input`]) and add [`DIMENSION_STEP`] to it as it draws.
#[derive(Clone, Debug)]
pub(crate) struct SobolLanes {
    seed: u64,
    /// The pixel started last and its key: the tile hands a pixel's samples to the lanes in
    /// turn, so the next sample's pixel is usually the same.
    last_pixel: Option<UVec2>,
    last_key: u32,
    reversed_index: [u32; WIDTH],
    /// Each lane's next draw's hash input: its pixel's key plus its dimension times
    /// [`DIMENSION_STEP`].
    input: [u32; WIDTH],
}

/// [`mix32`](super::sobol::mix32) in lanes.
#[inline(always)]
fn mix32<S: Simd>(s: S, mut x: S::U) -> S::U {
    let [m0, m1] = MIX32_MULTIPLIERS;
    x = x ^ (x >> 16);
    x = x.wrapping_mul(s.splat_u(m0));
    x = x ^ (x >> 15);
    x = x.wrapping_mul(s.splat_u(m1));
    x ^ (x >> 15)
}

/// [`lk_hash`](super::scramble::lk_hash) in lanes.
#[inline(always)]
fn lk_hash<S: Simd>(s: S, mut x: S::U, seed: S::U) -> S::U {
    x = x ^ x.wrapping_mul(s.splat_u(0x3d20_adea));
    x = x.wrapping_add(seed);
    x = x.wrapping_mul((seed >> 16) | s.splat_u(1));
    x = x ^ x.wrapping_mul(s.splat_u(0x0552_6c56));
    x ^ x.wrapping_mul(s.splat_u(0x53a2_2864))
}

/// [`fixed_to_unit`](super::scramble::fixed_to_unit) in lanes.
#[inline(always)]
fn fixed_to_unit<S: Simd>(s: S, v: S::U) -> S::F {
    (v >> 8).to_f32() * s.splat(1.0 / 16_777_216.0)
}

impl SobolLanes {
    /// Eight samplers for the render's seed.
    pub(crate) fn new(seed: u64) -> Self {
        Self {
            seed,
            last_pixel: None,
            last_key: 0,
            reversed_index: [0; WIDTH],
            input: [0; WIDTH],
        }
    }

    /// The key of `pixel` ([`pixel_key`]), remembered for the pixel asked for last: the tile
    /// hands a pixel's samples out in turn.
    #[inline]
    pub(crate) fn key(&mut self, pixel: UVec2) -> u32 {
        if self.last_pixel != Some(pixel) {
            self.last_pixel = Some(pixel);
            self.last_key = pixel_key(self.seed, pixel);
        }
        self.last_key
    }

    /// Start sample `index` of the pixel with `key` in lane `lane`, its first `dimensions`
    /// draws already made (by [`Self::draw_2d_at`]).
    #[inline]
    pub(crate) fn start_at(&mut self, lane: usize, key: u32, index: u32, dimensions: u32) {
        self.reversed_index[lane] = index.reverse_bits();
        self.input[lane] = draw_input(key, dimensions);
    }

    /// Draw `dimension` (a 2D one) of the samples whose pixel keys and indices are in the
    /// lanes, with no lane started: what [`Self::next_2d`] draws for a lane started with that
    /// key and index once it has made `dimension` draws. For draws made ahead of the lanes
    /// that will take the samples (the camera rays).
    #[inline(always)]
    pub(crate) fn draw_2d_at<S: Simd>(
        s: S,
        keys: S::U,
        indices: S::U,
        dimension: u32,
    ) -> (S::F, S::F) {
        let input = keys.wrapping_add(s.splat_u(dimension.wrapping_mul(DIMENSION_STEP)));
        let (x0, s_x, s_y) = seeds_and_index(s, input, indices.reverse_bits());
        values_2d_lanes(s, x0, s_x, s_y)
    }

    /// Advance the lanes in `mask` by one draw: the shuffled index's first Sobol coordinate and
    /// the two value seeds (the scalar sampler's `draw`).
    #[inline(always)]
    fn draw<S: Simd>(&mut self, s: S, mask: u32) -> (S::U, S::U, S::U) {
        let input = s.load_u(self.input);
        let drawn = seeds_and_index(s, input, s.load_u(self.reversed_index));
        let moved = S::U::select(
            s.mask(mask),
            input.wrapping_add(s.splat_u(DIMENSION_STEP)),
            input,
        );
        self.input = moved.to_array();
        drawn
    }

    /// The next value in `[0, 1)` of each lane in `mask` (other lanes: unspecified).
    #[inline(always)]
    pub(crate) fn next_1d<S: Simd>(&mut self, s: S, mask: u32) -> S::F {
        let (x0, s_x, _) = self.draw(s, mask);
        fixed_to_unit(s, lk_hash(s, x0.reverse_bits(), s_x).reverse_bits())
    }

    /// [`Self::draw`] for lane `lane` alone, with the scalar operations.
    #[inline(always)]
    fn draw_one(&mut self, lane: usize) -> (u32, u32, u32) {
        let (s_index, s_x, s_y) = draw_seeds(self.input[lane]);
        self.input[lane] = self.input[lane].wrapping_add(DIMENSION_STEP);
        (lk_hash_one(self.reversed_index[lane], s_index), s_x, s_y)
    }

    /// [`Self::next_1d`], a single lane in `mask` drawn by the scalar sampler's operations
    /// (the same bits; its dependent multiplies are 32-bit scalar ones, faster than the vector
    /// ones when one lane is all there is) and its value put in every lane (one lane written
    /// into an array and loaded whole, the load waited for the store).
    #[inline(always)]
    pub(crate) fn next_1d_lanes<S: Simd>(&mut self, s: S, mask: u32) -> S::F {
        if mask.is_power_of_two() {
            let lane = mask.trailing_zeros() as usize;
            let (x0, s_x, _) = self.draw_one(lane);
            return s.splat(value_1d(x0, s_x));
        }
        self.next_1d(s, mask)
    }

    /// The next two values in `[0, 1)` of each lane in `mask` (other lanes: unspecified).
    #[inline(always)]
    pub(crate) fn next_2d<S: Simd>(&mut self, s: S, mask: u32) -> (S::F, S::F) {
        let (x0, s_x, s_y) = self.draw(s, mask);
        values_2d_lanes(s, x0, s_x, s_y)
    }
}

/// A draw's shuffled index's first Sobol coordinate and its two value seeds, from its hash
/// input and the sample's reversed index (the scalar sampler's `draw`, in lanes).
#[inline(always)]
fn seeds_and_index<S: Simd>(s: S, input: S::U, reversed_index: S::U) -> (S::U, S::U, S::U) {
    let h = mix32(s, input);
    let [t0, t1] = VALUE_SEED_TAGS;
    let (s_x, s_y) = (mix32(s, h ^ s.splat_u(t0)), mix32(s, h ^ s.splat_u(t1)));
    (lk_hash(s, reversed_index, h), s_x, s_y)
}

/// A 2D draw's values from what [`seeds_and_index`] gives
/// ([`values_2d`](super::sobol::values_2d) in lanes).
#[inline(always)]
fn values_2d_lanes<S: Simd>(s: S, x0: S::U, s_x: S::U, s_y: S::U) -> (S::F, S::F) {
    let i = x0.reverse_bits();
    let [m0, m1, m2, m3] = SOBOL1_MASKS;
    let masks = [s.splat_u(m0), s.splat_u(m1), s.splat_u(m2), s.splat_u(m3)];
    let second = sobol1_reversed_in(i, masks);
    (
        fixed_to_unit(s, lk_hash(s, i, s_x).reverse_bits()),
        fixed_to_unit(s, lk_hash(s, second, s_y).reverse_bits()),
    )
}

#[cfg(test)]
mod tests {
    use glam::Vec2;
    use pt_accel::lanes::{FloatLanes, WithSimd, dispatch, dispatch_portable};

    use super::*;
    use crate::sampler::{Sampler, SobolSampler};

    /// Lanes at different pixels, sample indices and depths draw what eight scalar samplers
    /// draw, bit for bit, with the detected and the portable lanes.
    struct Compare;

    impl WithSimd for Compare {
        type Output = ();

        #[inline(always)]
        fn with_simd<S: Simd>(self, s: S) {
            let mut lanes = SobolLanes::new(42);
            let mut scalar: Vec<SobolSampler> = (0..WIDTH).map(|_| SobolSampler::new(42)).collect();
            // Pixels shared by several lanes at once (as a tile hands them out), and new ones.
            let start = |lane: usize, round: u32| {
                (
                    UVec2::new((lane as u32 % 3) * 7 + round / 40, 3 + round / 50),
                    (lane as u32) * 1000 + round * 5,
                )
            };
            for lane in 0..WIDTH {
                let (p, i) = start(lane, 0);
                let key = lanes.key(p);
                lanes.start_at(lane, key, i, 0);
                scalar[lane].start_pixel_sample(p, i);
            }
            for round in 0..200u32 {
                // Lanes take part in a draw in a pattern that changes every round, so their
                // dimensions drift apart; some restart.
                let mask = if round % 5 == 3 || round % 16 == 2 {
                    // One lane alone (`next_1d_lanes` then takes the scalar operations).
                    1 << (round as usize / 5 % WIDTH)
                } else {
                    (0x9e37_79b9u32.rotate_left(round) & 0xff) | 1
                };
                if round % 4 == 3 || round % 8 == 2 {
                    let v = lanes.next_1d_lanes(s, mask).to_array();
                    for lane in (0..WIDTH).filter(|l| mask & (1 << l) != 0) {
                        assert_eq!(v[lane].to_bits(), scalar[lane].next_1d().to_bits());
                    }
                } else if round % 2 == 0 {
                    let v = lanes.next_1d(s, mask).to_array();
                    for lane in (0..WIDTH).filter(|l| mask & (1 << l) != 0) {
                        assert_eq!(v[lane].to_bits(), scalar[lane].next_1d().to_bits());
                    }
                } else {
                    let (x, y) = lanes.next_2d(s, mask);
                    let (x, y) = (x.to_array(), y.to_array());
                    for lane in (0..WIDTH).filter(|l| mask & (1 << l) != 0) {
                        assert_eq!(Vec2::new(x[lane], y[lane]), scalar[lane].next_2d());
                    }
                }
                if round % 7 == 5 {
                    let lane = (round as usize / 7) % WIDTH;
                    let (p, i) = start(lane, round);
                    let key = lanes.key(p);
                    scalar[lane].start_pixel_sample(p, i);
                    if round % 2 == 0 {
                        lanes.start_at(lane, key, i, 0);
                    } else {
                        // Its first draw made ahead, as for camera rays.
                        let (x, y) = SobolLanes::draw_2d_at(s, s.splat_u(key), s.splat_u(i), 0);
                        let first = scalar[lane].next_2d();
                        assert_eq!(Vec2::new(x.to_array()[3], y.to_array()[3]), first);
                        lanes.start_at(lane, key, i, 1);
                    }
                }
            }
        }
    }

    /// Draws made ahead for eight samples (different pixels and indices in the lanes) are
    /// what fresh scalar samplers draw first and second.
    struct Ahead;

    impl WithSimd for Ahead {
        type Output = ();

        #[inline(always)]
        fn with_simd<S: Simd>(self, s: S) {
            let mut lanes = SobolLanes::new(7);
            let (mut keys, mut indices) = ([0; WIDTH], [0; WIDTH]);
            let mut expected = Vec::new();
            for lane in 0..WIDTH {
                let (p, i) = (UVec2::new(lane as u32 / 3, 5), 100 * lane as u32 + 3);
                (keys[lane], indices[lane]) = (lanes.key(p), i);
                let mut scalar = SobolSampler::new(7);
                scalar.start_pixel_sample(p, i);
                expected.push([scalar.next_2d(), scalar.next_2d()]);
            }
            for dimension in 0..2 {
                let (k, i) = (s.load_u(keys), s.load_u(indices));
                let (x, y) = SobolLanes::draw_2d_at(s, k, i, dimension);
                let (x, y) = (x.to_array(), y.to_array());
                for lane in 0..WIDTH {
                    let want = expected[lane][dimension as usize];
                    assert_eq!(Vec2::new(x[lane], y[lane]), want, "lane {lane}");
                }
            }
        }
    }

    #[test]
    fn draws_made_ahead_are_the_scalar_draws() {
        dispatch(Ahead);
        dispatch_portable(Ahead);
    }

    #[test]
    fn lanes_draw_what_scalar_samplers_draw() {
        dispatch(Compare);
        dispatch_portable(Compare);
    }
}
