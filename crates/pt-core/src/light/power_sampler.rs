//! Choosing which light to sample, in proportion to emitted power.

use crate::distribution::Distribution1D;
use crate::light::Light;

/// Picks a light with probability proportional to the luminance of its power. Lights with zero
/// power are never picked. With no (or only powerless) lights, nothing is sampled.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PowerLightSampler {
    distribution: Option<Distribution1D>,
    /// Each light's probability, `Distribution1D::pmf` computed once: a lookup instead of a
    /// division per sample.
    pmfs: Vec<f32>,
}

impl PowerLightSampler {
    /// Build from the scene's lights.
    #[must_use]
    pub fn new<L: Light>(lights: &[L]) -> Self {
        let weights: Vec<f32> = lights
            .iter()
            .map(|l| {
                let y = l.power().luminance();
                if y.is_finite() && y > 0.0 { y } else { 0.0 }
            })
            .collect();
        let distribution = Distribution1D::new(&weights);
        let pmfs = match &distribution {
            Some(d) => (0..weights.len()).map(|i| d.pmf(i)).collect(),
            None => Vec::new(),
        };
        Self { distribution, pmfs }
    }

    /// Choose a light: its index and probability, or `None` when no light can be sampled.
    #[inline]
    #[must_use]
    pub fn sample(&self, u: f32) -> Option<(usize, f32)> {
        let i = self.distribution.as_ref()?.sample_index(u);
        Some((i, self.pmfs[i]))
    }

    /// Choose a light as [`sample`](Self::sample) does, and also return `u` remapped to
    /// `[0, 1)` within the chosen light's share of `[0, 1)`: a fresh number for sampling a
    /// point on the light (next-event estimation draws one 2D sample for both the choice and
    /// the point, which keeps them stratified together). The remapped number keeps the bits of
    /// `u` the choice did not use: about 24 less the log2 of the light's share's reciprocal,
    /// plenty for scenes of up to tens of thousands of comparably bright lights.
    #[inline]
    #[must_use]
    pub fn sample_remapped(&self, u: f32) -> Option<(usize, f32, f32)> {
        let (i, _, remapped) = self.distribution.as_ref()?.sample_discrete(u);
        Some((i, self.pmfs[i], remapped))
    }

    /// `u`, which chose light `index` (by a search of its own over
    /// [`counted_cdf`](Self::counted_cdf)), remapped as [`sample_remapped`](Self::sample_remapped)
    /// remaps it.
    #[inline]
    #[must_use]
    pub(crate) fn remap(&self, index: usize, u: f32) -> f32 {
        self.distribution
            .as_ref()
            .map_or(0.0, |d| d.remap(index, u))
    }

    /// The cumulative distribution [`sample`](Self::sample) counts in, when there are at most
    /// eight lights (`Distribution1D::counted_cdf`).
    #[inline]
    #[must_use]
    pub(crate) fn counted_cdf(&self) -> Option<&[f32]> {
        self.distribution.as_ref()?.counted_cdf()
    }

    /// Probability that [`sample`](Self::sample) picks light `index`.
    #[inline]
    #[must_use]
    pub fn pmf(&self, index: usize) -> f32 {
        self.pmfs.get(index).copied().unwrap_or(0.0)
    }

    /// True when at least one light has power.
    #[inline]
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.distribution.is_none()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::color::Rgb;
    use crate::light::TriangleLight;
    use glam::Vec3;

    #[test]
    fn picks_in_proportion_to_power() {
        let tri = |s: f32, le: f32| {
            TriangleLight::new(
                [Vec3::ZERO, Vec3::X * s, Vec3::Y * s],
                Rgb::splat(le),
                false,
            )
            .unwrap()
        };
        let lights = [tri(1.0, 1.0), tri(2.0, 1.0), tri(1.0, 0.0001)];
        let s = PowerLightSampler::new(&lights);
        let total = 1.0 + 4.0 + 0.0001;
        assert!((s.pmf(0) - 1.0 / total).abs() < 1e-6);
        assert!((s.pmf(1) - 4.0 / total).abs() < 1e-6);
        assert_eq!(s.sample(0.5).unwrap().0, 1);
        assert!(
            PowerLightSampler::new::<TriangleLight>(&[])
                .sample(0.5)
                .is_none()
        );
    }

    #[test]
    fn remapped_choice_agrees_and_is_uniform_within_the_light() {
        let tri = |le: f32| {
            TriangleLight::new([Vec3::ZERO, Vec3::X, Vec3::Y], Rgb::splat(le), false).unwrap()
        };
        // Shares 0.2 and 0.8.
        let lights = [tri(1.0), tri(4.0)];
        let s = PowerLightSampler::new(&lights);
        let n = 10_000;
        let mut bins = [[0u32; 4]; 2];
        for k in 0..n {
            let u = (k as f32 + 0.5) / n as f32;
            let (i, pmf, r) = s.sample_remapped(u).unwrap();
            assert_eq!(Some((i, pmf)), s.sample(u), "u = {u}");
            assert!((0.0..1.0).contains(&r), "u = {u}: remapped {r}");
            bins[i][(r * 4.0) as usize] += 1;
        }
        // Evenly spaced `u` stay evenly spaced within each light's share: a quarter of the
        // light's draws in each quarter of [0, 1), to within rounding at the bins' edges.
        for (i, b) in bins.iter().enumerate() {
            let total: u32 = b.iter().sum();
            for &c in b {
                let expected = f64::from(total) / 4.0;
                assert!((f64::from(c) - expected).abs() <= 2.0, "light {i}: {b:?}");
            }
        }
    }
}
