//! Building a [`Scene`]: validation, area lights from emissive objects, the accelerator.

use glam::{Affine3A, Vec3};
use pt_accel::{Accel, AccelKind, AccelOptions, BuildQuality, Instance};

use crate::interaction::edge_scale2;
use crate::light::{BuiltinLight, Light, PowerLightSampler};
use crate::material::{BuiltinMaterial, Material};
use crate::scene::emitters::emissive_triangles;
use crate::scene::{
    MaterialId, Mesh, MeshId, Object, ObjectData, Scene, SceneError, SceneFeatures, SceneStats,
    SurfaceFilter, TriangleRecord,
};

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
    /// the default); see [`TriangleLight::with_solid_angle_sampling`](crate::TriangleLight::with_solid_angle_sampling) for when it pays.
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
        let mut cell_budget = super::emitters::TEXTURED_LIGHT_CELLS;
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
                    let (map, skipped) = emissive_triangles(
                        mesh,
                        &m,
                        e,
                        solid_angle_lights,
                        &mut cell_budget,
                        &mut lights,
                    );
                    skipped_emitters += skipped;
                    Some(map)
                }
            };
            // A bound on the inverse transform's norm, squared (Frobenius, rounded up), for
            // `near_edge`: how much the transform can shrink a triangle's altitudes.
            let edge_scale2 = transform.as_ref().map_or(1.0, |(_, nm)| edge_scale2(nm));
            data.push(ObjectData {
                mesh: obj.mesh.0,
                material: obj.material.0,
                transform,
                edge_scale2,
                lane_flat: transform.is_none()
                    && object_lights.is_none()
                    && mesh.normals().is_none(),
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

        // Per-triangle unit normals of the meshes some object places untransformed (world space
        // is object space): a hit reads its normal instead of computing it (a cross product,
        // square root and division in f64, on the critical path of every hit); the values are
        // bit for bit those `face_normal` computes.
        let mut face_normals: Vec<Box<[Vec3]>> = vec![Box::default(); meshes.len()];
        for d in &data {
            let normals = &mut face_normals[d.mesh as usize];
            if d.transform.is_none() && normals.is_empty() {
                let g = meshes[d.mesh as usize].geometry();
                let positions = g.positions();
                *normals = g
                    .indices()
                    .iter()
                    .map(|&[a, b, c]| {
                        super::face_normal([
                            positions[a as usize],
                            positions[b as usize],
                            positions[c as usize],
                        ])
                    })
                    .collect();
            }
        }

        // The same triangles as records of corners and normal, for the meshes the lane tracer
        // finishes in lanes (`Scene::lane_corners`).
        let mut flat_triangles: Vec<Box<[TriangleRecord]>> = vec![Box::default(); meshes.len()];
        for d in data.iter().filter(|d| d.lane_flat) {
            let m = d.mesh as usize;
            if flat_triangles[m].is_empty() {
                let g = meshes[m].geometry();
                let positions = g.positions();
                flat_triangles[m] = g
                    .indices()
                    .iter()
                    .zip(&face_normals[m])
                    .map(|(&[a, b, c], &n)| {
                        let p = [a, b, c].map(|i| positions[i as usize]);
                        TriangleRecord::new(p, n, [0.0; 4])
                    })
                    .collect();
            }
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
            vertex_attributes: materials.iter().any(|m| m.properties().reads_attributes),
            normal_maps: materials.iter().any(|m| m.properties().normal_map),
            surface_filters: false,
            absorbing_media: materials.iter().any(|m| m.absorption().is_some()),
        };
        let filters: Box<[SurfaceFilter]> = materials
            .iter()
            .map(|m| SurfaceFilter {
                single_sided: m.single_sided(),
                coverage: m.properties().coverage,
            })
            .collect();
        let features = SceneFeatures {
            surface_filters: filters.iter().any(|f| *f != SurfaceFilter::default()),
            ..features
        };
        Ok(Scene {
            accel,
            meshes,
            face_normals,
            flat_triangles,
            objects: data,
            materials,
            lights,
            light_sampler,
            infinite_lights,
            stats,
            features,
            filters,
        })
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;
    use pt_accel::TriangleMesh;

    use super::*;
    use crate::color::Rgb;
    use crate::scene::Emission;

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

    /// Vertex colours, a second coordinate set and tangents reach the hit when a material reads
    /// them, are placed by the instance transform (a mirror flips the tangent's handedness), and
    /// stay at their defaults when no material does.
    #[test]
    fn vertex_attributes_are_interpolated_for_materials_that_read_them() {
        use glam::{Vec2, Vec4};
        use pt_accel::Ray;
        let mesh = || {
            quad()
                .with_colors(vec![Vec4::new(1.0, 0.0, 0.0, 1.0); 4])
                .unwrap()
                .with_uv_set(1, vec![Vec2::splat(0.25); 4])
                .unwrap()
                .with_tangents(vec![Vec4::new(2.0, 0.0, 0.0, 1.0); 4])
                .unwrap()
        };
        let reads = crate::PbrMaterial {
            vertex_colors: true,
            ..crate::PbrMaterial::default()
        };
        let down = Ray::new(Vec3::new(0.5, 0.25, 1.0), -Vec3::Z);
        for (material, mirror) in [
            (BuiltinMaterial::from(reads.clone()), false),
            (reads.into(), true),
            (BuiltinMaterial::diffuse(Rgb::WHITE), false),
        ] {
            let mut b: SceneBuilder = SceneBuilder::new();
            let m = b.add_mesh(mesh());
            let mat = b.add_material(material);
            let mut object = Object::new(m, mat);
            let mut ray = down;
            if mirror {
                object = object.with_transform(Affine3A::from_scale(Vec3::new(-1.0, 1.0, 1.0)));
                ray.origin.x = -0.5;
            }
            b.add_object(object);
            // A second object, so instances are transformed per hit rather than baked.
            let other = b.add_mesh(quad());
            b.add_object(
                Object::new(other, mat).with_transform(Affine3A::from_translation(Vec3::Z * -5.0)),
            );
            let scene = b.build().unwrap();
            let a = scene.intersect(&ray).unwrap().attributes;
            if !scene.features().vertex_attributes {
                assert_eq!(a, crate::SurfaceAttributes::default());
                continue;
            }
            assert_eq!(a.color, Vec4::new(1.0, 0.0, 0.0, 1.0));
            assert_eq!(a.uv[1], Vec2::splat(0.25));
            let (t, w) = (a.tangent.truncate(), a.tangent.w);
            if mirror {
                assert!((t + Vec3::X).length() < 1e-6 && w == -1.0, "{}", a.tangent);
            } else {
                assert!((t - Vec3::X).length() < 1e-6 && w == 1.0, "{}", a.tangent);
            }
        }
        // A set beyond the supported ones is an error.
        assert!(matches!(
            quad().with_uv_set(crate::MAX_UV_SETS, vec![Vec2::ZERO; 4]),
            Err(SceneError::UvSet { .. })
        ));
    }
}
