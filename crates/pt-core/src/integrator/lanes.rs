//! The lane path tracer: eight paths per thread in SIMD lanes ([`pt_accel::lanes`]), each lane
//! refilled with the tile's next sample as its path ends.
//!
//! It computes the estimator of the one-path tracer (`path.rs`) for the scenes whose every material
//! it knows in lane form (Lambertian, mirror and smooth glass, no absorbing media) and the Sobol
//! sampler: triangle lights are sampled by area in lanes, every other light (environments, punctual
//! lights, textured emitters) by its own `sample_li`, lane by lane. Its lanes draw the same sample
//! values in the same order (the lane Sobol sampler is bit for bit the scalar one) and every lane
//! operation rounds as the scalar one it mirrors, so both tracers follow the same paths and their
//! films are equal bit for bit (`tests/lanes.rs` compares them). Work on several lanes at once: the
//! sampler's hashing, the shading frame, light sampling and MIS, the BSDFs and the path throughput;
//! ray queries eight at a time (`Accel::intersect_lanes`). Work per lane: the surface interaction,
//! emission seen by a ray, lights that sample themselves, and the film.
//!
//! The render driver picks it when [`RenderOptions::lanes`](crate::RenderOptions::lanes) is
//! set and [`LaneTracer::new`] accepts the scene; otherwise the one-path tracer runs.

use std::f32::consts::{FRAC_1_PI, FRAC_PI_4};

use glam::{UVec2, Vec2, Vec3};
use pt_accel::float::{gamma, next_float_down};
use pt_accel::lanes::{FloatLanes, MaskLanes, Simd, UintLanes, WIDTH, WithSimd, bits};
use pt_accel::{Ray, RayLanes};

use crate::bsdf::SampleInputs;
use crate::camera::{Camera, CameraSample, PinholeCamera};
use crate::color::Rgb;
use crate::film::Film;
use crate::integrator::LightStrategy;
use crate::integrator::path::{PathTracer, emission_weight};
use crate::interaction::{SurfacePoint, pull_inside};
use crate::light::{LaneLight, Light, LightSampleContext};
use crate::material::{LaneModel, Material};
use crate::render::{RenderControl, RenderOptions};
use crate::sampler::{SamplerFactory, SamplerKind, SobolLanes};
use crate::scene::{Scene, TriangleRecord};

/// A triangle light as the lanes read it: its corners, unit normal, area and radiance (red,
/// green, blue in `extra`) as one [`TriangleRecord`], read for eight lanes by
/// [`triangle_lanes`].
#[derive(Clone, Copy, Debug)]
struct LaneTriangle {
    record: TriangleRecord,
    two_sided: bool,
}

impl LaneTriangle {
    /// What the lanes read for a lane without a triangle light (masked out afterwards): a
    /// normal along z, area 1, no radiance.
    const NONE: Self = Self {
        record: TriangleRecord {
            rows: [[0.0; 8], [0.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0]],
        },
        two_sided: false,
    };
}

/// Three coordinates' lanes as a vector's.
#[inline(always)]
fn v3<S: Simd>([x, y, z]: [S::F; 3]) -> V<S> {
    V { x, y, z }
}

/// Eight lanes' triangle records ([`TriangleRecord`]) as lanes: `p[k][a]` is coordinate `a` of
/// corner `k`, `n[a]` of the normal, `extra[i]` the record's extra values.
struct TriangleLanes<S: Simd> {
    p: [[S::F; 3]; 3],
    n: [S::F; 3],
    extra: [S::F; 4],
}

/// Eight records (lane `i`'s is `t[i]`) by whole-register loads of their two rows and two
/// transpositions in registers.
#[inline(always)]
fn triangle_lanes<S: Simd>(s: S, t: [&TriangleRecord; WIDTH]) -> TriangleLanes<S> {
    let zero = s.splat(0.0);
    let mut rows = [[zero; 8]; 2];
    // Written out, not `array::from_fn`: no closure making lane values (`WithSimd`).
    for (r, row) in rows.iter_mut().enumerate() {
        *row = s.transpose([
            s.load(t[0].rows[r]),
            s.load(t[1].rows[r]),
            s.load(t[2].rows[r]),
            s.load(t[3].rows[r]),
            s.load(t[4].rows[r]),
            s.load(t[5].rows[r]),
            s.load(t[6].rows[r]),
            s.load(t[7].rows[r]),
        ]);
    }
    let [a, b] = rows;
    TriangleLanes {
        p: [[a[0], a[1], a[2]], [a[3], a[4], a[5]], [a[6], a[7], b[0]]],
        n: [b[1], b[2], b[3]],
        extra: [b[4], b[5], b[6], b[7]],
    }
}

/// The lane path tracer for one render: the one-path tracer's settings and the scene's
/// materials and lights in lane form.
#[derive(Clone, Debug)]
pub(crate) struct LaneTracer {
    settings: PathTracer,
    /// Per material: what the lanes read of it (one table, one bounds check per hit).
    materials: Vec<LaneMaterial>,
    /// Per light: the triangle the lanes sample by area, or `None` for a light that samples
    /// itself (environments, punctual lights, textured emitters).
    lights: Vec<Option<LaneTriangle>>,
    /// Some light samples itself.
    own_lights: bool,
    /// The light sampler's cumulative distribution where it chooses among at most eight
    /// lights (the lanes count in it), empty otherwise.
    light_cdf: Vec<f32>,
    /// The hits' triangles are asked for ahead ([`Scene::prefetch_hit`]): only where the
    /// meshes are too big to stay in cache (more than [`PREFETCH_TRIANGLES`] triangles).
    prefetch: bool,
}

/// Above this many triangles (over distinct meshes) the lane tracer asks for its hits'
/// triangles before shading them: their index lines are then likely cache misses (glass bunny
/// and dragons +4%). Below, the look-ups cost without a miss to hide (52 instructions per
/// camera sample on Mitsuba's box).
const PREFETCH_TRIANGLES: usize = 16_384;

impl LaneTracer {
    /// The lane tracer for this render, or `None` when the options do not ask for it or the
    /// scene has a part it does not know (then the one-path tracer renders).
    pub(crate) fn new<M: Material, L: Light, K: SamplerFactory>(
        scene: &Scene<M, L>,
        options: &RenderOptions<K>,
        settings: &PathTracer,
    ) -> Option<Self> {
        if !options.lanes
            || options.sampler.builtin_kind() != Some(SamplerKind::Sobol)
            || options.adaptive.is_some()
            || options.aovs.any()
            || scene.features().absorbing_media
        {
            return None;
        }
        let models = scene
            .materials()
            .iter()
            .map(|m| match m.lane_model()? {
                LaneModel::Lambertian(a) => Some((a, Kind::Lambertian, 1.0)),
                LaneModel::Mirror(r) => Some((r, Kind::Mirror, 1.0)),
                LaneModel::Glass { eta, tint } => Some((tint, Kind::Glass, eta)),
            })
            .collect::<Option<Vec<(Rgb, Kind, f32)>>>()?;
        // Triangle lights sampled by area in lanes; every other light samples itself, lane
        // by lane (its `sample_li`, as the one-path tracer calls it).
        let lights: Vec<Option<LaneTriangle>> = scene
            .lights()
            .iter()
            .map(|l| match l.lane_light() {
                Some(LaneLight::Triangle {
                    p,
                    n,
                    area,
                    radiance,
                    two_sided,
                }) => Some(LaneTriangle {
                    record: TriangleRecord::new(p, n, [area, radiance.r, radiance.g, radiance.b]),
                    two_sided,
                }),
                _ => None,
            })
            .collect();
        Some(Self {
            settings: *settings,
            materials: models
                .iter()
                .map(|&(albedo, kind, eta)| LaneMaterial { albedo, kind, eta })
                .collect(),
            own_lights: lights.iter().any(Option::is_none),
            lights,
            light_cdf: scene
                .light_sampler()
                .counted_cdf()
                .unwrap_or_default()
                .to_vec(),
            prefetch: scene.stats().unique_triangles > PREFETCH_TRIANGLES,
        })
    }
}

/// A material as the lanes read it.
#[derive(Clone, Copy, Debug)]
struct LaneMaterial {
    /// The Lambertian albedo, the mirror's reflectance or the glass's tint.
    albedo: Rgb,
    kind: Kind,
    /// The glass's relative index of refraction (1 for the others).
    eta: f32,
}

/// The kinds of material the lanes know.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Lambertian,
    Mirror,
    Glass,
}

/// Three lanes of vectors.
#[derive(Clone, Copy, Debug)]
struct V<S: Simd> {
    x: S::F,
    y: S::F,
    z: S::F,
}

impl<S: Simd> V<S> {
    /// Coordinate by coordinate, not by `Simd::load_vec3`: the arrays read here (a light
    /// sample's corners, normal and direction) are written lane by lane just before, and
    /// whole-register loads across those small stores wait for them (for the hits' vectors,
    /// before they were kept as [`Lanes3`], the diffuse and glass bunnies ran 7% slower so; the
    /// colours' loads, fewer, measured level to +1%).
    /// (Plain loops: `array::map` may be left out of line, outside the instruction set's
    /// entry; see `WithSimd`.)
    #[inline(always)]
    fn load(s: S, v: &[Vec3; WIDTH]) -> Self {
        let (mut x, mut y, mut z) = ([0.0; WIDTH], [0.0; WIDTH], [0.0; WIDTH]);
        for i in 0..WIDTH {
            (x[i], y[i], z[i]) = (v[i].x, v[i].y, v[i].z);
        }
        Self {
            x: s.load(x),
            y: s.load(y),
            z: s.load(z),
        }
    }

    /// `x x' + y y' + z z'`, summed left to right as glam's `Vec3::dot`.
    #[inline(always)]
    fn dot(self, o: Self) -> S::F {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Self {
            x: self.x - o.x,
            y: self.y - o.y,
            z: self.z - o.z,
        }
    }

    #[inline(always)]
    fn scale(self, f: S::F) -> Self {
        Self {
            x: self.x * f,
            y: self.y * f,
            z: self.z * f,
        }
    }

    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Self {
            x: self.x + o.x,
            y: self.y + o.y,
            z: self.z + o.z,
        }
    }

    /// The lanes as three arrays, stored a whole lane at a time.
    #[inline(always)]
    fn to_lanes(self) -> Lanes3 {
        Lanes3([self.x.to_array(), self.y.to_array(), self.z.to_array()])
    }
}

/// The ray of a lane without one (never traced: the queries take a mask), a constant copied
/// in whole registers (`Ray::new` built it on the stack from small stores).
const IDLE_RAY: Ray = Ray {
    origin: Vec3::ZERO,
    dir: Vec3::Z,
    t_min: 0.0,
    t_max: f32::INFINITY,
};

/// Three coordinates of every lane, as three arrays.
#[derive(Clone, Copy, Debug)]
struct Lanes3([[f32; WIDTH]; 3]);

impl Lanes3 {
    /// Zero in every lane.
    const ZERO: Self = Self([[0.0; WIDTH]; 3]);
    /// `Vec3::Z` in every lane.
    const Z: Self = Self([[0.0; WIDTH], [0.0; WIDTH], [1.0; WIDTH]]);
    /// One in every lane.
    const ONE: Self = Self([[1.0; WIDTH]; 3]);

    #[inline(always)]
    fn vec3(&self, lane: usize) -> Vec3 {
        Vec3::new(self.0[0][lane], self.0[1][lane], self.0[2][lane])
    }

    #[inline(always)]
    fn set(&mut self, lane: usize, v: Vec3) {
        (self.0[0][lane], self.0[1][lane], self.0[2][lane]) = (v.x, v.y, v.z);
    }

    /// The three arrays as lanes.
    #[inline(always)]
    fn load<S: Simd>(&self, s: S) -> V<S> {
        V {
            x: s.load(self.0[0]),
            y: s.load(self.0[1]),
            z: s.load(self.0[2]),
        }
    }
}

/// Lanes of RGB.
#[derive(Clone, Copy, Debug)]
struct C<S: Simd> {
    r: S::F,
    g: S::F,
    b: S::F,
}

impl<S: Simd> C<S> {
    /// Colours kept as `Vec3` (red in `x`): read into lanes by whole-register loads and
    /// shuffles, see [`Simd::load_vec3`].
    #[inline(always)]
    fn load(s: S, v: &[Vec3; WIDTH]) -> Self {
        let [r, g, b] = s.load_vec3(v);
        Self { r, g, b }
    }

    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        Self {
            r: self.r * o.r,
            g: self.g * o.g,
            b: self.b * o.b,
        }
    }

    #[inline(always)]
    fn scale(self, f: S::F) -> Self {
        Self {
            r: self.r * f,
            g: self.g * f,
            b: self.b * f,
        }
    }

    /// Lanes where every channel is zero.
    #[inline(always)]
    fn is_black(self, s: S) -> S::M {
        let z = s.splat(0.0);
        self.r.eq(z) & self.g.eq(z) & self.b.eq(z)
    }

    #[inline(always)]
    fn to_array(self) -> [Rgb; WIDTH] {
        let (r, g, b) = (self.r.to_array(), self.g.to_array(), self.b.to_array());
        let mut out = [Rgb::BLACK; WIDTH];
        for i in 0..WIDTH {
            out[i] = Rgb::new(r[i], g[i], b[i]);
        }
        out
    }
}

/// A colour as the `Vec3` the colour lanes are loaded from.
#[inline(always)]
fn packed(c: Rgb) -> Vec3 {
    Vec3::new(c.r, c.g, c.b)
}

/// The colour a [`packed`] `Vec3` holds.
#[inline(always)]
fn unpacked(v: Vec3) -> Rgb {
    Rgb::new(v.x, v.y, v.z)
}

/// The orthonormal frame around unit normals `n` (`Frame::from_z`, lane by lane): the tangent
/// `s`, the bitangent `t` and `n`.
#[inline(always)]
fn frame<S: Simd>(s: S, n: V<S>) -> (V<S>, V<S>) {
    use pt_accel::lanes::UintLanes;
    let one = s.splat(1.0);
    // copysign(1, n.z): -1 where the sign bit is set (also for -0.0).
    let negative = (n.z.to_bits() >> 31).eq(s.splat_u(1));
    let sign = S::F::select(negative, -one, one);
    let a = -one / (sign + n.z);
    let b = n.x * n.y * a;
    let t_s = V::<S> {
        x: one + sign * n.x * n.x * a,
        y: sign * b,
        z: -(sign * n.x),
    };
    let t_t = V::<S> {
        x: b,
        y: sign + n.y * n.y * a,
        z: -n.y,
    };
    (t_s, t_t)
}

/// `v` in the frame `(s, t, n)`: its three dot products (a function, not a closure, so that it
/// is compiled inside the instruction set's entry in every build).
#[inline(always)]
fn to_local<S: Simd>(v: V<S>, s: V<S>, t: V<S>, n: V<S>) -> V<S> {
    V::<S> {
        x: v.dot(s),
        y: v.dot(t),
        z: v.dot(n),
    }
}

/// [`SurfacePoint::offset_origin`] in lanes, operation for operation (so bit for bit): the
/// points `p`, with error bounds `err` and geometric normals `n`, moved off their surfaces
/// toward the side of `w`.
#[inline(always)]
fn offset_origin<S: Simd>(s: S, p: V<S>, err: V<S>, n: V<S>, w: V<S>) -> V<S> {
    let zero = s.splat(0.0);
    let n_abs = V::<S> {
        x: n.x.abs(),
        y: n.y.abs(),
        z: n.z.abs(),
    };
    let offset = n.scale(n_abs.dot(err));
    let behind = w.dot(n).lt(zero);
    let (scale, min) = (s.splat(1.0 / 8_388_608.0), s.splat(f32::MIN_POSITIVE));
    // Per axis: flipped to `w`'s side, added, then a step of one or two ulps away from `p`
    // (as the scalar function; a macro, not a closure over lane values: see `WithSimd`).
    macro_rules! axis {
        ($a:ident) => {{
            let o = S::F::select(behind, -offset.$a, offset.$a);
            let po = p.$a + o;
            let step = (po.abs() * scale).max(min);
            let step = S::F::select(o.gt(zero), step, S::F::select(o.lt(zero), -step, zero));
            po + step
        }};
    }
    V::<S> {
        x: axis!(x),
        y: axis!(y),
        z: axis!(z),
    }
}

/// A smooth dielectric's sample in lanes (`sample_smooth` with `fresnel_dielectric` and
/// `refract`, operation for operation).
struct GlassLanes<S: Simd> {
    /// The Fresnel reflectance of the interface at `wo` (the probability of reflecting).
    f: S::F,
    /// Lanes that reflect (`uc < F`).
    reflect: S::M,
    /// Lanes where the refraction exists, leaves the surface's plane and `F < 1`.
    refracts: S::M,
    /// The refracted direction (local) and its `etap`.
    wt: V<S>,
    etap: S::F,
}

#[inline(always)]
fn glass_lanes<S: Simd>(s: S, wo: V<S>, eta: S::F, uc: S::F) -> GlassLanes<S> {
    let (zero, one) = (s.splat(0.0), s.splat(1.0));
    // fresnel_dielectric(wo.z, eta)
    let c = wo.z.max(s.splat(-1.0)).min(one);
    let inside = c.lt(zero);
    let eta_f = S::F::select(inside, one / eta, eta);
    let c = S::F::select(inside, -c, c);
    let sin2_i = (one - c * c).max(zero);
    let sin2_t = sin2_i / (eta_f * eta_f);
    let cos_t = (one - sin2_t).max(zero).sqrt();
    let r_parl = (eta_f * c - cos_t) / (eta_f * c + cos_t);
    let r_perp = (c - eta_f * cos_t) / (c + eta_f * cos_t);
    let f = S::F::select(
        sin2_t.ge(one),
        one,
        s.splat(0.5) * (r_parl * r_parl + r_perp * r_perp),
    );
    // refract(wo, +z, eta): n . wo is wo.z exactly.
    let cos_i = wo.z;
    let below = cos_i.lt(zero);
    let etap = S::F::select(below, one / eta, eta);
    let cos_i = S::F::select(below, -cos_i, cos_i);
    let n_xy = S::F::select(below, s.splat(-0.0), zero);
    let n_z = S::F::select(below, -one, one);
    let sin2_i = (one - cos_i * cos_i).max(zero);
    let sin2_t = sin2_i / (etap * etap);
    let cos_t = (one - sin2_t).sqrt();
    let k = cos_i / etap - cos_t;
    let wt = V::<S> {
        x: -wo.x / etap + n_xy * k,
        y: -wo.y / etap + n_xy * k,
        z: -wo.z / etap + n_z * k,
    };
    GlassLanes {
        f,
        reflect: uc.lt(f),
        refracts: !sin2_t.ge(one) & !wt.z.eq(zero) & f.lt(one),
        wt,
        etap,
    }
}

/// `sampling::sin_cos_quarter` in lanes, operation for operation.
#[inline(always)]
fn sin_cos_quarter<S: Simd>(s: S, x: S::F) -> (S::F, S::F) {
    use crate::sampling::{COS_COEFFS, SIN_COEFFS};
    let z = x * x;
    // Splatted one by one: no closure over lane values (see `WithSimd`).
    let (s0, s1, s2) = (
        s.splat(SIN_COEFFS[0]),
        s.splat(SIN_COEFFS[1]),
        s.splat(SIN_COEFFS[2]),
    );
    let (c0, c1, c2) = (
        s.splat(COS_COEFFS[0]),
        s.splat(COS_COEFFS[1]),
        s.splat(COS_COEFFS[2]),
    );
    let sin = x + x * z * ((s0 * z + s1) * z + s2);
    let cos = (s.splat(1.0) - s.splat(0.5) * z) + z * z * ((c0 * z + c1) * z + c2);
    (sin, cos)
}

/// The MIS weight of the emission that lane `lane`'s ray, after `depth` bounces, sees from
/// light `index` (`emission_weight` for the lane).
///
/// A function rather than a closure over the lane loop's locals: where the compiler kept such
/// a closure out of line (a build for baseline x86-64, whose `emission_weight` is inlined
/// always), the closure's captures were written to the stack for every lane, light or not:
/// eight instructions per lane, 2% of that build's lane tracer on Mitsuba's box (callgrind),
/// which now executes as many instructions as an `x86-64-v3` build's.
#[inline]
fn lane_emission_weight<M: Material, L: Light>(
    scene: &Scene<M, L>,
    settings: &PathTracer,
    paths: &Paths,
    lane: usize,
    depth: u32,
    index: u32,
    ray: &Ray,
) -> f32 {
    let direct = depth == 0 || paths.specular & (1 << lane) != 0;
    let prev = paths.prev.context(lane);
    emission_weight(
        scene,
        index,
        direct,
        &prev,
        ray,
        paths.prev_pdf[lane],
        settings,
    )
}

/// The power heuristic (`sampling::power_heuristic`) in lanes.
#[inline(always)]
fn power_heuristic<S: Simd>(s: S, f_pdf: S::F, g_pdf: S::F) -> S::F {
    let (f, g) = (f_pdf * f_pdf, g_pdf * g_pdf);
    let sum = f + g;
    let w = f / sum;
    let w = S::F::select(sum.eq(s.splat(0.0)), s.splat(0.0), w);
    S::F::select(f.eq(s.splat(f32::INFINITY)), s.splat(1.0), w)
}

/// One tile rendered by the lane tracer: the film and the number of rays traced.
pub(crate) struct LaneTile<'a, M: Material, L: Light, C, K> {
    pub scene: &'a Scene<M, L>,
    pub camera: &'a C,
    pub options: &'a RenderOptions<K>,
    pub tracer: &'a LaneTracer,
    pub x0: u32,
    pub y0: u32,
    pub w: u32,
    pub h: u32,
    pub control: &'a RenderControl<'a>,
}

/// What each lane carries between bounces.
struct Paths {
    /// Lanes with a path.
    live: u32,
    /// Tile-local pixel of each lane's sample.
    pixel: [UVec2; WIDTH],
    ray: RayLanes,
    /// Throughput, channel by channel (red, green, blue), written and read as whole lanes.
    beta: Lanes3,
    l: [Rgb; WIDTH],
    /// The point each lane's ray left, for the MIS weight of emission it finds: the last
    /// bounce's hits, copied whole (a lane at a time, the copy took 74 instructions per
    /// camera sample on Mitsuba's box), read only where a ray meets a light.
    prev: PrevHits,
    prev_pdf: [f32; WIDTH],
    /// The product of `etap^2` over the path's refractions (Russian roulette divides it out).
    eta_scale: [f32; WIDTH],
    /// Lanes whose last bounce was specular (off a mirror or glass): emission they see next
    /// takes weight 1, as in the one-path tracer.
    specular: u32,
    depth: [u32; WIDTH],
}

impl<M: Material, L: Light, C: Camera, K> WithSimd for LaneTile<'_, M, L, C, K> {
    type Output = (Film, u64);

    #[inline(always)]
    fn with_simd<S: Simd>(self, s: S) -> (Film, u64) {
        run(s, &self)
    }
}

/// The surface hits of the lanes being shaded, as the lanes read them (lanes not shaded hold
/// stale values, which the masks leave out).
///
/// The vectors the shading reads as lanes are kept coordinate by coordinate, written so by the
/// hit loop (a lane at a time) and by [`Corners::finish`] (whole lanes): read as lanes without
/// a copy per lane.
struct Hits {
    /// The points' error bounds.
    err: Lanes3,
    n: Lanes3,
    ns: Lanes3,
    wo: Lanes3,
    p: Lanes3,
}

impl Hits {
    /// Lane `lane`'s point.
    #[inline(always)]
    fn point(&self, lane: usize) -> SurfacePoint {
        SurfacePoint {
            p: self.p.vec3(lane),
            p_error: self.err.vec3(lane),
            n: self.n.vec3(lane),
        }
    }
}

/// What [`LightSampleContext`] holds, for every lane: the point a path's ray left.
#[derive(Clone, Copy)]
struct PrevHits {
    p: Lanes3,
    err: Lanes3,
    n: Lanes3,
    ns: Lanes3,
}

impl PrevHits {
    /// `LightSampleContext::default()` in every lane.
    const DEFAULT: Self = Self {
        p: Lanes3::ZERO,
        err: Lanes3::ZERO,
        n: Lanes3::ZERO,
        ns: Lanes3::ZERO,
    };

    /// Lane `lane`'s context.
    #[inline(always)]
    fn context(&self, lane: usize) -> LightSampleContext {
        let point = SurfacePoint {
            p: self.p.vec3(lane),
            p_error: self.err.vec3(lane),
            n: self.n.vec3(lane),
        };
        LightSampleContext::new(point, self.ns.vec3(lane))
    }

    /// Lane `lane` set to `LightSampleContext::default()`.
    #[inline(always)]
    fn reset(&mut self, lane: usize) {
        for v in [&mut self.p, &mut self.err, &mut self.n, &mut self.ns] {
            v.set(lane, Vec3::ZERO);
        }
    }
}

/// The hits the tracer finishes in lanes ([`Scene::lane_corners`]): each lane's triangle (its
/// corners and face normal) and barycentrics.
struct Corners<'a> {
    tri: [&'a TriangleRecord; WIDTH],
    b1: [f32; WIDTH],
    b2: [f32; WIDTH],
}

impl<'a> Corners<'a> {
    /// [`Scene::lane_hit`]'s point, error bound, normals and direction back along the ray for
    /// the lanes of `mask`, in lanes with the same operations, into `hits` (other lanes kept).
    #[inline(always)]
    fn finish<S: Simd>(&self, s: S, rays: &RayLanes, mask: u32, hits: &mut Hits) {
        let (here, one, g7) = (s.mask(mask), s.splat(1.0), s.splat(gamma(7)));
        let (b1, b2) = (s.load(self.b1), s.load(self.b2));
        // `Hit::b0`.
        let b0 = (one - b1) - b2;
        // `Vec3::normalize` of the direction: the reciprocal of the length, then a product.
        let d = [
            s.load(rays.dir[0]),
            s.load(rays.dir[1]),
            s.load(rays.dir[2]),
        ];
        let r = one / ((d[0] * d[0] + d[1] * d[1]) + d[2] * d[2]).sqrt();
        let tri = triangle_lanes(s, self.tri);
        let mut err_sum = s.splat(0.0);
        for a in 0..3 {
            let q0 = tri.p[0][a] * b0;
            let q1 = tri.p[1][a] * b1;
            let q2 = tri.p[2][a] * b2;
            // The point and `barycentric_error`.
            let p = (q0 + q1) + q2;
            let e = ((q0.abs() + q1.abs()) + q2.abs()) * g7;
            err_sum = if a == 0 { e } else { err_sum + e };
            let n = tri.n[a];
            let wo = -(d[a] * r);
            hits.p.0[a] = S::F::select(here, p, s.load(hits.p.0[a])).to_array();
            hits.err.0[a] = S::F::select(here, e, s.load(hits.err.0[a])).to_array();
            hits.n.0[a] = S::F::select(here, n, s.load(hits.n.0[a])).to_array();
            hits.ns.0[a] = S::F::select(here, n, s.load(hits.ns.0[a])).to_array();
            hits.wo.0[a] = S::F::select(here, wo, s.load(hits.wo.0[a])).to_array();
        }
        // `near_edge`, and the few lanes it picks pulled inside as `Scene::lane_hit` does.
        let near = near_edge_lanes(s, &tri.p, [b0, b1, b2], err_sum).bits() & mask;
        if near != 0 {
            self.pull_inside(near, hits);
        }
    }

    /// `pull_inside` for the lanes of `near`.
    #[cold]
    #[inline(never)]
    fn pull_inside(&self, near: u32, hits: &mut Hits) {
        for lane in bits(near) {
            let (b1, b2) = (self.b1[lane], self.b2[lane]);
            let b = [(1.0 - b1) - b2, b1, b2];
            let p = self.tri[lane].p();
            if let Some((q, e)) = pull_inside(b, p, hits.err.vec3(lane)) {
                hits.p.set(lane, q);
                hits.err.set(lane, e);
            }
        }
    }
}

/// `near_edge` (scale 1) for every lane of the triangles `p` (`p[k][a]`: coordinate `a` of
/// corner `k`), operation for operation.
#[inline(always)]
fn near_edge_lanes<S: Simd>(s: S, p: &[[S::F; 3]; 3], b: [S::F; 3], err_sum: S::F) -> S::M {
    // Written out: closures holding lane values may be compiled outside the instruction set's
    // entry (`WithSimd`).
    let zero = s.splat(0.0);
    let (mut e0, mut e1, mut e2) = ([zero; 3], [zero; 3], [zero; 3]);
    for a in 0..3 {
        (e0[a], e1[a], e2[a]) = (p[2][a] - p[1][a], p[0][a] - p[2][a], p[1][a] - p[0][a]);
    }

    let n = [
        e1[1] * e2[2] - e1[2] * e2[1],
        e1[2] * e2[0] - e1[0] * e2[2],
        e1[0] * e2[1] - e1[1] * e2[0],
    ];
    let nn = (n[0] * n[0] + n[1] * n[1]) + n[2] * n[2];
    let l0 = (e0[0] * e0[0] + e0[1] * e0[1]) + e0[2] * e0[2];
    let l1 = (e1[0] * e1[0] + e1[1] * e1[1]) + e1[2] * e1[2];
    let l2 = (e2[0] * e2[0] + e2[1] * e2[1]) + e2[2] * e2[2];
    let ll = l0.max(l1.max(l2));
    let bm = b[0].min(b[1].min(b[2]));
    bm.lt(zero) | ((bm * bm) * nn).lt(((err_sum * err_sum) * s.splat(4.0)) * ll)
}

/// Which lanes are shaded and by what: the rest of `shade` is Lambertian.
#[derive(Clone, Copy)]
struct Kinds {
    shade: u32,
    mirrors: u32,
    glasses: u32,
    /// Each glass lane's relative index of refraction (1 elsewhere).
    etas: [f32; WIDTH],
}

/// The tile's samples, in the order the one-path tracer takes them: pixels row by row, each
/// pixel's sample indices in order.
struct Queue {
    w: u32,
    h: u32,
    range: std::ops::Range<u32>,
    next_pixel: u32,
    next_index: u32,
}

impl Queue {
    fn next(&mut self) -> Option<(UVec2, u32)> {
        if self.next_index >= self.range.end {
            self.next_pixel += 1;
            self.next_index = self.range.start;
        }
        if self.next_pixel >= self.w * self.h || self.range.is_empty() {
            return None;
        }
        let p = UVec2::new(self.next_pixel % self.w, self.next_pixel / self.w);
        let i = self.next_index;
        self.next_index += 1;
        Some((p, i))
    }
}

/// Camera rays made ahead, eight at a time, for the lanes that start the tile's next samples.
///
/// A lane starting a sample drew its film position and made its ray on its own (or with the
/// few lanes ending with it): a draw of one to three lanes whose dependent multiplies, and
/// the camera's square root and division, lay on the path from one bounce's end to the next
/// query (Mitsuba's box: 5% of the render). Here the tile's next eight samples are drawn and
/// their rays made together, once per eight, and the starting lanes take them in turn: the
/// same samples in the same order, the same draws (their dimensions are fixed: the film's,
/// then the lens's), the same rays.
struct Primaries {
    /// How many of the slots hold samples, and the next one to hand out.
    len: usize,
    next: usize,
    /// Each slot's tile-local pixel, sample index and pixel key (for the sampler).
    pixel: [UVec2; WIDTH],
    index: [u32; WIDTH],
    key: [u32; WIDTH],
    /// Each slot's ray, as the camera made it.
    ray: RayLanes,
}

/// What [`Primaries::fill`] needs of the tile and its camera.
struct PrimarySetup<'a, C> {
    camera: &'a C,
    /// The camera as a pinhole, whose rays are made in lanes.
    pinhole: Option<PinholeCamera>,
    uses_lens: bool,
    /// The tile's corner on the image, one over the image's size, and its aspect.
    origin: UVec2,
    inv: Vec2,
    aspect: f32,
}

impl Primaries {
    const EMPTY: Self = Self {
        len: 0,
        next: 0,
        pixel: [UVec2::ZERO; WIDTH],
        index: [0; WIDTH],
        key: [0; WIDTH],
        ray: RayLanes::splat(IDLE_RAY),
    };

    /// The tile's next (up to) eight samples from `queue`, drawn and their rays made; none
    /// when the tile has no samples left.
    #[inline(always)]
    fn fill<S: Simd, C: Camera>(
        &mut self,
        s: S,
        queue: &mut Queue,
        sampler: &mut SobolLanes,
        setup: &PrimarySetup<'_, C>,
    ) {
        self.next = 0;
        self.len = 0;
        let (mut gx, mut gy) = ([0u32; WIDTH], [0u32; WIDTH]);
        while self.len < WIDTH {
            let Some((pixel, index)) = queue.next() else {
                break;
            };
            let k = self.len;
            let global = setup.origin + pixel;
            (self.pixel[k], self.index[k], self.key[k]) = (pixel, index, sampler.key(global));
            (gx[k], gy[k]) = (global.x, global.y);
            self.len += 1;
        }
        if self.len == 0 {
            return;
        }
        // Slots past `len` draw from the last batch's keys and indices: never read.
        let (keys, indices) = (s.load_u(self.key), s.load_u(self.index));
        let (ux, uy) = SobolLanes::draw_2d_at(s, keys, indices, 0);
        // `(global.as_vec2() + u) * inv`, as the one-path tracer computes it.
        let fx = (s.load_u(gx).to_f32() + ux) * s.splat(setup.inv.x);
        let fy = (s.load_u(gy).to_f32() + uy) * s.splat(setup.inv.y);
        if let Some(pinhole) = setup.pinhole {
            let d = pinhole.directions_lanes(s, fx, fy, setup.aspect);
            // The range `Ray::new` gives, as `generate_ray` does.
            let eye = pinhole.eye();
            for a in 0..3 {
                self.ray.origin[a] = [eye[a]; WIDTH];
                self.ray.dir[a] = d[a].to_array();
            }
            (self.ray.t_min, self.ray.t_max) = ([0.0; WIDTH], [f32::INFINITY; WIDTH]);
            return;
        }
        let (fx, fy) = (fx.to_array(), fy.to_array());
        let lens = if setup.uses_lens {
            let (lx, ly) = SobolLanes::draw_2d_at(s, keys, indices, 1);
            Some((lx.to_array(), ly.to_array()))
        } else {
            None
        };
        for k in 0..self.len {
            let lens = lens.map_or(Vec2::splat(0.5), |(lx, ly)| Vec2::new(lx[k], ly[k]));
            let ray = setup.camera.generate_ray(&CameraSample {
                film: Vec2::new(fx[k], fy[k]),
                aspect: setup.aspect,
                lens,
            });
            self.ray.set(k, &ray);
        }
    }
}

#[inline(always)]
fn run<S: Simd, M: Material, L: Light, C: Camera, K>(
    s: S,
    job: &LaneTile<'_, M, L, C, K>,
) -> (Film, u64) {
    let (scene, options, tracer) = (job.scene, job.options, &job.tracer);
    let settings = &tracer.settings;
    let mut film = Film::new(job.w, job.h);
    let mut rays = 0u64;
    let inv = Vec2::new(1.0 / options.width as f32, 1.0 / options.height as f32);
    let aspect = options.width as f32 / options.height as f32;
    let mut queue = Queue {
        w: job.w,
        h: job.h,
        range: options.samples(),
        next_pixel: 0,
        next_index: options.samples().start,
    };
    // On the heap, once per tile: on the worker's stack (when the sampler held 9 KiB of seed
    // slots beside the paths) the same code ran 6% slower in rayon's global pool than in a
    // pool of its own, probably the stack's placement against the heap's hot data (two
    // threads, default pool: mirror bunny 0.99 -> 1.056 against the sampler's stalls
    // unfixed). The sampler is about 100 bytes now; the box stays until that is measured
    // again.
    let mut sampler = Box::new(SobolLanes::new(options.seed));
    let mut paths = Paths {
        live: 0,
        pixel: [UVec2::ZERO; WIDTH],
        ray: RayLanes::splat(IDLE_RAY),
        beta: Lanes3::ONE,
        l: [Rgb::BLACK; WIDTH],
        prev: PrevHits::DEFAULT,
        prev_pdf: [0.0; WIDTH],
        eta_scale: [1.0; WIDTH],
        specular: 0,
        depth: [0; WIDTH],
    };
    let origin = UVec2::new(job.x0, job.y0);
    let uses_lens = job.camera.uses_lens();
    let setup = PrimarySetup {
        camera: job.camera,
        // A pinhole that uses the lens would be asked for a lens draw it ignores; the rays
        // are made in lanes only where it does not.
        pinhole: job.camera.pinhole().filter(|_| !uses_lens),
        uses_lens,
        origin,
        inv,
        aspect,
    };
    // The sampler dimensions a sample has used when a lane takes it: the film's, and the
    // lens's for a camera that reads it.
    let dimensions = 1 + u32::from(uses_lens);
    let mut primaries = Primaries::EMPTY;

    // Start the tile's next samples in the lanes of `lanes`, in lane order (a lane the tile has
    // no sample left for stays empty), with the rays made ahead. A macro, not a closure: a
    // closure over lane values may be compiled outside the instruction set's entry (in a build
    // for baseline x86-64 its intrinsics then become calls).
    macro_rules! refill {
        ($lanes:expr) => {{
            let lanes: u32 = $lanes;
            let mut started = 0u32;
            for lane in bits(lanes) {
                if primaries.next == primaries.len {
                    primaries.fill(s, &mut queue, &mut sampler, &setup);
                    if primaries.len == 0 {
                        paths.live &= !(1 << lane);
                        continue;
                    }
                }
                let k = primaries.next;
                primaries.next += 1;
                sampler.start_at(lane, primaries.key[k], primaries.index[k], dimensions);
                paths.pixel[lane] = primaries.pixel[k];
                paths.ray.set(lane, &primaries.ray.get(k));
                paths.l[lane] = Rgb::BLACK;
                paths.prev.reset(lane);
                paths.depth[lane] = 0;
                started |= 1 << lane;
            }
            if started != 0 {
                paths.live |= started;
                paths.specular &= !started;
                // The lanes' arrays the shading loads whole, reset a whole lane at a time
                // (their last stores were whole lanes too): a load of fresh stores of single
                // lanes would wait for them.
                // (A macro, not a closure: see above.)
                let (new, one) = (s.mask(started), s.splat(1.0));
                macro_rules! reset {
                    ($a:expr, $v:expr) => {
                        S::F::select(new, $v, s.load($a)).to_array()
                    };
                }
                paths.beta = Lanes3([
                    reset!(paths.beta.0[0], one),
                    reset!(paths.beta.0[1], one),
                    reset!(paths.beta.0[2], one),
                ]);
                paths.eta_scale = reset!(paths.eta_scale, one);
                paths.prev_pdf = reset!(paths.prev_pdf, s.splat(0.0));
            }
        }};
    }
    // End the path in `lane`: its radiance goes to the film.
    let finish = |lane: usize, paths: &Paths, film: &mut Film| {
        let (p, l) = (paths.pixel[lane], paths.l[lane]);
        match options.sample_clamp {
            Some(max) => film.add_sample_clamped(p.x, p.y, l, max),
            None => film.add_sample(p.x, p.y, l),
        }
    };

    refill!(u32::MAX >> (32 - WIDTH));
    let mut corners = Corners {
        tri: [&TriangleRecord::ZERO; WIDTH],
        b1: [0.0; WIDTH],
        b2: [0.0; WIDTH],
    };
    let mut hits = Hits {
        err: Lanes3::ZERO,
        n: Lanes3::Z,
        ns: Lanes3::Z,
        wo: Lanes3::Z,
        p: Lanes3::Z,
    };
    while paths.live != 0 {
        if job.control.cancelled() {
            break;
        }
        // Closest hits, emission seen, the depth limit: lane by lane.
        let mut shade = 0u32;
        let mut albedo = [Vec3::ZERO; WIDTH];
        let mut mirrors = 0u32;
        let mut glasses = 0u32;
        let mut etas = [1.0f32; WIDTH];
        let mut ended = 0u32;
        // Lanes whose hit geometry is finished in lanes after the loop.
        let mut deferred = 0u32;
        let found = scene.hits_lanes(s, &paths.ray, paths.live);
        // Every lane's first dependent cache miss asked for at once, before the lanes are
        // shaded one after another (glass bunny +4%, dragons +4%, the others level).
        if tracer.prefetch {
            for h in found.iter().flatten() {
                scene.prefetch_hit(h);
            }
        }
        for lane in bits(paths.live) {
            rays += 1;
            let depth = paths.depth[lane];
            // The ray itself is read only where it escapes or meets a light (not for the hits
            // finished in lanes: 65 instructions per camera sample on Mitsuba's box).
            let h = match &found[lane] {
                Some(h) => h,
                None => {
                    // The ray escapes: what the environment sends along it, as the one-path
                    // tracer adds it.
                    if settings.environment {
                        let ray = paths.ray.get(lane);
                        for &index in scene.infinite_lights() {
                            let le = scene.lights()[index as usize].le(&ray);
                            if !le.is_black() {
                                let w = lane_emission_weight(
                                    scene, settings, &paths, lane, depth, index, &ray,
                                );
                                paths.l[lane] += unpacked(paths.beta.vec3(lane)) * le * w;
                            }
                        }
                    }
                    ended |= 1 << lane;
                    continue;
                }
            };
            let m = if let Some((t, material)) = scene.lane_corners(h) {
                // No emission here: finished in lanes after the loop, if shaded.
                corners.tri[lane] = t;
                (corners.b1[lane], corners.b2[lane]) = (h.b1, h.b2);
                deferred |= 1 << lane;
                material as usize
            } else {
                let ray = paths.ray.get(lane);
                let hit = scene.lane_hit(h, &ray);
                if let Some(light_index) = hit.light {
                    let light = &scene.lights()[light_index as usize];
                    let le = light.l(hit.point.p, hit.point.n, hit.uv, hit.wo);
                    if !le.is_black() {
                        let w = lane_emission_weight(
                            scene,
                            settings,
                            &paths,
                            lane,
                            depth,
                            light_index,
                            &ray,
                        );
                        paths.l[lane] += unpacked(paths.beta.vec3(lane)) * le * w;
                    }
                }
                // Kept whether or not the lane is shaded (the masks leave out those that
                // are not).
                hits.err.set(lane, hit.point.p_error);
                hits.n.set(lane, hit.point.n);
                hits.ns.set(lane, hit.ns);
                hits.wo.set(lane, hit.wo);
                hits.p.set(lane, hit.point.p);
                hit.material as usize
            };
            if depth == settings.max_depth {
                ended |= 1 << lane;
                continue;
            }
            paths.depth[lane] = depth + 1;
            let material = &tracer.materials[m];
            let (a, kind) = (material.albedo, material.kind);
            if a.is_black() && kind != Kind::Glass {
                // A black Lambertian or mirror scatters nothing (its flags are empty); glass
                // always reflects.
                ended |= 1 << lane;
                continue;
            }
            albedo[lane] = packed(a);
            etas[lane] = material.eta;
            let bit = 1 << lane;
            mirrors = (mirrors & !bit) | if kind == Kind::Mirror { bit } else { 0 };
            glasses = (glasses & !bit) | if kind == Kind::Glass { bit } else { 0 };
            shade |= 1 << lane;
        }
        if deferred & shade != 0 {
            corners.finish(s, &paths.ray, deferred & shade, &mut hits);
        }

        if shade != 0 {
            rays += shade_lanes(
                s,
                scene,
                tracer,
                &mut paths,
                &mut sampler,
                &hits,
                &albedo,
                Kinds {
                    shade,
                    mirrors,
                    glasses,
                    etas,
                },
                &mut ended,
            );
        }
        for lane in bits(ended) {
            finish(lane, &paths, &mut film);
        }
        refill!(ended);
    }
    (film, rays)
}

/// Lights that sample themselves may read large tables (an environment map's): for every lane,
/// the memory its `sample_li` will read first is asked for, then what it reads next
/// ([`Light::prefetch_sample_li`]'s steps 0 and 1), so that the lanes' cache misses overlap
/// rather than come one after another (the cube-map environment figure +10% and +11%). Out
/// of line: inline, the lane tracer's entry grew and Mitsuba's box, which has no such light,
/// lost 3.5%.
#[inline(never)]
fn prefetch_own_samples<M: Material, L: Light>(
    scene: &Scene<M, L>,
    tracer: &LaneTracer,
    lanes: u32,
    u_light: &[f32; WIDTH],
    uy: &[f32; WIDTH],
) {
    let mut own = 0u32;
    let mut light = [0usize; WIDTH];
    // The point's first number, as the tracer remaps it from `u_light`.
    let mut ux = [0.0; WIDTH];
    for lane in bits(lanes) {
        if let Some((index, _, remapped)) = scene.light_sampler().sample_remapped(u_light[lane])
            && tracer.lights[index].is_none()
        {
            own |= 1 << lane;
            light[lane] = index;
            ux[lane] = remapped;
        }
    }
    for step in 0..2 {
        for lane in bits(own) {
            let u = Vec2::new(ux[lane], uy[lane]);
            scene.lights()[light[lane]].prefetch_sample_li(u, step);
        }
    }
}

/// For each lane, how many entries of `cdf` are at or below its `u`.
#[inline(always)]
fn count_at_or_below<S: Simd>(s: S, cdf: &[f32], u: S::F) -> [u32; WIDTH] {
    use pt_accel::lanes::UintLanes;
    let (zero, one) = (s.splat_u(0), s.splat_u(1));
    let mut count = zero;
    for &c in cdf {
        count = count.wrapping_add(S::U::select(s.splat(c).le(u), one, zero));
    }
    count.to_array()
}

/// Next-event estimation, BSDF sampling and Russian roulette for the lanes in `shade`, all at
/// surface hits of Lambertian, mirror and smooth glass materials; lanes whose path ends join
/// `ended`. Returns the number of shadow rays traced.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn shade_lanes<S: Simd, M: Material, L: Light>(
    s: S,
    scene: &Scene<M, L>,
    tracer: &LaneTracer,
    paths: &mut Paths,
    sampler: &mut SobolLanes,
    hits: &Hits,
    albedo: &[Vec3; WIDTH],
    kinds: Kinds,
    ended: &mut u32,
) -> u64 {
    let Kinds {
        shade,
        mirrors,
        glasses,
        etas,
    } = kinds;
    let settings = &tracer.settings;
    let mut rays = 0;
    let ns = hits.ns.load(s);
    let n = hits.n.load(s);
    let wo = hits.wo.load(s);
    let p_ref = hits.p.load(s);
    let err = hits.err.load(s);
    let (fs, ft) = frame(s, ns);
    let wo_l = to_local(wo, fs, ft, ns);
    let refl = C::load(s, albedo);
    let f_lambert = refl.scale(s.splat(FRAC_1_PI));
    // Lambertian lanes sample lights and draw a cosine-weighted direction; mirror and glass
    // lanes (specular: no light sampling, no draws for it) reflect or refract.
    let diffuse = shade & !mirrors & !glasses;
    let mirror = s.mask(mirrors);
    let glass = s.mask(glasses);
    let zero = s.splat(0.0);
    let beta = {
        let b = paths.beta.load(s);
        C::<S> {
            r: b.x,
            g: b.y,
            b: b.z,
        }
    };

    // Every draw of this bounce before any of them is used (the light's, then the
    // direction's, the scalar tracer's order): each is a chain of dependent multiplies, and
    // drawn together they run side by side instead of one after another.
    // (An `if`, not `bool::then`: no closure over lane values, see `WithSimd`.)
    // Next-event estimation takes one 2D draw: its first number chooses the light and,
    // remapped within the light's share (`Distribution1D::sample_discrete`), places the point
    // with the second, as the one-path tracer's `sample_direct`.
    let light_draws = if settings.nee && diffuse != 0 {
        let (ux, uy) = sampler.next_2d(s, diffuse);
        Some((ux, uy))
    } else {
        None
    };
    // The BSDF's numbers only for the lanes whose BSDF reads them (`Bsdf::sample_inputs`, as
    // the one-path tracer draws them): the lobe choice for glass, the direction for
    // Lambertian surfaces, neither for mirrors.
    let uc = if glasses != 0 {
        sampler.next_1d(s, glasses)
    } else {
        s.splat(SampleInputs::UNDRAWN)
    };
    let bsdf_u = if diffuse != 0 {
        sampler.next_2d(s, diffuse)
    } else {
        let half = s.splat(SampleInputs::UNDRAWN);
        (half, half)
    };

    // Next-event estimation: a light chosen by power, a point on it by area.
    if let Some((u_light, uy)) = light_draws {
        // Among a few lights, each lane's choice counted in lanes (`Distribution1D`'s
        // counted search: the entries of the cdf at or below `u`).
        let counted = if tracer.light_cdf.is_empty() {
            None
        } else {
            Some(count_at_or_below(s, &tracer.light_cdf, u_light))
        };
        let u_light = u_light.to_array();
        // The point's first number: `u_light` remapped, lane by lane below.
        let mut ux = u_light;
        let mut chosen = 0u32;
        let mut pmf = [1.0f32; WIDTH];
        // Each lane's chosen light, read as lanes by `triangle_lanes` after the loop.
        let mut tris = [&LaneTriangle::NONE; WIDTH];
        let mut two_sided = 0u32;
        // Lanes whose light sampled itself (a usable sample: positive pdf, some radiance), its
        // direction, density, radiance and shadow-ray target; lanes whose light is a delta.
        let mut own = 0u32;
        let mut delta = 0u32;
        let mut own_wi = [Vec3::Z; WIDTH];
        let mut own_pdf = [1.0f32; WIDTH];
        let mut own_li = [Vec3::ZERO; WIDTH];
        let mut own_target = [SurfacePoint::exact(Vec3::ZERO); WIDTH];
        let mut uya = None;
        if tracer.own_lights {
            let a = uy.to_array();
            prefetch_own_samples(scene, tracer, diffuse, &u_light, &a);
            uya = Some(a);
        }
        for lane in bits(diffuse) {
            let pick = match &counted {
                Some(count) => {
                    let index = (count[lane] as usize).clamp(1, tracer.light_cdf.len() - 1) - 1;
                    // The remapping `sample_remapped` makes (the same function: the same bits).
                    ux[lane] = scene.light_sampler().remap(index, u_light[lane]);
                    Some((index, scene.light_sampler().pmf(index)))
                }
                None => scene.light_sampler().sample_remapped(u_light[lane]).map(
                    |(index, p, remapped)| {
                        ux[lane] = remapped;
                        (index, p)
                    },
                ),
            };
            if let Some((index, p)) = pick {
                pmf[lane] = p;
                let Some(t) = &tracer.lights[index] else {
                    let light = &scene.lights()[index];
                    delta |= u32::from(light.flags().is_delta()) << lane;
                    let uy = *uya.get_or_insert_with(|| uy.to_array());
                    let ctx = LightSampleContext::new(hits.point(lane), hits.ns.vec3(lane));
                    if let Some(ls) = light.sample_li(&ctx, Vec2::new(ux[lane], uy[lane]))
                        && !(ls.pdf <= 0.0 || ls.li.is_black())
                    {
                        own |= 1 << lane;
                        own_wi[lane] = ls.wi;
                        own_pdf[lane] = ls.pdf;
                        own_li[lane] = packed(ls.li);
                        own_target[lane] = ls.point;
                    }
                    continue;
                };
                chosen |= 1 << lane;
                tris[lane] = t;
                two_sided |= u32::from(t.two_sided) << lane;
            }
        }
        let ux = s.load(ux);
        let own_m = s.mask(own);
        let t = triangle_lanes(s, tris.map(|t| &t.record));
        // Written out, not `map`: no closure over lane values (`WithSimd`).
        let [p0, p1, p2, ln] = [t.p[0], t.p[1], t.p[2], t.n];
        let (p0, p1, p2, ln) = (v3::<S>(p0), v3::<S>(p1), v3::<S>(p2), v3::<S>(ln));
        let [area, r, g, b] = t.extra;
        let li = C::<S> { r, g, b };
        let two = s.mask(two_sided);
        // A receiver behind a one-sided light (or in its plane) gets nothing from it.
        let facing = two | ln.dot(p_ref.sub(p0)).gt(zero);
        // sample_uniform_triangle
        let half = s.splat(0.5);
        let first = ux.lt(uy);
        let b0a = ux * half;
        let b1b = uy * half;
        let b0 = S::F::select(first, b0a, ux - b1b);
        let b1 = S::F::select(first, uy - b0a, b1b);
        let b2 = s.splat(1.0) - b0 - b1;
        let p = p0.scale(b0).add(p1.scale(b1)).add(p2.scale(b2));
        let to_light = p.sub(p_ref);
        let dist2 = to_light.dot(to_light);
        let dist = dist2.sqrt();
        let wi = V::<S> {
            x: to_light.x / dist,
            y: to_light.y / dist,
            z: to_light.z / dist,
        };
        let back: V<S> = V::<S> {
            x: -wi.x,
            y: -wi.y,
            z: -wi.z,
        };
        let cos_back = ln.dot(back);
        let lit = two | cos_back.gt(zero);
        let cos_l = cos_back.abs();
        let pdf = dist2 / (cos_l * area);
        let pdf = S::F::select(pdf.is_finite(), pdf, zero);
        // The triangle lanes' conditions of TriangleLight::sample_li and sample_direct's checks.
        let tri_ok = s.mask(chosen)
            & facing
            & !dist2.eq(zero)
            & dist2.is_finite()
            & lit
            & !li.is_black(s)
            & !cos_l.eq(zero)
            & !pdf.eq(zero);
        // Lanes whose light sampled itself take its direction, density and radiance.
        let (wi, pdf, li) = if own == 0 {
            (wi, pdf, li)
        } else {
            let w = V::load(s, &own_wi);
            let l = C::load(s, &own_li);
            (
                V::<S> {
                    x: S::F::select(own_m, w.x, wi.x),
                    y: S::F::select(own_m, w.y, wi.y),
                    z: S::F::select(own_m, w.z, wi.z),
                },
                S::F::select(own_m, s.load(own_pdf), pdf),
                C::<S> {
                    r: S::F::select(own_m, l.r, li.r),
                    g: S::F::select(own_m, l.g, li.g),
                    b: S::F::select(own_m, l.b, li.b),
                },
            )
        };
        let wi_l = to_local(wi, fs, ft, ns);
        // consistent_sides and same_hemisphere
        let geometric = (wi.dot(n) * wo.dot(n)).gt(zero);
        let shading = (wi_l.z * wo_l.z).gt(zero);
        let consistent = !(geometric & !shading | shading & !geometric);
        let cos_i = wi_l.z.abs();
        let f = f_lambert.scale(S::F::select(shading, s.splat(1.0), zero) * cos_i);
        let light_pdf = s.load(pmf) * pdf;
        let weight = match settings.strategy {
            LightStrategy::Mis => {
                let bsdf_pdf = S::F::select(shading, cos_i.max(zero) * s.splat(FRAC_1_PI), zero);
                // A delta light's sample takes weight 1 (nothing else can find it).
                let w = power_heuristic(s, light_pdf, bsdf_pdf);
                S::F::select(s.mask(delta), s.splat(1.0), w)
            }
            _ => s.splat(1.0),
        };
        let contrib = beta.mul(f.mul(li).scale(weight / light_pdf));
        let ok = (tri_ok | own_m) & consistent & !f.is_black(s);
        let ok = ok.bits() & diffuse;
        if ok != 0 {
            // The triangle lanes' shadow rays (`spawn_ray_to` a point with the barycentric
            // error bound), in lanes; a light that sampled itself, lane by lane.
            let g7 = s.splat(gamma(7));
            macro_rules! bary_error {
                ($a:ident) => {
                    ((p0.$a * b0).abs() + (p1.$a * b1).abs() + (p2.$a * b2).abs()) * g7
                };
            }
            let p_error = V::<S> {
                x: bary_error!(x),
                y: bary_error!(y),
                z: bary_error!(z),
            };
            let from = offset_origin(s, p_ref, err, n, to_light);
            let to = offset_origin(s, p, p_error, ln, from.sub(p));
            let dir = to.sub(from);
            let contrib = contrib.to_array();
            // Written coordinate by coordinate, whole lanes at a time (lanes outside `ok` are
            // not traced).
            let mut shadow = RayLanes {
                origin: from.to_lanes().0,
                dir: dir.to_lanes().0,
                t_min: [0.0; WIDTH],
                t_max: [next_float_down(1.0); WIDTH],
            };
            for lane in bits(ok & own) {
                shadow.set(lane, &hits.point(lane).spawn_ray_to(&own_target[lane]));
            }
            rays += u64::from(ok.count_ones());
            let blocked = scene.occluded_lanes(s, &shadow, ok);
            for lane in bits(ok & !blocked) {
                paths.l[lane] += contrib[lane];
            }
        }
    }

    // Continue the path: a cosine-weighted direction (Lambertian::sample).
    let (ux, uy) = bsdf_u;
    // sample_uniform_disk_concentric: `sin_cos_quarter`'s polynomials in lanes.
    let two = s.splat(2.0);
    let one = s.splat(1.0);
    let ox = two * ux - one;
    let oy = two * uy - one;
    let centre = ox.eq(zero) & oy.eq(zero);
    let wide = ox.abs().gt(oy.abs());
    let r = S::F::select(wide, ox, oy);
    let x = s.splat(FRAC_PI_4) * (S::F::select(wide, oy, ox) / r);
    let (sin, cos) = sin_cos_quarter(s, x);
    let dx = S::F::select(centre, zero, r * S::F::select(wide, cos, sin));
    let dy = S::F::select(centre, zero, r * S::F::select(wide, sin, cos));
    let dz = (one - (dx * dx + dy * dy)).max(zero).sqrt();
    let flip = wo_l.z.lt(zero);
    // Glass (`sample_smooth` without a film): reflect with probability F, else refract
    // (computed only when some lane is glass).
    let g = if glasses != 0 {
        glass_lanes(s, wo_l, s.load(etas), uc)
    } else {
        GlassLanes {
            f: zero,
            reflect: s.mask(0),
            refracts: s.mask(0),
            wt: wo_l,
            etap: one,
        }
    };
    let reflect = mirror | (glass & g.reflect);
    let refract = glass & !g.reflect;
    // SpecularReflection::sample: the mirror direction about the shading normal, f = R / |cos|,
    // pdf 1 (a glass's reflection: f = F / |cos|, pdf F).
    let wi_l = V::<S> {
        x: S::F::select(reflect, -wo_l.x, S::F::select(refract, g.wt.x, dx)),
        y: S::F::select(reflect, -wo_l.y, S::F::select(refract, g.wt.y, dy)),
        z: S::F::select(
            reflect,
            wo_l.z,
            S::F::select(refract, g.wt.z, S::F::select(flip, -dz, dz)),
        ),
    };
    let cos_i = wi_l.z.abs();
    let pdf = S::F::select(
        mirror,
        one,
        S::F::select(
            glass,
            S::F::select(g.reflect, g.f, one - g.f),
            cos_i.max(zero) * s.splat(FRAC_1_PI),
        ),
    );
    let etap2 = g.etap * g.etap;
    let mut f = f_lambert;
    if mirrors != 0 {
        f = C::<S> {
            r: S::F::select(mirror, refl.r / cos_i, f.r),
            g: S::F::select(mirror, refl.g / cos_i, f.g),
            b: S::F::select(mirror, refl.b / cos_i, f.b),
        };
    }
    if glasses != 0 {
        // F / |cos| for a reflection, tint (1 - F) / |cos| / etap^2 for a refraction
        // (radiance).
        // (Written out per channel: no closure over lane values, see `WithSimd`.)
        let reflected = g.f / cos_i;
        let through = one - g.f;
        let (tr, tg, tb) = (
            (refl.r * through) / cos_i / etap2,
            (refl.g * through) / cos_i / etap2,
            (refl.b * through) / cos_i / etap2,
        );
        f = C::<S> {
            r: S::F::select(glass, S::F::select(g.reflect, reflected, tr), f.r),
            g: S::F::select(glass, S::F::select(g.reflect, reflected, tg), f.g),
            b: S::F::select(glass, S::F::select(g.reflect, reflected, tb), f.b),
        };
    }
    let wi = fs.scale(wi_l.x).add(ft.scale(wi_l.y)).add(ns.scale(wi_l.z));
    let geometric = (wi.dot(n) * wo.dot(n)).gt(zero);
    let shading = (wi_l.z * wo_l.z).gt(zero);
    let consistent = !(geometric & !shading | shading & !geometric);
    let beta = beta.mul(f.scale(cos_i / pdf));
    // A sample exists (glass: the refraction is possible, leaves the plane and F < 1), with a
    // positive pdf and a non-black f, on consistent sides.
    let sampled = !refract | g.refracts;
    let go =
        (!wo_l.z.eq(zero) & sampled & pdf.gt(zero) & !f.is_black(s) & consistent).bits() & shade;
    let etap2 = S::F::select(refract, etap2, one);
    *ended |= shade & !go;
    // Russian roulette in lanes, without a branch per lane on its coin tosses: the lanes past
    // the roulette depth whose throughput (over the refraction scale) is below the threshold
    // play, with the survival probability the largest channel over the threshold (times its
    // reciprocal, as the one-path tracer computes it).
    let eta_scale = s.load(paths.eta_scale);
    let eta_scale = S::F::select(s.mask(go), eta_scale * etap2, eta_scale);
    let rr_beta = beta.r.max(beta.g).max(beta.b) * eta_scale * s.splat(settings.rr_scale);
    let mut deep = 0u32;
    for lane in bits(go) {
        deep |= u32::from(paths.depth[lane] > settings.rr_depth) << lane;
    }
    let roulette = rr_beta.lt(one).bits() & deep;
    let mut beta = beta;
    if roulette != 0 {
        let q = (one - rr_beta).max(zero);
        let u = sampler.next_1d_lanes(s, roulette);
        let killed = u.lt(q).bits() & roulette;
        *ended |= killed;
        let (kept, d) = (s.mask(roulette & !killed), one - q);
        beta = C::<S> {
            r: S::F::select(kept, beta.r / d, beta.r),
            g: S::F::select(kept, beta.g / d, beta.g),
            b: S::F::select(kept, beta.b / d, beta.b),
        };
    }
    let finite = beta.r.is_finite() & beta.g.is_finite() & beta.b.is_finite();
    *ended |= go & !finite.bits();
    // `spawn_ray` from the hit points, in lanes. The new rays and the lanes' state the shading
    // loads whole, written whole lanes at a time: every lane's is written, and a lane that
    // does not go on is given a new path (or none) before they are read again.
    let origin = offset_origin(s, p_ref, err, n, wi);
    (paths.ray.origin, paths.ray.dir) = (origin.to_lanes().0, wi.to_lanes().0);
    (paths.ray.t_min, paths.ray.t_max) = ([0.0; WIDTH], [f32::INFINITY; WIDTH]);
    paths.beta = Lanes3([beta.r.to_array(), beta.g.to_array(), beta.b.to_array()]);
    (paths.eta_scale, paths.prev_pdf) = (eta_scale.to_array(), pdf.to_array());
    paths.specular = (paths.specular & !go) | ((mirrors | glasses) & go);
    // Whole arrays: the lanes not in `go` end here, and a lane is reset when a new path
    // starts in it.
    // Field by field: built whole, the record went through a temporary on the stack whose
    // 64-byte reloads straddled its unaligned 64-byte stores (a store-forwarding stall).
    paths.prev.p = hits.p;
    paths.prev.err = hits.err;
    paths.prev.n = hits.n;
    paths.prev.ns = hits.ns;
    rays
}
