//! Scenes: meshes placed as objects with materials and emission, lights, and the accelerator
//! over them. Build one with [`SceneBuilder`].

mod builder;
mod emitters;
mod error;
mod mesh;

use glam::{Affine3A, Mat3A, Vec2, Vec3};
use pt_accel::{Accel, AccelStats, Bounds3, Hit, Ray};

use crate::color::Rgb;
use crate::frame::Frame;
use crate::interaction::{
    SurfaceAttributes, SurfaceInteraction, SurfacePoint, barycentric_error,
    transform_point_with_error,
};
use crate::light::{BuiltinLight, PowerLightSampler};
use crate::material::BuiltinMaterial;

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

/// Unit normal of a triangle from its winding.
#[inline]
fn face_normal(p: [Vec3; 3]) -> Vec3 {
    // In f64: the f32 length of the cross product underflows for triangles 1e-11 across.
    pt_accel::triangle_normal(&p).unwrap_or(Vec3::Z)
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
    /// Light index per triangle (NO_LIGHT for triangles that do not emit), for emissive objects.
    lights: Option<Box<[u32]>>,
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
    /// first, so hits interpolate them ([`SurfaceAttributes`](crate::interaction::SurfaceAttributes)).
    pub vertex_attributes: bool,
    /// Some material bends the shading normal ([`Material::shading_normal`]: normal maps).
    pub normal_maps: bool,
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
    objects: Vec<ObjectData>,
    materials: Vec<M>,
    lights: Vec<L>,
    light_sampler: PowerLightSampler,
    /// Indices of the infinite (environment) lights, which rays that escape see.
    infinite_lights: Vec<u32>,
    stats: SceneStats,
    features: SceneFeatures,
}

impl<M, L> Scene<M, L> {
    /// The closest surface hit by `ray`, if any.
    #[inline]
    #[must_use]
    pub fn intersect(&self, ray: &Ray) -> Option<SurfaceInteraction> {
        self.accel
            .intersect(ray)
            .map(|hit| self.interaction(&hit, ray))
    }

    /// True when anything blocks `ray` within its range.
    #[inline]
    #[must_use]
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.accel.occluded(ray)
    }

    /// The surface interaction for an accelerator hit of `ray`.
    #[must_use]
    pub fn interaction(&self, hit: &Hit, ray: &Ray) -> SurfaceInteraction {
        let obj = &self.objects[hit.instance as usize];
        let mesh = &self.meshes[obj.mesh as usize];
        let idx = mesh.geometry().indices()[hit.prim as usize].map(|i| i as usize);
        let positions = mesh.geometry().positions();
        let p = idx.map(|i| positions[i]);
        let b = [hit.b0(), hit.b1, hit.b2];

        // Position with its error bound, and the geometric normal, in world space, computed from
        // the same vertices the accelerator intersected: world-space copies for flat
        // accelerators (bit-identical to the ones baked there), object space plus the transform's
        // error otherwise.
        let (p_world, p_error, mut n) = match &obj.transform {
            None => (
                p[0] * b[0] + p[1] * b[1] + p[2] * b[2],
                barycentric_error(b, p),
                face_normal(p),
            ),
            Some((m, _)) if self.accel.hits_in_world_space() => {
                let w = p.map(|v| m.transform_point3(v));
                (
                    w[0] * b[0] + w[1] * b[1] + w[2] * b[2],
                    barycentric_error(b, w),
                    face_normal(w),
                )
            }
            Some((m, normal_matrix)) => {
                let p_obj = p[0] * b[0] + p[1] * b[1] + p[2] * b[2];
                let (pw, e) = transform_point_with_error(m, p_obj, barycentric_error(b, p));
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

        let uv = match mesh.uvs() {
            Some(uvs) if self.features.texture_coordinates => {
                uvs[idx[0]] * b[0] + uvs[idx[1]] * b[1] + uvs[idx[2]] * b[2]
            }
            _ => Vec2::new(hit.b1, hit.b2),
        };
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
            point: SurfacePoint {
                p: p_world,
                p_error,
                n,
            },
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
