//! Cameras: map a position on the image to a primary ray.

use std::fmt;

use glam::{Vec2, Vec3};
use pt_accel::Ray;
use pt_accel::lanes::{FloatLanes, Simd};

/// Where on the image a primary ray goes through.
///
/// Non-exhaustive so that later camera models (time for motion blur, wavelength) can add
/// fields; make one with [`CameraSample::new`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct CameraSample {
    /// Position on the image in `[0, 1]^2`: `(0, 0)` is the top-left corner, `x` to the right,
    /// `y` down.
    pub film: Vec2,
    /// Image width over height.
    pub aspect: f32,
    /// A 2D sample for the lens (unused by pinhole cameras).
    pub lens: Vec2,
}

impl CameraSample {
    /// A sample at image position `film` (in `[0, 1]^2`, top-left origin) of an image with
    /// width/height `aspect`, with the lens sample at the lens centre.
    #[inline]
    #[must_use]
    pub fn new(film: Vec2, aspect: f32) -> Self {
        Self {
            film,
            aspect,
            lens: Vec2::splat(0.5),
        }
    }

    /// The same sample with lens sample `lens` in `[0, 1)^2`.
    #[inline]
    #[must_use]
    pub fn with_lens(mut self, lens: Vec2) -> Self {
        self.lens = lens;
        self
    }
}

/// Generates primary rays.
pub trait Camera: Send + Sync {
    /// The primary ray through an image position. Directions are unit length.
    fn generate_ray(&self, sample: &CameraSample) -> Ray;

    /// Whether [`CameraSample::lens`] matters to this camera. A camera that returns false
    /// (a pinhole) is given the lens centre, and the renderer saves the sampler draw.
    fn uses_lens(&self) -> bool {
        true
    }

    /// The pinhole camera this camera is, if it is one: a renderer may then make its rays
    /// eight at a time with [`PinholeCamera`]'s arithmetic (the lane path tracer does) instead
    /// of calling [`Camera::generate_ray`] for each. A camera that returns one must generate
    /// exactly that camera's rays. The default returns `None`.
    fn pinhole(&self) -> Option<PinholeCamera> {
        None
    }

    /// [`Material::render_scene`](crate::Material::render_scene)'s third step, for a scene of
    /// the built-in materials and lights: the renderer compiled in the calling crate (the
    /// default), or for [`PinholeCamera`] the sampler factory's step
    /// ([`SamplerFactory::render_builtin_pinhole`](crate::SamplerFactory::render_builtin_pinhole)).
    /// Not for use outside pt.
    #[doc(hidden)]
    fn render_builtin_scene<K: crate::SamplerFactory>(
        &self,
        scene: &crate::Scene,
        options: &crate::RenderOptions<K>,
        control: Option<&crate::render::RenderControl<'_>>,
    ) -> Result<crate::render::RenderOutput, crate::render::RenderError>
    where
        Self: Sized,
    {
        crate::render::render_generic(scene, self, options, control)
    }
}

/// Why a camera could not be made.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum CameraError {
    /// Eye and target coincide, or a vector is not finite.
    DegenerateView,
    /// The up vector is parallel to the viewing direction.
    UpParallelToView,
    /// The field of view is not in `(0, 180)` degrees.
    InvalidFov(f32),
}

impl fmt::Display for CameraError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::DegenerateView => write!(f, "camera eye and target coincide or are not finite"),
            Self::UpParallelToView => {
                write!(f, "camera up vector is parallel to the view direction")
            }
            Self::InvalidFov(v) => write!(f, "field of view {v} degrees is not in (0, 180)"),
        }
    }
}

impl std::error::Error for CameraError {}

/// An ideal pinhole perspective camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PinholeCamera {
    eye: Vec3,
    forward: Vec3,
    right: Vec3,
    up: Vec3,
    tan_half_fov_y: f32,
}

impl PinholeCamera {
    /// A camera at `eye` looking at `target`, with `up` roughly up, and a vertical field of view of
    /// `fov_y_degrees` (the angle between the top and bottom edges of the image).
    pub fn look_at(
        eye: Vec3,
        target: Vec3,
        up: Vec3,
        fov_y_degrees: f32,
    ) -> Result<Self, CameraError> {
        if !(fov_y_degrees > 0.0 && fov_y_degrees < 180.0) {
            return Err(CameraError::InvalidFov(fov_y_degrees));
        }
        let forward = (target - eye).normalize_or_zero();
        if forward == Vec3::ZERO || !eye.is_finite() || !up.is_finite() {
            return Err(CameraError::DegenerateView);
        }
        let right = forward.cross(up).normalize_or_zero();
        if right == Vec3::ZERO {
            return Err(CameraError::UpParallelToView);
        }
        Ok(Self {
            eye,
            forward,
            right,
            up: right.cross(forward),
            tan_half_fov_y: (fov_y_degrees.to_radians() * 0.5).tan(),
        })
    }

    /// Camera position.
    #[must_use]
    pub fn eye(&self) -> Vec3 {
        self.eye
    }

    /// Unit viewing direction.
    #[must_use]
    pub fn forward(&self) -> Vec3 {
        self.forward
    }

    /// Unit up direction of the image (orthogonal to [`forward`](Self::forward)).
    #[must_use]
    pub fn up(&self) -> Vec3 {
        self.up
    }

    /// The camera moved by `transform` (a rotation, uniform scale and translation; the field of
    /// view is kept), to follow a scene moved with the same transform.
    pub fn transformed(&self, transform: &glam::Affine3A) -> Result<Self, CameraError> {
        let eye = transform.transform_point3(self.eye);
        let forward = transform.transform_vector3(self.forward);
        Self::look_at(
            eye,
            eye + forward,
            transform.transform_vector3(self.up),
            self.fov_y_degrees(),
        )
    }

    /// The directions of the rays through the film positions `(fx, fy)` of eight samples, one
    /// per lane, of an image with width over height `aspect`: [`Camera::generate_ray`]'s
    /// operations in the same order, lane by lane (the same bits; the rays start at
    /// [`Self::eye`]).
    #[inline(always)]
    pub(crate) fn directions_lanes<S: Simd>(
        &self,
        s: S,
        fx: S::F,
        fy: S::F,
        aspect: f32,
    ) -> [S::F; 3] {
        let (one, two, tan) = (s.splat(1.0), s.splat(2.0), s.splat(self.tan_half_fov_y));
        let x = (two * fx - one) * tan * s.splat(aspect);
        let y = (one - two * fy) * tan;
        let (f, r, u) = (self.forward, self.right, self.up);
        let d = [
            s.splat(f.x) + s.splat(r.x) * x + s.splat(u.x) * y,
            s.splat(f.y) + s.splat(r.y) * x + s.splat(u.y) * y,
            s.splat(f.z) + s.splat(r.z) * x + s.splat(u.z) * y,
        ];
        // `Vec3::normalize`: times the reciprocal of the length.
        let inv_len = one / (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        [d[0] * inv_len, d[1] * inv_len, d[2] * inv_len]
    }

    /// Vertical field of view in degrees.
    #[must_use]
    pub fn fov_y_degrees(&self) -> f32 {
        2.0 * self.tan_half_fov_y.atan().to_degrees()
    }
}

impl Camera for PinholeCamera {
    #[inline]
    fn uses_lens(&self) -> bool {
        false
    }

    #[inline]
    fn pinhole(&self) -> Option<PinholeCamera> {
        Some(*self)
    }

    fn render_builtin_scene<K: crate::SamplerFactory>(
        &self,
        scene: &crate::Scene,
        options: &crate::RenderOptions<K>,
        control: Option<&crate::render::RenderControl<'_>>,
    ) -> Result<crate::render::RenderOutput, crate::render::RenderError> {
        K::render_builtin_pinhole(scene, self, options, control)
    }

    fn generate_ray(&self, s: &CameraSample) -> Ray {
        let x = (2.0 * s.film.x - 1.0) * self.tan_half_fov_y * s.aspect;
        let y = (1.0 - 2.0 * s.film.y) * self.tan_half_fov_y;
        let dir = (self.forward + self.right * x + self.up * y).normalize();
        Ray::new(self.eye, dir)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn center_ray_looks_forward_and_corners_span_the_fov() {
        let c = PinholeCamera::look_at(Vec3::ZERO, Vec3::Z, Vec3::Y, 90.0).unwrap();
        let center = c.generate_ray(&CameraSample {
            film: Vec2::splat(0.5),
            aspect: 1.0,
            lens: Vec2::ZERO,
        });
        assert!((center.dir - Vec3::Z).length() < 1e-6);
        let top = c.generate_ray(&CameraSample {
            film: Vec2::new(0.5, 0.0),
            aspect: 1.0,
            lens: Vec2::ZERO,
        });
        assert!(
            (top.dir.y - std::f32::consts::FRAC_1_SQRT_2).abs() < 1e-5,
            "top of image is up"
        );
        let left = c.generate_ray(&CameraSample {
            film: Vec2::new(0.0, 0.5),
            aspect: 2.0,
            lens: Vec2::ZERO,
        });
        // Looking down +z with +y up, the right vector is -x: the left edge is toward +x.
        assert!(left.dir.x > 0.0);
        assert!((c.fov_y_degrees() - 90.0).abs() < 1e-4);
    }

    #[test]
    fn rejects_bad_setups() {
        assert_eq!(
            PinholeCamera::look_at(Vec3::ONE, Vec3::ONE, Vec3::Y, 40.0),
            Err(CameraError::DegenerateView)
        );
        assert_eq!(
            PinholeCamera::look_at(Vec3::ZERO, Vec3::Y, Vec3::Y, 40.0),
            Err(CameraError::UpParallelToView)
        );
        assert_eq!(
            PinholeCamera::look_at(Vec3::ZERO, Vec3::Z, Vec3::Y, 0.0),
            Err(CameraError::InvalidFov(0.0))
        );
        assert!(PinholeCamera::look_at(Vec3::ZERO, Vec3::Z, Vec3::Y, f32::NAN).is_err());
    }
}
