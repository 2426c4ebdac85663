//! Dielectrics: smooth or rough glass.

use crate::bsdf::microfacet::roughness_to_alpha;
use crate::bsdf::{BuiltinBsdf, RoughDielectric, SmoothDielectric, TrowbridgeReitz};
use crate::color::Rgb;
use crate::material::{
    Material, MaterialContext, MaterialError, MaterialProperties, check_roughness,
};

/// Glass, water, any dielectric: a [`SmoothDielectric`] at roughness 0 (below the smoothness
/// threshold), a GGX [`RoughDielectric`] above. `eta` is `n_inside / n_outside`, with the
/// outside on the side the surface normal points to (the winding, or the vertex normals).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Glass {
    eta: f32,
    roughness: f32,
    tint: Rgb,
}

impl Glass {
    /// Smooth glass of relative IOR `eta` (1.5 for window glass, 1.33 for water). Fails unless
    /// `eta` is finite and positive.
    pub fn new(eta: f32) -> Result<Self, MaterialError> {
        if !(eta.is_finite() && eta > 0.0) {
            return Err(MaterialError {
                material: "glass",
                parameter: "eta",
                value: eta.to_string(),
                expected: "finite and > 0",
            });
        }
        Ok(Self {
            eta,
            roughness: 0.0,
            tint: Rgb::WHITE,
        })
    }

    /// The same glass with perceptual roughness `roughness` (`alpha = roughness^2`). Fails
    /// outside `[0, 1]`.
    pub fn with_roughness(self, roughness: f32) -> Result<Self, MaterialError> {
        Ok(Self {
            roughness: check_roughness("glass", roughness)?,
            ..self
        })
    }

    /// The same glass with a transmission tint (clamped to `[0, 1]`).
    #[must_use]
    pub fn with_tint(self, tint: Rgb) -> Self {
        Self { tint, ..self }
    }

    /// Relative index of refraction.
    #[must_use]
    pub fn eta(&self) -> f32 {
        self.eta
    }

    /// Perceptual roughness.
    #[must_use]
    pub fn roughness(&self) -> f32 {
        self.roughness
    }

    /// Transmission tint.
    #[must_use]
    pub fn tint(&self) -> Rgb {
        self.tint
    }
}

impl Material for Glass {
    type Bsdf = BuiltinBsdf;

    #[inline]
    fn bsdf(&self, _ctx: &MaterialContext) -> BuiltinBsdf {
        let d = TrowbridgeReitz::isotropic(roughness_to_alpha(self.roughness));
        if d.effectively_smooth() {
            SmoothDielectric::new(self.eta, self.tint).into()
        } else {
            RoughDielectric::new(d, self.eta, self.tint).into()
        }
    }

    fn lane_model(&self) -> Option<crate::material::LaneModel> {
        let d = TrowbridgeReitz::isotropic(roughness_to_alpha(self.roughness));
        d.effectively_smooth().then(|| {
            let b = SmoothDielectric::new(self.eta, self.tint);
            crate::material::LaneModel::Glass {
                eta: b.eta(),
                tint: b.tint(),
            }
        })
    }

    fn properties(&self) -> MaterialProperties {
        let smooth =
            TrowbridgeReitz::isotropic(roughness_to_alpha(self.roughness)).effectively_smooth();
        MaterialProperties::new(false, !smooth)
    }
}
