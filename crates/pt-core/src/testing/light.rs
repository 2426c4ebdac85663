//! The histogram of a light's sampling routine.

use crate::testing::{Draw, Histogram, HistogramConfig, histogram_of};

/// The histogram of a light's `sample_li` from `ctx`, with `pdf_li` integrated over the cells.
/// `frame` rotates world directions into the frame the cells are laid out in (so that, for
/// example, an equirectangular map's texels align with the cells).
pub fn light_histogram<L: crate::light::Light>(
    light: &L,
    ctx: &crate::light::LightSampleContext,
    frame: glam::Mat3,
    config: &HistogramConfig,
) -> Histogram {
    let back = frame.transpose();
    histogram_of(
        config,
        |rng| match light.sample_li(ctx, rng.uniform2()) {
            None => Draw::Failed,
            Some(s) if light.flags().is_delta() => {
                let _ = s;
                Draw::Delta
            }
            Some(s) => Draw::Direction(frame * s.wi),
        },
        |w| f64::from(light.pdf_li(ctx, back * w)),
        !light.flags().is_delta(),
    )
}
