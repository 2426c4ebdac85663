//! Orthonormal frames for moving directions between world space and a local shading space.

use glam::Vec3;

/// A right-handed orthonormal basis `(s, t, n)`. In a shading frame, `n` is the shading normal
/// and is the local `z` axis. Fields are private so the basis always stays orthonormal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    s: Vec3,
    t: Vec3,
    n: Vec3,
}

impl Frame {
    /// A frame whose `z` axis is the unit vector `n` (Duff et al., "Building an Orthonormal
    /// Basis, Revisited", JCGT 2017: branchless and continuous except at `n.z = -0`).
    #[inline]
    #[must_use]
    pub fn from_z(n: Vec3) -> Self {
        debug_assert!(
            (n.length_squared() - 1.0).abs() < 1e-3,
            "Frame::from_z needs a unit vector, got {n}"
        );
        let sign = 1.0f32.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        let s = Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let t = Vec3::new(b, sign + n.y * n.y * a, -n.y);
        Self { s, t, n }
    }

    /// A frame from a normal and a tangent direction: `s` is the tangent made orthogonal to `n`.
    /// Falls back to [`Frame::from_z`] when the tangent is parallel to `n` or degenerate.
    #[must_use]
    pub fn from_normal_tangent(n: Vec3, tangent: Vec3) -> Self {
        let s = (tangent - n * n.dot(tangent)).normalize_or_zero();
        if s == Vec3::ZERO {
            return Self::from_z(n);
        }
        Self {
            s,
            t: n.cross(s),
            n,
        }
    }

    /// World (or parent) direction to local coordinates.
    #[inline]
    #[must_use]
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.s), v.dot(self.t), v.dot(self.n))
    }

    /// Local direction to world (or parent) coordinates.
    #[inline]
    #[must_use]
    pub fn from_local(&self, v: Vec3) -> Vec3 {
        self.s * v.x + self.t * v.y + self.n * v.z
    }

    /// The `z` axis (the normal).
    #[inline]
    #[must_use]
    pub fn n(&self) -> Vec3 {
        self.n
    }

    /// The `x` axis.
    #[inline]
    #[must_use]
    pub fn s(&self) -> Vec3 {
        self.s
    }

    /// The `y` axis.
    #[inline]
    #[must_use]
    pub fn t(&self) -> Vec3 {
        self.t
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_are_orthonormal_and_invert() {
        let dirs = [
            Vec3::Z,
            -Vec3::Z,
            Vec3::X,
            Vec3::new(0.3, -0.4, 0.866).normalize(),
            Vec3::new(1e-7, 0.0, -1.0).normalize(),
        ];
        for n in dirs {
            let f = Frame::from_z(n);
            assert!((f.s.length() - 1.0).abs() < 1e-5);
            assert!((f.t.length() - 1.0).abs() < 1e-5);
            assert!(
                f.s.dot(f.t).abs() < 1e-5 && f.s.dot(n).abs() < 1e-5 && f.t.dot(n).abs() < 1e-5
            );
            assert!((f.s.cross(f.t) - n).length() < 1e-5, "right-handed");
            let v = Vec3::new(0.2, -0.7, 0.1);
            assert!((f.from_local(f.to_local(v)) - v).length() < 1e-5);
            assert!((f.to_local(n) - Vec3::Z).length() < 1e-5);
        }
    }
}
