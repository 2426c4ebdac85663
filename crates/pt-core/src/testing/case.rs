//! A BSDF under test: the model, an outgoing direction, and what is known about it.

use glam::Vec3;

use crate::bsdf::Bsdf;
use crate::color::Rgb;
use crate::testing::Failure;

/// What the delta lobes of a case must do, for [`check_delta`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum DeltaExpectation {
    /// The case has no delta lobe.
    None,
    /// Every sample is a delta reflection in the mirror direction, with throughput
    /// `f |cos| / pdf` equal to `weight` when it is given.
    Reflection {
        /// Expected throughput of each sample, if known.
        weight: Option<Rgb>,
    },
    /// A smooth dielectric boundary: reflection with the probability of the Fresnel equations,
    /// refraction by Snell's law otherwise.
    Dielectric {
        /// Relative IOR `n_inside / n_outside` (outside is `z > 0`).
        eta: f32,
        /// Transmission tint.
        tint: Rgb,
    },
}

/// One BSDF under test at one outgoing direction.
#[derive(Clone, Debug)]
pub struct BsdfCase<B> {
    /// A readable name: model, parameters and direction.
    pub name: String,
    /// The BSDF.
    pub bsdf: B,
    /// The outgoing direction (local frame, unit).
    pub wo: Vec3,
    /// Relative IOR `n_inside / n_outside` for models that transmit (used by the reciprocity
    /// check), 1 otherwise.
    pub eta: f32,
    /// What the delta lobes must do.
    pub delta: DeltaExpectation,
    /// The exact directional albedo in importance mode, when known (lossless models).
    pub albedo: Option<Rgb>,
}

impl<B: Bsdf> BsdfCase<B> {
    /// A case with no delta expectation and no known albedo, `eta = 1`.
    pub fn new(name: impl Into<String>, bsdf: B, wo: Vec3) -> Self {
        Self {
            name: name.into(),
            bsdf,
            wo: wo.normalize(),
            eta: 1.0,
            delta: DeltaExpectation::None,
            albedo: None,
        }
    }

    pub(crate) fn fail(&self, check: &'static str, message: String) -> Failure {
        Failure {
            case: self.name.clone(),
            check,
            message,
        }
    }

    /// Index of refraction on the side of `w` (outside, `z > 0`, is 1).
    pub(crate) fn ior(&self, w: Vec3) -> f32 {
        if w.z > 0.0 { 1.0 } else { self.eta }
    }
}
