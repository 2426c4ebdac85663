//! Eight triangles at once (the two four-triangle packets of a full leaf), tested against one
//! ray in one pass of eight-lane vectors: on AVX2 one 256-bit register holds a coordinate of all
//! eight, where the four-lane test needs two passes of 128-bit ones. Every lane follows the
//! four-lane test's operations in the same order (no fused multiply-add: the products and sums
//! round as they do there), so a lane's hit is bit for bit the scalar test's, and the results
//! of [`RayTriangleTest::closest8_full`] and [`RayTriangleTest::any8_full`] are exactly those of
//! the four-lane calls on the two packets in turn
//! (`eight_lanes_equal_two_four_lane_calls` checks it).

use crate::float::gamma;
use crate::simd::Simd8;
use crate::triangle::{RayTriangleTest, TriangleHit};

use super::Triangles4;

/// What the eight-lane pass decided: the lanes hit within its `t_max` (among those decided in
/// f32), the lanes with an edge function exactly zero in f32 (the scalar test, which recomputes
/// that edge in f64, decides them), and, when a lane is hit, the values its hit is finished
/// from.
type Pass8 = (u32, u32, Option<Lanes8>);

/// The per-lane values of an eight-lane pass.
struct Lanes8 {
    t: [f32; 8],
    inv_det: [f32; 8],
    e1: [f32; 8],
    e2: [f32; 8],
}

impl Lanes8 {
    /// The hit of lane `j`, rounded as the scalar test rounds it.
    #[inline(always)]
    fn get(&self, j: usize) -> TriangleHit {
        TriangleHit {
            t: self.t[j],
            b1: self.e1[j] * self.inv_det[j],
            b2: self.e2[j] * self.inv_det[j],
        }
    }
}

/// The largest magnitude of three lanes.
#[inline(always)]
fn max3<S: Simd8>(s: S, v: [S::F; 3]) -> S::F {
    s.max_or(s.max_or(s.abs(v[0]), s.abs(v[1])), s.abs(v[2]))
}

impl RayTriangleTest {
    /// The four-lane test's arithmetic ([`Self::intersect4`]) on the eight triangles of `p`,
    /// lane `4 k + i` being lane `i` of packet `k`.
    #[inline(always)]
    fn lanes8<S: Simd8>(&self, s: S, p: [&Triangles4; 2], t_max: f32) -> Pass8 {
        fn axes(q: &Triangles4) -> [&[glam::Vec4; 3]; 4] {
            [&q.x, &q.y, &q.z, &q.z]
        }
        // No closures over lane values here (nor `array::from_fn`): a build for baseline x86-64
        // may compile them outside the instruction set's entry, where every lane operation
        // becomes a function call (see `lanes::WithSimd`).
        let (a0, a1) = (axes(p[0]), axes(p[1]));
        let (kx, ky, kz) = (self.k[0] & 3, self.k[1] & 3, self.k[2] & 3);
        let (o0, o1, o2) = (s.splat(self.o[0]), s.splat(self.o[1]), s.splat(self.o[2]));
        let (sx, sy) = (s.splat(self.sx), s.splat(self.sy));
        let mut z_raw = [o0; 3];
        let mut x = [o0; 3];
        let mut y = [o0; 3];
        for c in 0..3 {
            z_raw[c] = s.sub(s.load_pair(&a0[kz][c], &a1[kz][c]), o2);
            x[c] = s.add(
                s.sub(s.load_pair(&a0[kx][c], &a1[kx][c]), o0),
                s.mul(z_raw[c], sx),
            );
            y[c] = s.add(
                s.sub(s.load_pair(&a0[ky][c], &a1[ky][c]), o1),
                s.mul(z_raw[c], sy),
            );
        }
        // Edge functions, corner i: x[i+1] y[i+2] - y[i+1] x[i+2] (the scalar test's lanes).
        let e = [
            s.sub(s.mul(x[1], y[2]), s.mul(y[1], x[2])),
            s.sub(s.mul(x[2], y[0]), s.mul(y[2], x[0])),
            s.sub(s.mul(x[0], y[1]), s.mul(y[0], x[1])),
        ];
        let zero = s.splat(0.0);
        // Lanes with an edge function exactly zero (or NaN) in f32: the scalar test recomputes
        // that edge in f64.
        let mut uncertain = 0;
        let (mut neg, mut pos) = (0, 0);
        for v in e {
            let (n, p) = (s.lt_mask(v, zero), s.lt_mask(zero, v));
            uncertain |= !(n | p);
            neg |= n;
            pos |= p;
        }
        let uncertain = uncertain & 0xff;
        let inside = 0xff & !uncertain & !(neg & pos);
        if inside == 0 {
            return (0, uncertain, None);
        }
        let det = s.add(s.add(e[0], e[1]), e[2]);
        let sz = s.splat(self.sz);
        let z = [
            s.mul(z_raw[0], sz),
            s.mul(z_raw[1], sz),
            s.mul(z_raw[2], sz),
        ];
        let t_scaled = s.add(
            s.add(s.mul(e[0], z[0]), s.mul(e[1], z[1])),
            s.mul(e[2], z[2]),
        );
        let inf = s.splat(f32::INFINITY);
        let det_ok = s.ne_mask(det, zero) & s.lt_mask(s.abs(det), inf);
        let bound = s.mul(s.splat(t_max), det);
        let in_range =
            (s.lt_mask(zero, det) & s.lt_mask(zero, t_scaled) & s.le_mask(t_scaled, bound))
                | (s.lt_mask(det, zero) & s.lt_mask(t_scaled, zero) & s.le_mask(bound, t_scaled));
        // Crossings behind the origin or beyond `t_max` (a closest-hit query's usual case once
        // a hit is known) need neither the division nor the error bound.
        if det_ok & in_range & inside == 0 {
            return (0, uncertain, None);
        }
        let inv_det = s.div(s.splat(1.0), det);
        let t = s.mul(t_scaled, inv_det);
        let t_ok = s.le_mask(s.splat(self.t_min), t) & s.lt_mask(s.abs(t), inf);
        let (max_z, max_z_raw, max_x, max_y, max_e) = (
            max3(s, z),
            max3(s, z_raw),
            max3(s, x),
            max3(s, y),
            max3(s, e),
        );
        let delta_z = s.mul(s.splat(gamma(3)), max_z);
        let delta_x = s.mul(s.splat(gamma(5)), s.add(max_x, max_z_raw));
        let delta_y = s.mul(s.splat(gamma(5)), s.add(max_y, max_z_raw));
        let delta_e = s.mul(
            s.splat(2.0),
            s.add(
                s.add(
                    s.mul(s.mul(s.splat(gamma(2)), max_x), max_y),
                    s.mul(delta_y, max_x),
                ),
                s.mul(delta_x, max_y),
            ),
        );
        let delta_t = s.mul(
            s.mul(
                s.splat(3.0),
                s.add(
                    s.add(
                        s.mul(s.mul(s.splat(gamma(3)), max_e), max_z),
                        s.mul(delta_e, max_z),
                    ),
                    s.mul(delta_z, max_e),
                ),
            ),
            s.abs(inv_det),
        );
        let crossed = det_ok & in_range & t_ok;
        let accepted = crossed & s.lt_mask(delta_t, t);
        let hit = accepted & inside;
        // Crossings within the error bound: the scalar test decides them in f64.
        let uncertain = uncertain | (crossed & inside & !accepted);
        if hit == 0 {
            return (0, uncertain, None);
        }
        let values = Lanes8 {
            t: s.to_array(t),
            inv_det: s.to_array(inv_det),
            e1: s.to_array(e[1]),
            e2: s.to_array(e[2]),
        };
        (hit, uncertain, Some(values))
    }

    /// The nearest hit of packet `k` within `t_max`, as [`Self::closest4`] picks it: the
    /// vector hits first (lowest lane on a tie), then the uncertain lanes through the scalar
    /// test.
    #[inline(always)]
    fn resolve8(
        &self,
        pass: &Pass8,
        k: usize,
        tris: &Triangles4,
        bound: f32,
        t_max: f32,
    ) -> Option<(usize, TriangleHit)> {
        let mut best: Option<(usize, TriangleHit)> = None;
        let mut t_best = t_max;
        let (hit, uncertain, values) = pass;
        let mut hit = (hit >> (4 * k)) & 0xf;
        while let Some(l) = values
            && hit != 0
        {
            let i = hit.trailing_zeros() as usize;
            hit &= hit - 1;
            let j = 4 * k + i;
            if l.t[j] <= t_max && best.is_none_or(|(_, b)| l.t[j] < b.t) {
                best = Some((i, l.get(j)));
            }
        }
        if let Some((_, h)) = best {
            t_best = h.t;
        }
        let mut uncertain = (uncertain >> (4 * k)) & 0xf;
        while uncertain != 0 {
            let i = uncertain.trailing_zeros() as usize;
            uncertain &= uncertain - 1;
            if let Some(h) = self.intersect_packed(&tris.lane(i), bound)
                && (h.t < t_best || (h.t == t_best && best.is_none_or(|(b, _)| i < b)))
            {
                t_best = h.t;
                best = Some((i, h));
            }
        }
        best
    }

    /// [`Self::closest4_full`] on `p[0]` and then on `p[1]` with `t_max` lowered to the first
    /// one's hit (the same `bound`), in one eight-lane pass: per packet, its lane and hit,
    /// exactly as the two calls return them.
    #[inline(always)]
    pub(crate) fn closest8_full<S: Simd8>(
        &self,
        s: S,
        p: [&Triangles4; 2],
        bound: f32,
        t_max: f32,
    ) -> [Option<(usize, TriangleHit)>; 2] {
        let pass = self.lanes8(s, p, bound);
        if pass.0 | pass.1 == 0 {
            return [None, None];
        }
        let first = self.resolve8(&pass, 0, p[0], bound, t_max);
        let second = self.resolve8(&pass, 1, p[1], bound, first.map_or(t_max, |(_, h)| h.t));
        [first, second]
    }

    /// True when any of the eight triangles of `p` is hit ([`Self::any4`] on each packet).
    #[inline(always)]
    pub(crate) fn any8_full<S: Simd8>(&self, s: S, p: [&Triangles4; 2], t_max: f32) -> bool {
        let (hit, mut uncertain, _) = self.lanes8(s, p, t_max);
        if hit != 0 {
            return true;
        }
        while uncertain != 0 {
            let j = uncertain.trailing_zeros() as usize;
            uncertain &= uncertain - 1;
            if self
                .intersect_packed(&p[j / 4].lane(j % 4), t_max)
                .is_some()
            {
                return true;
            }
        }
        false
    }
}

#[cfg(test)]
mod tests {
    use glam::{Vec3, Vec3A};

    use super::*;
    use crate::ray::Ray;
    use crate::simd::Portable;
    use crate::triangle::{PackedTriangle, PackedTriangles4};

    /// The eight-lane pass returns exactly what the four-lane test returns on the two packets
    /// in turn (the second with `t_max` lowered to the first's hit), for every instruction set
    /// this CPU has: random triangles and rays at many scales, rays aimed at the triangles'
    /// corners and edges (where the f64 fallback runs), triangles repeated across the packets
    /// (ties), and finite and infinite `t_max`.
    #[test]
    fn eight_lanes_equal_two_four_lane_calls() {
        let mut rnd = crate::test_rng::uniform(0x2545_f491_4f6c_dd1du64);
        let (mut hits, mut uncertain_rays) = (0, 0);
        for round in 0..20_000 {
            let scale = 10f32.powi((round % 9) as i32 - 4);
            let offset = if round % 5 == 0 { 1e4 * scale } else { 0.0 };
            let mut v =
                || Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5) * scale + Vec3::splat(offset);
            let mut tris: Vec<PackedTriangle> = (0..8)
                .map(|_| PackedTriangle::new(&[v(), v(), v()].map(Vec3A::from)))
                .collect();
            if round % 4 == 1 {
                // The same triangle in both packets: equal distances decide by packet order.
                tris[5] = tris[(round / 4) % 4];
            }
            let aim = tris[(round / 3) % 8].corners();
            let mut origin = Vec3A::from(v()) + Vec3A::new(0.0, 0.0, 2.0 * scale);
            let mut target = match round % 3 {
                0 => (aim[0] + aim[1] + aim[2]) / 3.0,
                1 => aim[round % 3],
                _ => (aim[0] + aim[1]) * 0.5,
            };
            if round % 11 == 0 {
                // Toward a triangle's centre from heights above it shrinking by sqrt(2) per
                // round: somewhere the hit's distance crosses the bound on its rounding error,
                // which decides it.
                target = (aim[0] + aim[1] + aim[2]) / 3.0;
                let n = (aim[1] - aim[0]).cross(aim[2] - aim[0]).normalize_or_zero();
                origin = target + n * scale * 2f32.powf(-(((round / 11) % 48) as f32) * 0.5);
            }
            let ray = Ray::with_t_max(
                origin.into(),
                (target - origin).into(),
                if round % 7 == 0 {
                    0.5 * scale
                } else {
                    f32::INFINITY
                },
            );
            let test = RayTriangleTest::new(&ray);
            let packets = [
                Triangles4::from_full(&PackedTriangles4::new(&tris[..4])),
                Triangles4::from_full(&PackedTriangles4::new(&tris[4..])),
            ];
            let bound = ray.t_max;
            let first = test.closest4_full(&packets[0], bound, ray.t_max);
            let second =
                test.closest4_full(&packets[1], bound, first.map_or(ray.t_max, |(_, h)| h.t));
            let any =
                test.any4_full(&packets[0], ray.t_max) || test.any4_full(&packets[1], ray.t_max);
            let bits = |r: [Option<(usize, TriangleHit)>; 2]| {
                r.map(|o| o.map(|(lane, h)| (lane, h.t.to_bits(), h.b1.to_bits(), h.b2.to_bits())))
            };
            let want = bits([first, second]);
            let pair = [&packets[0], &packets[1]];
            assert_eq!(
                bits(test.closest8_full(Portable, pair, bound, ray.t_max)),
                want,
                "round {round}"
            );
            assert_eq!(
                test.any8_full(Portable, pair, ray.t_max),
                any,
                "round {round}"
            );
            #[cfg(target_arch = "x86_64")]
            if let Some(avx2) = crate::simd::Avx2::detect() {
                // Outside a target-feature function the intrinsics are calls, not single
                // instructions: slower, with the same results.
                assert_eq!(
                    bits(test.closest8_full(avx2, pair, bound, ray.t_max)),
                    want,
                    "round {round}"
                );
                assert_eq!(test.any8_full(avx2, pair, ray.t_max), any, "round {round}");
            }
            hits += usize::from(first.is_some() || second.is_some());
            uncertain_rays += usize::from(test.lanes8(Portable, pair, ray.t_max).1 != 0);
        }
        assert!(hits > 5_000, "only {hits} rays hit");
        assert!(
            uncertain_rays > 1_000,
            "only {uncertain_rays} rays took the f64 fallback"
        );
    }
}
