//! The six-face cube-map environment, importance sampled by texel solid angle.

use glam::{Mat3, Vec2, Vec3};
use pt_accel::{Bounds3, Ray};

use crate::color::Rgb;
use crate::image::Image;
use crate::light::environment::placement::Placement;
use crate::light::environment::{Cells, TexelDistribution, bilinear, check_texels, filter_3x3};
use crate::light::{Light, LightError, LightFlags, LightSample, LightSampleContext};

/// Cube face names in storage order.
pub const CUBE_FACES: [&str; 6] = ["px", "nx", "py", "ny", "pz", "nz"];

/// A direction in the OpenGL cube-map frame to `(face, s, t)` with `s, t` in `[0, 1]`, and the
/// major-axis magnitude `|ma|` of the (not necessarily unit) direction.
#[must_use]
pub fn cube_face_st(d: Vec3) -> (usize, Vec2, f32) {
    let a = d.abs();
    let (face, ma, sc, tc) = if a.x >= a.y && a.x >= a.z {
        if d.x > 0.0 {
            (0, a.x, -d.z, -d.y)
        } else {
            (1, a.x, d.z, -d.y)
        }
    } else if a.y >= a.z {
        if d.y > 0.0 {
            (2, a.y, d.x, d.z)
        } else {
            (3, a.y, d.x, -d.z)
        }
    } else if d.z > 0.0 {
        (4, a.z, d.x, -d.y)
    } else {
        (5, a.z, -d.x, -d.y)
    };
    let st = Vec2::new(0.5 * (sc / ma + 1.0), 0.5 * (tc / ma + 1.0));
    (face, st.clamp(Vec2::ZERO, Vec2::ONE), ma)
}

/// `(face, s, t)` to the point on the cube `[-1, 1]^3` (OpenGL frame): the inverse of
/// [`cube_face_st`].
#[must_use]
pub fn cube_face_point(face: usize, st: Vec2) -> Vec3 {
    let sc = 2.0 * st.x - 1.0;
    let tc = 2.0 * st.y - 1.0;
    match face {
        0 => Vec3::new(1.0, -tc, -sc),
        1 => Vec3::new(-1.0, -tc, sc),
        2 => Vec3::new(sc, 1.0, tc),
        3 => Vec3::new(sc, -1.0, -tc),
        4 => Vec3::new(sc, -tc, 1.0),
        _ => Vec3::new(-sc, -tc, -1.0),
    }
}

/// Solid angle subtended by the rectangle `[x0, x1] x [y0, y1]` of the plane at distance 1.
pub(crate) fn rect_solid_angle(x0: f32, x1: f32, y0: f32, y1: f32) -> f32 {
    let f = |x: f32, y: f32| (x * y).atan2((x * x + y * y + 1.0).sqrt());
    f(x1, y1) - f(x0, y1) - f(x1, y0) + f(x0, y0)
}

/// A six-face cube map environment (the report's sky box), importance sampled.
///
/// Texels are chosen with probability proportional to their filtered luminance times their solid
/// angle: first a cell of 8x8 texels (its face, row and column) by a distribution over the
/// cells, small enough to stay in the cache, then the texel within the cell from the cell's own
/// sums, which lie together in four cache lines (a 1024-texel face has 16,384 cells).
#[derive(Clone, Debug, PartialEq)]
pub struct CubemapEnvironment {
    faces: [Image; 6],
    size: u32,
    /// Each face's texels as sampling cells.
    cells: Cells,
    distribution: Option<TexelDistribution>,
    integral: Rgb,
    place: Placement,
}

/// World/map-frame direction to the OpenGL cube frame (x mirrored, see the module docs).
#[inline]
pub(crate) fn to_gl(d: Vec3) -> Vec3 {
    Vec3::new(-d.x, d.y, d.z)
}

impl CubemapEnvironment {
    /// A cube map from faces in the order `+x, -x, +y, -y, +z, -z` ([`CUBE_FACES`]), linear RGB,
    /// square and all the same size. Fails otherwise, or on a negative or non-finite texel.
    pub fn new(faces: [Image; 6]) -> Result<Self, LightError> {
        let size = faces[0].width();
        for (f, name) in faces.iter().zip(CUBE_FACES) {
            if f.width() != size || f.height() != size {
                return Err(LightError::BadSize(format!(
                    "cube faces must be square and the same size: {} is {}x{}, {} is {size}x{size}",
                    name,
                    f.width(),
                    f.height(),
                    CUBE_FACES[0]
                )));
            }
            check_texels(f, name)?;
        }
        let n = size as usize;
        let texel = 2.0 / size as f32;
        let mut omegas = Vec::with_capacity(n * n);
        for row in 0..n {
            for col in 0..n {
                let (x0, y0) = (-1.0 + col as f32 * texel, -1.0 + row as f32 * texel);
                omegas.push(rect_solid_angle(x0, x0 + texel, y0, y0 + texel));
            }
        }
        let cells = Cells::new(n, n);
        let mut map = Self {
            faces,
            size,
            cells,
            distribution: None,
            integral: Rgb::BLACK,
            place: Placement::new(),
        };
        let mut weights = vec![0.0f32; 6 * cells.items()];
        let mut integral = Rgb::BLACK;
        // Each face's luminance with a one-texel border from its neighbours (what `fetch`
        // returns there), computed once per texel rather than once per filter tap.
        let side = n + 2;
        let mut lum = vec![0.0f32; side * side];
        for face in 0..6 {
            for (i, l) in lum.iter_mut().enumerate() {
                let (c, r) = ((i % side) as i64 - 1, (i / side) as i64 - 1);
                *l = map.fetch(face, c, r).luminance();
            }
            for row in 0..n {
                for col in 0..n {
                    let centre = (row + 1) * side + col + 1;
                    let filtered =
                        filter_3x3(|dx, dy| lum[(centre as i64 + dy * side as i64 + dx) as usize]);
                    let omega = omegas[row * n + col];
                    weights[cells.item(face, col, row)] = filtered * omega;
                    integral += map.faces[face].get(col as u32, row as u32) * omega;
                }
            }
        }
        map.distribution = TexelDistribution::new(&weights);
        map.integral = integral;
        Ok(map)
    }

    /// Rotate the map: `rotation` takes map-frame directions to world directions.
    pub fn with_rotation(mut self, rotation: Mat3) -> Result<Self, LightError> {
        self.place.set_rotation(rotation)?;
        Ok(self)
    }

    /// Multiply the radiance by `scale` (finite, `>= 0`).
    pub fn with_scale(mut self, scale: f32) -> Result<Self, LightError> {
        let brightest = self
            .faces
            .iter()
            .flat_map(Image::pixels)
            .fold(0.0f32, |m, c| m.max(c.max_component()));
        self.place.set_scale(scale, brightest)?;
        Ok(self)
    }

    /// Face size in texels.
    #[must_use]
    pub fn size(&self) -> u32 {
        self.size
    }

    /// The texel `(face, column, row)` that world direction `wi` sees, and `|ma|`.
    // Here and below: always inlined without AVX2 (see the module's docs).
    #[cfg_attr(target_feature = "avx2", inline)]
    #[cfg_attr(not(target_feature = "avx2"), inline(always))]
    fn texel(&self, wi: Vec3) -> (usize, u32, u32, f32) {
        let (face, st, ma) = cube_face_st(to_gl(self.place.to_map * wi));
        let n = self.size;
        let col = ((st.x * n as f32) as u32).min(n - 1);
        let row = ((st.y * n as f32) as u32).min(n - 1);
        (face, col, row, ma)
    }

    /// Texel `(col, row)` of `face`, or, for a position up to one texel beyond the face's edge,
    /// the texel of the neighbouring face that its centre projects to (so that interpolation
    /// crosses the seams).
    #[cfg_attr(target_feature = "avx2", inline)]
    #[cfg_attr(not(target_feature = "avx2"), inline(always))]
    fn fetch(&self, face: usize, col: i64, row: i64) -> Rgb {
        let n = i64::from(self.size);
        if (0..n).contains(&col) && (0..n).contains(&row) {
            return self.faces[face].get(col as u32, row as u32);
        }
        let st = Vec2::new((col as f32 + 0.5) / n as f32, (row as f32 + 0.5) / n as f32);
        let (f, st, _) = cube_face_st(cube_face_point(face, st));
        let nf = n as f32;
        let c = ((st.x * nf) as i64).clamp(0, n - 1);
        let r = ((st.y * nf) as i64).clamp(0, n - 1);
        self.faces[f].get(c as u32, r as u32)
    }

    /// Radiance at `st` on `face`, interpolated bilinearly between texel centres.
    #[cfg_attr(target_feature = "avx2", inline)]
    #[cfg_attr(not(target_feature = "avx2"), inline(always))]
    fn lookup(&self, face: usize, st: Vec2) -> Rgb {
        let n = self.size as f32;
        bilinear(st * n, |x, y| self.fetch(face, x, y))
    }

    /// Radiance arriving from world direction `wi` (unit), scale included.
    #[must_use]
    #[cfg_attr(not(target_feature = "avx2"), inline(always))]
    pub fn radiance(&self, wi: Vec3) -> Rgb {
        let (face, st, _) = cube_face_st(to_gl(self.place.to_map * wi));
        self.lookup(face, st) * self.place.scale
    }
}

impl Light for CubemapEnvironment {
    fn flags(&self) -> LightFlags {
        LightFlags::INFINITE
    }

    fn power(&self) -> Rgb {
        self.place.power(self.integral)
    }

    #[cfg_attr(not(target_feature = "avx2"), inline(always))]
    fn sample_li(&self, ctx: &LightSampleContext, u: Vec2) -> Option<LightSample> {
        let dist = self.distribution.as_ref()?;
        let (index, pmf, ux) = dist.sample_discrete(u.x);
        if pmf <= 0.0 {
            return None;
        }
        let n = self.size as usize;
        let (face, col, row) = self.cells.texel(index);
        let st = Vec2::new((col as f32 + ux) / n as f32, (row as f32 + u.y) / n as f32);
        let p = cube_face_point(face, st);
        let r = p.length();
        // Uniform over the texel's area (2/n)^2 on the face, converted to solid angle.
        let texel_area = (2.0 / n as f32) * (2.0 / n as f32);
        let pdf = pmf / texel_area * r * r * r;
        let wi = (self.place.to_world * to_gl(p / r)).normalize();
        let li = self.lookup(face, st);
        Some(self.place.sample(ctx, wi, li, pdf))
    }

    #[cfg_attr(not(target_feature = "avx2"), inline(always))]
    fn prefetch_sample_li(&self, u: Vec2, step: u32) {
        let Some(dist) = &self.distribution else {
            return;
        };
        if step == 0 {
            dist.prefetch(u.x);
        } else if step == 1 {
            // The rows of the bilinear lookup's texels (clamped to the face: a tap across a
            // seam is not asked for).
            let (index, _, ux) = dist.sample_discrete(u.x);
            let (face, col, row) = self.cells.texel(index);
            let p = Vec2::new(col as f32 + ux, row as f32 + u.y) - 0.5;
            let last = self.size - 1;
            // Clamped at 0 first, truncation is the floor (and needs no `floorf` call).
            let x = (p.x.max(0.0) as u32).min(last);
            let y = p.y.max(0.0) as u32;
            for row in [y.min(last), (y + 1).min(last)] {
                self.faces[face].prefetch_pair(x, row);
            }
        }
    }

    #[cfg_attr(not(target_feature = "avx2"), inline(always))]
    fn pdf_li(&self, _ctx: &LightSampleContext, wi: Vec3) -> f32 {
        let Some(dist) = self.distribution.as_ref() else {
            return 0.0;
        };
        let (face, col, row, ma) = self.texel(wi.normalize());
        let n = self.size as usize;
        let pmf = dist.pmf(self.cells.item(face, col as usize, row as usize));
        let r = 1.0 / ma;
        let texel_area = (2.0 / n as f32) * (2.0 / n as f32);
        pmf / texel_area * r * r * r
    }

    #[cfg_attr(not(target_feature = "avx2"), inline(always))]
    fn le(&self, ray: &Ray) -> Rgb {
        self.radiance(ray.dir.normalize())
    }

    fn preprocess(&mut self, scene_bounds: &Bounds3) {
        self.place.preprocess(scene_bounds);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cube_faces_round_trip_and_tile() {
        for face in 0..6 {
            for st in [
                Vec2::new(0.1, 0.2),
                Vec2::new(0.5, 0.5),
                Vec2::new(0.9, 0.7),
            ] {
                let p = cube_face_point(face, st);
                let (f2, st2, ma) = cube_face_st(p * 3.0);
                assert_eq!(f2, face, "face of {p}");
                assert!((st2 - st).length() < 1e-6);
                assert!((ma - 3.0).abs() < 1e-5);
            }
        }
        // The OpenGL table: the centre of each face is its axis.
        let axes = [
            Vec3::X,
            Vec3::NEG_X,
            Vec3::Y,
            Vec3::NEG_Y,
            Vec3::Z,
            Vec3::NEG_Z,
        ];
        for (face, axis) in axes.iter().enumerate() {
            assert_eq!(cube_face_point(face, Vec2::splat(0.5)), *axis);
        }
        // Cross layout `nx pz px nz`: the right edge of pz meets the left edge of px, the right
        // edge of px the left edge of nz; py's bottom edge meets pz's top edge.
        let e = 1e-4;
        let pairs = [
            ((4, Vec2::new(1.0, 0.3)), (0, Vec2::new(0.0, 0.3))),
            ((0, Vec2::new(1.0, 0.6)), (5, Vec2::new(0.0, 0.6))),
            ((1, Vec2::new(1.0, 0.6)), (4, Vec2::new(0.0, 0.6))),
            ((2, Vec2::new(0.4, 1.0)), (4, Vec2::new(0.4, 0.0))),
            ((4, Vec2::new(0.4, 1.0)), (3, Vec2::new(0.4, 0.0))),
        ];
        for ((fa, a), (fb, b)) in pairs {
            let pa = cube_face_point(fa, a).normalize();
            let pb = cube_face_point(fb, b).normalize();
            assert!((pa - pb).length() < e, "faces {fa} and {fb} do not meet");
        }
        // Texel solid angles cover the sphere.
        let n = 64;
        let t = 2.0 / n as f32;
        let mut sum = 0.0f64;
        for r in 0..n {
            for c in 0..n {
                let x0 = -1.0 + c as f32 * t;
                let y0 = -1.0 + r as f32 * t;
                sum += f64::from(rect_solid_angle(x0, x0 + t, y0, y0 + t));
            }
        }
        assert!((6.0 * sum - 4.0 * std::f64::consts::PI).abs() < 1e-4);
    }

    /// The sampling weights (from the bordered luminance planes) equal the filtered
    /// luminance taken tap by tap through `fetch`, across the seams, on a random map.
    #[test]
    fn sampling_weights_filter_across_the_seams() {
        let n = 5u32;
        let mut state = 7u32;
        let faces = std::array::from_fn(|_| {
            let mut img = Image::new(n, n);
            for y in 0..n {
                for x in 0..n {
                    let mut r = || {
                        state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
                        (state >> 8) as f32 / (1 << 24) as f32 * 10.0
                    };
                    img.set(x, y, Rgb::new(r(), r(), r()));
                }
            }
            img
        });
        let map = CubemapEnvironment::new(faces).unwrap();
        let m = n as usize;
        let t = 2.0 / n as f32;
        let dist = map.distribution.as_ref().unwrap();
        let mut seen = vec![false; dist.len()];
        for face in 0..6 {
            for r in 0..m {
                for c in 0..m {
                    let (ci, ri) = (c as i64, r as i64);
                    let l = filter_3x3(|dx, dy| map.fetch(face, ci + dx, ri + dy).luminance());
                    let (x0, y0) = (-1.0 + c as f32 * t, -1.0 + r as f32 * t);
                    let expected = l * rect_solid_angle(x0, x0 + t, y0, y0 + t);
                    let item = map.cells.item(face, c, r);
                    assert_eq!(map.cells.texel(item), (face, c, r));
                    seen[item] = true;
                    // A difference of running sums: within the rounding of the cell's sum.
                    let w = dist.weight(item);
                    assert!((w - expected).abs() <= 1e-5 * expected, "{face} {c} {r}");
                }
            }
        }
        // Every other item (beyond a face's edge in its last cells) has weight 0.
        for (item, seen) in seen.into_iter().enumerate() {
            assert!(seen || dist.weight(item) == 0.0, "item {item}");
        }
    }
}
