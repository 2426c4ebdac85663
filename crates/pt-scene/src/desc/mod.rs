//! The format-neutral scene description every loader produces, and the one place where it
//! becomes a [`pt_core::Scene`].
//!
//! A [`SceneDesc`] holds meshes (one material-free geometry each), materials described by their
//! physical parameters ([`MaterialDesc`], close to glTF's metallic-roughness model), instances
//! (mesh, material, transform), cameras and the file it came from. [`SceneDesc::build`] maps the
//! materials onto the built-in models, turns emissive instances into area lights, places a camera
//! (the file's, or one framing the scene) and adds an optional environment.
//!
//! # Material mapping
//!
//! Materials from glTF files (`MaterialDesc::gltf`) render with glTF's own metallic-roughness
//! BSDF ([`MetallicRoughness`](pt_core::MetallicRoughness): a GGX metal with Schlick Fresnel
//! `F0` = base colour, mixed by `metallic` with a Fresnel-weighted GGX specular layer over a
//! diffuse base), evaluated per hit through a [`PbrMaterial`](pt_core::PbrMaterial) so that
//! textures and factors combine as the specification says. Two exceptions: `transmission >= 0.5`
//! becomes [`Glass`](pt_core::Glass) (`eta = ior`, roughness, tint = base colour), and a mirror flag
//! becomes a [`Mirror`](pt_core::Mirror).
//!
//! OBJ and PLY materials (Phong-style parameters that do not describe a layered surface) become
//! the one built-in model that best matches their dominant lobe:
//!
//! | condition (first that holds) | built-in material |
//! |---|---|
//! | `transmission >= 0.5` | [`Glass`](pt_core::Glass): `eta = ior`, roughness, tint = base colour |
//! | `metallic >= 0.5` | [`Metal`](pt_core::Metal): Schlick Fresnel with `F0` = base colour, roughness |
//! | `specular` mirror flag (OBJ `illum 3`, `5`) | [`Mirror`](pt_core::Mirror) with the specular colour |
//! | otherwise | [`Diffuse`](pt_core::Diffuse) with the base colour |
//!
//! A material with a base colour or metallic-roughness texture becomes a
//! [`PbrMaterial`](pt_core::PbrMaterial), which applies the same rule per hit after multiplying
//! the factors by the textures.
//!
//! Emission (`emissive * strength`) is kept whatever the surface model: every triangle of an
//! emissive instance becomes an area light, one-sided along the winding (glTF emitters are
//! one-sided; OBJ files rarely get the winding of their lights right, so OBJ emitters are
//! two-sided).

mod material;
mod tangents;

pub use material::{MaterialDesc, TextureRef};

use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::Arc;

use glam::{Affine3A, Vec2, Vec3, Vec4};
use pt_core::pt_accel::{Bounds3, TriangleMesh};
use pt_core::{
    BuiltinLight, BuiltinMaterial, DirectionalLight, Emission, Mesh, Object, PinholeCamera,
    PointLight, Rgb, SceneBuilder, SpotLight, Texture,
};

use crate::SceneBundle;
use crate::error::LoadError;

/// Geometry of one mesh (one glTF primitive, one OBJ object or group).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshDesc {
    /// Name for messages ("mesh 3 primitive 1", the OBJ object name).
    pub name: String,
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Per-vertex normals (empty when the file has none).
    pub normals: Vec<Vec3>,
    /// Per-vertex texture coordinates (empty when the file has none).
    pub uvs: Vec<Vec2>,
    /// Texture-coordinate sets 1, 2, ... (glTF's `TEXCOORD_1` onward), each per vertex; empty
    /// sets stand for sets the file lacks.
    pub extra_uv_sets: Vec<Vec<Vec2>>,
    /// Per-vertex linear RGBA colours (glTF's `COLOR_0`; empty when the file has none).
    pub colors: Vec<Vec4>,
    /// Per-vertex tangents with the bitangent's handedness in `w` (glTF's `TANGENT`; empty when
    /// the file has none, in which case [`SceneDesc::build`] generates MikkTSpace tangents for
    /// meshes drawn with a normal map).
    pub tangents: Vec<Vec4>,
    /// Triangles as vertex indices.
    pub indices: Vec<[u32; 3]>,
}

impl MeshDesc {
    /// The renderable mesh: geometry and every attribute the description has.
    ///
    /// # Errors
    ///
    /// A message saying what is wrong (a malformed triangle list, an attribute count that is
    /// not one per vertex, non-finite values).
    pub fn to_mesh(&self) -> Result<Mesh, String> {
        let e = |e: pt_core::SceneError| e.to_string();
        let geometry = TriangleMesh::new(self.positions.clone(), self.indices.clone())
            .map_err(|e| e.to_string())?;
        let mut mesh = Mesh::new(geometry);
        if !self.normals.is_empty() {
            mesh = mesh.with_normals(self.normals.clone()).map_err(e)?;
        }
        if !self.uvs.is_empty() {
            mesh = mesh.with_uvs(self.uvs.clone()).map_err(e)?;
        }
        for (i, set) in self.extra_uv_sets.iter().enumerate() {
            if !set.is_empty() {
                mesh = mesh.with_uv_set(i + 1, set.clone()).map_err(e)?;
            }
        }
        if !self.colors.is_empty() {
            mesh = mesh.with_colors(self.colors.clone()).map_err(e)?;
        }
        if !self.tangents.is_empty() {
            mesh = mesh.with_tangents(self.tangents.clone()).map_err(e)?;
        }
        Ok(mesh)
    }
}

/// One placed mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct InstanceDesc {
    /// Index into [`SceneDesc::meshes`].
    pub mesh: usize,
    /// Index into [`SceneDesc::materials`].
    pub material: usize,
    /// Object to world.
    pub transform: Affine3A,
}

/// A perspective camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraDesc {
    /// Camera to world (the camera looks along its local `-z`, `+y` up, as in glTF).
    pub transform: Affine3A,
    /// Vertical field of view in degrees.
    pub yfov_deg: f32,
}

/// A light that is not a surface (glTF `KHR_lights_punctual`).
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum LightDesc {
    /// A point light: world position, intensity (colour times strength, per steradian).
    Point {
        /// World position.
        position: Vec3,
        /// Intensity per channel.
        intensity: Rgb,
    },
    /// A spot light.
    Spot {
        /// World position.
        position: Vec3,
        /// World direction the cone points along.
        direction: Vec3,
        /// Intensity per channel on the axis.
        intensity: Rgb,
        /// Full intensity within this angle (radians).
        inner_angle: f32,
        /// Zero beyond this angle (radians).
        outer_angle: f32,
    },
    /// A directional light.
    Directional {
        /// World direction the light travels along.
        direction: Vec3,
        /// Irradiance on a surface facing the light.
        irradiance: Rgb,
    },
}

/// A scene as loaded from a file, before it is built.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SceneDesc {
    /// The file it came from.
    pub source: PathBuf,
    /// Geometry.
    pub meshes: Vec<MeshDesc>,
    /// Materials.
    pub materials: Vec<MaterialDesc>,
    /// Placed meshes.
    pub instances: Vec<InstanceDesc>,
    /// Cameras, in file order.
    pub cameras: Vec<CameraDesc>,
    /// Punctual lights.
    pub lights: Vec<LightDesc>,
    /// Decoded textures, shared by the materials that use them.
    pub textures: Vec<Arc<Texture>>,
}

/// Choices made when a description becomes a scene.
///
/// ```
/// use pt_scene::BuildOptions;
/// use pt_core::{UniformEnvironment, Rgb};
/// let options = BuildOptions::default()
///     .environment(UniformEnvironment::new(Rgb::splat(0.5))?.into());
/// assert!(options.camera.is_none());
/// # Ok::<(), pt_core::LightError>(())
/// ```
#[derive(Clone, Debug, Default)]
#[non_exhaustive]
pub struct BuildOptions {
    /// Use this camera instead of the file's (or the framing default).
    pub camera: Option<PinholeCamera>,
    /// Light the scene with this environment too.
    pub environment: Option<BuiltinLight>,
    /// Sample the emitting triangles by solid angle instead of by area
    /// (`SceneBuilder::solid_angle_light_sampling`).
    pub solid_angle_light_sampling: bool,
    /// Make every emitting surface emit from both faces. Emission is one-sided by default (from
    /// the front, the side the counter-clockwise winding's normal points to) in every format,
    /// as in pbrt, Mitsuba and glTF; glTF materials with `doubleSided: true` emit from both
    /// sides without this. Blender Cycles' mesh emission is two-sided: set this for scenes
    /// exported from it.
    pub two_sided_lights: bool,
}

impl BuildOptions {
    /// Emit from both faces of every emitting surface (`true`), or as the file says (`false`,
    /// the default: one-sided, except glTF's double-sided materials).
    #[must_use]
    pub fn two_sided_lights(mut self, on: bool) -> Self {
        self.two_sided_lights = on;
        self
    }

    /// Use `camera` instead of the file's.
    #[must_use]
    pub fn camera(mut self, camera: PinholeCamera) -> Self {
        self.camera = Some(camera);
        self
    }

    /// Add an environment light.
    #[must_use]
    pub fn environment(mut self, light: BuiltinLight) -> Self {
        self.environment = Some(light);
        self
    }

    /// Sample emitting triangles by solid angle (`true`) or by area (`false`, the default).
    #[must_use]
    pub fn solid_angle_light_sampling(mut self, on: bool) -> Self {
        self.solid_angle_light_sampling = on;
        self
    }
}

impl SceneDesc {
    /// World-space bounds of all instances.
    #[must_use]
    pub fn bounds(&self) -> Bounds3 {
        let mut b = Bounds3::EMPTY;
        for inst in &self.instances {
            if let Some(mesh) = self.meshes.get(inst.mesh) {
                for p in &mesh.positions {
                    b = b.union_point(inst.transform.transform_point3(*p));
                }
            }
        }
        b
    }

    /// A camera that frames the scene's bounds: from the front (`+z`), slightly above, with a
    /// 40 degree vertical field of view ([`Self::framing_camera_with`] `+y` up and 40 degrees).
    #[must_use]
    pub fn framing_camera(&self) -> Option<PinholeCamera> {
        self.framing_camera_with(Vec3::Y, 40.0)
    }

    /// A camera that frames the scene's bounds upright along `up`, slightly above the front,
    /// with a vertical field of view of `fov_y_degrees`, at the distance where the bounds'
    /// sphere fills that field. The front is `+z` unless `up` is within about 25 degrees of the
    /// z axis, when it is `-y` (a `+z`-up model, as CAD and Blender exports often are, seen
    /// from the front as Blender's front view sees it), made perpendicular to `up`. `None` when
    /// the scene has no finite bounds, `up` is zero or not finite, or the field of view is not
    /// in (0, 180) degrees.
    ///
    /// ```
    /// use pt_scene::{SceneDesc, glam::Vec3};
    /// # fn frame(desc: &SceneDesc) {
    /// // A Z-up model, framed upright through a narrower lens than the default.
    /// let camera = desc.framing_camera_with(Vec3::Z, 25.0);
    /// # let _ = camera;
    /// # }
    /// ```
    #[must_use]
    pub fn framing_camera_with(&self, up: Vec3, fov_y_degrees: f32) -> Option<PinholeCamera> {
        let up = up.try_normalize()?;
        let front = if up.z.abs() < 0.9 { Vec3::Z } else { -Vec3::Y };
        // With `up` = +y this is +z exactly, so the default framing is unchanged bit for bit.
        let front = (front - front.dot(up) * up).normalize();
        let b = self.bounds();
        if !(b.min.is_finite() && b.max.is_finite()) || b.min.cmpgt(b.max).any() {
            return None;
        }
        let center = (b.min + b.max) * 0.5;
        // A scene a micrometre across is framed as well as a room; only a scene of one point
        // (no extent at all) gets a nominal size.
        let radius = (b.max - b.min).as_dvec3().length() as f32 * 0.5;
        let radius = if radius > 0.0 {
            radius
        } else {
            center.abs().max_element().max(1.0) * 1e-3
        };
        let fov = fov_y_degrees;
        let distance = radius / (fov.to_radians() * 0.5).sin() * 1.05;
        let from = center + (front + 0.25 * up).normalize() * distance;
        PinholeCamera::look_at(from, center, up, fov).ok()
    }

    /// Whether anything in the scene emits light: a light of the file, or an instance whose
    /// material has emission. A scene without is black unless an environment is added.
    #[must_use]
    pub fn has_lights(&self) -> bool {
        !self.lights.is_empty()
            || self.instances.iter().any(|inst| {
                self.materials
                    .get(inst.material)
                    .is_some_and(|m| !m.emission.is_black())
            })
    }

    /// The camera described by the file, if it has one and it is valid.
    #[must_use]
    pub fn file_camera(&self) -> Option<PinholeCamera> {
        self.try_file_camera().ok().flatten()
    }

    /// The camera described by the file: `Ok(None)` when it has none, an error naming the
    /// camera when it cannot be used (a field of view outside (0, 180) degrees or not a
    /// number, a transform that is not finite or scales a direction to zero).
    pub fn try_file_camera(&self) -> Result<Option<PinholeCamera>, LoadError> {
        let Some(c) = self.cameras.first() else {
            return Ok(None);
        };
        let from = c.transform.transform_point3(Vec3::ZERO);
        let forward = c.transform.transform_vector3(Vec3::NEG_Z);
        let up = c.transform.transform_vector3(Vec3::Y);
        let invalid = |why: String| LoadError::invalid(&self.source, "camera 0", why);
        if !(from.is_finite() && forward.is_finite() && up.is_finite()) {
            return Err(invalid("its node transform is not finite".into()));
        }
        PinholeCamera::look_at(from, from + forward, up, c.yfov_deg)
            .map(Some)
            .map_err(|e| {
                invalid(format!(
                    "{e} (field of view {} degrees, looking along {forward}, up {up})",
                    c.yfov_deg
                ))
            })
    }

    /// Build the scene: meshes, materials (mapped as in the module docs), objects with their
    /// emission, the camera (options, else the file's, else framing) and the environment.
    pub fn build(&self, options: &BuildOptions) -> Result<SceneBundle, LoadError> {
        let path = &self.source;
        let mut b = SceneBuilder::new();
        b.solid_angle_light_sampling(options.solid_angle_light_sampling);
        b.source(path.display().to_string());
        // Meshes drawn with a normal map (the base's or the coat's) or anisotropy need tangents; generate MikkTSpace ones
        // where the file has none, from the coordinate set of the (first) map drawn on them.
        let mut normal_map_set: Vec<Option<usize>> = vec![None; self.meshes.len()];
        for inst in &self.instances {
            // Anisotropy needs them too: its texture's set, else the first.
            let set = self
                .materials
                .get(inst.material)
                .filter(|m| m.gltf)
                .and_then(|m| {
                    m.normal_texture
                        .as_ref()
                        .or(m.clearcoat_normal_texture.as_ref())
                        .map(|t| t.uv_set)
                        .or_else(|| {
                            (m.anisotropy_strength > 0.0)
                                .then(|| m.anisotropy_texture.as_ref().map_or(0, |t| t.uv_set))
                        })
                });
            if let (Some(slot), Some(set)) = (normal_map_set.get_mut(inst.mesh), set) {
                slot.get_or_insert(set);
            }
        }
        let mut mesh_ids = Vec::with_capacity(self.meshes.len());
        for (i, m) in self.meshes.iter().enumerate() {
            let element = || {
                if m.name.is_empty() {
                    format!("mesh {i}")
                } else {
                    format!("mesh {i} ({})", m.name)
                }
            };
            let generated;
            let m = match normal_map_set[i] {
                Some(set) if m.tangents.is_empty() => {
                    let mut copy = m.clone();
                    if !tangents::generate_tangents(&mut copy, set) {
                        log::warn!(
                            "{}: {}: a normal map or anisotropy is drawn on it, but it has no TEXCOORD_{set} \
                             to derive tangents from; the map is not applied",
                            path.display(),
                            element()
                        );
                    }
                    generated = copy;
                    &generated
                }
                _ => m,
            };
            mesh_ids.push(
                b.add_mesh(
                    m.to_mesh()
                        .map_err(|e| LoadError::invalid(path, element(), e))?,
                ),
            );
        }
        // A glTF material drawn on a mesh with vertex colours multiplies them in: one built-in
        // material per (material, colours) pair used.
        let has_colors: Vec<bool> = self.meshes.iter().map(|m| !m.colors.is_empty()).collect();
        let mut material_ids = Vec::with_capacity(self.materials.len());
        let mut colored_ids: HashMap<usize, pt_core::MaterialId> = HashMap::new();
        for (i, m) in self.materials.iter().enumerate() {
            let material = m.to_material_with(&self.textures).map_err(|e| {
                LoadError::invalid(path, format!("material {i} ({})", m.name), e.to_string())
            })?;
            material_ids.push(b.add_material(material));
        }
        for inst in &self.instances {
            let (Some(m), Some(true)) = (
                self.materials.get(inst.material),
                has_colors.get(inst.mesh).copied(),
            ) else {
                continue;
            };
            if m.gltf && !colored_ids.contains_key(&inst.material) {
                let material = m.to_material_on(&self.textures, true).map_err(|e| {
                    LoadError::invalid(
                        path,
                        format!("material {} ({})", inst.material, m.name),
                        e.to_string(),
                    )
                })?;
                colored_ids.insert(inst.material, b.add_material(material));
            }
        }
        let default_material = b.add_material(BuiltinMaterial::diffuse(Rgb::splat(0.8)));
        for (i, inst) in self.instances.iter().enumerate() {
            let mesh = *mesh_ids.get(inst.mesh).ok_or_else(|| {
                LoadError::invalid(path, format!("instance {i}"), "mesh index out of range")
            })?;
            let (material, emission) = match self.materials.get(inst.material) {
                Some(m) => {
                    let colored = has_colors.get(inst.mesh).copied().unwrap_or(false);
                    let id = match colored_ids.get(&inst.material) {
                        Some(&id) if colored => id,
                        _ => material_ids[inst.material],
                    };
                    (id, m)
                }
                None => (default_material, &MaterialDesc::default()),
            };
            // The loaders check raw vertices against MAX_COORDINATE; a node transform can
            // still carry them beyond it (a translation of 1e20), where the object would vanish.
            if let Some(m) = self.meshes.get(inst.mesh) {
                let limit = pt_core::pt_accel::MAX_COORDINATE;
                if let Some(p) = m
                    .positions
                    .iter()
                    .map(|&p| inst.transform.transform_point3(p))
                    .find(|p| !(p.is_finite() && p.abs().max_element() <= limit))
                {
                    return Err(LoadError::invalid(
                        path,
                        format!("instance {i} of mesh {} ({})", inst.mesh, m.name),
                        format!(
                            "its transform places a vertex at {p}, beyond +-{limit:e}, the largest \
                             coordinate pt can trace"
                        ),
                    ));
                }
            }
            let mut object = Object::new(mesh, material).with_transform(inst.transform);
            if !emission.emission.is_black() {
                let mut e = Emission::new(emission.emission);
                if emission.two_sided_emission || options.two_sided_lights {
                    e = e.two_sided();
                }
                if let Some(t) = emission
                    .emissive_texture
                    .and_then(|t| t.resolve(&self.textures))
                {
                    e = e.with_texture(t);
                }
                object = object.with_emission(e);
            }
            b.add_object(object);
        }
        for (i, l) in self.lights.iter().enumerate() {
            let light: Result<BuiltinLight, pt_core::LightError> = match *l {
                LightDesc::Point {
                    position,
                    intensity,
                } => PointLight::new(position, intensity).map(Into::into),
                LightDesc::Spot {
                    position,
                    direction,
                    intensity,
                    inner_angle,
                    outer_angle,
                } => SpotLight::new(position, direction, intensity, inner_angle, outer_angle)
                    .map(Into::into),
                LightDesc::Directional {
                    direction,
                    irradiance,
                } => DirectionalLight::new(direction, irradiance).map(Into::into),
            };
            let light =
                light.map_err(|e| LoadError::invalid(path, format!("light {i}"), e.to_string()))?;
            b.add_light(light);
        }
        if let Some(env) = &options.environment {
            b.add_light(env.clone());
        }
        let scene = b
            .build()
            .map_err(|e| LoadError::invalid(path, "scene", e.to_string()))?;
        let file_camera = match options.camera {
            Some(_) => None,
            None => self.try_file_camera().unwrap_or_else(|e| {
                log::warn!("{e}; using a camera that frames the scene");
                None
            }),
        };
        let camera = options
            .camera
            .or(file_camera)
            .or_else(|| self.framing_camera())
            .unwrap_or_else(|| {
                PinholeCamera::look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 40.0)
                    .expect("a valid default camera")
            });
        Ok(SceneBundle { scene, camera })
    }
}
