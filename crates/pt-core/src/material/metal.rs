//! Metals: the GGX conductor with a Fresnel model.

use crate::bsdf::microfacet::roughness_to_alpha;
use crate::bsdf::{ConductorFresnel, RoughConductor, TrowbridgeReitz};
use crate::color::Rgb;
use crate::material::{
    Material, MaterialContext, MaterialError, MaterialProperties, check_roughness,
};

/// A metal: the GGX [`RoughConductor`] with perceptual `roughness` (`alpha = roughness^2`;
/// 0 is a Fresnel-weighted mirror) and a Fresnel model (a tint, or a measured complex IOR such
/// as [`ConductorFresnel::GOLD`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Metal {
    fresnel: ConductorFresnel,
    roughness: f32,
}

impl Metal {
    /// A metal. Fails on a roughness outside `[0, 1]`, a Schlick tint outside `[0, 1]`, or a
    /// complex IOR that is not finite and non-negative.
    pub fn new(fresnel: ConductorFresnel, roughness: f32) -> Result<Self, MaterialError> {
        let bad = |parameter, value: Rgb, expected| MaterialError {
            material: "metal",
            parameter,
            value: format!("{value:?}"),
            expected,
        };
        let all = |v: Rgb, ok: &dyn Fn(f32) -> bool| (0..3).all(|c| ok(v[c]));
        match fresnel {
            ConductorFresnel::Schlick(f0) => {
                if !all(f0, &|x| (0.0..=1.0).contains(&x)) {
                    return Err(bad("F0", f0, "in [0, 1] per channel"));
                }
            }
            ConductorFresnel::Complex { eta, k } => {
                if !all(eta, &|x| x.is_finite() && x > 0.0) {
                    return Err(bad("eta", eta, "finite and > 0 per channel"));
                }
                if !all(k, &|x| x.is_finite() && x >= 0.0) {
                    return Err(bad("k", k, "finite and >= 0 per channel"));
                }
            }
        }
        Ok(Self {
            fresnel,
            roughness: check_roughness("metal", roughness)?,
        })
    }

    /// The Fresnel model.
    #[must_use]
    pub fn fresnel(&self) -> ConductorFresnel {
        self.fresnel
    }

    /// Perceptual roughness in `[0, 1]`.
    #[must_use]
    pub fn roughness(&self) -> f32 {
        self.roughness
    }
}

impl Material for Metal {
    type Bsdf = RoughConductor;

    #[inline]
    fn bsdf(&self, _ctx: &MaterialContext) -> RoughConductor {
        RoughConductor::new(
            TrowbridgeReitz::isotropic(roughness_to_alpha(self.roughness)),
            self.fresnel,
        )
    }

    fn properties(&self) -> MaterialProperties {
        let smooth =
            TrowbridgeReitz::isotropic(roughness_to_alpha(self.roughness)).effectively_smooth();
        MaterialProperties::new(false, !smooth)
    }
}
