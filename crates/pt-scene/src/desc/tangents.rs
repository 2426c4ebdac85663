//! MikkTSpace tangents for meshes that a normal map is drawn on but whose file gives none, as
//! the glTF specification asks ("client implementations SHOULD calculate tangents using default
//! MikkTSpace algorithms").
//!
//! MikkTSpace (Mikkelsen 2008) is the tangent basis that normal-map bakers use; the
//! `bevy_mikktspace` crate is a safe Rust port that reproduces the reference C implementation
//! bit for bit. It produces one tangent per triangle corner; corners of one vertex that get
//! different tangents (along mirrored UV seams, where the handedness flips) split the vertex.

use std::collections::HashMap;

use glam::{Vec2, Vec3, Vec4};

use crate::desc::MeshDesc;

/// The mesh as MikkTSpace reads it, with the per-corner results.
struct Corners<'a> {
    mesh: &'a MeshDesc,
    uvs: &'a [Vec2],
    /// Flat normals per triangle, for meshes without vertex normals.
    face_normals: Vec<Vec3>,
    tangents: Vec<Option<Vec4>>,
}

impl bevy_mikktspace::Geometry for Corners<'_> {
    fn num_faces(&self) -> usize {
        self.mesh.indices.len()
    }

    fn num_vertices_of_face(&self, _face: usize) -> usize {
        3
    }

    fn position(&self, face: usize, vert: usize) -> [f32; 3] {
        self.mesh.positions[self.mesh.indices[face][vert] as usize].into()
    }

    fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
        let v = self.mesh.indices[face][vert] as usize;
        match self.mesh.normals.get(v) {
            Some(n) if *n != Vec3::ZERO => (*n).into(),
            _ => self.face_normals[face].into(),
        }
    }

    fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
        // glTF's v grows down the image while a normal map's green channel points up it: the
        // basis is computed with v flipped, so that its bitangent is the map's +y.
        let uv = self.uvs[self.mesh.indices[face][vert] as usize];
        [uv.x, 1.0 - uv.y]
    }

    fn set_tangent(
        &mut self,
        tangent_space: Option<bevy_mikktspace::TangentSpace>,
        face: usize,
        vert: usize,
    ) {
        self.tangents[3 * face + vert] = tangent_space.map(|t| Vec4::from(t.tangent_encoded()));
    }
}

/// Give `mesh` MikkTSpace tangents computed from texture-coordinate set `uv_set`, splitting
/// vertices whose corners disagree. Returns false, leaving the mesh as it was, when the mesh
/// has no such coordinates.
pub(crate) fn generate_tangents(mesh: &mut MeshDesc, uv_set: usize) -> bool {
    let uvs = if uv_set == 0 {
        &mesh.uvs
    } else {
        match mesh.extra_uv_sets.get(uv_set - 1) {
            Some(set) => set,
            None => return false,
        }
    };
    if uvs.len() != mesh.positions.len() || mesh.indices.is_empty() {
        return false;
    }
    let face_normals = mesh
        .indices
        .iter()
        .map(|t| {
            let p = t.map(|i| mesh.positions[i as usize]);
            (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero()
        })
        .collect();
    let mut corners = Corners {
        mesh,
        uvs,
        face_normals,
        tangents: vec![None; 3 * mesh.indices.len()],
    };
    // The crate's error type has no values: generation cannot fail.
    let _ = bevy_mikktspace::generate_tangents(&mut corners);
    let tangents = corners.tangents;
    split_by_tangent(mesh, &tangents);
    true
}

/// Set one tangent per vertex from the per-corner ones, duplicating a vertex (with all its
/// attributes) for each further distinct tangent its corners have. Corners without a tangent
/// (degenerate triangles with no neighbour) take zero: no normal mapping there.
fn split_by_tangent(mesh: &mut MeshDesc, corners: &[Option<Vec4>]) {
    let n = mesh.positions.len();
    let mut tangent: Vec<Option<Vec4>> = vec![None; n];
    let mut copies: HashMap<(u32, [u32; 4]), u32> = HashMap::new();
    for (c, t) in corners.iter().enumerate() {
        let t = t.unwrap_or(Vec4::ZERO);
        let v = mesh.indices[c / 3][c % 3];
        match tangent[v as usize] {
            None => tangent[v as usize] = Some(t),
            Some(existing) if existing == t => {}
            Some(_) => {
                let key = (v, t.to_array().map(f32::to_bits));
                let copy = *copies.entry(key).or_insert_with(|| {
                    let copy = duplicate_vertex(mesh, v as usize);
                    tangent.push(Some(t));
                    copy
                });
                mesh.indices[c / 3][c % 3] = copy;
            }
        }
    }
    mesh.tangents = tangent
        .into_iter()
        .map(|t| t.unwrap_or(Vec4::ZERO))
        .collect();
}

/// Append a copy of vertex `v` (every attribute but the tangent); returns its index.
fn duplicate_vertex(mesh: &mut MeshDesc, v: usize) -> u32 {
    fn dup<T: Copy>(values: &mut Vec<T>, v: usize) {
        if let Some(&x) = values.get(v) {
            values.push(x);
        }
    }
    let index = mesh.positions.len() as u32;
    dup(&mut mesh.positions, v);
    dup(&mut mesh.normals, v);
    dup(&mut mesh.uvs, v);
    for set in &mut mesh.extra_uv_sets {
        dup(set, v);
    }
    dup(&mut mesh.colors, v);
    index
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit quad in the xy plane facing +z, u along +x and glTF's v down the image (along -y).
    fn quad(mirrored_right_half: bool) -> MeshDesc {
        let mut positions = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ];
        let mut uvs = vec![
            Vec2::new(0.0, 1.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(0.0, 0.0),
        ];
        let mut indices = vec![[0, 1, 2], [0, 2, 3]];
        if mirrored_right_half {
            // A second quad to the right sharing the edge 1-2, with u mirrored (running back
            // from 1 to 0): its tangents point along -x with the opposite handedness.
            positions.extend([Vec3::new(2.0, 0.0, 0.0), Vec3::new(2.0, 1.0, 0.0)]);
            uvs.extend([Vec2::new(0.0, 1.0), Vec2::new(0.0, 0.0)]);
            indices.extend([[1, 4, 5], [1, 5, 2]]);
        }
        MeshDesc {
            name: "quad".into(),
            normals: vec![Vec3::Z; positions.len()],
            positions,
            uvs,
            indices,
            ..MeshDesc::default()
        }
    }

    #[test]
    fn tangents_follow_u_and_the_bitangent_points_up_the_image() {
        let mut m = quad(false);
        assert!(generate_tangents(&mut m, 0));
        assert_eq!(m.positions.len(), 4, "no vertex needs splitting");
        for t in &m.tangents {
            assert!((t.truncate() - Vec3::X).length() < 1e-5, "{t}");
            // Bitangent = w * n x t = +y: up the image, where v decreases.
            assert_eq!(t.w, 1.0);
            assert_eq!(Vec3::Z.cross(t.truncate()) * t.w, Vec3::Y);
        }
    }

    #[test]
    fn mirrored_uvs_split_the_shared_vertices() {
        let mut m = quad(true);
        assert!(generate_tangents(&mut m, 0));
        // The two shared vertices (1 and 2) are split: six plus two.
        assert_eq!(m.positions.len(), 8);
        assert_eq!(m.tangents.len(), 8);
        for (f, tri) in m.indices.iter().enumerate() {
            for &v in tri {
                let t = m.tangents[v as usize];
                let expected = if f < 2 { Vec3::X } else { -Vec3::X };
                assert!((t.truncate() - expected).length() < 1e-5, "face {f}: {t}");
                // The bitangent still points up the image (+y) on both halves.
                let b = Vec3::Z.cross(t.truncate()) * t.w;
                assert!((b - Vec3::Y).length() < 1e-5, "face {f}: {b}");
            }
        }
        // Split copies carry the other attributes.
        assert_eq!(m.uvs.len(), 8);
        assert_eq!(m.normals.len(), 8);
    }

    /// The Khronos mirror test stores tangents its authoring tool made with MikkTSpace; made
    /// again from its positions, normals and coordinates they must agree, handedness included
    /// (which the v flip decides).
    #[test]
    fn generated_tangents_match_the_ones_a_file_stores() {
        let name = "gltf-conformance/NormalTangentMirrorTest/NormalTangentMirrorTest.glb";
        let Some(path) = crate::assets::find_asset_or_skip(name).unwrap() else {
            return;
        };
        let desc = crate::load_scene(&path).unwrap();
        let stored = &desc.meshes[0];
        assert!(!stored.tangents.is_empty());
        let mut made = stored.clone();
        made.tangents.clear();
        assert!(generate_tangents(&mut made, 0));
        let (mut agree, mut corners) = (0, 0);
        for (a, b) in stored.indices.iter().zip(&made.indices) {
            for k in 0..3 {
                let (s, m) = (stored.tangents[a[k] as usize], made.tangents[b[k] as usize]);
                corners += 1;
                if s.w == m.w && s.truncate().normalize().dot(m.truncate()) > 0.99 {
                    agree += 1;
                }
            }
        }
        let share = f64::from(agree) / f64::from(corners);
        println!("{agree} of {corners} corners agree");
        assert!(share > 0.99, "{agree} of {corners} corners agree");
    }

    #[test]
    fn no_coordinates_no_tangents() {
        let mut m = quad(false);
        m.uvs.clear();
        assert!(!generate_tangents(&mut m, 0));
        assert!(!generate_tangents(&mut m, 2));
        assert!(m.tangents.is_empty());
    }
}
