//! Four triangles at once: their corners across SIMD lanes, tested against one ray with the same
//! arithmetic as the scalar test, lane for lane (so the results are bit for bit the same).

use glam::{Vec3A, Vec4};

use crate::triangle::{ERROR_CONSTANTS, Maxima, PackedTriangle, RayTriangleTest, TriangleHit};

/// Four triangles stored across SIMD lanes: lane `i` of `x[c]` is the x coordinate of corner `c`
/// of triangle `i`. [`RayTriangleTest::intersect4`] tests all four at once.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PackedTriangles4 {
    tris: Triangles4,
    /// Bit mask of the lanes that hold a triangle (the last packet of a list may be partly
    /// empty).
    live: u32,
}

/// The coordinates of four triangles, every lane live: 144 bytes, so that packets stored one
/// after another each touch three cache lines whatever their 16-byte alignment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Triangles4 {
    pub(crate) x: [Vec4; 3],
    pub(crate) y: [Vec4; 3],
    pub(crate) z: [Vec4; 3],
}

impl Triangles4 {
    /// The triangle in lane `i` (for the lanes that need the exact, f64, edge test).
    #[inline]
    pub(crate) fn lane(&self, i: usize) -> PackedTriangle {
        let corners = |v: &[Vec4; 3]| Vec3A::new(v[0][i], v[1][i], v[2][i]);
        PackedTriangle {
            xs: corners(&self.x),
            ys: corners(&self.y),
            zs: corners(&self.z),
        }
    }

    /// The four triangles of a packet whose lanes are all live (see
    /// [`PackedTriangles4::padded`]).
    pub fn from_full(p: &PackedTriangles4) -> Self {
        debug_assert_eq!(p.live, 0b1111);
        p.tris
    }
}

impl PackedTriangles4 {
    /// Pack up to four triangles (`tris.len()` in 1..=4).
    #[must_use]
    pub fn new(tris: &[PackedTriangle]) -> Self {
        assert!(
            (1..=4).contains(&tris.len()),
            "a packet holds 1 to 4 triangles"
        );
        let mut all = [tris[0]; 4];
        all[..tris.len()].copy_from_slice(tris);
        let lane = |f: &dyn Fn(&PackedTriangle) -> f32| {
            Vec4::new(f(&all[0]), f(&all[1]), f(&all[2]), f(&all[3]))
        };
        let corner = |c: usize| (lane(&|t| t.xs[c]), lane(&|t| t.ys[c]), lane(&|t| t.zs[c]));
        let (c0, c1, c2) = (corner(0), corner(1), corner(2));
        Self {
            tris: Triangles4 {
                x: [c0.0, c1.0, c2.0],
                y: [c0.1, c1.1, c2.1],
                z: [c0.2, c1.2, c2.2],
            },
            live: (1u32 << tris.len()) - 1,
        }
    }

    /// The triangle in lane `i` (for the lanes that need the exact, f64, edge test).
    #[inline]
    fn lane(&self, i: usize) -> PackedTriangle {
        self.tris.lane(i)
    }

    /// Pack one to four triangles and fill the remaining lanes with copies of the last one, so
    /// that every lane is live (a copy can only repeat a hit of its original, in a later lane).
    #[must_use]
    pub fn padded(tris: &[PackedTriangle]) -> Self {
        let last = *tris.last().expect("a packet holds 1 to 4 triangles");
        let mut all = [last; 4];
        all[..tris.len()].copy_from_slice(tris);
        Self::new(&all)
    }

    /// Bit mask of the lanes that hold a triangle.
    #[inline(always)]
    fn live(&self) -> u32 {
        self.live
    }

    /// How many lanes hold a triangle.
    #[must_use]
    pub fn len(&self) -> usize {
        self.live.count_ones() as usize
    }

    /// True when no lane holds a triangle (never, for a packet made by [`Self::new`]).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.live == 0
    }
}

/// The largest magnitude of three vectors, lane by lane.
#[inline(always)]
fn max3(v: [Vec4; 3]) -> Vec4 {
    v[0].abs().max(v[1].abs()).max(v[2].abs())
}

/// What the four-lane test decided in f32, before any lane is picked.
#[derive(Clone, Copy)]
struct Lanes4 {
    /// Lanes hit (bit `i` for lane `i`), among those decided in f32.
    hit: u32,
    /// Lanes with an edge function exactly zero (or NaN) in f32, or crossing within the f32
    /// bound on `t`'s error: the scalar test, which recomputes that edge or `t` in f64,
    /// decides them.
    uncertain: u32,
    t: Vec4,
    inv_det: Vec4,
    e1: Vec4,
    e2: Vec4,
}

impl Lanes4 {
    /// No lane hit in f32; the `uncertain` ones are left to the scalar test.
    #[inline(always)]
    fn miss(uncertain: u32) -> Self {
        Self {
            hit: 0,
            uncertain,
            t: Vec4::ZERO,
            inv_det: Vec4::ZERO,
            e1: Vec4::ZERO,
            e2: Vec4::ZERO,
        }
    }

    /// The hit of lane `i` (which must be in `hit`), rounded as the scalar test rounds it.
    #[inline(always)]
    fn get(&self, i: usize) -> TriangleHit {
        TriangleHit {
            t: self.t[i],
            b1: self.e1[i] * self.inv_det[i],
            b2: self.e2[i] * self.inv_det[i],
        }
    }
}

impl RayTriangleTest {
    /// The four-lane test up to the choice of lanes: every lane follows the scalar test's
    /// operations in the same order (the range checks and the error bound of [`Self::finish`],
    /// lane-wise), so a lane it accepts is exactly the scalar test's hit. `live` masks the lanes
    /// that hold a triangle.
    #[inline(always)]
    fn lanes4(&self, p: &Triangles4, t_max: f32, live: u32) -> Lanes4 {
        // Translate, permute and shear (per corner, four triangles per vector), as the scalar
        // test does.
        let axes = [&p.x, &p.y, &p.z, &p.z];
        let [kx, ky, kz] = self.k.map(|a| a & 3);
        let z_raw: [Vec4; 3] = std::array::from_fn(|c| axes[kz][c] - self.o[2]);
        let x: [Vec4; 3] = std::array::from_fn(|c| (axes[kx][c] - self.o[0]) + z_raw[c] * self.sx);
        let y: [Vec4; 3] = std::array::from_fn(|c| (axes[ky][c] - self.o[1]) + z_raw[c] * self.sy);
        // Edge functions, corner i: x[i+1] y[i+2] - y[i+1] x[i+2] (the scalar test's lanes).
        let e = [
            x[1] * y[2] - y[1] * x[2],
            x[2] * y[0] - y[2] * x[0],
            x[0] * y[1] - y[0] * x[1],
        ];
        let zero = Vec4::ZERO;
        // Lanes with an edge function exactly zero (or NaN) in f32: the scalar test recomputes
        // that edge in f64. (Vector masks, one bit mask each at the end.)
        let (n0, n1, n2) = (e[0].cmplt(zero), e[1].cmplt(zero), e[2].cmplt(zero));
        let (p0, p1, p2) = (e[0].cmpgt(zero), e[1].cmpgt(zero), e[2].cmpgt(zero));
        let uncertain = live & !((n0 | p0) & (n1 | p1) & (n2 | p2)).bitmask();
        // Lanes decided in f32 that the ray passes inside of: all three edge functions of one
        // strict sign.
        let (all_neg, all_pos) = (n0 & n1 & n2, p0 & p1 & p2);
        let inside = live & (all_neg | all_pos).bitmask();
        let det = e[0] + e[1] + e[2];
        if inside == 0 {
            return Lanes4::miss(uncertain);
        }
        let z = [z_raw[0] * self.sz, z_raw[1] * self.sz, z_raw[2] * self.sz];
        // e.dot(z) as glam computes it for Vec3A: (e0 z0 + e1 z1) + e2 z2.
        let t_scaled = (e[0] * z[0] + e[1] * z[1]) + e[2] * z[2];
        // `finish`, lane-wise: a finite non-zero determinant, the scaled distance inside the range
        // on the determinant's side, t finite and not below t_min, t above its error bound.
        let inf = Vec4::INFINITY;
        let det_ok = det.cmpne(zero) & det.abs().cmplt(inf);
        let bound = Vec4::splat(t_max) * det;
        let in_range = (det.cmpgt(zero) & t_scaled.cmpgt(zero) & t_scaled.cmple(bound))
            | (det.cmplt(zero) & t_scaled.cmplt(zero) & t_scaled.cmpge(bound));
        // Crossings behind the origin or beyond `t_max` (a closest-hit query's usual case once
        // a hit is known) need neither the division nor the error bound.
        if (det_ok & in_range).bitmask() & inside == 0 {
            return Lanes4::miss(uncertain);
        }
        let inv_det = Vec4::ONE / det;
        let t = t_scaled * inv_det;
        let t_ok = t.cmpge(Vec4::splat(self.t_min)) & t.abs().cmplt(inf);
        let m = Maxima {
            x: max3(x),
            y: max3(y),
            z: max3(z),
            z_raw: max3(z_raw),
            e: max3(e),
        };
        let [c0, c1, c2, c3, c4] = ERROR_CONSTANTS;
        let splat = Vec4::splat;
        let c = [splat(c0), splat(c1), splat(c2), splat(c3), splat(c4)];
        let delta_t = m.t_error_bound(inv_det.abs(), c);
        let crossed = det_ok & in_range & t_ok;
        let accepted = crossed & t.cmpgt(delta_t);
        Lanes4 {
            hit: accepted.bitmask() & inside,
            // Crossings within the error bound: the scalar test decides them in f64.
            uncertain: uncertain | (crossed.bitmask() & inside & !accepted.bitmask()),
            t,
            inv_det,
            e1: e[1],
            e2: e[2],
        }
    }

    /// [`intersect_packed`](Self::intersect_packed) for four triangles at once: lane `i` of
    /// the result is exactly (bit for bit) what `intersect_packed(tri_i, t_max)` returns. A lane
    /// with an edge function exactly zero in f32, or a crossing within the f32 bound on `t`'s
    /// error, is finished by the scalar test itself (which recomputes that edge, or `t`, in
    /// f64).
    #[inline]
    #[must_use]
    pub fn intersect4(&self, p: &PackedTriangles4, t_max: f32) -> [Option<TriangleHit>; 4] {
        let l = self.lanes4(&p.tris, t_max, p.live());
        std::array::from_fn(|lane| {
            if l.hit & (1 << lane) != 0 {
                Some(l.get(lane))
            } else if l.uncertain & (1 << lane) != 0 {
                self.intersect_packed(&p.lane(lane), t_max)
            } else {
                None
            }
        })
    }

    /// The nearest hit among the four triangles with `t <= t_max` (and all the conditions of
    /// [`intersect_packed`](Self::intersect_packed)): its lane and the hit, exactly as the scalar
    /// test computes it. Of several lanes at the same distance the lowest wins.
    #[inline(always)]
    #[must_use]
    pub fn closest4(&self, p: &PackedTriangles4, t_max: f32) -> Option<(usize, TriangleHit)> {
        self.closest4_in(&p.tris, p.live(), t_max, t_max)
    }

    /// [`Self::closest4`] with the range check on the scaled distance made against `bound`
    /// (at least `t_max`; see [`super::tie_bound`]) and only the divided distance against
    /// `t_max`: a closest-hit query's step once it has a hit at `t_max`.
    #[inline(always)]
    pub(crate) fn closest4_bounded(
        &self,
        p: &PackedTriangles4,
        bound: f32,
        t_max: f32,
    ) -> Option<(usize, TriangleHit)> {
        self.closest4_in(&p.tris, p.live(), bound, t_max)
    }

    /// [`Self::closest4_bounded`] for a packet whose four lanes are all live.
    #[inline(always)]
    pub(crate) fn closest4_full(
        &self,
        p: &Triangles4,
        bound: f32,
        t_max: f32,
    ) -> Option<(usize, TriangleHit)> {
        self.closest4_in(p, 0b1111, bound, t_max)
    }

    #[inline(always)]
    fn closest4_in(
        &self,
        p: &Triangles4,
        live: u32,
        bound: f32,
        t_max: f32,
    ) -> Option<(usize, TriangleHit)> {
        let l = self.lanes4(p, bound, live);
        let mut best = None;
        let mut t_best = t_max;
        // The range check works on the scaled distance; the division can round t just past t_max.
        let hit = l.hit & l.t.cmple(Vec4::splat(t_max)).bitmask();
        if hit != 0 {
            // Nearly always one lane: the nearest of several only where triangles meet.
            let lane = if hit & (hit - 1) == 0 {
                hit.trailing_zeros()
            } else {
                let t = Vec4::select(mask4(hit), l.t, Vec4::INFINITY);
                (t.cmpeq(Vec4::splat(t.min_element())).bitmask() & hit).trailing_zeros()
            };
            let h = l.get(lane as usize);
            t_best = h.t;
            best = Some((lane as usize, h));
        }
        let mut uncertain = l.uncertain;
        while uncertain != 0 {
            let lane = uncertain.trailing_zeros() as usize;
            uncertain &= uncertain - 1;
            if let Some(h) = self.intersect_packed(&p.lane(lane), bound)
                && (h.t < t_best || (h.t == t_best && best.is_none_or(|(b, _)| lane < b)))
            {
                t_best = h.t;
                best = Some((lane, h));
            }
        }
        best
    }

    /// True when any of the four triangles is hit (the conditions of
    /// [`intersect_packed`](Self::intersect_packed)).
    #[inline(always)]
    #[must_use]
    pub fn any4(&self, p: &PackedTriangles4, t_max: f32) -> bool {
        self.any4_in(&p.tris, p.live(), t_max)
    }

    /// [`Self::any4`] for a packet whose four lanes are all live.
    #[inline(always)]
    pub(crate) fn any4_full(&self, p: &Triangles4, t_max: f32) -> bool {
        self.any4_in(p, 0b1111, t_max)
    }

    #[inline(always)]
    fn any4_in(&self, p: &Triangles4, live: u32, t_max: f32) -> bool {
        let l = self.lanes4(p, t_max, live);
        if l.hit != 0 {
            return true;
        }
        let mut uncertain = l.uncertain;
        while uncertain != 0 {
            let lane = uncertain.trailing_zeros() as usize;
            uncertain &= uncertain - 1;
            if self.intersect_packed(&p.lane(lane), t_max).is_some() {
                return true;
            }
        }
        false
    }
}

/// A lane mask (bit `i` for lane `i`) as a vector mask.
#[inline(always)]
fn mask4(bits: u32) -> glam::BVec4A {
    glam::BVec4A::new(bits & 1 != 0, bits & 2 != 0, bits & 4 != 0, bits & 8 != 0)
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::ray::Ray;

    /// The four-lane test returns, lane for lane, exactly what the scalar test returns: same
    /// hits, same misses, same bits of t and barycentrics, for random triangles and rays at many
    /// scales, rays aimed at corners and edges (where the f64 fallback runs), and partial packets.
    #[test]
    fn four_lanes_equal_the_scalar_test_bit_for_bit() {
        let mut rnd = crate::test_rng::uniform(0x9e37_79b9_7f4a_7c15u64);
        let (mut hits, mut fallbacks) = (0, 0);
        for round in 0..20_000 {
            let scale = 10f32.powi((round % 9) as i32 - 4);
            let offset = if round % 5 == 0 { 1e4 * scale } else { 0.0 };
            let mut r: Vec<f32> = (0..48).map(|_| rnd()).collect();
            let mut k = 0;
            let mut v = || {
                k += 3;
                Vec3::new(r[k - 3] - 0.5, r[k - 2] - 0.5, r[k - 1] - 0.5) * scale
                    + Vec3::splat(offset)
            };
            let tris: Vec<PackedTriangle> = (0..4)
                .map(|_| PackedTriangle::new(&[v(), v(), v()].map(Vec3A::from)))
                .collect();
            let origin = Vec3A::from(v()) + Vec3A::new(0.0, 0.0, 2.0 * scale);
            r.clear();
            let n = 1 + round % 4;
            let packet = PackedTriangles4::new(&tris[..n]);
            // Aim at a random point of the first triangle, at one of its corners, or at the
            // midpoint of one of its edges.
            let c = tris[0].corners();
            let target = match round % 3 {
                0 => {
                    let (a, b) = (rnd(), rnd());
                    let (a, b) = if a + b > 1.0 {
                        (1.0 - a, 1.0 - b)
                    } else {
                        (a, b)
                    };
                    c[0] + (c[1] - c[0]) * a + (c[2] - c[0]) * b
                }
                1 => c[round % 3],
                _ => (c[0] + c[1]) * 0.5,
            };
            let ray = Ray::with_t_max(
                origin.into(),
                (target - origin).into(),
                if round % 7 == 0 { 0.5 } else { f32::INFINITY },
            );
            let test = RayTriangleTest::new(&ray);
            let four = test.intersect4(&packet, ray.t_max);
            for lane in 0..4 {
                let want = if lane < n {
                    test.intersect_packed(&tris[lane], ray.t_max)
                } else {
                    None
                };
                let same = match (four[lane], want) {
                    (Some(a), Some(b)) => {
                        a.t.to_bits() == b.t.to_bits()
                            && a.b1.to_bits() == b.b1.to_bits()
                            && a.b2.to_bits() == b.b2.to_bits()
                    }
                    (None, None) => true,
                    _ => false,
                };
                assert!(
                    same,
                    "round {round}, lane {lane}: {:?} against {want:?}",
                    four[lane]
                );
                hits += usize::from(want.is_some());
            }
            fallbacks += usize::from(round % 3 != 0);
        }
        assert!(
            hits > 10_000,
            "only {hits} hits: the rays should mostly hit"
        );
        assert!(fallbacks > 0);
    }
}
