//! Scenes: meshes placed as objects with materials and emission, lights, and the accelerator
//! over them. Build one with [`SceneBuilder`].

mod builder;
mod emitters;
mod error;
mod mesh;

use glam::{Affine3A, Mat3A, Vec2, Vec3};
use pt_accel::lanes::Simd;
use pt_accel::{Accel, AccelStats, Bounds3, Hit, Ray, RayLanes};

use crate::color::Rgb;
use crate::frame::Frame;
use crate::interaction::{
    SurfaceAttributes, SurfaceInteraction, SurfacePoint, barycentric_error, barycentric_point,
    near_edge, pull_inside, transform_point_with_error,
};
use crate::light::{BuiltinLight, PowerLightSampler};
use crate::material::{BuiltinMaterial, Material, MaterialContext};

pub use builder::SceneBuilder;
pub use error::SceneError;
pub use mesh::{MAX_UV_SETS, Mesh};

/// Index of a mesh added to a [`SceneBuilder`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct MeshId(pub u32);

/// Index of a material added to a [`SceneBuilder`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct MaterialId(pub u32);

/// Light emitted by the surface of an object: every triangle becomes an area light.
#[derive(Clone, Debug, PartialEq)]
pub struct Emission {
    /// Emitted radiance, constant over the surface.
    pub radiance: Rgb,
    /// Emit from both faces; by default only the front face emits (the side of the triangle's
    /// winding normal, or of its vertex normals when the mesh has them).
    pub two_sided: bool,
    /// A texture multiplying `radiance` (glTF's emissive texture), read on the mesh's
    /// coordinate set and with the transform the map names. Each triangle becomes a
    /// [`TexturedTriangleLight`](crate::TexturedTriangleLight): the texture is evaluated where
    /// rays hit and where light samples land, and samples follow the texture's brightness.
    /// A mesh without the coordinate set emits `radiance` times the texture at `(0, 0)`.
    pub texture: Option<crate::texture::TextureMap>,
}

impl Emission {
    /// One-sided emission of the given radiance.
    #[must_use]
    pub fn new(radiance: Rgb) -> Self {
        Self {
            radiance,
            two_sided: false,
            texture: None,
        }
    }

    /// The same emission modulated by a texture (see [`Emission::texture`]): an
    /// `Arc<Texture>` (coordinate set 0) or a [`TextureMap`](crate::TextureMap).
    #[must_use]
    pub fn with_texture(mut self, texture: impl Into<crate::texture::TextureMap>) -> Self {
        self.texture = Some(texture.into());
        self
    }

    /// Emit from both faces.
    #[must_use]
    pub fn two_sided(mut self) -> Self {
        self.two_sided = true;
        self
    }
}

/// One placement of a mesh in the scene, with its material and optional emission.
#[derive(Clone, Debug, PartialEq)]
pub struct Object {
    /// The mesh.
    pub mesh: MeshId,
    /// The surface material.
    pub material: MaterialId,
    /// Object-to-world transform (must be invertible).
    pub transform: Affine3A,
    /// Emission, if the surface is a light.
    pub emission: Option<Emission>,
}

impl Object {
    /// The mesh with a material, untransformed and not emitting.
    #[must_use]
    pub fn new(mesh: MeshId, material: MaterialId) -> Self {
        Self {
            mesh,
            material,
            transform: Affine3A::IDENTITY,
            emission: None,
        }
    }

    /// Set the object-to-world transform.
    #[must_use]
    pub fn with_transform(mut self, transform: Affine3A) -> Self {
        self.transform = transform;
        self
    }

    /// Make the surface emit.
    #[must_use]
    pub fn with_emission(mut self, emission: Emission) -> Self {
        self.emission = Some(emission);
        self
    }
}

/// [`pull_inside`] for a triangle whose corners `p` are in object space and whose hit's error
/// bound `err` is in world space: pulled among the transformed corners, with the bound of
/// their transformation added.
#[cold]
#[inline(never)]
fn pull_inside_transformed(
    m: &Affine3A,
    b: [f32; 3],
    p: [Vec3; 3],
    err: Vec3,
) -> Option<(Vec3, Vec3)> {
    let w = p.map(|v| transform_point_with_error(m, v, Vec3::ZERO));
    let (q, e) = pull_inside(b, [w[0].0, w[1].0, w[2].0], err)?;
    Some((q, e + w[0].1.max(w[1].1).max(w[2].1)))
}

/// Unit normal of a triangle from its winding.
#[inline]
fn face_normal(p: [Vec3; 3]) -> Vec3 {
    // In f64: the f32 length of the cross product underflows for triangles 1e-11 across.
    pt_accel::triangle_normal(&p).unwrap_or(Vec3::Z)
}

/// A hit as the lane tracer reads it ([`Scene::lane_hit`]): [`SurfaceInteraction`]'s point,
/// shading normal, texture coordinates, direction back along the ray, material and light.
#[derive(Clone, Copy, Debug)]
pub(crate) struct LaneHit {
    pub point: SurfacePoint,
    pub ns: Vec3,
    pub uv: Vec2,
    pub wo: Vec3,
    pub material: u32,
    pub light: Option<u32>,
}

/// Marker for "this triangle is not a light".
const NO_LIGHT: u32 = u32::MAX;

/// Per-object data used at every hit.
#[derive(Clone, Debug)]
struct ObjectData {
    mesh: u32,
    material: u32,
    /// `None` for the identity transform (no transform work per hit).
    transform: Option<(Affine3A, Mat3A)>,
    /// The square of a bound on the inverse transform's norm (1 without a transform):
    /// [`near_edge`]'s `scale2` for hits whose corners stay in object space.
    edge_scale2: f32,
    /// No transform, no vertex normals, no emission: its hits are the lane tracer's to
    /// finish ([`Scene::lane_corners`]).
    lane_flat: bool,
    /// Light index per triangle (NO_LIGHT for triangles that do not emit), for emissive objects.
    lights: Option<Box<[u32]>>,
}

/// A triangle's corners, unit normal and four more values (`extra`) in one cache line, as two
/// rows of eight floats: `p0 p1 p2 n` coordinate by coordinate, then `extra`. The lane tracer
/// reads eight lanes' records whole and turns them into coordinates by two in-register
/// transpositions, instead of copying each value into per-lane arrays that vector loads then
/// wait for. Used for the triangles of meshes some object places untransformed, without
/// vertex normals or emission ([`ObjectData::lane_flat`]; the normal bit for bit
/// `face_normal`'s, `extra` zero): a hit's geometry by one bounds check instead of through
/// the vertex indices (Mitsuba's box: 42 instructions per hit before); and for the lane
/// tracer's triangle lights (`extra`: area and radiance).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub(crate) struct TriangleRecord {
    pub(crate) rows: [[f32; 8]; 2],
}

impl TriangleRecord {
    /// A record of zeros, for lanes that have none.
    pub(crate) const ZERO: Self = Self {
        rows: [[0.0; 8]; 2],
    };

    /// The record of corners `p`, unit normal `n` and `extra`.
    pub(crate) fn new(p: [Vec3; 3], n: Vec3, extra: [f32; 4]) -> Self {
        let [e0, e1, e2, e3] = extra;
        Self {
            rows: [
                [
                    p[0].x, p[0].y, p[0].z, p[1].x, p[1].y, p[1].z, p[2].x, p[2].y,
                ],
                [p[2].z, n.x, n.y, n.z, e0, e1, e2, e3],
            ],
        }
    }

    /// The corners.
    pub(crate) fn p(&self) -> [Vec3; 3] {
        let [a, b] = &self.rows;
        [
            Vec3::new(a[0], a[1], a[2]),
            Vec3::new(a[3], a[4], a[5]),
            Vec3::new(a[6], a[7], b[0]),
        ]
    }

    /// The unit face normal.
    #[cfg(test)]
    pub(crate) fn n(&self) -> Vec3 {
        let b = &self.rows[1];
        Vec3::new(b[1], b[2], b[3])
    }
}

/// Counts describing a built scene.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct SceneStats {
    /// Objects (instances).
    pub objects: usize,
    /// Distinct meshes.
    pub meshes: usize,
    /// Triangles over distinct meshes.
    pub unique_triangles: usize,
    /// Triangles over all objects (instancing counts a mesh once per object).
    pub instanced_triangles: usize,
    /// Lights, including one per emitting triangle.
    pub lights: usize,
    /// Emitting triangles that could not become lights (zero area or non-finite).
    pub skipped_emitters: usize,
    /// What the accelerator built.
    pub accel: AccelStats,
}

/// What a scene needs from the renderer, found once when the scene is built (DESIGN.md section
/// 6). The renderer reads it once per render and leaves out the work a scene does not need;
/// [`RenderStats`](crate::RenderStats) reports what was left out.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub struct SceneFeatures {
    /// The scene has a light that next-event estimation can sample.
    pub light_sampling: bool,
    /// The scene has an environment (an infinite light), which rays that escape must look up.
    pub environment: bool,
    /// Some material can produce a non-delta BSDF; when none can, every bounce is specular and
    /// neither next-event estimation nor MIS weights are ever needed.
    pub non_delta_materials: bool,
    /// Some material reads texture coordinates, so hits interpolate them.
    pub texture_coordinates: bool,
    /// Some material reads vertex colours or tangents, or texture-coordinate sets beyond the
    /// first, so hits interpolate them ([`SurfaceAttributes`]).
    pub vertex_attributes: bool,
    /// Some material bends the shading normal ([`Material::shading_normal`]: normal maps).
    pub normal_maps: bool,
    /// Some material is single-sided ([`Material::single_sided`]) or partly transparent
    /// ([`Material::coverage`]), so ray queries filter their hits (closest hits step over
    /// rejected ones; shadow rays stop only at accepted ones). Without, queries run unfiltered.
    pub surface_filters: bool,
    /// Some material encloses an absorbing medium ([`Material::absorption`]), so paths track
    /// whether they are inside one.
    pub absorbing_media: bool,
}

impl SceneFeatures {
    /// The parts of the renderer this scene lets it skip, each with the reason, for the render
    /// summary.
    #[must_use]
    pub fn skipped(&self) -> Vec<&'static str> {
        let mut out = Vec::new();
        if !self.light_sampling {
            out.push("light sampling (no lights)");
        } else if !self.non_delta_materials {
            out.push("light sampling and MIS (only delta BSDFs)");
        }
        if !self.environment {
            out.push("environment lookups (no environment)");
        }
        if !self.texture_coordinates {
            out.push("texture coordinates (no textures)");
        }
        out
    }
}

/// The vertex attributes at barycentrics `b` of the triangle `idx` of `mesh`, placed by
/// `obj`'s transform, with the tangent made orthogonal to the world shading normal `ns`.
fn vertex_attributes(
    mesh: &Mesh,
    obj: &ObjectData,
    idx: [usize; 3],
    b: [f32; 3],
    ns: Vec3,
) -> SurfaceAttributes {
    let mut a = SurfaceAttributes::default();
    for (set, uv) in a.uv.iter_mut().enumerate() {
        if let Some(uvs) = mesh.uv_set(set) {
            *uv = uvs[idx[0]] * b[0] + uvs[idx[1]] * b[1] + uvs[idx[2]] * b[2];
        }
    }
    if let Some(c) = mesh.colors() {
        a.color = c[idx[0]] * b[0] + c[idx[1]] * b[1] + c[idx[2]] * b[2];
    }
    if let Some(t) = mesh.tangents() {
        let t_obj = t[idx[0]] * b[0] + t[idx[1]] * b[1] + t[idx[2]] * b[2];
        let (dir, mut sign) = (t_obj.truncate(), if t_obj.w < 0.0 { -1.0 } else { 1.0 });
        let dir = match &obj.transform {
            None => dir,
            Some((m, _)) => {
                // A mirroring transform flips the bitangent's handedness.
                if m.matrix3.determinant() < 0.0 {
                    sign = -sign;
                }
                m.transform_vector3(dir)
            }
        };
        // Gram-Schmidt against the shading normal.
        let t = (dir - ns * ns.dot(dir)).normalize_or_zero();
        if t.is_finite() {
            a.tangent = t.extend(if t == Vec3::ZERO { 0.0 } else { sign });
        }
    }
    a
}

/// A renderable scene: geometry with its accelerator, materials and lights.
///
/// Generic over the material and light types so that user-defined enums (see
/// [`material_enum!`](crate::material_enum), [`light_enum!`](crate::light_enum)) are dispatched
/// statically; the defaults are the built-ins.
#[derive(Clone, Debug)]
pub struct Scene<M = BuiltinMaterial, L = BuiltinLight> {
    accel: Accel,
    meshes: Vec<Mesh>,
    /// Per mesh, its triangles' unit normals (`face_normal`) when some object places it
    /// untransformed; empty otherwise.
    face_normals: Vec<Box<[Vec3]>>,
    /// Per mesh, its triangles as [`TriangleRecord`] records when some object places it as
    /// [`ObjectData::lane_flat`] says; empty otherwise.
    flat_triangles: Vec<Box<[TriangleRecord]>>,
    objects: Vec<ObjectData>,
    materials: Vec<M>,
    lights: Vec<L>,
    light_sampler: PowerLightSampler,
    /// Indices of the infinite (environment) lights, which rays that escape see.
    infinite_lights: Vec<u32>,
    stats: SceneStats,
    features: SceneFeatures,
    /// Per material: what hits on it must be checked for (empty without surface filters).
    filters: Box<[SurfaceFilter]>,
}

/// What a hit on a material must be checked for ([`SceneFeatures::surface_filters`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct SurfaceFilter {
    /// Back faces are invisible.
    single_sided: bool,
    /// Rays pass through with probability `1 - coverage`.
    coverage: bool,
}

/// A uniform number in `[0, 1)` from the ray and the triangle it hit: the stochastic
/// transparency test's random number, the same for the same ray whatever the thread.
#[inline]
fn hash_u01(ray: &Ray, hit: &Hit) -> f32 {
    let mut h = 0x9e37_79b9_7f4a_7c15u64 ^ u64::from(hit.instance) << 32 ^ u64::from(hit.prim);
    for v in [
        ray.origin.x,
        ray.origin.y,
        ray.origin.z,
        ray.dir.x,
        ray.dir.y,
        ray.dir.z,
    ] {
        h ^= u64::from(v.to_bits());
        h = h.wrapping_mul(0xff51_afd7_ed55_8ccd);
        h ^= h >> 33;
    }
    h = h.wrapping_mul(0xc4ce_b9fe_1a85_ec53);
    h ^= h >> 33;
    (h >> 40) as f32 * (1.0 / (1u64 << 24) as f32)
}

impl<M: Material, L> Scene<M, L> {
    /// The closest surface hit by `ray`, if any. Back faces of single-sided materials and,
    /// with probability `1 - coverage`, hits on partly transparent ones are stepped over.
    #[inline]
    #[must_use]
    pub fn intersect(&self, ray: &Ray) -> Option<SurfaceInteraction> {
        let hit = if self.features.surface_filters {
            self.intersect_filtered(ray)
        } else {
            self.accel.intersect(ray)
        };
        hit.map(|hit| self.interaction(&hit, ray))
    }

    /// The filtered closest-hit query, kept out of line so that the unfiltered path (every
    /// opaque scene) stays as small as it was.
    #[inline(never)]
    fn intersect_filtered(&self, ray: &Ray) -> Option<Hit> {
        self.accel
            .intersect_filtered(ray, |hit| self.accepts(hit, ray))
    }

    /// The filtered shadow query, out of line like [`Self::intersect_filtered`].
    #[inline(never)]
    fn occluded_filtered(&self, ray: &Ray) -> bool {
        self.accel
            .occluded_filtered(ray, |hit| self.accepts(hit, ray))
    }

    /// True when anything blocks `ray` within its range (hits filtered as by
    /// [`intersect`](Self::intersect)).
    #[inline]
    #[must_use]
    pub fn occluded(&self, ray: &Ray) -> bool {
        if self.features.surface_filters {
            self.occluded_filtered(ray)
        } else {
            self.accel.occluded(ray)
        }
    }

    /// The accelerator's closest hits (surface filters applied) of the rays in the lanes set in
    /// `mask`, before their interactions ([`Self::interaction`]), from code running with the
    /// lanes of `s`: all of them in one call where the accelerator can
    /// (`Accel::intersect_lanes_in`, with the caller's instruction set). Each equals
    /// [`Self::intersect`]'s.
    #[inline(always)]
    pub(crate) fn hits_lanes<S: Simd>(
        &self,
        s: S,
        rays: &RayLanes,
        mask: u32,
    ) -> [Option<Hit>; pt_accel::lanes::WIDTH] {
        if self.features.surface_filters {
            std::array::from_fn(|lane| {
                (mask & (1 << lane) != 0)
                    .then(|| self.intersect_filtered(&rays.get(lane)))
                    .flatten()
            })
        } else {
            self.accel.intersect_lanes_in(s, rays, mask)
        }
    }

    /// [`Self::occluded`] for the rays in the lanes set in `mask`, from code running with the
    /// lanes of `s`: bit `i` set when `rays[i]` is blocked.
    #[inline(always)]
    pub(crate) fn occluded_lanes<S: Simd>(&self, s: S, rays: &RayLanes, mask: u32) -> u32 {
        if self.features.surface_filters {
            pt_accel::lanes::mask_where(mask, |lane| self.occluded_filtered(&rays.get(lane)))
        } else {
            self.accel.occluded_lanes_in(s, rays, mask)
        }
    }

    /// Whether a hit stops the ray: not a back face of a single-sided material, and on a
    /// partly transparent one, kept with probability equal to its coverage.
    fn accepts(&self, hit: &Hit, ray: &Ray) -> bool {
        let obj = &self.objects[hit.instance as usize];
        let filter = self.filters[obj.material as usize];
        if filter.single_sided {
            let mesh = &self.meshes[obj.mesh as usize];
            let idx = mesh.geometry().indices()[hit.prim as usize];
            let p = idx.map(|i| mesh.geometry().positions()[i as usize]);
            let n = face_normal(p);
            // The front face's normal in world space: the normal transform of the object-space
            // winding normal (its sign follows glTF's rule for mirroring transforms).
            let front = match &obj.transform {
                None => n,
                Some((_, nm)) => Vec3::from(*nm * glam::Vec3A::from(n)),
            };
            if front.dot(ray.dir) >= 0.0 {
                return false;
            }
        }
        if filter.coverage {
            let si = self.interaction(hit, ray);
            let ctx = MaterialContext::new(si.point.p, si.n(), si.ns(), si.wo, si.uv)
                .with_attributes(si.attributes);
            let c = self.materials[obj.material as usize].coverage(&ctx);
            if c < 1.0 {
                return c > 0.0 && hash_u01(ray, hit) < c;
            }
        }
        true
    }
}

impl<M, L> Scene<M, L> {
    /// Ask for the cache line of a hit triangle's vertex indices, which [`Self::lane_hit`]
    /// reads first: on a big mesh a cache miss, on which the positions' and normals' misses
    /// then wait. The lane tracer asks for all its lanes' lines before shading any lane, so
    /// that the misses overlap.
    #[inline(always)]
    pub(crate) fn prefetch_hit(&self, hit: &Hit) {
        let obj = &self.objects[hit.instance as usize];
        let mesh = &self.meshes[obj.mesh as usize];
        if let Some(i) = mesh.geometry().indices().get(hit.prim as usize) {
            pt_accel::lanes::prefetch(i);
        }
    }

    /// The common case of [`Self::lane_hit`], for the lane tracer to finish in lanes: a hit on
    /// an untransformed object without vertex normals or emission. Its triangle's record
    /// (corners and face normal, which is also the shading normal) and its material;
    /// [`Self::lane_hit`]'s point is `p[0] b0 + p[1] b1 + p[2] b2` with
    /// [`barycentric_error`]'s bound. `None` for every other hit.
    #[inline(always)]
    pub(crate) fn lane_corners(&self, hit: &Hit) -> Option<(&TriangleRecord, u32)> {
        let obj = &self.objects[hit.instance as usize];
        if !obj.lane_flat {
            return None;
        }
        let t = self.flat_triangles[obj.mesh as usize].get(hit.prim as usize)?;
        Some((t, obj.material))
    }

    /// What every hit needs, shared by [`Self::interaction`] and [`Self::lane_hit`]: the point
    /// with its error bound and the geometric normal (turned to the shading normal's side), the
    /// shading normal, the triangle's vertex indices and the barycentrics.
    #[inline(always)]
    fn hit_geometry(&self, hit: &Hit) -> (SurfacePoint, Vec3, [usize; 3], [f32; 3]) {
        let obj = &self.objects[hit.instance as usize];
        let mesh = &self.meshes[obj.mesh as usize];
        let [i0, i1, i2] = mesh.geometry().indices()[hit.prim as usize];
        let idx = [i0 as usize, i1 as usize, i2 as usize];
        let positions = mesh.geometry().positions();
        // Written out, not `idx.map`: the closure's array was assembled on the stack from
        // 8- and 4-byte stores and read back in 16-byte loads (a store-forwarding stall per
        // hit, 2-3% of a render).
        let p = [positions[idx[0]], positions[idx[1]], positions[idx[2]]];
        let b = [hit.b0(), hit.b1, hit.b2];

        // Position with its error bound, and the geometric normal, in world space, computed from
        // the same vertices the accelerator intersected: world-space copies for flat
        // accelerators (bit-identical to the ones baked there), object space plus the transform's
        // error otherwise. A point within its error bound of an edge is pulled inside
        // (`pull_inside`).
        let (p_world, p_error, mut n) = match &obj.transform {
            None => {
                let (q, e) = barycentric_point(b, p);
                let n = match self.face_normals[obj.mesh as usize].get(hit.prim as usize) {
                    Some(&n) => n,
                    None => face_normal(p),
                };
                (q, e, n)
            }
            Some((m, _)) if self.accel.hits_in_world_space() => {
                let w = p.map(|v| m.transform_point3(v));
                let (q, e) = barycentric_point(b, w);
                (q, e, face_normal(w))
            }
            Some((m, normal_matrix)) => {
                let p_obj = p[0] * b[0] + p[1] * b[1] + p[2] * b[2];
                let (mut pw, mut e) = transform_point_with_error(m, p_obj, barycentric_error(b, p));
                if near_edge(b, p, e, obj.edge_scale2) {
                    (pw, e) = pull_inside_transformed(m, b, p, e).unwrap_or((pw, e));
                }
                let ng_obj = face_normal(p);
                (
                    pw,
                    e,
                    Vec3::from(*normal_matrix * glam::Vec3A::from(ng_obj)).normalize(),
                )
            }
        };

        // Shading normal from vertex normals; the geometric normal is flipped to its side, so
        // that vertex normals decide which side is the outside.
        let mut ns = n;
        if let Some(normals) = mesh.normals() {
            let ns_obj = normals[idx[0]] * b[0] + normals[idx[1]] * b[1] + normals[idx[2]] * b[2];
            let ns_world = match &obj.transform {
                None => ns_obj,
                Some((_, nm)) => Vec3::from(*nm * glam::Vec3A::from(ns_obj)),
            }
            .normalize_or_zero();
            if ns_world != Vec3::ZERO && ns_world.is_finite() {
                if n.dot(ns_world) < 0.0 {
                    n = -n;
                }
                ns = ns_world;
            }
        }

        (
            SurfacePoint {
                p: p_world,
                p_error,
                n,
            },
            ns,
            idx,
            b,
        )
    }

    /// Texture coordinates of a hit: interpolated where the scene reads them, the barycentrics
    /// otherwise.
    #[inline(always)]
    fn hit_uv(&self, hit: &Hit, obj: &ObjectData, idx: [usize; 3], b: [f32; 3]) -> Vec2 {
        match self.meshes[obj.mesh as usize].uvs() {
            Some(uvs) if self.features.texture_coordinates => {
                uvs[idx[0]] * b[0] + uvs[idx[1]] * b[1] + uvs[idx[2]] * b[2]
            }
            _ => Vec2::new(hit.b1, hit.b2),
        }
    }

    /// The parts of [`Self::interaction`] the lane tracer reads, with the same values, without
    /// the shading frame, texture coordinates and vertex attributes it does not.
    ///
    /// Always inlined: the lane tracer calls it from inside its instruction set's entry, and a
    /// program built for baseline x86-64 otherwise compiled it out of line with SSE2 only and
    /// a call per lane (9.6% of Mitsuba's box there, 0.88x the host build's speed).
    #[inline(always)]
    pub(crate) fn lane_hit(&self, hit: &Hit, ray: &Ray) -> LaneHit {
        let (point, ns, idx, b) = self.hit_geometry(hit);
        let obj = &self.objects[hit.instance as usize];
        LaneHit {
            point,
            ns,
            uv: self.hit_uv(hit, obj, idx, b),
            wo: -ray.dir.normalize(),
            material: obj.material,
            light: obj
                .lights
                .as_ref()
                .map(|l| l[hit.prim as usize])
                .filter(|&l| l != NO_LIGHT),
        }
    }

    /// The surface interaction for an accelerator hit of `ray`.
    #[must_use]
    pub fn interaction(&self, hit: &Hit, ray: &Ray) -> SurfaceInteraction {
        let (point, ns, idx, b) = self.hit_geometry(hit);
        let obj = &self.objects[hit.instance as usize];
        let mesh = &self.meshes[obj.mesh as usize];
        let uv = self.hit_uv(hit, obj, idx, b);
        let attributes = if self.features.vertex_attributes {
            vertex_attributes(mesh, obj, idx, b, ns)
        } else {
            SurfaceAttributes::default()
        };
        let light = obj
            .lights
            .as_ref()
            .map(|l| l[hit.prim as usize])
            .filter(|&l| l != NO_LIGHT);

        SurfaceInteraction {
            point,
            shading: Frame::from_z(ns),
            uv,
            attributes,
            wo: -ray.dir.normalize(),
            t: hit.t,
            material: obj.material,
            light,
            instance: hit.instance,
            prim: hit.prim,
        }
    }

    /// What the scene needs from the renderer (the scene analysis).
    #[inline]
    #[must_use]
    pub fn features(&self) -> &SceneFeatures {
        &self.features
    }

    /// The materials, indexed by [`SurfaceInteraction::material`].
    #[inline]
    #[must_use]
    pub fn materials(&self) -> &[M] {
        &self.materials
    }

    /// The lights, indexed by [`SurfaceInteraction::light`].
    #[inline]
    #[must_use]
    pub fn lights(&self) -> &[L] {
        &self.lights
    }

    /// Indices (into [`lights`](Self::lights)) of the infinite lights: what a ray that escapes
    /// the scene sees. Empty when the scene has no environment, so misses cost nothing.
    #[inline]
    #[must_use]
    pub fn infinite_lights(&self) -> &[u32] {
        &self.infinite_lights
    }

    /// Chooses lights for next-event estimation.
    #[inline]
    #[must_use]
    pub fn light_sampler(&self) -> &PowerLightSampler {
        &self.light_sampler
    }

    /// The meshes.
    #[must_use]
    pub fn meshes(&self) -> &[Mesh] {
        &self.meshes
    }

    /// Bounds of all geometry.
    #[must_use]
    pub fn bounds(&self) -> Bounds3 {
        self.accel.bounds()
    }

    /// Counts describing the scene and its accelerator.
    #[must_use]
    pub fn stats(&self) -> &SceneStats {
        &self.stats
    }
}

#[cfg(test)]
mod filter_tests {
    use glam::Vec3;
    use pt_accel::TriangleMesh;

    use super::*;
    use crate::material::{AlphaMode, PbrMaterial};

    /// A unit square in the plane `z`, wound counter-clockwise seen from `+z` when `up`.
    fn square(z: f32, up: bool) -> Mesh {
        let p = vec![
            Vec3::new(-1.0, -1.0, z),
            Vec3::new(1.0, -1.0, z),
            Vec3::new(1.0, 1.0, z),
            Vec3::new(-1.0, 1.0, z),
        ];
        let idx = if up {
            vec![[0, 1, 2], [0, 2, 3]]
        } else {
            vec![[0, 2, 1], [0, 3, 2]]
        };
        Mesh::new(TriangleMesh::new(p, idx).unwrap())
    }

    /// A test square at z = 0 of material `front` (placed by `transform`) before an opaque
    /// backdrop at z = -1 (instance 1).
    fn scene(front: PbrMaterial, up: bool, transform: Affine3A) -> Scene {
        let mut b: SceneBuilder = SceneBuilder::new();
        let m0 = b.add_mesh(square(0.0, up));
        let m1 = b.add_mesh(square(-1.0, true));
        let f = b.add_material(BuiltinMaterial::from(front));
        let back = b.add_material(BuiltinMaterial::diffuse(Rgb::WHITE));
        b.add_object(Object::new(m0, f).with_transform(transform));
        b.add_object(Object::new(m1, back));
        b.build().unwrap()
    }

    fn first_instance(s: &Scene, origin: Vec3) -> Option<u32> {
        s.intersect(&Ray::new(origin, -Vec3::Z))
            .map(|si| si.instance)
    }

    #[test]
    fn back_faces_of_single_sided_materials_are_invisible() {
        let single = PbrMaterial {
            double_sided: false,
            ..PbrMaterial::default()
        };
        let o = Vec3::new(0.1, 0.2, 1.0);
        // Facing the ray: seen.
        let s = scene(single.clone(), true, Affine3A::IDENTITY);
        assert!(s.features().surface_filters);
        assert_eq!(first_instance(&s, o), Some(0));
        // Facing away: the ray passes to the backdrop, and a shadow ray through it to a point
        // between the two is not blocked.
        let s = scene(single.clone(), false, Affine3A::IDENTITY);
        assert_eq!(first_instance(&s, o), Some(1));
        assert!(!s.occluded(&Ray::with_t_max(o, -Vec3::Z, 1.5)));
        assert!(s.occluded(&Ray::with_t_max(o, -Vec3::Z, 2.5)));
        // Mirrored by its instance (negative determinant): glTF's rule makes the clockwise
        // winding the front, so the square wound counter-clockwise still faces +z.
        let mirror = Affine3A::from_scale(Vec3::new(-1.0, 1.0, 1.0));
        let s = scene(single.clone(), true, mirror);
        assert_eq!(first_instance(&s, o), Some(0));
        let s = scene(single, false, mirror);
        assert_eq!(first_instance(&s, o), Some(1));
        // Double-sided (the default): both faces are seen, and no filter runs.
        let s = scene(PbrMaterial::default(), false, Affine3A::IDENTITY);
        assert!(!s.features().surface_filters);
        assert_eq!(first_instance(&s, o), Some(0));
    }

    #[test]
    fn masked_alpha_cuts_out_at_the_cutoff() {
        for (alpha, seen) in [(0.4, false), (0.6, true)] {
            let m = PbrMaterial {
                alpha,
                alpha_mode: AlphaMode::Mask(0.5),
                ..PbrMaterial::default()
            };
            let s = scene(m, true, Affine3A::IDENTITY);
            let o = Vec3::new(0.3, -0.4, 1.0);
            assert_eq!(first_instance(&s, o), Some(if seen { 0 } else { 1 }));
            assert_eq!(s.occluded(&Ray::with_t_max(o, -Vec3::Z, 1.5)), seen);
        }
    }

    #[test]
    fn blended_alpha_stops_rays_with_probability_alpha() {
        let m = PbrMaterial {
            alpha: 0.3,
            alpha_mode: AlphaMode::Blend,
            ..PbrMaterial::default()
        };
        let s = scene(m, true, Affine3A::IDENTITY);
        let n = 20_000;
        let (mut stopped, mut blocked) = (0, 0);
        for i in 0..n {
            let o = Vec3::new(
                (i % 100) as f32 / 100.0 - 0.5,
                (i / 100) as f32 / 200.0 - 0.5,
                1.0,
            );
            stopped += usize::from(first_instance(&s, o) == Some(0));
            blocked += usize::from(s.occluded(&Ray::with_t_max(o, -Vec3::Z, 1.5)));
        }
        // Binomial: sd = sqrt(0.3 * 0.7 / n) = 0.0032; 4 sd (two-sided p < 1e-4).
        for (what, k) in [("camera", stopped), ("shadow", blocked)] {
            let f = k as f64 / n as f64;
            assert!(
                (f - 0.3).abs() < 0.013,
                "{what} rays stopped with frequency {f}"
            );
        }
        // The same ray gives the same answer.
        let o = Vec3::new(0.123, 0.456, 1.0);
        let a = first_instance(&s, o);
        assert!((0..10).all(|_| first_instance(&s, o) == a));
    }

    /// The normals a hit reads from the per-mesh table are those computed from its corners,
    /// bit for bit; the table is filled only for meshes placed untransformed, and the lane
    /// tracer's records of corners and normal only for those without normals or emission.
    #[test]
    fn face_normal_table_matches_corners() {
        // A tilted triangle (no axis-aligned normal), placed as it is and moved along x.
        let p = [
            Vec3::new(-1.0, -0.9, 0.1),
            Vec3::new(1.1, -1.0, -0.3),
            Vec3::new(0.2, 1.0, 0.7),
        ];
        let tilted = || Mesh::new(TriangleMesh::new(p.to_vec(), vec![[0, 1, 2]]).unwrap());
        let mut b: SceneBuilder = SceneBuilder::new();
        let shared = b.add_mesh(tilted());
        let moved_only = b.add_mesh(tilted());
        let m = b.add_material(BuiltinMaterial::diffuse(Rgb::WHITE));
        let shift = Affine3A::from_translation(Vec3::new(5.0, 0.0, 0.0));
        b.add_object(Object::new(shared, m));
        b.add_object(Object::new(shared, m).with_transform(shift));
        b.add_object(Object::new(moved_only, m).with_transform(shift * shift));
        let s = b.build().unwrap();
        let want = face_normal(p);
        assert_eq!(s.face_normals[0].as_ref(), [want]);
        assert!(s.face_normals[1].is_empty());
        assert_eq!(
            s.flat_triangles[0].as_ref(),
            [TriangleRecord::new(p, want, [0.0; 4])]
        );
        assert_eq!(
            (s.flat_triangles[0][0].p(), s.flat_triangles[0][0].n()),
            (p, want)
        );
        assert!(s.flat_triangles[1].is_empty());
        let hit = s
            .accel
            .intersect(&Ray::new(Vec3::new(0.1, 0.0, 5.0), -Vec3::Z))
            .expect("the ray meets the untransformed triangle");
        assert_eq!(s.lane_corners(&hit), Some((&s.flat_triangles[0][0], 0)));
        for (x, instance) in [(0.0, 0), (5.0, 1), (10.0, 2)] {
            let si = s
                .intersect(&Ray::new(Vec3::new(x + 0.1, 0.0, 5.0), -Vec3::Z))
                .unwrap();
            assert_eq!(si.instance, instance);
            let corners = p.map(|v| v + Vec3::new(x, 0.0, 0.0));
            assert_eq!(si.point.n.to_array(), face_normal(corners).to_array());
        }
    }
}
