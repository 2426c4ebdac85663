//! Rays and hit records.

use glam::Vec3;

/// A ray `origin + t * dir` for `t` in `[t_min, t_max]`.
///
/// `dir` need not be unit length: `t` is measured in multiples of `dir`. Shadow rays toward a
/// point use the unnormalised segment as `dir` and `t_max` just below 1; instance traversal keeps
/// the object-space direction unnormalised so that `t` stays in world units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Start point.
    pub origin: Vec3,
    /// Direction (any non-zero length).
    pub dir: Vec3,
    /// Smallest accepted hit distance. Robustly spawned rays use 0.
    pub t_min: f32,
    /// Largest accepted hit distance (`f32::INFINITY` for an unbounded ray).
    pub t_max: f32,
}

impl Ray {
    /// An unbounded ray starting at `origin`.
    #[inline]
    #[must_use]
    pub fn new(origin: Vec3, dir: Vec3) -> Self {
        Self {
            origin,
            dir,
            t_min: 0.0,
            t_max: f32::INFINITY,
        }
    }

    /// A ray limited to `t` in `[0, t_max]`.
    #[inline]
    #[must_use]
    pub fn with_t_max(origin: Vec3, dir: Vec3, t_max: f32) -> Self {
        Self {
            origin,
            dir,
            t_min: 0.0,
            t_max,
        }
    }

    /// The point at parameter `t`.
    #[inline]
    #[must_use]
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + self.dir * t
    }

    /// True when origin and direction are finite and the direction is not zero.
    #[inline]
    #[must_use]
    pub fn is_valid(&self) -> bool {
        // Both vectors at once and without branches (this runs for every query): `|v| < inf`
        // is false for infinities and NaNs alike. (Not `o.max(d) < inf`: the maximum of a NaN
        // and a number is the number, which let a NaN origin through.)
        let inf = glam::Vec3A::INFINITY;
        let (o, d) = (
            glam::Vec3A::from(self.origin).abs(),
            glam::Vec3A::from(self.dir).abs(),
        );
        (o.cmplt(inf) & d.cmplt(inf)).all() & (d.max_element() > 0.0)
    }
}

/// The closest (or any) intersection found along a ray.
///
/// Barycentric coordinates refer to the triangle's vertices in index order: the hit point is
/// `(1 - b1 - b2) * p0 + b1 * p1 + b2 * p2`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Ray parameter of the hit, in units of the query ray's direction.
    pub t: f32,
    /// Index of the instance that was hit.
    pub instance: u32,
    /// Index of the triangle within its mesh (the order the mesh was given in).
    pub prim: u32,
    /// Barycentric weight of the triangle's second vertex.
    pub b1: f32,
    /// Barycentric weight of the triangle's third vertex.
    pub b2: f32,
}

impl Hit {
    /// Barycentric weight of the triangle's first vertex.
    #[inline]
    #[must_use]
    pub fn b0(&self) -> f32 {
        1.0 - self.b1 - self.b2
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rays_with_a_non_finite_or_zero_component_are_invalid() {
        assert!(Ray::new(Vec3::ZERO, Vec3::Z).is_valid());
        assert!(Ray::new(Vec3::splat(-3e38), Vec3::new(0.0, -1e-30, 0.0)).is_valid());
        for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
            for axis in 0..3 {
                let mut v = Vec3::new(1.0, 2.0, 3.0);
                v[axis] = bad;
                assert!(!Ray::new(v, Vec3::Z).is_valid(), "origin {v}");
                assert!(!Ray::new(Vec3::ZERO, v).is_valid(), "direction {v}");
            }
        }
        assert!(!Ray::new(Vec3::ONE, Vec3::ZERO).is_valid());
        assert!(!Ray::new(Vec3::ONE, Vec3::new(-0.0, 0.0, -0.0)).is_valid());
    }
}
