//! Area lights from emissive objects: one light per valid triangle, textured ones sampled by
//! the texels they cover.

use glam::{Affine3A, Vec2, Vec3};

use crate::light::{BuiltinLight, TexturedTriangleLight, TriangleLight};
use crate::scene::{Mesh, NO_LIGHT};

/// The most sampling cells of textured lights in one scene (4 bytes each, twice over): 16 MiB.
pub(super) const TEXTURED_LIGHT_CELLS: usize = 1 << 21;

/// Create one area light per valid triangle of an emitting object; returns the per-triangle
/// light indices and the number of triangles that could not emit. Textured lights take their
/// sampling cells from `cell_budget`.
pub(super) fn emissive_triangles<L: From<BuiltinLight>>(
    mesh: &Mesh,
    m: &Affine3A,
    emission: &crate::scene::Emission,
    solid_angle: bool,
    cell_budget: &mut usize,
    lights: &mut Vec<L>,
) -> (Box<[u32]>, usize) {
    let (two_sided, base) = (emission.two_sided, emission.radiance);
    let geometry = mesh.geometry();
    // The texture and the coordinates it reads; without them, a constant factor (the texture
    // at (0, 0), what materials see on a mesh without the set).
    let texture = emission
        .texture
        .as_ref()
        .map(|map| (map, mesh.uv_set(map.uv_set)));
    let factor = match texture {
        Some((map, None)) => map.texture.eval(map.transform.transform_point2(Vec2::ZERO)),
        _ => crate::color::Rgb::WHITE,
    };
    let base = base * factor;
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
            let mut idx = *idx;
            let p = idx.map(|i| world[i as usize]);
            // With vertex normals, the front face is the side they point to.
            if let Some(ns) = &normals_world {
                let n_avg: Vec3 = idx.iter().map(|&i| ns[i as usize]).sum();
                if pt_accel::triangle_cross(&p).dot(n_avg.as_dvec3()) < 0.0 {
                    idx.swap(1, 2);
                }
            }
            let p = idx.map(|i| world[i as usize]);
            if base.is_black() {
                return NO_LIGHT;
            }
            let Some(shape) = TriangleLight::new(p, base, two_sided) else {
                skipped += 1;
                return NO_LIGHT;
            };
            let shape = shape.with_solid_angle_sampling(solid_angle);
            let light = match texture {
                Some((map, Some(uvs))) => {
                    match TexturedTriangleLight::new(
                        shape,
                        idx.map(|i| uvs[i as usize]),
                        map.transform,
                        map.texture.clone(),
                        cell_budget,
                    ) {
                        Some(l) => BuiltinLight::from(l),
                        // Black over the triangle: it emits nothing.
                        None => return NO_LIGHT,
                    }
                }
                _ => BuiltinLight::from(shape),
            };
            lights.push(L::from(light));
            lights.len() as u32 - 1
        })
        .collect();
    (map, skipped)
}

#[cfg(test)]
mod tests {
    use pt_accel::TriangleMesh;

    use super::*;
    use crate::color::Rgb;
    use crate::light::Light;
    use crate::material::BuiltinMaterial;
    use crate::scene::{Emission, Object, SceneBuilder};

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

    /// Four texels: the left half red, the right half blue.
    fn img_texture() -> std::sync::Arc<crate::texture::Texture> {
        let mut img = crate::image::Image::new(4, 1);
        for x in 0..4 {
            let c = if x < 2 {
                Rgb::new(1.0, 0.0, 0.0)
            } else {
                Rgb::new(0.0, 0.0, 1.0)
            };
            img.set(x, 0, c);
        }
        std::sync::Arc::new(crate::texture::Texture::new(img))
    }

    #[test]
    fn emissive_textures_give_each_triangle_its_mean_and_vary_within_it() {
        // Texture: left half red, right half blue. Triangle A's texture coordinates lie in the
        // left half, triangle B's in the right half.
        let tex = img_texture();
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
        let mean = |i: usize| match &s.lights()[i] {
            BuiltinLight::TexturedTriangle(t) => t.mean() * t.shape().radiance(),
            other => panic!("{other:?}"),
        };
        let (a, c) = (mean(0), mean(1));
        assert!(a.r > 1.5 && a.b < 0.5, "left triangle is red: {a:?}");
        assert!(c.b > 1.5 && c.r < 0.5, "right triangle is blue: {c:?}");
        // Within a triangle the radiance is the texture's where the ray hits: a triangle whose
        // coordinates span the boundary is red on one side and blue on the other.
        let p = vec![Vec3::ZERO, Vec3::X, Vec3::Y];
        let uv = vec![
            glam::Vec2::new(0.1, 0.5),
            glam::Vec2::new(0.9, 0.5),
            glam::Vec2::new(0.1, 0.6),
        ];
        let mesh = Mesh::new(TriangleMesh::new(p, vec![[0, 1, 2]]).unwrap())
            .with_uvs(uv)
            .unwrap();
        let tex = img_texture();
        let mut b: SceneBuilder = SceneBuilder::new();
        let m = b.add_mesh(mesh);
        let mat = b.add_material(BuiltinMaterial::diffuse(Rgb::WHITE));
        b.add_object(
            Object::new(m, mat).with_emission(Emission::new(Rgb::WHITE).with_texture(tex)),
        );
        let s = b.build().unwrap();
        let le = |x: f32| {
            let si = s
                .intersect(&pt_accel::Ray::new(Vec3::new(x, 0.05, 1.0), -Vec3::Z))
                .unwrap();
            s.lights()[si.light.unwrap() as usize].l(si.point.p, si.n(), si.uv, si.wo)
        };
        let (left, right) = (le(0.25), le(0.75));
        assert!(left.r > 0.9 && left.b < 0.1, "{left:?}");
        assert!(right.b > 0.9 && right.r < 0.1, "{right:?}");
    }
}
