//! Converting measured spectra to linear sRGB, for presets built from published spectral data.
//!
//! The CIE 1931 2-degree colour matching functions are approximated by the multi-lobe Gaussian
//! fit of Wyman, Sloan and Shirley, "Simple Analytic Approximations to the CIE XYZ Color Matching
//! Functions", JCGT 2(2), 2013 (under 1% error against the tables). XYZ goes to linear sRGB with
//! the standard D65 matrix, and each channel is divided by that of a constant spectrum of 1 over
//! the same wavelength range: a flat spectrum of value `v` maps to `(v, v, v)`, which is what an
//! RGB renderer means by a grey albedo or a white light of radiance `v`.

use pt_core::Rgb;

fn lobe(l: f64, mu: f64, s1: f64, s2: f64) -> f64 {
    let s = if l < mu { s1 } else { s2 };
    (-0.5 * ((l - mu) / s).powi(2)).exp()
}

/// The fitted CIE 1931 colour matching functions at wavelength `l` in nm.
fn cmf(l: f64) -> [f64; 3] {
    [
        1.056 * lobe(l, 599.8, 37.9, 31.0) + 0.362 * lobe(l, 442.0, 16.0, 26.7)
            - 0.065 * lobe(l, 501.1, 20.4, 26.2),
        0.821 * lobe(l, 568.8, 46.9, 40.5) + 0.286 * lobe(l, 530.9, 16.3, 31.1),
        1.217 * lobe(l, 437.0, 11.8, 36.0) + 0.681 * lobe(l, 459.0, 26.0, 13.8),
    ]
}

fn xyz_to_linear_srgb(c: [f64; 3]) -> [f64; 3] {
    [
        3.240_454_2 * c[0] - 1.537_138_5 * c[1] - 0.498_531_4 * c[2],
        -0.969_266 * c[0] + 1.876_010_8 * c[1] + 0.041_556 * c[2],
        0.055_643_4 * c[0] - 0.204_025_9 * c[1] + 1.057_225_2 * c[2],
    ]
}

/// Unnormalised sRGB of a spectrum over `[lo, hi]` nm, by the trapezoid rule at 1 nm.
fn integrate(lo: f64, hi: f64, value: impl Fn(f64) -> f64) -> [f64; 3] {
    let n = (hi - lo).round() as usize;
    let mut xyz = [0.0f64; 3];
    for i in 0..=n {
        let l = lo + i as f64;
        let w = if i == 0 || i == n { 0.5 } else { 1.0 };
        let v = value(l) * w;
        for (acc, c) in xyz.iter_mut().zip(cmf(l)) {
            *acc += v * c;
        }
    }
    xyz_to_linear_srgb(xyz)
}

/// Linear, white-balanced sRGB of a spectrum given as (wavelength nm, value) knots with linear
/// interpolation in between, over the knots' wavelength range.
///
/// # Panics
/// If fewer than two knots are given or the wavelengths do not increase.
#[must_use]
pub fn spectrum_to_rgb(knots: &[(f32, f32)]) -> Rgb {
    assert!(
        knots.len() >= 2 && knots.windows(2).all(|w| w[1].0 > w[0].0),
        "knots must increase"
    );
    let (lo, hi) = (f64::from(knots[0].0), f64::from(knots[knots.len() - 1].0));
    let value = |l: f64| {
        let i = knots
            .partition_point(|k| f64::from(k.0) <= l)
            .clamp(1, knots.len() - 1);
        let ((a, va), (b, vb)) = (knots[i - 1], knots[i]);
        let t = (l - f64::from(a)) / f64::from(b - a);
        f64::from(va) + (f64::from(vb) - f64::from(va)) * t.clamp(0.0, 1.0)
    };
    let c = integrate(lo, hi, value);
    let white = integrate(lo, hi, |_| 1.0);
    Rgb::new(
        (c[0] / white[0]) as f32,
        (c[1] / white[1]) as f32,
        (c[2] / white[2]) as f32,
    )
}

/// [`spectrum_to_rgb`] for values sampled at `start, start + step, ...` nm.
#[must_use]
pub fn sampled_spectrum_to_rgb(start_nm: f32, step_nm: f32, values: &[f32]) -> Rgb {
    let knots: Vec<(f32, f32)> = values
        .iter()
        .enumerate()
        .map(|(i, &v)| (start_nm + step_nm * i as f32, v))
        .collect();
    spectrum_to_rgb(&knots)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::presets::cornell_data as data;

    fn close(a: Rgb, b: [f32; 3]) -> bool {
        (a.r - b[0]).abs() < 1e-3 && (a.g - b[1]).abs() < 1e-3 && (a.b - b[2]).abs() < 1e-3
    }

    #[test]
    fn flat_spectrum_is_grey() {
        let c = spectrum_to_rgb(&[(400.0, 0.5), (700.0, 0.5)]);
        assert!(close(c, [0.5, 0.5, 0.5]), "{c:?}");
    }

    #[test]
    fn cornell_colors_match_an_independent_computation() {
        // Values computed independently (Python, same fit and matrix) when the preset was written.
        let white = sampled_spectrum_to_rgb(data::START_NM, data::STEP_NM, &data::WHITE);
        let red = sampled_spectrum_to_rgb(data::START_NM, data::STEP_NM, &data::RED);
        let green = sampled_spectrum_to_rgb(data::START_NM, data::STEP_NM, &data::GREEN);
        let light = spectrum_to_rgb(&data::LIGHT_EMISSION);
        assert!(close(white, [0.7378, 0.7361, 0.7374]), "{white:?}");
        assert!(close(red, [0.4718, 0.0469, 0.0489]), "{red:?}");
        assert!(close(green, [0.0879, 0.3984, 0.0844]), "{green:?}");
        assert!(
            (light.r - 17.197).abs() < 1e-2
                && (light.g - 11.474).abs() < 1e-2
                && (light.b - 3.062).abs() < 1e-2,
            "{light:?}"
        );
    }
}
