//! Thin-film interference: the reflectance of a surface under a thin transparent film (soap
//! bubbles, oil on water, anodised metal), as glTF's `KHR_materials_iridescence` defines it.
//!
//! Reference: L. Belcour and P. Barla, "A Practical Extension to Microfacet Theory for the
//! Modeling of Varying Iridescence", ACM TOG 36(4), 2017. Light reflected at the film's top
//! interface and light reflected (after any number of round trips) at the base interferes;
//! the spectral reflectance is an Airy sum whose terms oscillate with the optical path
//! difference `2 n_film d cos(theta_film)`. Integrated against the CIE colour matching
//! functions each term has a closed form when those are approximated by Gaussians (their
//! Fourier transforms are Gaussians): the sum's constant term plus two oscillating ones give
//! the reflectance in XYZ, converted to linear Rec. 709 RGB. The film's top interface uses
//! the exact dielectric Fresnel (so a vanishing film leaves the base exactly), the base
//! interface Schlick's from the base's `F0` (its index of refraction derived from it), as
//! the extension does, with phase shifts of pi where light reflects off a denser medium.

use std::f32::consts::PI;

use crate::color::Rgb;

/// Schlick's Fresnel with `f90 = 1`.
#[inline]
fn schlick(f0: f32, cos: f32) -> f32 {
    let m = (1.0 - cos).clamp(0.0, 1.0);
    let m2 = m * m;
    f0 + (1.0 - f0) * m2 * m2 * m
}

/// `((a - b) / (a + b))^2`, the normal-incidence reflectance between indices `a` and `b`.
#[inline]
fn f0_between(a: f32, b: f32) -> f32 {
    let r = (a - b) / (a + b);
    r * r
}

/// The index of refraction (against 1) whose normal-incidence reflectance is `f0`.
#[inline]
fn ior_from_f0(f0: f32) -> f32 {
    let s = f0.clamp(0.0, 0.9999).sqrt();
    (1.0 + s) / (1.0 - s)
}

/// The colour (linear Rec. 709) of one interference term of optical path difference `opd`
/// (nanometres) and phase shift `shift` per channel: the Fourier transform of the CIE
/// colour-matching functions (as Belcour and Barla's Gaussian fit) at that path difference,
/// normalised so that `Y = 1` at zero path difference.
#[inline]
fn sensitivity(opd: f32, shift: [f32; 3]) -> Rgb {
    // Gaussian fit of the XYZ matching functions in frequency space: amplitude, centre and
    // variance per component (X needs a second lobe), from the paper's supplemental material.
    const VAL: [f32; 3] = [5.4856e-13, 4.4201e-13, 5.2481e-13];
    const POS: [f32; 3] = [1.6810e6, 1.7953e6, 2.2084e6];
    const VAR: [f32; 3] = [4.3278e9, 9.3046e9, 6.6121e9];
    let phase = 2.0 * PI * opd * 1e-9;
    let mut xyz = [0.0f32; 3];
    for c in 0..3 {
        xyz[c] = VAL[c]
            * (2.0 * PI * VAR[c]).sqrt()
            * (POS[c] * phase + shift[c]).cos()
            * (-phase * phase * VAR[c]).exp();
    }
    xyz[0] += 9.7470e-14
        * (2.0 * PI * 4.5282e9f32).sqrt()
        * (2.2399e6 * phase + shift[0]).cos()
        * (-4.5282e9 * phase * phase).exp();
    let [x, y, z] = xyz.map(|v| v / 1.0685e-7);
    // CIE XYZ to linear Rec. 709 (sRGB primaries, D65).
    Rgb::new(
        3.240_454_2 * x - 1.537_138_5 * y - 0.498_531_4 * z,
        -0.969_266 * x + 1.876_010_8 * y + 0.041_556 * z,
        0.055_643_4 * x - 0.204_025_9 * y + 1.057_225_2 * z,
    )
}

/// The reflectance, per channel, of a base of normal-incidence reflectance `base_f0` under a
/// film of index `film_ior` and thickness `thickness` (nanometres), in a medium of index
/// `outside_ior`, for light arriving at cosine `cos` (to the microfacet normal). A film
/// thinner than about 30 nm fades into the bare base (the film's index blends into the
/// outside's), so a thickness of 0 gives the base's own Schlick reflectance.
#[must_use]
pub fn thin_film_fresnel(
    outside_ior: f32,
    film_ior: f32,
    thickness: f32,
    cos: f32,
    base_f0: Rgb,
) -> Rgb {
    let cos = cos.clamp(0.0, 1.0);
    let thickness = if thickness.is_finite() {
        thickness.max(0.0)
    } else {
        0.0
    };
    // Fade the film in over its first 30 nm (smoothstep).
    let t = (thickness / 30.0).clamp(0.0, 1.0);
    let film = outside_ior + (film_ior - outside_ior) * t * t * (3.0 - 2.0 * t);
    // Into the film (Snell); total internal reflection reflects everything.
    let sin2_film = (outside_ior / film).powi(2) * (1.0 - cos * cos);
    if sin2_film >= 1.0 {
        return Rgb::WHITE;
    }
    let cos_film = (1.0 - sin2_film).sqrt();
    // Top interface: reflectance (exact dielectric Fresnel, so that a film of the outside's
    // index reflects nothing), transmission both ways, phase shifts.
    let r12 = crate::bsdf::fresnel::fresnel_dielectric(cos, film / outside_ior);
    let t121 = 1.0 - r12;
    let phi12 = if film < outside_ior { PI } else { 0.0 };
    let phi21 = PI - phi12;
    let opd = 2.0 * film * thickness * cos_film;
    let f0 = [base_f0.r, base_f0.g, base_f0.b];
    let mut shift = [0.0f32; 3];
    // Per channel: the Airy sum's constant term `R12 + Rs`, and the first oscillating
    // amplitude `C1 = (Rs - T121) sqrt(R12 R23)`, each further term `sqrt(R12 R23)` weaker.
    let mut dc = [0.0f32; 3];
    let mut c1 = [0.0f32; 3];
    let mut ratio = [0.0f32; 3];
    for c in 0..3 {
        // Bottom interface: the base's index from its F0.
        let base_ior = ior_from_f0(f0[c]);
        let r23 = schlick(f0_between(base_ior, film), cos_film);
        let phi23 = if base_ior < film { PI } else { 0.0 };
        shift[c] = phi21 + phi23;
        let r123 = (r12 * r23).clamp(1e-5, 0.9999);
        let rs = t121 * t121 * r23 / (1.0 - r123);
        dc[c] = r12 + rs;
        ratio[c] = r123.sqrt();
        c1[c] = (rs - t121) * ratio[c];
    }
    let mut result = Rgb::new(dc[0], dc[1], dc[2]);
    let mut cm = c1;
    for m in 1..=2 {
        let s = sensitivity(m as f32 * opd, shift.map(|p| m as f32 * p));
        result += Rgb::new(2.0 * cm[0] * s.r, 2.0 * cm[1] * s.g, 2.0 * cm[2] * s.b);
        for c in 0..3 {
            cm[c] *= ratio[c];
        }
    }
    result.map(|v| v.clamp(0.0, 1.0))
}

/// A thin film on a dielectric interface (`KHR_materials_iridescence` on glass): the
/// interface reflects, per channel, `mix(F, thin_film_fresnel(...), weight)` with `F` the
/// bare interface's exact Fresnel, and transmits the rest, so each channel's reflectance and
/// transmittance still sum to 1. The film sits on the outside (the side the normal points
/// to, in air); light meeting it from inside sees the reflectance of the outside direction
/// Snell's law pairs with it (a lossless film reflects alike from both sides), which keeps
/// the interface reciprocal. Films on interfaces with `eta <= 1` are ignored.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThinFilm {
    weight: f32,
    ior: f32,
    thickness: f32,
}

impl ThinFilm {
    /// A film of weight `weight` (`[0, 1]`), index of refraction `ior` (at least 1; else
    /// 1.3) and `thickness` nanometres (non-negative; else 0).
    #[must_use]
    pub fn new(weight: f32, ior: f32, thickness: f32) -> Self {
        Self {
            weight: if weight.is_nan() {
                0.0
            } else {
                weight.clamp(0.0, 1.0)
            },
            ior: if ior.is_finite() && ior >= 1.0 {
                ior
            } else {
                1.3
            },
            thickness: if thickness.is_finite() {
                thickness.max(0.0)
            } else {
                0.0
            },
        }
    }

    /// The interface's reflectance per channel for light meeting it at cosine `cos` to its
    /// (micro)normal (negative from inside), relative IOR `eta`.
    #[must_use]
    pub fn reflectance(&self, cos: f32, eta: f32) -> Rgb {
        let bare = crate::bsdf::fresnel::fresnel_dielectric(cos, eta);
        if self.weight == 0.0 || eta <= 1.0 || bare >= 1.0 {
            return Rgb::splat(bare);
        }
        let cos_out = if cos >= 0.0 {
            cos
        } else {
            // From inside: the outside direction Snell's law pairs with it.
            let sin2 = eta * eta * (1.0 - cos * cos).max(0.0);
            if sin2 >= 1.0 {
                return Rgb::WHITE;
            }
            (1.0 - sin2).sqrt()
        };
        let f0 = f0_between(eta, 1.0);
        let film = thin_film_fresnel(1.0, self.ior, self.thickness, cos_out, Rgb::splat(f0));
        (Rgb::splat(bare) * (1.0 - self.weight) + film * self.weight).map(|c| {
            if c.is_finite() {
                c.clamp(0.0, 1.0)
            } else {
                bare
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_matching_functions_are_normalised() {
        // At zero path difference the luminance term is 1 (white, in XYZ: the sum of the
        // matching functions' areas): RGB close to the D65-ish white of equal-energy XYZ.
        let s = sensitivity(0.0, [0.0; 3]);
        let y = 0.2126 * s.r + 0.7152 * s.g + 0.0722 * s.b;
        assert!((y - 1.0).abs() < 0.01, "{s:?}");
    }

    #[test]
    fn without_a_film_it_is_the_base_reflectance() {
        let base = Rgb::new(0.04, 0.5, 0.9);
        for cos in [1.0, 0.7, 0.3, 0.05] {
            let f = thin_film_fresnel(1.0, 1.33, 0.0, cos, base);
            for (got, f0) in [(f.r, base.r), (f.g, base.g), (f.b, base.b)] {
                let want = schlick(f0, cos);
                assert!((got - want).abs() < 0.01, "cos {cos}: {got} != {want}");
            }
        }
    }

    #[test]
    fn films_colour_the_reflection_and_stay_in_range() {
        // A soap-like film over glass: the colour changes with thickness, reflectance stays
        // within [0, 1] and the three channels differ.
        let mut colours = Vec::new();
        for thickness in [100.0, 250.0, 400.0, 550.0] {
            for cos in [1.0, 0.6, 0.2] {
                let f = thin_film_fresnel(1.0, 1.33, thickness, cos, Rgb::splat(0.04));
                assert!(
                    f.is_valid_nonnegative() && f.max_component() <= 1.0,
                    "{f:?}"
                );
                if cos == 1.0 {
                    colours.push(f);
                }
            }
        }
        assert!(
            colours.iter().any(|c| (c.r - c.b).abs() > 0.01),
            "{colours:?}"
        );
        assert!(colours.windows(2).all(|w| w[0] != w[1]), "{colours:?}");
    }
}
