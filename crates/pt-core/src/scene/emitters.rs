//! Area lights from emissive objects: one light per valid triangle, with the power of the
//! texels it covers.

use glam::{Affine3A, Vec3};

use crate::light::{BuiltinLight, TriangleLight};
use crate::scene::{Mesh, NO_LIGHT};

/// Create one area light per valid triangle of an emitting object; returns the per-triangle
/// light indices and the number of triangles that could not emit.
pub(super) fn emissive_triangles<L: From<BuiltinLight>>(
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
    use pt_accel::TriangleMesh;

    use super::*;
    use crate::color::Rgb;
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
