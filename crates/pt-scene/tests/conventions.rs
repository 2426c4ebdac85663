//! The conventions pt shares with the reference renderers (docs/conventions.md): emission is
//! one-sided, from the front face, in every format unless asked otherwise (glTF's double-sided
//! materials, `BuildOptions::two_sided_lights`); a glTF primitive without a material gets the
//! specification's default material; a camera that cannot be used is an error when asked for
//! and a warning otherwise; out-of-range MTL parameters are replaced, not used.

use std::path::PathBuf;

use pt_core::glam::{Vec2, Vec3};
use pt_core::{Light, LightSampleContext};
use pt_scene::desc::MaterialDesc;
use pt_scene::gltf::load_gltf_slice;
use pt_scene::{BuildOptions, SceneBundle, load_scene};

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pt-conv-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Whether the scene's lights send light to `p` (from any of a few sample positions).
fn lit_at(bundle: &SceneBundle, p: Vec3) -> bool {
    bundle.scene.lights().iter().any(|l| {
        [Vec2::splat(0.3), Vec2::new(0.7, 0.2), Vec2::new(0.2, 0.6)]
            .into_iter()
            .filter_map(|u| l.sample_li(&LightSampleContext::at(p), u))
            .any(|s| !s.li.is_black())
    })
}

/// A unit light quad at height 1 whose counter-clockwise winding faces down (-y), as the lights
/// of the Cornell box OBJs do.
const DOWN_QUAD: &str = "mtllib l.mtl\nusemtl lamp\n\
    v 0 1 0\nv 1 1 0\nv 1 1 1\nv 0 1 1\nf 1 2 3 4\n";

#[test]
fn obj_emission_is_one_sided_from_the_front_unless_asked() {
    let dir = scratch("obj");
    std::fs::write(dir.join("l.mtl"), "newmtl lamp\nKd 0 0 0\nKe 5 5 5\n").unwrap();
    std::fs::write(dir.join("l.obj"), DOWN_QUAD).unwrap();
    let desc = load_scene(dir.join("l.obj")).unwrap();
    let (below, above) = (Vec3::new(0.5, 0.0, 0.5), Vec3::new(0.5, 2.0, 0.5));

    let one = desc.build(&BuildOptions::default()).unwrap();
    assert!(lit_at(&one, below), "the front (below) is lit");
    assert!(!lit_at(&one, above), "the back (above) is dark");

    let two = desc
        .build(&BuildOptions::default().two_sided_lights(true))
        .unwrap();
    assert!(
        lit_at(&two, below) && lit_at(&two, above),
        "both sides when asked"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A glTF file with one emissive triangle facing +z, `doubleSided` as given, a second
/// primitive without a material, and, when `camera` is given, a camera node with these extra
/// properties (`"scale":[0,0,0]`, say) and this perspective projection.
fn gltf(double_sided: bool, camera: Option<(&str, &str)>) -> Vec<u8> {
    // Three vertices (0,0,0), (1,0,0), (0,1,0) as little-endian f32, base64 in a data URI.
    let mut bytes = Vec::new();
    for v in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    let b64 = base64(&bytes);
    let (camera_node, camera, cameras) = match camera {
        Some((node, projection)) => (
            ",2",
            format!(r#",{{"camera":0{node}}}"#),
            format!(r#","cameras":[{{"type":"perspective","perspective":{projection}}}]"#),
        ),
        None => ("", String::new(), String::new()),
    };
    format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0,1{camera_node}]}}]{cameras},
        "nodes":[{{"mesh":0}},{{"mesh":1,"translation":[0,0,-5]}}{camera}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"material":0}}]}},
                  {{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],
        "materials":[{{"emissiveFactor":[1,1,1],"doubleSided":{double_sided}}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3",
                      "min":[0,0,0],"max":[1,1,0]}}],
        "bufferViews":[{{"buffer":0,"byteLength":36}}],
        "buffers":[{{"byteLength":36,"uri":"data:application/octet-stream;base64,{b64}"}}]}}"#,
    )
    .into_bytes()
}

pub fn base64(data: &[u8]) -> String {
    const T: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::new();
    for c in data.chunks(3) {
        let n = u32::from(c[0]) << 16
            | u32::from(*c.get(1).unwrap_or(&0)) << 8
            | u32::from(*c.get(2).unwrap_or(&0));
        for i in 0..4 {
            if i <= c.len() {
                s.push(T[(n >> (18 - 6 * i) & 63) as usize] as char);
            } else {
                s.push('=');
            }
        }
    }
    s
}

#[test]
fn gltf_double_sided_materials_emit_from_both_sides() {
    let (front, back) = (Vec3::new(0.2, 0.2, 1.0), Vec3::new(0.2, 0.2, -1.0));
    let one = load_gltf_slice(&gltf(false, None), "one.gltf")
        .unwrap()
        .build(&BuildOptions::default())
        .unwrap();
    assert!(lit_at(&one, front) && !lit_at(&one, back));
    let two = load_gltf_slice(&gltf(true, None), "two.gltf")
        .unwrap()
        .build(&BuildOptions::default())
        .unwrap();
    assert!(lit_at(&two, front) && lit_at(&two, back));
}

#[test]
fn gltf_primitives_without_a_material_get_the_specifications_default() {
    let desc = load_gltf_slice(&gltf(false, None), "default.gltf").unwrap();
    assert_eq!(desc.instances.len(), 2);
    let plain = desc.instances.iter().find(|i| i.material != 0).unwrap();
    let m = &desc.materials[plain.material];
    assert_eq!(m, &MaterialDesc::gltf_default());
    assert_eq!(
        (m.base_color, m.metallic, m.roughness),
        (pt_core::Rgb::WHITE, 1.0, 1.0)
    );
    // Rendered with glTF's metallic-roughness BSDF, as every glTF material is.
    assert!(matches!(
        m.to_material().unwrap(),
        pt_core::BuiltinMaterial::Pbr(p) if p.layered && p.metallic == 1.0
    ));
}

#[test]
fn an_unusable_file_camera_is_an_error_when_asked_for_and_a_warning_otherwise() {
    for (node, projection, why) in [
        ("", r#"{"yfov":0,"znear":0.1}"#, "field of view"),
        (
            r#","scale":[0,0,0]"#,
            r#"{"yfov":0.7,"znear":0.1}"#,
            "camera 0",
        ),
    ] {
        let file = gltf(false, Some((node, projection)));
        let desc = load_gltf_slice(&file, "cam.gltf").unwrap();
        let e = desc.try_file_camera().unwrap_err().to_string();
        assert!(e.contains("cam.gltf") && e.contains(why), "{e}");
        // Not asked for: the scene still builds, with the framing camera.
        let bundle = desc.build(&BuildOptions::default()).unwrap();
        assert_eq!(Some(bundle.camera), desc.framing_camera());
    }
}

#[test]
fn the_framing_camera_stands_upright_along_the_up_it_is_given() {
    let dir = scratch("up");
    std::fs::write(dir.join("l.mtl"), "newmtl lamp\nKd 0 0 0\nKe 5 5 5\n").unwrap();
    // A post standing along +z, as a Z-up model would.
    std::fs::write(
        dir.join("l.obj"),
        "mtllib l.mtl\nusemtl lamp\nv 0 0 0\nv 1 0 0\nv 1 0 4\nv 0 0 4\nf 1 2 3 4\n",
    )
    .unwrap();
    let desc = load_scene(dir.join("l.obj")).unwrap();
    let center = Vec3::new(0.5, 0.0, 2.0);
    assert_eq!(
        desc.framing_camera(),
        desc.framing_camera_with(Vec3::Y, 40.0)
    );
    let y = desc.framing_camera().unwrap();
    assert!(y.up().dot(Vec3::Y) > 0.9 && y.forward().dot(-Vec3::Z) > 0.9);
    for up in [Vec3::Z, Vec3::new(0.0, 0.1, 3.0)] {
        let cam = desc.framing_camera_with(up, 40.0).unwrap();
        // Upright along +z, seen from the front (-y) and a little above, aimed at the centre.
        assert!(cam.up().dot(Vec3::Z) > 0.9, "{:?}", cam.up());
        assert!(cam.forward().dot(Vec3::Y) > 0.9, "{:?}", cam.forward());
        assert!(cam.eye().z > center.z && cam.eye().y < center.y);
        assert!(cam.forward().dot((center - cam.eye()).normalize()) > 0.9999);
    }
    // Another lens: the same direction, at the distance where the bounds fill it.
    let (wide, narrow) = (
        desc.framing_camera_with(Vec3::Y, 40.0).unwrap(),
        desc.framing_camera_with(Vec3::Y, 20.0).unwrap(),
    );
    assert_eq!(narrow.fov_y_degrees(), 20.0);
    assert!(narrow.forward().dot(wide.forward()) > 0.99999);
    let ratio = (narrow.eye() - center).length() / (wide.eye() - center).length();
    let expected = 20f32.to_radians().sin() / 10f32.to_radians().sin();
    assert!(
        (ratio - expected).abs() < 1e-4,
        "{ratio} against {expected}"
    );
    for bad in [0.0, 180.0, f32::NAN, -5.0] {
        assert_eq!(desc.framing_camera_with(Vec3::Y, bad), None, "{bad}");
    }
    for bad in [
        Vec3::ZERO,
        Vec3::new(f32::NAN, 1.0, 0.0),
        Vec3::new(1e-45, 0.0, 0.0),
    ] {
        assert_eq!(desc.framing_camera_with(bad, 40.0), None, "{bad:?}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn an_index_of_refraction_that_is_not_positive_is_replaced() {
    let dir = scratch("ni");
    std::fs::write(
        dir.join("l.mtl"),
        "newmtl lamp\nNi -1\nillum 7\nnewmtl b\nNi nan\nillum 7\n",
    )
    .unwrap();
    std::fs::write(dir.join("l.obj"), DOWN_QUAD).unwrap();
    let desc = load_scene(dir.join("l.obj")).unwrap();
    for m in &desc.materials {
        assert_eq!(m.ior, 1.5, "{}", m.name);
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
