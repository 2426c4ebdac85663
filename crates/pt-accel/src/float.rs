//! Floating-point error analysis helpers.
//!
//! These follow the running error analysis of *Physically Based Rendering* (4th ed., section 6.8):
//! `gamma(n)` bounds the relative error of `n` successive f32 roundings, and the `next_float_*`
//! functions move a value by exactly one unit in the last place. They are what lets the renderer
//! offset spawned rays by a proven bound instead of a tuned epsilon.

/// Half of the distance between 1 and the next f32: the unit roundoff of round-to-nearest.
pub const MACHINE_EPSILON: f32 = f32::EPSILON * 0.5;

/// Bound on the relative error accumulated by `n` floating-point operations,
/// `n * eps / (1 - n * eps)` with `eps` the unit roundoff.
#[inline]
#[must_use]
pub const fn gamma(n: i32) -> f32 {
    let ne = n as f32 * MACHINE_EPSILON;
    ne / (1.0 - ne)
}

/// The smallest f32 strictly greater than `v` (infinity stays infinity, NaN stays NaN).
#[inline]
#[must_use]
pub fn next_float_up(v: f32) -> f32 {
    if v.is_infinite() && v > 0.0 || v.is_nan() {
        return v;
    }
    // -0.0 and +0.0 both step to the smallest positive subnormal.
    let v = if v == -0.0 { 0.0 } else { v };
    let bits = v.to_bits();
    let bits = if v >= 0.0 { bits + 1 } else { bits - 1 };
    f32::from_bits(bits)
}

/// The largest f32 strictly smaller than `v` (negative infinity and NaN are returned unchanged).
#[inline]
#[must_use]
pub fn next_float_down(v: f32) -> f32 {
    if v.is_infinite() && v < 0.0 || v.is_nan() {
        return v;
    }
    let v = if v == 0.0 { -0.0 } else { v };
    let bits = v.to_bits();
    let bits = if v > 0.0 { bits - 1 } else { bits + 1 };
    f32::from_bits(bits)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn next_float_steps_one_ulp() {
        assert_eq!(next_float_up(1.0), 1.0 + f32::EPSILON);
        assert_eq!(next_float_down(1.0), 1.0 - f32::EPSILON / 2.0);
        assert!(next_float_up(0.0) > 0.0);
        assert!(next_float_up(-0.0) > 0.0);
        assert!(next_float_down(0.0) < 0.0);
        assert_eq!(next_float_up(-1.0), -1.0 + f32::EPSILON / 2.0);
        assert_eq!(next_float_up(f32::INFINITY), f32::INFINITY);
        assert_eq!(next_float_down(f32::NEG_INFINITY), f32::NEG_INFINITY);
        assert_eq!(next_float_up(f32::MAX), f32::INFINITY);
    }

    #[test]
    fn gamma_grows_with_n() {
        assert!(gamma(1) > MACHINE_EPSILON);
        assert!(gamma(3) < gamma(5));
        assert!((gamma(3) - 3.0 * MACHINE_EPSILON).abs() < 1e-12);
    }
}
