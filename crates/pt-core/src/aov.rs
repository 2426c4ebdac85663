//! Auxiliary outputs (AOVs): the albedo and shading normal of each sample's first non-specular
//! hit, averaged per pixel like the colour. They guide a denoiser ([`crate::denoise`]) and are
//! useful on their own (compositing, checking a scene's materials and normals).
//!
//! Conventions (those Intel Open Image Denoise asks for):
//! - The **first non-specular hit** is the first surface whose BSDF has a diffuse or glossy lobe:
//!   paths go on through ideal mirrors and smooth glass, so a glass bunny shows the albedo and
//!   normals of what is seen through it and in it.
//! - **Albedo** is the one-sample estimate of the surface's directional albedo, `f cos / pdf` of
//!   the BSDF sample drawn there, clamped to [0, 1] per channel: the reflectance for a Lambertian
//!   surface (exact, noise-free), the Fresnel-weighted colour of a rough conductor, a blend of
//!   the lobes' colours for layered materials; averaged over a pixel's samples it converges to
//!   the surface's albedo for the viewing direction.
//! - A path that ends without a non-specular hit records the **emitted radiance** where it ended
//!   (an emitter, or the environment along an escaping ray; black if none), clamped to [0, 1].
//! - **Normal** is the world-space shading normal (after normal maps) of that hit, as the
//!   surface gives it (not flipped toward the ray); zero for rays that escape. The per-pixel
//!   mean is not renormalised.
//!
//! The sums are exact fixed point ([`crate::film::AuxSum`]), so renders with AOVs are as
//! deterministic and as mergeable (partial renders, [`crate::PartialRender`]) as the colour.

use std::fmt;
use std::str::FromStr;

use glam::Vec3;

use crate::color::Rgb;

/// Which auxiliary outputs a render produces ([`crate::RenderOptions::aovs`]).
///
/// ```
/// use pt_core::Aovs;
/// let aovs: Aovs = "albedo,normal".parse()?;
/// assert_eq!(aovs, Aovs::ALL);
/// assert!(!Aovs::NONE.any());
/// # Ok::<(), String>(())
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Aovs {
    /// The albedo of the first non-specular hit.
    pub albedo: bool,
    /// The shading normal of the first non-specular hit.
    pub normal: bool,
}

impl Aovs {
    /// No auxiliary outputs (the default: no cost).
    pub const NONE: Aovs = Aovs {
        albedo: false,
        normal: false,
    };
    /// Albedo and normal, what a denoiser takes.
    pub const ALL: Aovs = Aovs {
        albedo: true,
        normal: true,
    };

    /// Whether any is asked for. The film then keeps both (48 bytes per pixel more).
    #[must_use]
    pub fn any(self) -> bool {
        self.albedo || self.normal
    }

    /// Both outputs together (`self` or `other` asks for it).
    #[must_use]
    pub fn union(self, other: Aovs) -> Aovs {
        Aovs {
            albedo: self.albedo || other.albedo,
            normal: self.normal || other.normal,
        }
    }
}

impl FromStr for Aovs {
    type Err = String;

    /// A comma-separated list of `albedo` and `normal`, or `none`.
    fn from_str(s: &str) -> Result<Self, String> {
        let mut aovs = Aovs::NONE;
        for name in s.split(',').map(str::trim) {
            match name {
                "albedo" => aovs.albedo = true,
                "normal" => aovs.normal = true,
                "none" => {}
                other => {
                    return Err(format!(
                        "unknown AOV {other:?} (expected albedo, normal or none)"
                    ));
                }
            }
        }
        Ok(aovs)
    }
}

impl fmt::Display for Aovs {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match (self.albedo, self.normal) {
            (true, true) => f.write_str("albedo,normal"),
            (true, false) => f.write_str("albedo"),
            (false, true) => f.write_str("normal"),
            (false, false) => f.write_str("none"),
        }
    }
}

/// What one sample records for the AOVs, filled by the path tracer. Monomorphised away when a
/// render has none ([`NoAov`]).
pub(crate) trait AovRecord: Default {
    /// Whether this recorder records anything (a constant, so the path tracer's checks vanish
    /// when it does not).
    const ON: bool;
    /// Whether the sample's values are set.
    fn is_set(&self) -> bool;
    /// Set the sample's values (the first call wins).
    fn set(&mut self, albedo: Rgb, normal: Vec3);
}

/// The recorder of renders without AOVs: records nothing, costs nothing.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct NoAov;

impl AovRecord for NoAov {
    const ON: bool = false;
    #[inline(always)]
    fn is_set(&self) -> bool {
        true
    }
    #[inline(always)]
    fn set(&mut self, _: Rgb, _: Vec3) {}
}

/// One sample's albedo and normal.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct AovSample {
    pub(crate) albedo: Rgb,
    pub(crate) normal: Vec3,
    set: bool,
}

impl AovRecord for AovSample {
    const ON: bool = true;
    #[inline]
    fn is_set(&self) -> bool {
        self.set
    }
    #[inline]
    fn set(&mut self, albedo: Rgb, normal: Vec3) {
        if !self.set {
            self.albedo = albedo;
            self.normal = normal;
            self.set = true;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parse_and_print() {
        for (text, aovs) in [
            (
                "albedo",
                Aovs {
                    albedo: true,
                    normal: false,
                },
            ),
            (
                "normal",
                Aovs {
                    albedo: false,
                    normal: true,
                },
            ),
            ("normal, albedo", Aovs::ALL),
            ("none", Aovs::NONE),
        ] {
            assert_eq!(text.parse::<Aovs>().unwrap(), aovs);
            assert_eq!(aovs.to_string().parse::<Aovs>().unwrap(), aovs);
        }
        let e = "albedo,depth".parse::<Aovs>().unwrap_err();
        assert!(e.contains("\"depth\""), "{e}");
    }
}
