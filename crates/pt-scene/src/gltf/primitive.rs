//! One triangle primitive's vertices and indices, read into a [`MeshDesc`].

use std::path::Path;

use glam::{Vec2, Vec3};

use crate::desc::MeshDesc;
use crate::error::LoadError;
use crate::gltf::checks::check_accessor;

pub(crate) fn read_primitive(
    prim: &::gltf::Primitive<'_>,
    buffers: &[::gltf::buffer::Data],
    path: &Path,
    element: &str,
) -> Result<MeshDesc, LoadError> {
    use ::gltf::Semantic;
    use ::gltf::accessor::{DataType, Dimensions};
    let float = [DataType::F32];
    let checks = [
        (
            prim.get(&Semantic::Positions),
            "POSITION",
            Dimensions::Vec3,
            &float[..],
        ),
        (
            prim.get(&Semantic::Normals),
            "NORMAL",
            Dimensions::Vec3,
            &float[..],
        ),
        (
            prim.get(&Semantic::TexCoords(0)),
            "TEXCOORD_0",
            Dimensions::Vec2,
            &[DataType::F32, DataType::U8, DataType::U16][..],
        ),
        (
            prim.indices(),
            "indices",
            Dimensions::Scalar,
            &[DataType::U8, DataType::U16, DataType::U32][..],
        ),
    ];
    for (accessor, what, dimensions, types) in checks {
        if let Some(a) = accessor {
            check_accessor(&a, dimensions, types, buffers)
                .map_err(|e| LoadError::invalid(path, format!("{element}, {what}"), e))?;
        }
    }
    let reader = prim.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
    let positions: Vec<Vec3> = reader
        .read_positions()
        .ok_or_else(|| LoadError::invalid(path, element, "no POSITION attribute"))?
        .map(Vec3::from)
        .collect();
    if let Some((i, problem)) = positions
        .iter()
        .enumerate()
        .find_map(|(i, &p)| crate::error::position_problem(p).map(|e| (i, e)))
    {
        return Err(LoadError::invalid(
            path,
            format!("{element}, vertex {i}"),
            problem,
        ));
    }
    let normals: Vec<Vec3> = reader
        .read_normals()
        .map(|n| n.map(Vec3::from).collect())
        .unwrap_or_default();
    let uvs: Vec<Vec2> = reader
        .read_tex_coords(0)
        .map(|t| t.into_f32().map(Vec2::from).collect())
        .unwrap_or_default();
    let flat: Vec<u32> = match reader.read_indices() {
        Some(ix) => ix.into_u32().collect(),
        None => (0..positions.len() as u32).collect(),
    };
    if flat.len() % 3 != 0 {
        return Err(LoadError::invalid(
            path,
            element,
            format!("{} indices is not a whole number of triangles", flat.len()),
        ));
    }
    if let Some(&bad) = flat.iter().find(|&&i| i as usize >= positions.len()) {
        return Err(LoadError::invalid(
            path,
            element,
            format!("index {bad} out of range for {} vertices", positions.len()),
        ));
    }
    let indices = flat.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect();
    Ok(MeshDesc {
        name: element.to_string(),
        normals: if normals.len() == positions.len() {
            normals
        } else {
            Vec::new()
        },
        uvs: if uvs.len() == positions.len() {
            uvs
        } else {
            Vec::new()
        },
        positions,
        indices,
    })
}
