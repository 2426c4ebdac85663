//! Non-finite safety: scenes built to provoke NaN or infinity. Each one either is refused with a
//! clear error (bad input) or renders with **zero** non-finite samples and a finite image. The
//! film would drop and count a non-finite sample (it never reaches an output file), but a
//! count above zero here is a bug to fix, not noise.
//!
//! The cases: degenerate, NaN/infinite and needle triangles (plain and emitting), zero-length,
//! huge, tiny and flipped shading normals, roughness exactly 0 and 1, eta exactly 1, emitters of
//! zero area, a camera inside smooth and rough glass, rays exactly parallel to surfaces, a light
//! in the plane of the surface it lights, and very bright, very small lights.

use crate::support;
use pt::prelude::*;
use pt::pt_accel::TriangleMesh;
use pt::pt_core::{BuiltinLight, MaterialId, PointLight};
use pt::pt_scene::shapes::{cube, quad};
use support::uv_sphere;

/// Render a scene through `camera` and check that every sample was finite.
fn check(name: &str, scene: &Scene, camera: &PinholeCamera, depth: u32) -> Image {
    let opts = RenderOptions::new(24, 24).spp(16).max_depth(depth).seed(9);
    let out = render(scene, camera, &opts, None).unwrap_or_else(|e| panic!("{name}: {e}"));
    assert_eq!(
        out.stats.non_finite_samples, 0,
        "{name}: {} non-finite samples",
        out.stats.non_finite_samples
    );
    assert!(
        out.image
            .as_slice()
            .iter()
            .all(|v| v.is_finite() && *v >= 0.0),
        "{name}: image has a negative or non-finite value"
    );
    out.image
}

/// A closed room lit by a ceiling panel, with `add` placing the objects under test inside.
fn room(add: impl FnOnce(&mut SceneBuilder, MaterialId)) -> Scene {
    let mut b = SceneBuilder::new();
    let walls = b.add_mesh(cube(2.0, true));
    let white = b.add_material(BuiltinMaterial::diffuse(Rgb::splat(0.6)));
    b.add_object(Object::new(walls, white));
    let panel = b.add_mesh(quad([
        Vec3::new(-0.5, 1.99, -0.5),
        Vec3::new(0.5, 1.99, -0.5),
        Vec3::new(0.5, 1.99, 0.5),
        Vec3::new(-0.5, 1.99, 0.5),
    ]));
    b.add_object(
        Object::new(panel, white).with_emission(Emission::new(Rgb::splat(8.0)).two_sided()),
    );
    add(&mut b, white);
    b.build().unwrap()
}

fn camera() -> PinholeCamera {
    PinholeCamera::look_at(Vec3::new(0.0, 0.0, 1.9), Vec3::ZERO, Vec3::Y, 70.0).unwrap()
}

fn mesh(positions: Vec<Vec3>, indices: Vec<[u32; 3]>) -> Mesh {
    Mesh::new(TriangleMesh::new(positions, indices).unwrap())
}

#[test]
fn degenerate_non_finite_and_needle_triangles() {
    let v = Vec3::new;
    let positions = vec![
        // 0-2: a good triangle.
        v(-1.0, -1.0, 0.0),
        v(0.0, -1.0, 0.0),
        v(-0.5, 0.0, 0.0),
        // 3-5: collinear.
        v(0.0, 0.0, 0.0),
        v(0.5, 0.5, 0.0),
        v(1.0, 1.0, 0.0),
        // 6-7: NaN and infinite corners.
        v(f32::NAN, 0.0, 0.0),
        v(0.0, f32::INFINITY, 0.0),
        // 8-10: a needle 1e-7 wide and 1.5 long, and 11-13 one of area ~1e-14.
        v(0.2, -1.5, -0.5),
        v(0.2 + 1e-7, -1.5, -0.5),
        v(0.2, 0.0, -0.5),
        v(0.5, 0.5, -0.5),
        v(0.5 + 1e-7, 0.5, -0.5),
        v(0.5, 0.5 + 1e-7, -0.5),
    ];
    let indices = vec![
        [0, 1, 2],
        [3, 4, 5],
        [3, 3, 4],
        [6, 0, 1],
        [7, 1, 2],
        [8, 9, 10],
        [11, 12, 13],
    ];
    for emitting in [false, true] {
        for material in [
            BuiltinMaterial::diffuse(Rgb::splat(0.5)),
            BuiltinMaterial::mirror(Rgb::splat(0.9)),
            Glass::new(1.5).unwrap().into(),
        ] {
            let name = format!("degenerate triangles, emitting {emitting}, {material:?}");
            let scene = room(|b, _| {
                let m = b.add_mesh(mesh(positions.clone(), indices.clone()));
                let mat = b.add_material(material);
                let mut o = Object::new(m, mat);
                if emitting {
                    o = o.with_emission(Emission::new(Rgb::splat(5.0)).two_sided());
                }
                b.add_object(o);
            });
            // The NaN, infinite and zero-area triangles are skipped (and counted).
            assert_eq!(scene.stats().accel.skipped_triangles, 4);
            check(&name, &scene, &camera(), 8);
        }
    }
}

#[test]
fn odd_shading_normals() {
    let sphere = uv_sphere(0.8, 12, 24);
    let count = sphere.geometry().positions().len();
    let outward: Vec<Vec3> = sphere
        .geometry()
        .positions()
        .iter()
        .map(|p| p.normalize())
        .collect();
    let cases: Vec<(&str, Vec<Vec3>)> = vec![
        (
            "zero-length normals",
            (0..count)
                .map(|i| if i % 3 == 0 { Vec3::ZERO } else { outward[i] })
                .collect(),
        ),
        ("huge normals", outward.iter().map(|n| *n * 1e30).collect()),
        ("tiny normals", outward.iter().map(|n| *n * 1e-30).collect()),
        ("flipped normals", outward.iter().map(|n| -*n).collect()),
        (
            "normals at right angles to the surface",
            outward.iter().map(|n| n.any_orthogonal_vector()).collect(),
        ),
    ];
    for (name, normals) in cases {
        for material in [
            BuiltinMaterial::diffuse(Rgb::splat(0.5)),
            Metal::new(ConductorFresnel::GOLD, 0.3).unwrap().into(),
            Glass::new(1.5).unwrap().into(),
            Glass::new(1.5).unwrap().with_roughness(0.4).unwrap().into(),
        ] {
            let m = sphere.clone().with_normals(normals.clone()).unwrap();
            let label = format!("{name}, {material:?}");
            let scene = room(|b, _| {
                let id = b.add_mesh(m);
                let mat = b.add_material(material);
                b.add_object(Object::new(id, mat));
            });
            check(&label, &scene, &camera(), 12);
        }
    }
    // Non-finite normals are bad input: refused with an error that says so.
    let bad = sphere
        .clone()
        .with_normals((0..count).map(|_| Vec3::new(f32::NAN, 0.0, 1.0)).collect());
    match bad {
        Err(e) => assert!(e.to_string().contains("normal"), "{e}"),
        Ok(m) => {
            let mut b = SceneBuilder::new();
            let id = b.add_mesh(m);
            let mat = b.add_material(BuiltinMaterial::diffuse(Rgb::WHITE));
            b.add_object(Object::new(id, mat));
            let e = b.build().expect_err("NaN normals must be refused");
            assert!(e.to_string().contains("normal"), "{e}");
        }
    }
}

#[test]
fn extreme_material_parameters() {
    let sphere = uv_sphere(0.8, 16, 32).with_smooth_normals();
    let materials: Vec<(&str, BuiltinMaterial)> = vec![
        (
            "metal roughness 0",
            Metal::new(ConductorFresnel::SILVER, 0.0).unwrap().into(),
        ),
        (
            "metal roughness 1",
            Metal::new(ConductorFresnel::COPPER, 1.0).unwrap().into(),
        ),
        (
            "glass roughness 0",
            Glass::new(1.5).unwrap().with_roughness(0.0).unwrap().into(),
        ),
        (
            "glass roughness 1",
            Glass::new(1.5).unwrap().with_roughness(1.0).unwrap().into(),
        ),
        ("glass eta 1", Glass::new(1.0).unwrap().into()),
        (
            "rough glass eta 1",
            Glass::new(1.0).unwrap().with_roughness(0.5).unwrap().into(),
        ),
        (
            "glass eta 1.0001",
            Glass::new(1.0001)
                .unwrap()
                .with_roughness(0.01)
                .unwrap()
                .into(),
        ),
        (
            "glass eta 4",
            Glass::new(4.0)
                .unwrap()
                .with_roughness(0.001)
                .unwrap()
                .into(),
        ),
    ];
    for (name, material) in materials {
        let scene = room(|b, _| {
            let id = b.add_mesh(sphere.clone());
            let mat = b.add_material(material);
            b.add_object(Object::new(id, mat));
        });
        check(name, &scene, &camera(), 16);
    }
    // Absurd parameters are refused.
    assert!(Glass::new(0.0).is_err());
    assert!(Glass::new(f32::NAN).is_err());
    assert!(Glass::new(1.5).unwrap().with_roughness(-0.1).is_err());
    assert!(Metal::new(ConductorFresnel::GOLD, f32::INFINITY).is_err());
}

#[test]
fn camera_inside_glass() {
    for roughness in [0.0, 0.3] {
        let glass = Glass::new(1.5).unwrap().with_roughness(roughness).unwrap();
        // Inside a sphere, and inside a box of glass (flat faces: total internal reflection).
        for (shape, m) in [
            ("sphere", uv_sphere(1.0, 16, 32).with_smooth_normals()),
            ("box", cube(1.0, false)),
        ] {
            let scene = room(|b, _| {
                let id = b.add_mesh(m);
                let mat = b.add_material(glass);
                b.add_object(Object::new(id, mat));
            });
            let cam = PinholeCamera::look_at(
                Vec3::new(0.1, 0.2, 0.3),
                Vec3::new(0.0, 1.0, 0.0),
                Vec3::Z,
                90.0,
            )
            .unwrap();
            let img = check(
                &format!("camera inside a glass {shape}, roughness {roughness}"),
                &scene,
                &cam,
                24,
            );
            assert!(
                img.mean().max_component() > 0.0,
                "{shape}: nothing seen from inside"
            );
        }
    }
}

#[test]
fn exactly_grazing_rays_and_lights_in_the_surface_plane() {
    // The camera sits exactly in the plane of the floor (y = -2 is the room's floor; this one
    // is an extra floor at y = 0): half its rays run exactly along a surface.
    let scene = room(|b, white| {
        let floor = b.add_mesh(quad([
            Vec3::new(-1.5, 0.0, -1.5),
            Vec3::new(-1.5, 0.0, 1.5),
            Vec3::new(1.5, 0.0, 1.5),
            Vec3::new(1.5, 0.0, -1.5),
        ]));
        b.add_object(Object::new(floor, white));
        // An emitter standing exactly in the plane of the floor, edge-on to it.
        let edge_on = b.add_mesh(quad([
            Vec3::new(-0.3, 0.0, -1.0),
            Vec3::new(0.3, 0.0, -1.0),
            Vec3::new(0.3, 0.0, -1.2),
            Vec3::new(-0.3, 0.0, -1.2),
        ]));
        b.add_object(Object::new(edge_on, white).with_emission(Emission::new(Rgb::splat(4.0))));
        // A point light exactly on the floor.
        b.add_light(BuiltinLight::from(
            PointLight::new(Vec3::new(0.5, 0.0, 0.5), Rgb::splat(2.0)).unwrap(),
        ));
    });
    for eye in [Vec3::new(0.0, 0.0, 1.9), Vec3::new(1.0, 0.0, 1.0)] {
        let cam = PinholeCamera::look_at(eye, Vec3::new(0.0, 0.0, -1.0), Vec3::Y, 60.0).unwrap();
        check("grazing rays", &scene, &cam, 8);
    }
}

#[test]
fn very_bright_tiny_lights() {
    for (radiance, size) in [(1e12f32, 1e-4f32), (1e20, 1e-8), (1e6, 1e-12)] {
        let scene = room(|b, white| {
            let tiny = b.add_mesh(quad([
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(size, 0.0, 0.0),
                Vec3::new(size, 0.0, size),
                Vec3::new(0.0, 0.0, size),
            ]));
            b.add_object(
                Object::new(tiny, white)
                    .with_emission(Emission::new(Rgb::splat(radiance)).two_sided()),
            );
            let mirror = b.add_material(Mirror::new(Rgb::splat(0.9)));
            let ball = b.add_mesh(uv_sphere(0.4, 12, 24).with_smooth_normals());
            b.add_object(
                Object::new(ball, mirror)
                    .with_transform(Affine3A::from_translation(Vec3::new(0.8, -1.0, 0.0))),
            );
            b.add_light(BuiltinLight::from(
                PointLight::new(Vec3::new(-1.0, -1.999, 0.0), Rgb::splat(1e30)).unwrap(),
            ));
        });
        check(
            &format!("light of radiance {radiance} and size {size}"),
            &scene,
            &camera(),
            8,
        );
    }
}

#[test]
fn zero_area_emitters_emit_nothing_and_are_counted() {
    let mut b = SceneBuilder::new();
    let flat = b.add_mesh(mesh(
        vec![Vec3::ZERO, Vec3::X, Vec3::X * 2.0],
        vec![[0, 1, 2]],
    ));
    let white = b.add_material(BuiltinMaterial::diffuse(Rgb::WHITE));
    b.add_object(Object::new(flat, white).with_emission(Emission::new(Rgb::splat(10.0))));
    let scene = b.build().unwrap();
    assert_eq!(
        scene.lights().len(),
        0,
        "a zero-area emitter became a light"
    );
    assert_eq!(
        scene.stats().skipped_emitters,
        1,
        "the skipped emitter is counted"
    );
    let img = check("only a zero-area emitter", &scene, &camera(), 4);
    assert!(img.as_slice().iter().all(|&v| v == 0.0));
}
