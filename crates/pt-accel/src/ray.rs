//! Rays and hit records.

use glam::Vec3;

use crate::lanes::{FloatLanes, MaskLanes, Simd, WIDTH};

/// A ray `origin + t * dir` for `t` in `[t_min, t_max]`.
///
/// `dir` need not be unit length: `t` is measured in multiples of `dir`. Shadow rays toward a
/// point use the unnormalised segment as `dir` and `t_max` just below 1; instance traversal keeps
/// the object-space direction unnormalised so that `t` stays in world units.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
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

/// Eight rays stored coordinate by coordinate (structure of arrays): what the lane queries
/// ([`Accel::intersect_lanes`](crate::Accel::intersect_lanes) and the rest) take.
///
/// Lane `i` is the ray with origin `(origin[0][i], origin[1][i], origin[2][i])`, and so on.
/// Code that computes rays in lanes writes each coordinate with one whole-register store, and
/// the queries read the lanes they test together (a packet's constants, the validity check)
/// with one load each, without copying eight `Ray`s into lanes and back. One-ray queries
/// compiled into the caller read their lane's coordinates with [`Self::get`]; those called out
/// of line take all eight from [`Self::to_rays`]. Lanes outside a query's mask may hold
/// anything (NaN included): they are not read as rays.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub struct RayLanes {
    /// The origins' x, y and z coordinates.
    pub origin: [[f32; WIDTH]; 3],
    /// The directions' x, y and z coordinates.
    pub dir: [[f32; WIDTH]; 3],
    /// Each ray's smallest accepted hit distance.
    pub t_min: [f32; WIDTH],
    /// Each ray's largest accepted hit distance.
    pub t_max: [f32; WIDTH],
}

impl RayLanes {
    /// `ray` in every lane.
    #[must_use]
    pub const fn splat(ray: Ray) -> Self {
        Self {
            origin: [
                [ray.origin.x; WIDTH],
                [ray.origin.y; WIDTH],
                [ray.origin.z; WIDTH],
            ],
            dir: [[ray.dir.x; WIDTH], [ray.dir.y; WIDTH], [ray.dir.z; WIDTH]],
            t_min: [ray.t_min; WIDTH],
            t_max: [ray.t_max; WIDTH],
        }
    }

    /// The ray in lane `lane`.
    #[inline(always)]
    #[must_use]
    pub fn get(&self, lane: usize) -> Ray {
        let (o, d) = (&self.origin, &self.dir);
        Ray {
            origin: Vec3::new(o[0][lane], o[1][lane], o[2][lane]),
            dir: Vec3::new(d[0][lane], d[1][lane], d[2][lane]),
            t_min: self.t_min[lane],
            t_max: self.t_max[lane],
        }
    }

    /// The eight rays, for queries that take them one at a time out of line.
    ///
    /// Such a query reads its ray from memory; a ray made by [`Self::get`] for each call is
    /// built on the stack from small stores that the query's wider loads then wait for (the
    /// instanced dragons 5% slower than from rays stored whole). Made all at once before the
    /// queries, by whole-register loads, a transposition and one store per ray, the rays are
    /// in memory, stored whole, well before they are read.
    #[inline(always)]
    #[must_use]
    pub fn to_rays<S: Simd>(&self, s: S) -> [Ray; WIDTH] {
        let (o, d) = (&self.origin, &self.dir);
        let rows = s.transpose([
            s.load(o[0]),
            s.load(o[1]),
            s.load(o[2]),
            s.load(d[0]),
            s.load(d[1]),
            s.load(d[2]),
            s.load(self.t_min),
            s.load(self.t_max),
        ]);
        let mut out = [Ray::new(Vec3::ZERO, Vec3::Z); WIDTH];
        for (ray, row) in out.iter_mut().zip(rows) {
            let a = row.to_array();
            *ray = Ray {
                origin: Vec3::new(a[0], a[1], a[2]),
                dir: Vec3::new(a[3], a[4], a[5]),
                t_min: a[6],
                t_max: a[7],
            };
        }
        out
    }

    /// Put `ray` in lane `lane`.
    #[inline(always)]
    pub fn set(&mut self, lane: usize, ray: &Ray) {
        for a in 0..3 {
            self.origin[a][lane] = ray.origin[a];
            self.dir[a][lane] = ray.dir[a];
        }
        self.t_min[lane] = ray.t_min;
        self.t_max[lane] = ray.t_max;
    }

    /// The lanes of `mask` whose rays are valid ([`Ray::is_valid`]: a finite origin, a finite
    /// and non-zero direction), checked in lanes.
    #[inline(always)]
    #[must_use]
    pub fn valid_lanes<S: Simd>(&self, s: S, mask: u32) -> u32 {
        let (inf, zero) = (s.splat(f32::INFINITY), s.splat(0.0));
        let (o, d) = (&self.origin, &self.dir);
        // `|v| < inf` is false for infinities and NaNs alike.
        let finite =
            s.load(o[0]).abs().lt(inf) & s.load(o[1]).abs().lt(inf) & s.load(o[2]).abs().lt(inf);
        let (dx, dy, dz) = (s.load(d[0]).abs(), s.load(d[1]).abs(), s.load(d[2]).abs());
        let dir = dx.lt(inf) & dy.lt(inf) & dz.lt(inf) & (dx.gt(zero) | dy.gt(zero) | dz.gt(zero));
        (finite & dir).bits() & mask
    }
}

impl From<&[Ray; WIDTH]> for RayLanes {
    #[inline]
    fn from(rays: &[Ray; WIDTH]) -> Self {
        let mut out = Self::splat(Ray::new(Vec3::ZERO, Vec3::Z));
        for (lane, ray) in rays.iter().enumerate() {
            out.set(lane, ray);
        }
        out
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

    /// The validity check in lanes, with both kinds of lanes.
    struct Valid<'a>(&'a RayLanes, u32);

    impl crate::lanes::WithSimd for Valid<'_> {
        type Output = u32;
        fn with_simd<S: Simd>(self, s: S) -> u32 {
            self.0.valid_lanes(s, self.1)
        }
    }

    /// `RayLanes::to_rays` with the lanes given.
    struct ToRays<'a>(&'a RayLanes);

    impl crate::lanes::WithSimd for ToRays<'_> {
        type Output = [Ray; WIDTH];
        fn with_simd<S: Simd>(self, s: S) -> [Ray; WIDTH] {
            self.0.to_rays(s)
        }
    }

    /// Rays stored by coordinate come back as they went in (one by one, and all eight by the
    /// transposition, with the detected and the portable lanes), and their validity in lanes is
    /// each ray's own (every non-finite or zero component in every coordinate, some lanes
    /// outside the mask), with the detected and the portable lanes.
    #[test]
    fn ray_lanes_keep_rays_and_check_them_as_one_ray() {
        let mut rays = Vec::new();
        for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 0.0, -0.0] {
            for axis in 0..6 {
                let (mut o, mut d) = (Vec3::new(1.0, -2.0, 3.0), Vec3::new(-0.5, 0.25, 1e-30));
                if axis < 3 {
                    o[axis] = bad;
                } else {
                    d[axis - 3] = bad;
                }
                rays.push(Ray::with_t_max(o, d, 2.5));
            }
        }
        rays.push(Ray::new(Vec3::ONE, Vec3::ZERO));
        rays.push(Ray::new(Vec3::splat(-3e38), Vec3::new(0.0, -1e-30, 0.0)));
        while rays.len() % WIDTH != 0 {
            rays.push(Ray::new(Vec3::ZERO, Vec3::X));
        }
        let (mut valid, mut invalid) = (0, 0);
        for (k, chunk) in rays.chunks_exact(WIDTH).enumerate() {
            let group: [Ray; WIDTH] = std::array::from_fn(|i| chunk[i]);
            let lanes = RayLanes::from(&group);
            let mask = [0xff, 0x7e, 0xa5][k % 3];
            let mut want = 0;
            for (lane, ray) in group.iter().enumerate() {
                let got = lanes.get(lane);
                // Bit for bit, NaN included.
                assert_eq!(
                    (
                        got.origin.to_array().map(f32::to_bits),
                        got.dir.to_array().map(f32::to_bits)
                    ),
                    (
                        ray.origin.to_array().map(f32::to_bits),
                        ray.dir.to_array().map(f32::to_bits)
                    ),
                );
                assert_eq!((got.t_min, got.t_max), (ray.t_min, ray.t_max));
                for all in [
                    crate::lanes::dispatch(ToRays(&lanes)),
                    crate::lanes::dispatch_portable(ToRays(&lanes)),
                ] {
                    let (a, b) = (all[lane], got);
                    assert_eq!(
                        [a.origin, a.dir].map(|v| v.to_array().map(f32::to_bits)),
                        [b.origin, b.dir].map(|v| v.to_array().map(f32::to_bits)),
                        "lane {lane}"
                    );
                    assert_eq!((a.t_min, a.t_max), (b.t_min, b.t_max));
                }
                if mask & (1 << lane) != 0 {
                    want |= u32::from(ray.is_valid()) << lane;
                    valid += usize::from(ray.is_valid());
                    invalid += usize::from(!ray.is_valid());
                }
            }
            assert_eq!(
                crate::lanes::dispatch(Valid(&lanes, mask)),
                want,
                "{group:?}"
            );
            assert_eq!(crate::lanes::dispatch_portable(Valid(&lanes, mask)), want);
        }
        assert!(
            valid > 5 && invalid > 10,
            "{valid} valid, {invalid} invalid"
        );
    }
}
