//! One triangle primitive's vertices and indices, read into a [`MeshDesc`].

use std::path::Path;

use glam::{Vec2, Vec3, Vec4};

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
            prim.get(&Semantic::TexCoords(1)),
            "TEXCOORD_1",
            Dimensions::Vec2,
            &[DataType::F32, DataType::U8, DataType::U16][..],
        ),
        (
            prim.get(&Semantic::TexCoords(2)),
            "TEXCOORD_2",
            Dimensions::Vec2,
            &[DataType::F32, DataType::U8, DataType::U16][..],
        ),
        (
            prim.get(&Semantic::TexCoords(3)),
            "TEXCOORD_3",
            Dimensions::Vec2,
            &[DataType::F32, DataType::U8, DataType::U16][..],
        ),
        (
            prim.get(&Semantic::Tangents),
            "TANGENT",
            Dimensions::Vec4,
            &float[..],
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
    // COLOR_0 is RGB or RGBA, float or normalised unsigned bytes or shorts.
    if let Some(a) = prim.get(&Semantic::Colors(0)) {
        let dims = if a.dimensions() == Dimensions::Vec3 {
            Dimensions::Vec3
        } else {
            Dimensions::Vec4
        };
        check_accessor(
            &a,
            dims,
            &[DataType::F32, DataType::U8, DataType::U16],
            buffers,
        )
        .map_err(|e| LoadError::invalid(path, format!("{element}, COLOR_0"), e))?;
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
    let uv_set = |set: u32| -> Vec<Vec2> {
        reader
            .read_tex_coords(set)
            .map(|t| t.into_f32().map(Vec2::from).collect())
            .unwrap_or_default()
    };
    let uvs = uv_set(0);
    let mut extra_uv_sets: Vec<Vec<Vec2>> = (1..pt_core::MAX_UV_SETS as u32)
        .map(|set| {
            let v = uv_set(set);
            if v.len() == positions.len() {
                v
            } else {
                Vec::new()
            }
        })
        .collect();
    while extra_uv_sets.last().is_some_and(Vec::is_empty) {
        extra_uv_sets.pop();
    }
    if prim
        .get(&Semantic::TexCoords(pt_core::MAX_UV_SETS as u32))
        .is_some()
    {
        log::warn!(
            "{}: {element}: texture-coordinate sets from TEXCOORD_{} on are ignored",
            path.display(),
            pt_core::MAX_UV_SETS
        );
    }
    let colors: Vec<Vec4> = reader
        .read_colors(0)
        .map(|c| c.into_rgba_f32().map(Vec4::from).collect())
        .unwrap_or_default();
    let tangents: Vec<Vec4> = reader
        .read_tangents()
        .map(|t| t.map(Vec4::from).collect())
        .unwrap_or_default();
    // Non-finite attributes would be refused when the scene is built; say where they are.
    let attribute_problem = [
        ("NORMAL", normals.iter().position(|n| !n.is_finite())),
        ("TEXCOORD_0", uvs.iter().position(|t| !t.is_finite())),
        ("COLOR_0", colors.iter().position(|c| !c.is_finite())),
        ("TANGENT", tangents.iter().position(|t| !t.is_finite())),
    ];
    if let Some((what, Some(i))) = attribute_problem.into_iter().find(|(_, p)| p.is_some()) {
        return Err(LoadError::invalid(
            path,
            format!("{element}, {what}, vertex {i}"),
            "not finite (NaN or infinite)",
        ));
    }
    let flat: Vec<u32> = match reader.read_indices() {
        Some(ix) => ix.into_u32().collect(),
        None => (0..positions.len() as u32).collect(),
    };
    if !flat.len().is_multiple_of(3) {
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
        extra_uv_sets,
        colors: if colors.len() == positions.len() {
            colors
        } else {
            Vec::new()
        },
        tangents: if tangents.len() == positions.len() {
            tangents
        } else {
            Vec::new()
        },
        positions,
        indices,
    })
}
