//! The matte material.

use crate::bsdf::Lambertian;
use crate::color::Rgb;
use crate::material::{Material, MaterialContext, MaterialProperties};

/// A matte material: Lambertian reflection with a constant albedo.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Diffuse {
    /// Albedo, per channel in `[0, 1]`.
    pub reflectance: Rgb,
}

impl Diffuse {
    /// A matte material with the given albedo.
    #[must_use]
    pub fn new(reflectance: Rgb) -> Self {
        Self { reflectance }
    }
}

impl Material for Diffuse {
    type Bsdf = Lambertian;

    #[inline]
    fn bsdf(&self, _ctx: &MaterialContext) -> Lambertian {
        Lambertian::new(self.reflectance)
    }

    fn properties(&self) -> MaterialProperties {
        MaterialProperties::new(false, true)
    }

    fn lane_model(&self) -> Option<crate::material::LaneModel> {
        Some(crate::material::LaneModel::Lambertian(
            Lambertian::new(self.reflectance).reflectance(),
        ))
    }
}
