//! The walk over a glTF scene's node graph: world transforms, and the cameras, punctual lights
//! and mesh instances the nodes carry.

use std::collections::HashMap;
use std::path::Path;

use glam::{Affine3A, Mat4, Vec3};
use pt_core::Rgb;

use crate::desc::{CameraDesc, InstanceDesc, LightDesc, SceneDesc};
use crate::error::LoadError;
use crate::gltf::primitive::read_primitive;
use crate::limits::Limits;

/// The state of one walk: what has been read, and the counts the limits bound.
pub(super) struct NodeWalk<'a> {
    doc: &'a ::gltf::Document,
    buffers: &'a [::gltf::buffer::Data],
    path: &'a Path,
    limits: &'a Limits,
    /// The material of primitives that name none (the specification's default).
    default_material: usize,
    /// Per mesh and primitive, the geometry and material it was read as (None: not yet).
    geometry: Vec<Vec<Option<(usize, usize)>>>,
    /// One geometry per distinct set of accessors (POSITION, indices, NORMAL, TEXCOORD_0):
    /// primitives often share them and differ only in material.
    by_accessors: HashMap<[Option<usize>; 9], usize>,
    /// Nodes placed so far (shared subtrees count once per placement).
    visited: u64,
    /// Triangles read so far.
    triangles: u64,
}

/// A step of the depth-first walk: enter a node under its parent's world transform, or leave
/// one (it is then no longer on the current path).
enum Step<'a> {
    Enter(::gltf::Node<'a>, Affine3A),
    Leave(usize),
}

impl<'a> NodeWalk<'a> {
    pub(super) fn new(
        doc: &'a ::gltf::Document,
        buffers: &'a [::gltf::buffer::Data],
        path: &'a Path,
        limits: &'a Limits,
        default_material: usize,
    ) -> Self {
        Self {
            doc,
            buffers,
            path,
            limits,
            default_material,
            geometry: doc
                .meshes()
                .map(|m| vec![None; m.primitives().len()])
                .collect(),
            by_accessors: HashMap::new(),
            visited: 0,
            triangles: 0,
        }
    }

    /// Walk `scene` depth first into `desc`. A node on the current path met again is a cycle
    /// (the spec requires a forest; a node listing itself among its children is the smallest
    /// case); shared subtrees are allowed but every placement counts toward `max_instances`, so
    /// a graph that places exponentially many instances is refused early.
    pub(super) fn walk(
        mut self,
        scene: &::gltf::Scene<'a>,
        desc: &mut SceneDesc,
    ) -> Result<(), LoadError> {
        let mut on_path = vec![false; self.doc.nodes().len()];
        let mut stack: Vec<Step<'a>> = scene
            .nodes()
            .map(|n| Step::Enter(n, Affine3A::IDENTITY))
            .collect();
        while let Some(step) = stack.pop() {
            let (node, parent) = match step {
                Step::Enter(node, parent) => (node, parent),
                Step::Leave(i) => {
                    on_path[i] = false;
                    continue;
                }
            };
            if on_path[node.index()] {
                return Err(LoadError::invalid(
                    self.path,
                    format!("node {}", node.index()),
                    "the node graph is cyclic: this node is its own ancestor",
                ));
            }
            let world = self.visit(&node, parent, desc)?;
            on_path[node.index()] = true;
            stack.push(Step::Leave(node.index()));
            for child in node.children() {
                stack.push(Step::Enter(child, world));
            }
        }
        Ok(())
    }

    /// Place one node: its camera, light and mesh under its world transform, which is returned.
    fn visit(
        &mut self,
        node: &::gltf::Node<'a>,
        parent: Affine3A,
        desc: &mut SceneDesc,
    ) -> Result<Affine3A, LoadError> {
        let path = self.path;
        self.visited += 1;
        Limits::check(
            path,
            "nodes",
            "max_instances",
            self.visited,
            self.limits.max_instances as u64,
        )?;
        let local = Mat4::from_cols_array_2d(&node.transform().matrix());
        if !local.is_finite() {
            return Err(LoadError::invalid(
                path,
                format!("node {}", node.index()),
                "transform is not finite",
            ));
        }
        let world = parent * Affine3A::from_mat4(local);
        if let Some(camera) = node.camera()
            && let ::gltf::camera::Projection::Perspective(p) = camera.projection()
        {
            desc.cameras.push(CameraDesc {
                transform: world,
                yfov_deg: p.yfov().to_degrees(),
            });
        }
        if let Some(light) = node.light() {
            desc.lights.push(light_desc(&light, world));
            if light.range().is_some() {
                log::warn!(
                    "{}: light {} has a range; pt ignores it (inverse-square falloff only)",
                    path.display(),
                    light.index()
                );
            }
        }
        if let Some(mesh) = node.mesh() {
            // EXT_mesh_gpu_instancing: the mesh placed once per instance, each under its own
            // transform inside the node's.
            let placements = match self.gpu_instances(node)? {
                Some(local) => local.into_iter().map(|m| world * m).collect(),
                None => vec![world],
            };
            for prim in mesh.primitives() {
                if let Some((mesh_index, material)) = self.primitive(&mesh, &prim, desc)? {
                    for &transform in &placements {
                        desc.instances.push(InstanceDesc {
                            mesh: mesh_index,
                            material,
                            transform,
                        });
                    }
                }
            }
        }
        Ok(world)
    }

    /// The instance transforms of `node`'s `EXT_mesh_gpu_instancing` (translation, rotation
    /// and scale accessors of equal counts; rotations as float or normalised signed
    /// integers), if it has the extension. Every instance counts toward `max_instances`.
    fn gpu_instances(
        &mut self,
        node: &::gltf::Node<'a>,
    ) -> Result<Option<Vec<Affine3A>>, LoadError> {
        use ::gltf::accessor::{DataType, Dimensions};
        let Some(ext) = node.extension_value("EXT_mesh_gpu_instancing") else {
            return Ok(None);
        };
        let path = self.path;
        let element = format!("node {}, EXT_mesh_gpu_instancing", node.index());
        let attributes = ext.get("attributes");
        let accessor = |name: &str| -> Result<Option<::gltf::Accessor<'a>>, LoadError> {
            let Some(v) = attributes.and_then(|a| a.get(name)) else {
                return Ok(None);
            };
            v.as_u64()
                .and_then(|i| self.doc.accessors().nth(usize::try_from(i).ok()?))
                .map(Some)
                .ok_or_else(|| {
                    LoadError::invalid(path, element.clone(), format!("{name} names no accessor"))
                })
        };
        let (t, r, s) = (
            accessor("TRANSLATION")?,
            accessor("ROTATION")?,
            accessor("SCALE")?,
        );
        let counts: Vec<usize> = [&t, &r, &s]
            .iter()
            .filter_map(|a| a.as_ref())
            .map(|a| a.count())
            .collect();
        let Some(&count) = counts.first() else {
            return Ok(None);
        };
        if counts.iter().any(|&c| c != count) {
            return Err(LoadError::invalid(
                path,
                element,
                "its accessors' counts differ",
            ));
        }
        self.visited += count as u64;
        Limits::check(
            path,
            element.clone(),
            "max_instances",
            self.visited,
            self.limits.max_instances as u64,
        )?;
        let check = |a: &::gltf::Accessor<'_>, dims, types: &[DataType]| {
            crate::gltf::checks::check_accessor(a, dims, types, self.buffers)
                .map_err(|e| LoadError::invalid(path, element.clone(), e))
        };
        // Every accessor is checked (type, bounds within its buffer) before anything of
        // `count` is allocated, so the count is backed by the file's bytes.
        for (a, dims, types) in [
            (&t, Dimensions::Vec3, &[DataType::F32][..]),
            (&s, Dimensions::Vec3, &[DataType::F32][..]),
            (
                &r,
                Dimensions::Vec4,
                &[DataType::F32, DataType::I8, DataType::I16][..],
            ),
        ] {
            if let Some(a) = a {
                check(a, dims, types)?;
            }
        }
        let buffers = self.buffers;
        let get = |b: ::gltf::Buffer<'_>| buffers.get(b.index()).map(|d| &d.0[..]);
        let vec3 = |a: &Option<::gltf::Accessor<'a>>,
                    default: Vec3|
         -> Result<Vec<Vec3>, LoadError> {
            match a {
                None => Ok(vec![default; count]),
                Some(a) => {
                    check(a, Dimensions::Vec3, &[DataType::F32])?;
                    let it = ::gltf::accessor::Iter::<[f32; 3]>::new(a.clone(), get).ok_or_else(
                        || LoadError::invalid(path, element.clone(), "unreadable accessor"),
                    )?;
                    Ok(it.map(Vec3::from).collect())
                }
            }
        };
        let translations = vec3(&t, Vec3::ZERO)?;
        let scales = vec3(&s, Vec3::ONE)?;
        let rotations: Vec<glam::Quat> = match &r {
            None => vec![glam::Quat::IDENTITY; count],
            Some(a) => {
                check(
                    a,
                    Dimensions::Vec4,
                    &[DataType::F32, DataType::I8, DataType::I16],
                )?;
                let unreadable =
                    || LoadError::invalid(path, element.clone(), "unreadable accessor");
                match a.data_type() {
                    DataType::I8 => ::gltf::accessor::Iter::<[i8; 4]>::new(a.clone(), get)
                        .ok_or_else(unreadable)?
                        .map(|q| {
                            glam::Quat::from_array(q.map(|v| (f32::from(v) / 127.0).max(-1.0)))
                        })
                        .collect(),
                    DataType::I16 => ::gltf::accessor::Iter::<[i16; 4]>::new(a.clone(), get)
                        .ok_or_else(unreadable)?
                        .map(|q| {
                            glam::Quat::from_array(q.map(|v| (f32::from(v) / 32767.0).max(-1.0)))
                        })
                        .collect(),
                    _ => ::gltf::accessor::Iter::<[f32; 4]>::new(a.clone(), get)
                        .ok_or_else(unreadable)?
                        .map(glam::Quat::from_array)
                        .collect(),
                }
            }
        };
        if translations.len() != count || rotations.len() != count || scales.len() != count {
            return Err(LoadError::invalid(
                path,
                element,
                "its accessors hold fewer values than they count",
            ));
        }
        let mut out = Vec::with_capacity(count);
        for i in 0..count {
            let (tr, ro, sc) = (translations[i], rotations[i], scales[i]);
            if !(tr.is_finite() && ro.is_finite() && sc.is_finite()) || ro.length_squared() == 0.0 {
                return Err(LoadError::invalid(
                    path,
                    element,
                    format!("instance {i} has a transform that is not finite or a zero rotation"),
                ));
            }
            out.push(Affine3A::from_scale_rotation_translation(
                sc,
                ro.normalize(),
                tr,
            ));
        }
        Ok(Some(out))
    }

    /// The geometry and material of a primitive, read on first use (None: not triangles,
    /// skipped with a warning).
    fn primitive(
        &mut self,
        mesh: &::gltf::Mesh<'a>,
        prim: &::gltf::Primitive<'a>,
        desc: &mut SceneDesc,
    ) -> Result<Option<(usize, usize)>, LoadError> {
        if let Some(found) = self.geometry[mesh.index()][prim.index()] {
            return Ok(Some(found));
        }
        let path = self.path;
        let element = format!("mesh {} primitive {}", mesh.index(), prim.index());
        if prim.mode() != ::gltf::mesh::Mode::Triangles {
            log::warn!(
                "{}: {element} uses mode {:?}, only TRIANGLES is rendered; skipped",
                path.display(),
                prim.mode()
            );
            return Ok(None);
        }
        let accessor = |s: ::gltf::Semantic| prim.get(&s).map(|a| a.index());
        let key = [
            accessor(::gltf::Semantic::Positions),
            prim.indices().map(|a| a.index()),
            accessor(::gltf::Semantic::Normals),
            accessor(::gltf::Semantic::TexCoords(0)),
            accessor(::gltf::Semantic::TexCoords(1)),
            accessor(::gltf::Semantic::TexCoords(2)),
            accessor(::gltf::Semantic::TexCoords(3)),
            accessor(::gltf::Semantic::Colors(0)),
            accessor(::gltf::Semantic::Tangents),
        ];
        let index = match self.by_accessors.get(&key) {
            Some(&i) => i,
            None => {
                // Checked from the accessor's count before anything is read.
                let corners = prim
                    .indices()
                    .or_else(|| prim.get(&::gltf::Semantic::Positions))
                    .map_or(0, |a| a.count());
                self.triangles += corners as u64 / 3;
                Limits::check(
                    path,
                    &element,
                    "max_triangles",
                    self.triangles,
                    self.limits.max_triangles as u64,
                )?;
                desc.meshes
                    .push(read_primitive(prim, self.buffers, path, &element)?);
                self.by_accessors.insert(key, desc.meshes.len() - 1);
                desc.meshes.len() - 1
            }
        };
        let material = prim.material().index().unwrap_or(self.default_material);
        let found = (index, material);
        self.geometry[mesh.index()][prim.index()] = Some(found);
        Ok(Some(found))
    }
}

/// A `KHR_lights_punctual` light placed by `world`: colour times intensity, at the node's origin,
/// pointing along its `-z`.
fn light_desc(light: &::gltf::khr_lights_punctual::Light<'_>, world: Affine3A) -> LightDesc {
    use ::gltf::khr_lights_punctual::Kind;
    let [r, g, b] = light.color();
    let color = Rgb::new(r, g, b) * light.intensity();
    let position = world.transform_point3(Vec3::ZERO);
    let direction = world.transform_vector3(Vec3::NEG_Z).normalize_or_zero();
    match light.kind() {
        Kind::Point => LightDesc::Point {
            position,
            intensity: color,
        },
        Kind::Spot {
            inner_cone_angle,
            outer_cone_angle,
        } => LightDesc::Spot {
            position,
            direction,
            intensity: color,
            inner_angle: inner_cone_angle,
            outer_angle: outer_cone_angle,
        },
        Kind::Directional => LightDesc::Directional {
            direction,
            irradiance: color,
        },
    }
}
