//! The perfect mirror.

use crate::bsdf::SpecularReflection;
use crate::color::Rgb;
use crate::material::{Material, MaterialContext, MaterialProperties};

/// A perfect mirror: every ray reflects in the mirror direction, attenuated by `reflectance` at
/// every angle ([`SpecularReflection`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mirror {
    /// Reflectance per channel in `[0, 1]` (clamped).
    pub reflectance: Rgb,
}

impl Mirror {
    /// A mirror with the given reflectance.
    #[must_use]
    pub fn new(reflectance: Rgb) -> Self {
        Self { reflectance }
    }
}

impl Material for Mirror {
    type Bsdf = SpecularReflection;

    #[inline]
    fn bsdf(&self, _ctx: &MaterialContext) -> SpecularReflection {
        SpecularReflection::new(self.reflectance)
    }

    fn properties(&self) -> MaterialProperties {
        MaterialProperties::new(false, false)
    }

    fn lane_model(&self) -> Option<crate::material::LaneModel> {
        Some(crate::material::LaneModel::Mirror(
            SpecularReflection::new(self.reflectance).reflectance(),
        ))
    }
}
