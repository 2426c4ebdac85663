//! Building a [`Scene`]: validation, area lights from emissive objects, the accelerator.

use std::fmt;

use glam::{Affine3A, Vec3};
use pt_accel::{Accel, AccelKind, AccelOptions, BuildQuality, Instance, MeshError};

use crate::light::BuiltinLight;
use crate::light::{Light, PowerLightSampler, TriangleLight};
use crate::material::{BuiltinMaterial, Material};
use crate::scene::{
    MaterialId, Mesh, MeshId, NO_LIGHT, Object, ObjectData, Scene, SceneFeatures, SceneStats,
};

/// Why a scene could not be built.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum SceneError {
    /// An object refers to a mesh that was not added.
    MeshOutOfRange {
        /// Object index.
        object: usize,
        /// The mesh it names.
        mesh: u32,
    },
    /// An object refers to a material that was not added.
    MaterialOutOfRange {
        /// Object index.
        object: usize,
        /// The material it names.
        material: u32,
    },
    /// An object's transform is not finite or not invertible.
    InvalidTransform {
        /// Object index.
        object: usize,
    },
    /// An object's emitted radiance is negative or not finite.
    InvalidEmission {
        /// Object index.
        object: usize,
    },
    /// A per-vertex attribute has the wrong number of entries.
    AttributeCount {
        /// Which attribute.
        attribute: &'static str,
        /// One per vertex.
        expected: usize,
        /// What was given.
        actual: usize,
    },
    /// A per-vertex attribute holds a NaN or infinite value.
    NonFiniteAttribute {
        /// Which attribute.
        attribute: &'static str,
        /// The first vertex with a non-finite value.
        vertex: usize,
    },
    /// A mesh is malformed.
    Mesh(MeshError),
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::MeshOutOfRange { object, mesh } => {
                write!(f, "object {object} uses mesh {mesh}, which does not exist")
            }
            Self::MaterialOutOfRange { object, material } => {
                write!(
                    f,
                    "object {object} uses material {material}, which does not exist"
                )
            }
            Self::InvalidTransform { object } => {
                write!(
                    f,
                    "object {object} has a transform that is not finite or not invertible"
                )
            }
            Self::InvalidEmission { object } => {
                write!(
                    f,
                    "object {object} has emitted radiance that is negative or not finite"
                )
            }
            Self::AttributeCount {
                attribute,
                expected,
                actual,
            } => write!(
                f,
                "mesh has {actual} {attribute}, expected one per vertex ({expected})"
            ),
            Self::NonFiniteAttribute { attribute, vertex } => write!(
                f,
                "mesh {attribute} of vertex {vertex} are not finite (NaN or infinite)"
            ),
            Self::Mesh(e) => write!(f, "invalid mesh: {e}"),
        }
    }
}

impl std::error::Error for SceneError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Self::Mesh(e) => Some(e),
            _ => None,
        }
    }
}

impl From<MeshError> for SceneError {
    fn from(e: MeshError) -> Self {
        Self::Mesh(e)
    }
}

/// Collects meshes, materials, objects and lights, then validates them and builds a [`Scene`].
///
/// ```
/// use pt_core::{BuiltinMaterial, Emission, Mesh, Object, Rgb, Scene, SceneBuilder};
/// use pt_core::pt_accel::TriangleMesh;
/// use pt_core::glam::Vec3;
///
/// let mut b = SceneBuilder::new();
/// let quad = b.add_mesh(Mesh::new(TriangleMesh::new(
///     vec![Vec3::new(-1.0, 0.0, -1.0), Vec3::new(1.0, 0.0, -1.0), Vec3::new(1.0, 0.0, 1.0), Vec3::new(-1.0, 0.0, 1.0)],
///     vec![[0, 2, 1], [0, 3, 2]],
/// )?));
/// let white = b.add_material(BuiltinMaterial::diffuse(Rgb::splat(0.8)));
/// b.add_object(Object::new(quad, white));
/// let light = Object::new(quad, white)
///     .with_transform(pt_core::glam::Affine3A::from_translation(Vec3::Y * 2.0))
///     .with_emission(Emission::new(Rgb::splat(5.0)).two_sided());
/// b.add_object(light);
/// let scene: Scene = b.build()?;
/// assert_eq!(scene.lights().len(), 2);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Debug)]
pub struct SceneBuilder<M = BuiltinMaterial, L = BuiltinLight> {
    meshes: Vec<Mesh>,
    materials: Vec<M>,
    objects: Vec<Object>,
    lights: Vec<L>,
    accel: AccelOptions,
    solid_angle_lights: bool,
    source: Option<String>,
}

impl<M, L> Default for SceneBuilder<M, L> {
    fn default() -> Self {
        Self {
            meshes: Vec::new(),
            materials: Vec::new(),
            objects: Vec::new(),
            lights: Vec::new(),
            accel: AccelOptions::default(),
            solid_angle_lights: false,
            source: None,
        }
    }
}

impl SceneBuilder {
    /// An empty builder for the built-in materials and lights. For user material or light
    /// enums, use `SceneBuilder::<MyMaterial, MyLight>::default()`.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }
}

/// `L` is the scene's light type: [`BuiltinLight`], or a user enum made with
/// [`light_enum!`](crate::light_enum) that holds the built-in lights as one variant (emitting
/// objects become `BuiltinLight` area lights, converted into `L`).
impl<M: Material, L: Light + From<BuiltinLight>> SceneBuilder<M, L> {
    /// Add a mesh; place it with [`add_object`](Self::add_object), as often as needed.
    pub fn add_mesh(&mut self, mesh: impl Into<Mesh>) -> MeshId {
        self.meshes.push(mesh.into());
        MeshId(self.meshes.len() as u32 - 1)
    }

    /// Add a material.
    pub fn add_material(&mut self, material: impl Into<M>) -> MaterialId {
        self.materials.push(material.into());
        MaterialId(self.materials.len() as u32 - 1)
    }

    /// Place a mesh in the scene. Objects that emit become one area light per triangle.
    pub fn add_object(&mut self, object: Object) -> &mut Self {
        self.objects.push(object);
        self
    }

    /// Apply `transform` after the transform of every object added so far: moves, turns or
    /// scales the geometry (and its area lights) as one. Lights added with
    /// [`add_light`](Self::add_light) are not surfaces and are left as they are. Used to place
    /// a whole scene, and by the stress tests to scale and translate one.
    pub fn transform_objects(&mut self, transform: Affine3A) -> &mut Self {
        for o in &mut self.objects {
            o.transform = transform * o.transform;
        }
        self
    }

    /// Add a light that is not a surface (point, spot, directional or environment lights).
    pub fn add_light(&mut self, light: impl Into<L>) -> &mut Self {
        self.lights.push(light.into());
        self
    }

    /// Choose the accelerator (default: [`AccelKind::Auto`]).
    pub fn accel(&mut self, kind: AccelKind) -> &mut Self {
        self.accel.kind = kind;
        self
    }

    /// Choose the BVH build effort (default: [`BuildQuality::Medium`]).
    pub fn build_quality(&mut self, quality: BuildQuality) -> &mut Self {
        self.accel.quality = quality;
        self
    }

    /// Set all accelerator options at once.
    pub fn accel_options(&mut self, options: AccelOptions) -> &mut Self {
        self.accel = options;
        self
    }

    /// Sample the area lights of emitting objects by solid angle (`true`) or by area (`false`,
    /// the default); see [`TriangleLight::with_solid_angle_sampling`] for when it pays.
    pub fn solid_angle_light_sampling(&mut self, on: bool) -> &mut Self {
        self.solid_angle_lights = on;
        self
    }

    /// Name what this scene comes from (a file's path, say): the warnings of [`build`](Self::build)
    /// start with it.
    pub fn source(&mut self, name: impl Into<String>) -> &mut Self {
        self.source = Some(name.into());
        self
    }

    /// Validate everything, create the area lights and build the accelerator.
    pub fn build(self) -> Result<Scene<M, L>, SceneError> {
        let Self {
            meshes,
            materials,
            objects,
            mut lights,
            accel,
            solid_angle_lights,
            source,
        } = self;

        let mut data = Vec::with_capacity(objects.len());
        let mut instances = Vec::with_capacity(objects.len());
        let mut skipped_emitters = 0;
        let mut instanced_triangles = 0;
        for (i, obj) in objects.iter().enumerate() {
            let mesh = meshes
                .get(obj.mesh.0 as usize)
                .ok_or(SceneError::MeshOutOfRange {
                    object: i,
                    mesh: obj.mesh.0,
                })?;
            if obj.material.0 as usize >= materials.len() {
                return Err(SceneError::MaterialOutOfRange {
                    object: i,
                    material: obj.material.0,
                });
            }
            let m = obj.transform;
            let det = m.matrix3.determinant();
            if !m.is_finite() || det == 0.0 || !det.is_finite() {
                return Err(SceneError::InvalidTransform { object: i });
            }
            let transform = (m != Affine3A::IDENTITY).then(|| (m, m.matrix3.inverse().transpose()));
            instanced_triangles += mesh.geometry().triangle_count();

            let object_lights = match &obj.emission {
                None => None,
                Some(e) if !e.radiance.is_valid_nonnegative() => {
                    return Err(SceneError::InvalidEmission { object: i });
                }
                Some(e) if e.radiance.is_black() => None,
                Some(e) => {
                    let (map, skipped) =
                        emissive_triangles(mesh, &m, e, solid_angle_lights, &mut lights);
                    skipped_emitters += skipped;
                    Some(map)
                }
            };
            data.push(ObjectData {
                mesh: obj.mesh.0,
                material: obj.material.0,
                transform,
                lights: object_lights,
            });
            instances.push(Instance::with_transform(obj.mesh.0, m));
        }
        let from = source
            .as_deref()
            .map_or(String::new(), |s| format!("{s}: "));
        if skipped_emitters > 0 {
            log::warn!(
                "{from}{skipped_emitters} emitting triangles have zero area or non-finite corners and emit nothing"
            );
        }

        let accel = Accel::build(&meshes, &instances, &accel);
        if accel.stats().skipped_triangles > 0 {
            log::warn!(
                "{from}{} of {} triangles are degenerate or not finite and were left out",
                accel.stats().skipped_triangles,
                accel.stats().input_triangles
            );
        }
        let bounds = accel.bounds();
        for light in &mut lights {
            light.preprocess(&bounds);
        }
        let light_sampler = PowerLightSampler::new(&lights);
        let infinite_lights: Vec<u32> = lights
            .iter()
            .enumerate()
            .filter(|(_, l)| l.flags().is_infinite())
            .map(|(i, _)| i as u32)
            .collect();
        let stats = SceneStats {
            objects: objects.len(),
            meshes: meshes.len(),
            unique_triangles: meshes.iter().map(|m| m.geometry().triangle_count()).sum(),
            instanced_triangles,
            lights: lights.len(),
            skipped_emitters,
            accel: accel.stats().clone(),
        };
        let features = SceneFeatures {
            light_sampling: !light_sampler.is_empty(),
            environment: !infinite_lights.is_empty(),
            non_delta_materials: materials.iter().any(|m| m.properties().non_delta),
            texture_coordinates: materials.iter().any(|m| m.properties().reads_uv),
        };
        Ok(Scene {
            accel,
            meshes,
            objects: data,
            materials,
            lights,
            light_sampler,
            infinite_lights,
            stats,
            features,
        })
    }
}

/// Create one area light per valid triangle of an emitting object; returns the per-triangle
/// light indices and the number of triangles that could not emit.
fn emissive_triangles<L: From<BuiltinLight>>(
    mesh: &Mesh,
    m: &Affine3A,
    emission: &crate::scene::Emission,
    solid_angle: bool,
    lights: &mut Vec<L>,
) -> (Box<[u32]>, usize) {
    let (two_sided, base) = (emission.two_sided, emission.radiance);
    let geometry = mesh.geometry();
    // The radiance of triangle `idx`: constant, or the emissive texture's mean over its texture
    // coordinates (the centroids of the 10 upward cells of a 4x4 subdivision of the triangle).
    let radiance_of = |idx: &[u32; 3]| match (&emission.texture, mesh.uvs()) {
        (Some(tex), Some(uvs)) => {
            let t = idx.map(|i| uvs[i as usize]);
            let n = 4;
            let mut sum = crate::color::Rgb::BLACK;
            let mut count = 0.0f32;
            for a in 0..n {
                for b in 0..n - a {
                    // Upward sub-triangle centroid of the (a, b) cell.
                    let (u, v) = (
                        (a as f32 + 1.0 / 3.0) / n as f32,
                        (b as f32 + 1.0 / 3.0) / n as f32,
                    );
                    let uv = t[0] * (1.0 - u - v) + t[1] * u + t[2] * v;
                    sum += tex.eval(uv);
                    count += 1.0;
                }
            }
            base * (sum / count)
        }
        _ => base,
    };
    // Transform each vertex exactly as the accelerator does, so the light's triangle is
    // bit-identical to the one rays hit.
    let world: Vec<Vec3> = geometry
        .positions()
        .iter()
        .map(|&p| m.transform_point3(p))
        .collect();
    let normals_world: Option<Vec<Vec3>> = mesh.normals().map(|ns| {
        let nm = m.matrix3.inverse().transpose();
        ns.iter()
            .map(|&n| Vec3::from(nm * glam::Vec3A::from(n)))
            .collect()
    });
    let mut skipped = 0;
    let map = geometry
        .indices()
        .iter()
        .map(|idx| {
            let mut p = idx.map(|i| world[i as usize]);
            // With vertex normals, the front face is the side they point to.
            if let Some(ns) = &normals_world {
                let n_avg: Vec3 = idx.iter().map(|&i| ns[i as usize]).sum();
                if pt_accel::triangle_cross(&p).dot(n_avg.as_dvec3()) < 0.0 {
                    p.swap(1, 2);
                }
            }
            let radiance = radiance_of(idx);
            if radiance.is_black() {
                return NO_LIGHT;
            }
            match TriangleLight::new(p, radiance, two_sided) {
                Some(tl) => {
                    let tl = tl.with_solid_angle_sampling(solid_angle);
                    lights.push(L::from(BuiltinLight::from(tl)));
                    lights.len() as u32 - 1
                }
                None => {
                    skipped += 1;
                    NO_LIGHT
                }
            }
        })
        .collect();
    (map, skipped)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::color::Rgb;
    use crate::scene::Emission;
    use pt_accel::TriangleMesh;

    fn quad() -> Mesh {
        Mesh::new(
            TriangleMesh::new(
                vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y],
                vec![[0, 1, 2], [0, 2, 3]],
            )
            .unwrap(),
        )
    }

    #[test]
    fn validation_errors_name_the_object() {
        let mut b: SceneBuilder = SceneBuilder::new();
        let m = b.add_mesh(quad());
        let mat = b.add_material(BuiltinMaterial::diffuse(Rgb::WHITE));
        b.add_object(Object::new(m, MaterialId(3)));
        assert_eq!(
            b.build().unwrap_err(),
            SceneError::MaterialOutOfRange {
                object: 0,
                material: 3
            }
        );

        let mut b: SceneBuilder = SceneBuilder::new();
        let m = b.add_mesh(quad());
        let mat2 = b.add_material(BuiltinMaterial::diffuse(Rgb::WHITE));
        b.add_object(
            Object::new(m, mat2).with_transform(Affine3A::from_scale(Vec3::new(1.0, 0.0, 1.0))),
        );
        assert_eq!(
            b.build().unwrap_err(),
            SceneError::InvalidTransform { object: 0 }
        );

        let mut b: SceneBuilder = SceneBuilder::new();
        let m = b.add_mesh(quad());
        let _ = b.add_material(BuiltinMaterial::diffuse(Rgb::WHITE));
        b.add_object(Object::new(m, mat).with_emission(Emission::new(Rgb::splat(f32::NAN))));
        assert_eq!(
            b.build().unwrap_err(),
            SceneError::InvalidEmission { object: 0 }
        );

        let mut b: SceneBuilder = SceneBuilder::new();
        let _ = b.add_material(BuiltinMaterial::diffuse(Rgb::WHITE));
        b.add_object(Object::new(MeshId(0), mat));
        assert!(b.build().unwrap_err().to_string().contains("mesh 0"));
    }

    #[test]
    fn emissive_objects_become_lights_and_zero_area_triangles_are_skipped() {
        let mut b: SceneBuilder = SceneBuilder::new();
        let mesh = Mesh::new(
            TriangleMesh::new(
                vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::X * 2.0],
                vec![[0, 1, 2], [0, 1, 3]],
            )
            .unwrap(),
        );
        let m = b.add_mesh(mesh);
        let mat = b.add_material(BuiltinMaterial::diffuse(Rgb::WHITE));
        b.add_object(Object::new(m, mat).with_emission(Emission::new(Rgb::splat(1.0))));
        let s = b.build().unwrap();
        assert_eq!(s.lights().len(), 1);
        assert_eq!(s.stats().skipped_emitters, 1);
        assert_eq!(s.stats().accel.skipped_triangles, 1);
        // A ray hitting the valid triangle reports its light.
        let hit = s
            .intersect(&pt_accel::Ray::new(Vec3::new(0.2, 0.2, 1.0), -Vec3::Z))
            .unwrap();
        assert_eq!(hit.light, Some(0));
    }

    #[test]
    fn emissive_textures_give_each_triangle_its_mean() {
        // Texture: left half red, right half blue. Triangle A's texture coordinates lie in the
        // left half, triangle B's in the right half.
        let mut img = crate::image::Image::new(4, 1);
        for x in 0..4 {
            let c = if x < 2 {
                Rgb::new(1.0, 0.0, 0.0)
            } else {
                Rgb::new(0.0, 0.0, 1.0)
            };
            img.set(x, 0, c);
        }
        let tex = std::sync::Arc::new(crate::texture::Texture::new(img));
        let p = vec![
            Vec3::ZERO,
            Vec3::X,
            Vec3::Y,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(3.0, 0.0, 0.0),
            Vec3::new(2.0, 1.0, 0.0),
        ];
        // Away from the colour boundary and from the wrap-around, where bilinear filtering mixes.
        let uv = vec![
            glam::Vec2::new(0.15, 0.1),
            glam::Vec2::new(0.35, 0.1),
            glam::Vec2::new(0.15, 0.9),
            glam::Vec2::new(0.65, 0.1),
            glam::Vec2::new(0.85, 0.1),
            glam::Vec2::new(0.65, 0.9),
        ];
        let mesh = Mesh::new(TriangleMesh::new(p, vec![[0, 1, 2], [3, 4, 5]]).unwrap())
            .with_uvs(uv)
            .unwrap();
        let mut b: SceneBuilder = SceneBuilder::new();
        let m = b.add_mesh(mesh);
        let mat = b.add_material(BuiltinMaterial::diffuse(Rgb::WHITE));
        b.add_object(
            Object::new(m, mat).with_emission(Emission::new(Rgb::splat(2.0)).with_texture(tex)),
        );
        let s = b.build().unwrap();
        assert_eq!(s.lights().len(), 2);
        let radiance = |i: usize| match &s.lights()[i] {
            BuiltinLight::Triangle(t) => t.radiance(),
            other => panic!("{other:?}"),
        };
        let (a, c) = (radiance(0), radiance(1));
        assert!(a.r > 1.5 && a.b < 0.5, "left triangle is red: {a:?}");
        assert!(c.b > 1.5 && c.r < 0.5, "right triangle is blue: {c:?}");
    }
}
