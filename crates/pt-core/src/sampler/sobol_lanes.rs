//! The Sobol sampler for eight samples at once, one per SIMD lane: each lane draws exactly (bit
//! for bit) what a [`SobolSampler`](super::SobolSampler) draws for the same seed, pixel, sample
//! index and dimension, whatever the other lanes hold; the lanes' dimensions advance
//! independently (paths in different lanes bounce at different depths).

use glam::UVec2;
use pt_accel::lanes::{FloatLanes, Simd, UintLanes, WIDTH};

use crate::sampler::scramble::{PixelSeeds, lk_hash as lk_hash_one};
use crate::sampler::sobol::{
    SOBOL_TAG, SOBOL1_MASKS, sobol1_reversed_in, split_seed, value_1d, values_2d,
};

/// Pixels whose dimension seeds are kept: twice the lanes, so that a lane starting a new pixel
/// always finds a slot no other lane uses.
const SLOTS: usize = 2 * WIDTH;

/// Eight Sobol samplers in lanes.
///
/// The per-pixel dimension seeds are kept in slots shared by the lanes: the tile hands the
/// samples of one pixel to the lanes in turn, and each would otherwise hash the same seeds again.
#[derive(Clone, Debug)]
pub(crate) struct SobolLanes {
    seed: u64,
    slots: [PixelSeeds; SLOTS],
    /// The slot each lane draws its seeds from.
    slot: [usize; WIDTH],
    /// Where the search for a free slot starts next.
    next_slot: usize,
    /// The slot of the pixel started last: the next sample is usually the same pixel's.
    last_slot: usize,
    reversed_index: [u32; WIDTH],
    dimension: [u32; WIDTH],
    /// Each lane's seeds of its next draw (index shuffle, first and second value), found
    /// when the lane moves on, long before the draw loads them as lanes: a load of eight
    /// fresh scalar stores would wait for all of them to retire.
    s_index: [u32; WIDTH],
    s_x: [u32; WIDTH],
    s_y: [u32; WIDTH],
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
            slots: std::array::from_fn(|_| PixelSeeds::new()),
            slot: std::array::from_fn(|i| i),
            next_slot: WIDTH,
            last_slot: 0,
            reversed_index: [0; WIDTH],
            dimension: [0; WIDTH],
            s_index: [0; WIDTH],
            s_x: [0; WIDTH],
            s_y: [0; WIDTH],
        }
    }

    /// Start sample `index` of `pixel` in lane `lane`.
    #[inline]
    pub(crate) fn start(&mut self, lane: usize, pixel: UVec2, index: u32) {
        // A pixel is in at most one slot, so the last pixel's slot, when it holds this pixel,
        // is the one the search would find (without its unpredictable branches).
        let last = self.last_slot % SLOTS;
        let found = if self.slots[last].pixel() == Some(pixel) {
            Some(last)
        } else {
            self.slots.iter().position(|s| s.pixel() == Some(pixel))
        };
        let slot = match found {
            Some(slot) => slot,
            None => {
                // A slot no other lane draws from (there are twice as many as lanes).
                let mut slot = self.next_slot;
                while (0..WIDTH).any(|l| l != lane && self.slot[l] == slot) {
                    slot = (slot + 1) % SLOTS;
                }
                self.next_slot = (slot + 1) % SLOTS;
                self.slots[slot].start_pixel(pixel, self.seed, SOBOL_TAG);
                slot
            }
        };
        self.slot[lane] = slot;
        self.last_slot = slot;
        self.reversed_index[lane] = index.reverse_bits();
        self.dimension[lane] = 0;
        self.find_seeds(lane);
    }

    /// The seeds of lane `lane`'s next draw.
    #[inline(always)]
    fn find_seeds(&mut self, lane: usize) {
        let h = self.slots[self.slot[lane]].dimension(self.dimension[lane]);
        (self.s_index[lane], self.s_x[lane], self.s_y[lane]) = split_seed(h);
    }

    /// Advance the lanes in `mask` by one draw: the shuffled index's first Sobol coordinate and
    /// the two value seeds (the scalar sampler's `draw`).
    #[inline(always)]
    fn draw<S: Simd>(&mut self, s: S, mask: u32) -> (S::U, S::U, S::U) {
        let (s_index, s_x, s_y) = (
            s.load_u(self.s_index),
            s.load_u(self.s_x),
            s.load_u(self.s_y),
        );
        let x0 = lk_hash(s, s.load_u(self.reversed_index), s_index);
        let mut m = mask;
        while m != 0 {
            let lane = m.trailing_zeros() as usize;
            m &= m - 1;
            self.dimension[lane] += 1;
            self.find_seeds(lane);
        }
        (x0, s_x, s_y)
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
        let x0 = lk_hash_one(self.reversed_index[lane], self.s_index[lane]);
        let (s_x, s_y) = (self.s_x[lane], self.s_y[lane]);
        self.dimension[lane] += 1;
        self.find_seeds(lane);
        (x0, s_x, s_y)
    }

    /// [`Self::next_1d`] as an array, a single lane by the scalar operations.
    #[inline(always)]
    pub(crate) fn next_1d_array<S: Simd>(&mut self, s: S, mask: u32) -> [f32; WIDTH] {
        if mask.is_power_of_two() {
            let lane = mask.trailing_zeros() as usize;
            let (x0, s_x, _) = self.draw_one(lane);
            let mut x = [0.0; WIDTH];
            x[lane] = value_1d(x0, s_x);
            return x;
        }
        self.next_1d(s, mask).to_array()
    }

    /// [`Self::next_2d`] as arrays (other lanes: unspecified), with a single lane in `mask`
    /// drawn by the scalar sampler's operations (the same bits; its dependent multiplies are
    /// 32-bit scalar ones, faster than the vector ones when one lane is all there is, as when
    /// one path ends and the next sample starts).
    #[inline(always)]
    pub(crate) fn next_2d_arrays<S: Simd>(
        &mut self,
        s: S,
        mask: u32,
    ) -> ([f32; WIDTH], [f32; WIDTH]) {
        if mask.is_power_of_two() {
            let lane = mask.trailing_zeros() as usize;
            let (x0, s_x, s_y) = self.draw_one(lane);
            let (mut x, mut y) = ([0.0; WIDTH], [0.0; WIDTH]);
            (x[lane], y[lane]) = values_2d(x0, s_x, s_y);
            return (x, y);
        }
        let (x, y) = self.next_2d(s, mask);
        (x.to_array(), y.to_array())
    }

    /// The next two values in `[0, 1)` of each lane in `mask` (other lanes: unspecified).
    #[inline(always)]
    pub(crate) fn next_2d<S: Simd>(&mut self, s: S, mask: u32) -> (S::F, S::F) {
        let (x0, s_x, s_y) = self.draw(s, mask);
        let i = x0.reverse_bits();
        let [m0, m1, m2, m3] = SOBOL1_MASKS;
        let masks = [s.splat_u(m0), s.splat_u(m1), s.splat_u(m2), s.splat_u(m3)];
        let second = sobol1_reversed_in(i, masks);
        (
            fixed_to_unit(s, lk_hash(s, i, s_x).reverse_bits()),
            fixed_to_unit(s, lk_hash(s, second, s_y).reverse_bits()),
        )
    }
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
                lanes.start(lane, p, i);
                scalar[lane].start_pixel_sample(p, i);
            }
            for round in 0..200u32 {
                // Lanes take part in a draw in a pattern that changes every round, so their
                // dimensions drift apart; some restart.
                let mask = if round % 5 == 3 || round % 16 == 2 {
                    // One lane alone (`next_2d_arrays` then takes the scalar operations).
                    1 << (round as usize / 5 % WIDTH)
                } else {
                    (0x9e37_79b9u32.rotate_left(round) & 0xff) | 1
                };
                if round % 4 == 3 {
                    let (x, y) = lanes.next_2d_arrays(s, mask);
                    for lane in (0..WIDTH).filter(|l| mask & (1 << l) != 0) {
                        assert_eq!(Vec2::new(x[lane], y[lane]), scalar[lane].next_2d());
                    }
                } else if round % 8 == 2 {
                    let v = lanes.next_1d_array(s, mask);
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
                    lanes.start(lane, p, i);
                    scalar[lane].start_pixel_sample(p, i);
                }
            }
        }
    }

    #[test]
    fn lanes_draw_what_scalar_samplers_draw() {
        dispatch(Compare);
        dispatch_portable(Compare);
    }
}
