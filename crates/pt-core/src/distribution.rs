//! Piecewise-constant 1D distributions for discrete choices (which light) and continuous
//! sampling (rows and columns of an environment map).

use glam::Vec2;

/// A piecewise-constant density over `[0, 1)` with `n` equal segments, proportional to
/// non-negative weights. Sampling is by binary search over the cumulative sum; from 256
/// segments on, a guide table narrows the search first (the same segment, found in
/// two or three steps instead of one per level, each a cache miss in a search through the
/// megabytes of a cube map's distribution).
#[derive(Clone, Debug, PartialEq)]
pub struct Distribution1D {
    func: Vec<f32>,
    /// `cdf[i] = sum of func[..i] / total`; `cdf[n] = 1`.
    cdf: Vec<f32>,
    integral: f32,
    /// Empty, or `K + 1` entries for a power of two `K`: `guide[k]` is the number of `cdf`
    /// values at most `k / K` (the cutpoint method of Chen and Asau, 1974). Both `k / K` and
    /// `u * K` are exact in f32, so a `u` in `[k / K, (k + 1) / K)` has its answer between
    /// `guide[k]` and `guide[k + 1]`.
    guide: Vec<u32>,
}

/// Distributions with at least this many segments get a guide table: below it the binary
/// search is a few steps through one or two cache lines.
const GUIDED: usize = 256;

/// Distributions with at most this many segments are searched by counting the `cdf` entries at
/// or below `u` (the same index as the binary search: the `cdf` is sorted), without branches:
/// a scene's light choice among a few lights was a mispredicted search per light sample.
const COUNTED: usize = 8;

impl Distribution1D {
    /// A distribution proportional to `weights`. Returns `None` when there are no weights, a
    /// weight is negative or not finite, or all weights are zero.
    #[must_use]
    pub fn new(weights: &[f32]) -> Option<Self> {
        let n = weights.len();
        if n == 0 || weights.iter().any(|w| !w.is_finite() || *w < 0.0) {
            return None;
        }
        // Accumulate in f64 so that long tails of small weights keep their mass.
        let mut cdf = Vec::with_capacity(n + 1);
        let mut acc = 0.0f64;
        cdf.push(0.0);
        for &w in weights {
            acc += w as f64;
            cdf.push(acc);
        }
        if acc <= 0.0 || !acc.is_finite() {
            return None;
        }
        let cdf = cdf
            .into_iter()
            .map(|c| (c / acc) as f32)
            .collect::<Vec<_>>();
        let guide = guide(&cdf);
        Some(Self {
            func: weights.to_vec(),
            cdf,
            integral: (acc / n as f64) as f32,
            guide,
        })
    }

    /// Number of segments.
    #[inline]
    #[must_use]
    pub fn len(&self) -> usize {
        self.func.len()
    }

    /// Always false: a distribution has at least one segment.
    #[inline]
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.func.is_empty()
    }

    /// Integral of the unnormalised step function over `[0, 1]` (the mean weight).
    #[inline]
    #[must_use]
    pub fn integral(&self) -> f32 {
        self.integral
    }

    /// The weights the distribution was built from.
    #[inline]
    #[must_use]
    pub fn weights(&self) -> &[f32] {
        &self.func
    }

    /// Index of the segment containing `u`: the largest `i` with `cdf[i] <= u`, skipping
    /// zero-weight segments.
    #[inline]
    fn find(&self, u: f32) -> usize {
        // partition_point gives the first index whose cdf exceeds u; the segment is the one
        // before. With a guide, the search runs only between the bounds of u's bucket.
        let i = if self.cdf.len() <= COUNTED + 1 {
            self.cdf.iter().map(|&c| usize::from(c <= u)).sum()
        } else if self.guide.len() > 1 && (0.0..1.0).contains(&u) {
            let k = (u * (self.guide.len() - 1) as f32) as usize;
            let (lo, hi) = (self.guide[k] as usize, self.guide[k + 1] as usize);
            lo + self.cdf[lo..hi].partition_point(|&c| c <= u)
        } else {
            self.cdf.partition_point(|&c| c <= u)
        };
        i.clamp(1, self.func.len()) - 1
    }

    /// The `cdf` (`len() + 1` entries from 0 to 1) of a distribution searched by counting
    /// (at most eight segments), for callers that count in SIMD lanes: the segment for `u` is
    /// the number of entries at or below `u`, clamped to `1..=len()`, minus one. `None` for
    /// longer distributions.
    #[inline]
    #[must_use]
    pub(crate) fn counted_cdf(&self) -> Option<&[f32]> {
        (self.cdf.len() <= COUNTED + 1).then_some(&self.cdf[..])
    }

    /// The segment [`sample_discrete`](Self::sample_discrete) chooses for `u`, alone.
    #[inline]
    #[must_use]
    pub fn sample_index(&self, u: f32) -> usize {
        self.find(u)
    }

    /// Choose a segment with probability proportional to its weight. Returns the index, its
    /// probability, and `u` remapped to `[0, 1)` within the segment (for reuse as a fresh sample).
    #[inline]
    #[must_use]
    pub fn sample_discrete(&self, u: f32) -> (usize, f32, f32) {
        let i = self.find(u);
        (i, self.pmf(i), self.remap(i, u))
    }

    /// `u`, which chose segment `i`, remapped to `[0, 1)` within the segment's range of the
    /// cdf (0 for an empty segment): what [`sample_discrete`](Self::sample_discrete) returns
    /// beside `i`, for callers that found `i` themselves (the lane tracer's counted search).
    #[inline]
    #[must_use]
    pub(crate) fn remap(&self, i: usize, u: f32) -> f32 {
        let (lo, hi) = (self.cdf[i], self.cdf[i + 1]);
        let width = hi - lo;
        if width > 0.0 {
            ((u - lo) / width).min(crate::sampling::ONE_MINUS_EPSILON)
        } else {
            0.0
        }
    }

    /// Probability of choosing segment `i` with [`sample_discrete`](Self::sample_discrete).
    #[inline]
    #[must_use]
    pub fn pmf(&self, i: usize) -> f32 {
        self.func
            .get(i)
            .map_or(0.0, |&w| w / (self.integral * self.func.len() as f32))
    }

    /// Sample a point in `[0, 1)` with density proportional to the step function. Returns the
    /// point, its density, and the segment index.
    #[inline]
    #[must_use]
    pub fn sample_continuous(&self, u: f32) -> (f32, f32, usize) {
        let i = self.find(u);
        let (lo, hi) = (self.cdf[i], self.cdf[i + 1]);
        let du = if hi > lo { (u - lo) / (hi - lo) } else { 0.0 };
        let x = ((i as f32 + du) / self.func.len() as f32).min(crate::sampling::ONE_MINUS_EPSILON);
        (x, self.func[i] / self.integral, i)
    }

    /// Density of [`sample_continuous`](Self::sample_continuous) at `x` in `[0, 1)`.
    #[inline]
    #[must_use]
    pub fn pdf_continuous(&self, x: f32) -> f32 {
        let n = self.func.len();
        let i = ((x * n as f32) as usize).min(n - 1);
        self.func[i] / self.integral
    }
}

/// The guide table of a cumulative sum (see [`Distribution1D`]'s `guide`): empty below
/// [`GUIDED`] segments, else with `K` the largest power of two not above a quarter of the
/// segment count (at most 2^22, where `k / K` stays exact in f32): a bucket holds about four
/// segments where the density is even, and the table costs a quarter of the cumulative sum's
/// memory.
fn guide(cdf: &[f32]) -> Vec<u32> {
    let n = cdf.len() - 1;
    if n < GUIDED || u32::try_from(cdf.len()).is_err() {
        return Vec::new();
    }
    let k_max = (1usize << (n / 4).ilog2()).min(1 << 22);
    let mut guide = Vec::with_capacity(k_max + 1);
    let mut j = 0;
    for k in 0..=k_max {
        let t = k as f32 / k_max as f32;
        while j < cdf.len() && cdf[j] <= t {
            j += 1;
        }
        guide.push(j as u32);
    }
    guide
}

/// A piecewise-constant density over `[0, 1)^2` on an `nu x nv` grid, proportional to
/// non-negative weights (row-major, `v` selects the row): a marginal distribution over rows and
/// one conditional distribution per row (pbrt's `PiecewiseConstant2D`).
#[derive(Clone, Debug, PartialEq)]
pub struct Distribution2D {
    conditional: Vec<Distribution1D>,
    marginal: Distribution1D,
}

impl Distribution2D {
    /// A distribution proportional to `weights` (`nu * nv` of them, row-major). Returns `None`
    /// when the sizes disagree, a weight is negative or not finite, or all are zero.
    #[must_use]
    pub fn new(weights: &[f32], nu: usize, nv: usize) -> Option<Self> {
        if nu == 0 || nv == 0 || weights.len() != nu * nv {
            return None;
        }
        let uniform = vec![1.0f32; nu];
        let mut conditional = Vec::with_capacity(nv);
        let mut row_weights = Vec::with_capacity(nv);
        for row in weights.chunks_exact(nu) {
            match Distribution1D::new(row) {
                Some(d) => {
                    row_weights.push(d.integral());
                    conditional.push(d);
                }
                None => {
                    if row.iter().any(|w| !w.is_finite() || *w < 0.0) {
                        return None;
                    }
                    // An all-zero row is never chosen; any conditional will do.
                    row_weights.push(0.0);
                    conditional.push(Distribution1D::new(&uniform)?);
                }
            }
        }
        Some(Self {
            marginal: Distribution1D::new(&row_weights)?,
            conditional,
        })
    }

    /// Sample a point with density proportional to the step function; returns it and its
    /// density.
    #[inline]
    #[must_use]
    pub fn sample_continuous(&self, u: Vec2) -> (Vec2, f32) {
        let (v, pdf_v, row) = self.marginal.sample_continuous(u.y);
        let (x, pdf_u, _) = self.conditional[row].sample_continuous(u.x);
        (Vec2::new(x, v), pdf_v * pdf_u)
    }

    /// Density of [`sample_continuous`](Self::sample_continuous) at `p` in `[0, 1)^2`.
    #[inline]
    #[must_use]
    pub fn pdf(&self, p: Vec2) -> f32 {
        let nv = self.conditional.len();
        let row = ((p.y * nv as f32) as usize).min(nv - 1);
        self.marginal.pdf_continuous(p.y) * self.conditional[row].pdf_continuous(p.x)
    }
}

/// A discrete distribution over many items in blocks of `B`, for the megabytes of an environment
/// map's texels: a [`Distribution1D`] over the blocks' sums (small enough to stay in the cache)
/// chooses a block, then the block's own running sums (`B` floats side by side, one or a few
/// cache lines) choose the item by counting. Sampling the full per-item distribution by one
/// search takes two dependent cache misses (a guide entry, then the cumulative sums) before
/// the texel; this takes one. The probabilities are the same (an item's weight over the total),
/// up to rounding.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct BlockDistribution<const B: usize> {
    blocks: Distribution1D,
    /// Per block, the running sums of its items' weights (the last is the block's sum).
    sums: Vec<Block<B>>,
    /// Sum of every weight: an item's probability is its weight over this.
    total: f32,
}

/// One block's running sums, cache-line aligned.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
struct Block<const B: usize>([f32; B]);

impl<const B: usize> BlockDistribution<B> {
    /// A distribution proportional to `weights` (a whole number of blocks, item `i` in block
    /// `i / B`). Returns `None` when there are no weights or not a whole number of blocks, a
    /// weight is negative or not finite, or all weights are zero.
    #[must_use]
    pub(crate) fn new(weights: &[f32]) -> Option<Self> {
        if weights.is_empty()
            || !weights.len().is_multiple_of(B)
            || weights.iter().any(|w| !w.is_finite() || *w < 0.0)
        {
            return None;
        }
        // The probabilities do not change with a common factor: weights near `f32::MAX` are
        // scaled down so that a block's running sums stay finite.
        let largest = weights.iter().fold(0.0f32, |m, &w| m.max(w));
        let scale = if largest > 1e30 { 1.0 / largest } else { 1.0 };
        let sums: Vec<Block<B>> = weights
            .chunks_exact(B)
            .map(|chunk| {
                let mut acc = 0.0f32;
                Block(std::array::from_fn(|k| {
                    acc += chunk[k] * scale;
                    acc
                }))
            })
            .collect();
        let block_sums: Vec<f32> = sums.iter().map(|b| b.0[B - 1]).collect();
        let total = block_sums.iter().map(|&w| f64::from(w)).sum::<f64>() as f32;
        if !total.is_finite() {
            return None;
        }
        Some(Self {
            blocks: Distribution1D::new(&block_sums)?,
            sums,
            total,
        })
    }

    /// Number of items (blocks times `B`).
    #[cfg(test)]
    pub(crate) fn len(&self) -> usize {
        self.sums.len() * B
    }

    /// Item `i`'s weight as sampled (a difference of running sums), 0 beyond the end.
    #[inline]
    #[must_use]
    pub(crate) fn weight(&self, i: usize) -> f32 {
        let Some(block) = self.sums.get(i / B) else {
            return 0.0;
        };
        let j = i % B;
        let lo = if j > 0 { block.0[j - 1] } else { 0.0 };
        block.0[j] - lo
    }

    /// Probability of choosing item `i` with [`sample_discrete`](Self::sample_discrete).
    #[inline]
    #[must_use]
    pub(crate) fn pmf(&self, i: usize) -> f32 {
        self.weight(i) / self.total
    }

    /// Ask for the cache lines that [`sample_discrete`](Self::sample_discrete) with this `u`
    /// will read (the chosen block's sums; the block distribution is small and cached).
    #[inline]
    pub(crate) fn prefetch(&self, u: f32) {
        let b = self.blocks.sample_index(u);
        if let Some(block) = self.sums.get(b) {
            for line in block.0.chunks(16) {
                pt_accel::lanes::prefetch(&line[0]);
            }
        }
    }

    /// Choose an item with probability proportional to its weight. Returns the index, its
    /// probability (0 only in the rounding case below), and `u` remapped to `[0, 1)` within
    /// the item.
    #[inline]
    #[must_use]
    pub(crate) fn sample_discrete(&self, u: f32) -> (usize, f32, f32) {
        let (b, _, u_block) = self.blocks.sample_discrete(u);
        let sums = &self.sums[b].0;
        let t = u_block * sums[B - 1];
        // The item whose range [sums[j - 1], sums[j]) holds `t`: the number of running sums at
        // or below it (items of zero weight have empty ranges and are never counted into).
        let mut j = sums.iter().map(|&c| usize::from(c <= t)).sum::<usize>();
        // `t` rounded up to the block's sum: the last item with weight.
        if j >= B {
            j = B - 1;
            while j > 0 && self.weight(b * B + j) <= 0.0 {
                j -= 1;
            }
        }
        let lo = if j > 0 { sums[j - 1] } else { 0.0 };
        let w = sums[j] - lo;
        if w <= 0.0 {
            return (b * B + j, 0.0, 0.0);
        }
        let remapped = ((t - lo) / w).clamp(0.0, crate::sampling::ONE_MINUS_EPSILON);
        (b * B + j, w / self.total, remapped)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_invalid_weights() {
        assert!(Distribution1D::new(&[]).is_none());
        assert!(Distribution1D::new(&[0.0, 0.0]).is_none());
        assert!(Distribution1D::new(&[1.0, -1.0]).is_none());
        assert!(Distribution1D::new(&[1.0, f32::NAN]).is_none());
    }

    #[test]
    fn discrete_sampling_follows_weights_and_skips_zeros() {
        let d = Distribution1D::new(&[1.0, 0.0, 3.0]).unwrap();
        assert_eq!(d.pmf(0), 0.25);
        assert_eq!(d.pmf(1), 0.0);
        assert_eq!(d.pmf(2), 0.75);
        let n = 10_000;
        let mut counts = [0usize; 3];
        for i in 0..n {
            let u = (i as f32 + 0.5) / n as f32;
            let (k, p, r) = d.sample_discrete(u);
            assert!((0.0..1.0).contains(&r));
            assert_eq!(p, d.pmf(k));
            counts[k] += 1;
        }
        assert_eq!(counts, [2500, 0, 7500]);
        // The edges of the range map to valid segments.
        assert_eq!(d.sample_discrete(0.0).0, 0);
        assert_eq!(d.sample_discrete(crate::sampling::ONE_MINUS_EPSILON).0, 2);
    }

    /// The guided search finds exactly the segment the plain binary search finds: weights with
    /// runs of zeros, a peak and a long faint tail; `u` at every cumulative value and its
    /// neighbours, at every bucket edge and its neighbours, at random, and outside `[0, 1)`.
    #[test]
    fn guided_search_equals_binary_search() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut rnd = move || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        for n in [GUIDED, 5000, 3 * 128 * 128] {
            let weights: Vec<f32> = (0..n)
                .map(|i| match i % 97 {
                    0..=9 => 0.0,
                    10 => 1e4 * rnd(),
                    _ if i > n / 2 => 1e-6 * rnd(),
                    _ => rnd(),
                })
                .collect();
            let d = Distribution1D::new(&weights).unwrap();
            assert!(d.guide.len() > 1, "{n} segments have no guide");
            let plain = |u: f32| d.cdf.partition_point(|&c| c <= u).clamp(1, n) - 1;
            // The neighbouring floats of a value in [0, 1] (`f32::next_up` needs Rust 1.86).
            let around = |x: f32| {
                let b = x.to_bits();
                [
                    x,
                    f32::from_bits(b.saturating_sub(1)),
                    f32::from_bits(b + 1),
                ]
            };
            let mut us: Vec<f32> = d.cdf.iter().flat_map(|&c| around(c)).collect();
            let k = d.guide.len() - 1;
            for b in 0..=k {
                us.extend(around(b as f32 / k as f32));
            }
            us.extend((0..100_000).map(|_| rnd()));
            us.extend([-1.0, -0.0, 1.0, 2.0, f32::NAN, f32::INFINITY]);
            us.push(crate::sampling::ONE_MINUS_EPSILON);
            for u in us {
                assert_eq!(d.find(u), plain(u), "n {n}, u {u:e}");
            }
        }
        // Small distributions search without a guide.
        assert!(Distribution1D::new(&[1.0; 16]).unwrap().guide.is_empty());
    }

    /// The counted search of small distributions finds the binary search's segment for every
    /// `u`, zero-weight segments (first, inner, last) and values outside `[0, 1)` included.
    #[test]
    fn counted_search_equals_binary_search() {
        let cases: [&[f32]; 7] = [
            &[1.0],
            &[0.0, 1.0],
            &[1.0, 0.0],
            &[0.25, 0.0, 0.0, 2.0],
            &[3.0, 1e-7, 0.0, 1.0, 5.0],
            &[1.0; COUNTED],
            &[0.0, 1.0, 0.0, 2.0, 0.0, 3.0, 0.0, 0.0],
        ];
        for w in cases {
            let d = Distribution1D::new(w).unwrap();
            let n = w.len();
            let plain = |u: f32| d.cdf.partition_point(|&c| c <= u).clamp(1, n) - 1;
            let mut us: Vec<f32> = (0..=4096).map(|i| i as f32 / 4096.0).collect();
            for &c in &d.cdf {
                let b = c.to_bits();
                us.extend([
                    c,
                    f32::from_bits(b.saturating_sub(1)),
                    f32::from_bits(b + 1),
                ]);
            }
            us.extend([-1.0, -0.0, 1.0, 2.0, f32::NAN, f32::INFINITY]);
            us.push(crate::sampling::ONE_MINUS_EPSILON);
            for u in us {
                assert_eq!(d.find(u), plain(u), "{w:?}, u {u:e}");
                assert!(
                    w[d.find(u)] > 0.0 || !(0.0..1.0).contains(&u),
                    "{w:?}, u {u:e}"
                );
            }
        }
    }

    /// The blocked distribution chooses each item with its weight's share (zeros never, a
    /// block of zeros never, a peak and a faint tail), and its probabilities sum to 1.
    #[test]
    fn block_sampling_follows_weights() {
        let mut weights = vec![0.0f32; 4 * 16];
        for (i, w) in weights.iter_mut().enumerate() {
            *w = match i {
                0..=15 => 0.0,
                20 => 100.0,
                _ if i % 5 == 0 => 0.0,
                _ if i >= 48 => 1e-3,
                _ => (i % 7) as f32 + 0.5,
            };
        }
        let d = BlockDistribution::<16>::new(&weights).unwrap();
        assert_eq!(d.len(), 64);
        let total: f64 = weights.iter().map(|&w| f64::from(w)).sum();
        let mut sum = 0.0f64;
        for (i, &w) in weights.iter().enumerate() {
            let expected = f64::from(w) / total;
            assert!(
                (f64::from(d.pmf(i)) - expected).abs() < 1e-6 * expected.max(1e-3),
                "{i}"
            );
            sum += f64::from(d.pmf(i));
        }
        assert!((sum - 1.0).abs() < 1e-5);
        let n = 1 << 20;
        let mut counts = vec![0usize; 64];
        for k in 0..n {
            let u = (k as f32 + 0.5) / n as f32;
            let (i, p, r) = d.sample_discrete(u);
            assert!((0.0..1.0).contains(&r), "u {u}: remapped {r}");
            assert_eq!(p, d.pmf(i));
            counts[i] += 1;
        }
        for (i, &c) in counts.iter().enumerate() {
            let expected = f64::from(d.pmf(i)) * n as f64;
            // Stratified `u`: each item's count is its share to within a couple of samples
            // per block boundary.
            assert!(
                (c as f64 - expected).abs() <= 4.0,
                "item {i}: {c} against {expected}"
            );
        }
        // The ends of the range map to items with weight.
        for u in [0.0, crate::sampling::ONE_MINUS_EPSILON] {
            let (i, p, _) = d.sample_discrete(u);
            assert!(weights[i] > 0.0 && p > 0.0, "u {u}: item {i}");
        }
        // Weights near the largest float: the same choices as small ones.
        let huge: Vec<f32> = weights.iter().map(|&w| w * 3e36).collect();
        let h = BlockDistribution::<16>::new(&huge).unwrap();
        for i in 0..64 {
            assert!(
                (h.pmf(i) - d.pmf(i)).abs() <= 1e-6 * d.pmf(i).max(1e-3),
                "{i}"
            );
        }
        assert!(BlockDistribution::<16>::new(&[1.0; 17]).is_none());
        assert!(BlockDistribution::<16>::new(&[0.0; 32]).is_none());
        assert!(BlockDistribution::<16>::new(&[f32::NAN; 16]).is_none());
        assert!(BlockDistribution::<16>::new(&[]).is_none());
    }

    #[test]
    fn continuous_pdf_integrates_to_one() {
        let d = Distribution1D::new(&[0.5, 2.0, 0.0, 1.5]).unwrap();
        let n = 4000;
        let integral: f32 = (0..n)
            .map(|i| d.pdf_continuous((i as f32 + 0.5) / n as f32))
            .sum::<f32>()
            / n as f32;
        assert!((integral - 1.0).abs() < 1e-5);
        let (x, pdf, i) = d.sample_continuous(0.3);
        assert_eq!(pdf, d.pdf_continuous(x));
        assert_eq!(i, 1);
    }
}
