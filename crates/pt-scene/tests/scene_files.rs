//! Scene files: every glTF sample and the Cornell OBJ files load, build and render without
//! non-finite samples, with hand-checked counts; corrupted copies of them give `Err` or `Ok`,
//! never a panic.

use std::path::PathBuf;

use pt_core::{RenderOptions, render};
use pt_scene::assets::find_asset_or_skip;
use pt_scene::{BuildOptions, load_scene};

fn asset(name: &str) -> Option<PathBuf> {
    find_asset_or_skip(name).unwrap()
}

/// (file, geometries, instances, unique triangles, materials, cameras, textures, lights).
/// Geometries are distinct accessor sets, instances the primitives reachable from the scene's
/// nodes, materials the file's plus pt's default, textures the distinct (image, colour space)
/// pairs materials use, lights the emissive triangles of the placed primitives; triangle counts
/// as published in ../shared/assets/SOURCES.md. All were checked against the files' JSON by a
/// separate script.
type Counts = (
    &'static str,
    usize,
    usize,
    usize,
    usize,
    usize,
    usize,
    usize,
);
const GLTF: [Counts; 9] = [
    ("gltf/Box.glb", 1, 1, 12, 2, 0, 0, 0),
    ("gltf/BoxTextured.glb", 1, 1, 12, 2, 0, 1, 0),
    ("gltf/Suzanne/Suzanne.gltf", 1, 1, 3_936, 2, 0, 2, 0),
    ("gltf/EmissiveStrengthTest.glb", 6, 6, 90, 7, 0, 1, 60),
    ("gltf/AttenuationTest.glb", 13, 23, 172, 19, 0, 2, 0),
    (
        "gltf/TransmissionRoughnessTest.glb",
        4,
        9,
        12_992,
        10,
        0,
        5,
        0,
    ),
    // Eight colour and data textures and one transmission texture.
    ("gltf/TransmissionTest.glb", 7, 22, 50_879, 15, 1, 9, 36),
    // Base colour, metallic-roughness and normal map of the flowers.
    ("gltf/GlassVaseFlowers.glb", 2, 4, 7_018, 4, 0, 3, 0),
    (
        "gltf/MetalRoughSpheresNoTextures.glb",
        26,
        123,
        12_209,
        99,
        0,
        0,
        0,
    ),
];

#[test]
fn gltf_samples_load_and_render() {
    for (name, geometries, instances, triangles, materials, cameras, textures, lights) in GLTF {
        let Some(path) = asset(name) else { continue };
        let desc = load_scene(&path).unwrap_or_else(|e| panic!("{e}"));
        let tris: usize = desc.meshes.iter().map(|m| m.indices.len()).sum();
        println!(
            "{name}: {} geometries, {} instances, {} materials, {} cameras, {tris} triangles",
            desc.meshes.len(),
            desc.instances.len(),
            desc.materials.len(),
            desc.cameras.len()
        );
        assert_eq!(desc.meshes.len(), geometries, "{name}");
        assert_eq!(desc.instances.len(), instances, "{name}");
        assert_eq!(tris, triangles, "{name}");
        assert_eq!(desc.materials.len(), materials, "{name}");
        assert_eq!(desc.cameras.len(), cameras, "{name}");
        assert_eq!(desc.textures.len(), textures, "{name}");
        let bundle = desc.build(&BuildOptions::default()).unwrap();
        assert_eq!(bundle.scene.stats().lights, lights, "{name}");
        let out = render(
            &bundle.scene,
            &bundle.camera,
            &RenderOptions::new(32, 32).spp(4),
            None,
        )
        .unwrap();
        assert_eq!(out.stats.non_finite_samples, 0, "{name}");
    }
}

#[test]
fn emissive_strength_makes_area_lights() {
    let Some(path) = asset("gltf/EmissiveStrengthTest.glb") else {
        return;
    };
    let desc = load_scene(&path).unwrap();
    let emissive: Vec<f32> = desc
        .materials
        .iter()
        .map(|m| m.emission.max_component())
        .filter(|&e| e > 0.0)
        .collect();
    // The test file's emitters use strengths 1, 2, 4, 8 and 16 on a white emissive factor.
    assert!(emissive.iter().any(|&e| e > 10.0), "{emissive:?}");
    let bundle = desc.build(&BuildOptions::default()).unwrap();
    assert!(bundle.scene.stats().lights > 0);
}

#[test]
fn transmission_becomes_glass() {
    // The transmission texture is read (it multiplies the factor at each hit).
    if let Some(path) = asset("gltf/TransmissionTest.glb") {
        let desc = load_scene(&path).unwrap();
        assert!(
            desc.materials
                .iter()
                .any(|m| m.transmission_texture.is_some())
        );
    }
    let Some(path) = asset("gltf/TransmissionRoughnessTest.glb") else {
        return;
    };
    let desc = load_scene(&path).unwrap();
    let glass: Vec<_> = desc
        .materials
        .iter()
        .filter(|m| m.transmission >= 0.5)
        .collect();
    assert!(!glass.is_empty());
    for m in glass {
        assert!(matches!(
            m.to_material().unwrap(),
            pt_core::BuiltinMaterial::Glass(_)
        ));
    }
}

#[test]
fn cornell_obj_files_load() {
    // The single-file Cornell box: its light is stored as `Ka 20 20 20` (no `Ke`).
    if let Some(path) = asset("cornell/tinyobjloader/cornell_box.obj") {
        let desc = load_scene(&path).unwrap();
        let light = desc.materials.iter().find(|m| m.name == "light").unwrap();
        assert_eq!(light.emission, pt_core::Rgb::splat(20.0));
        let bundle = desc.build(&BuildOptions::default()).unwrap();
        assert_eq!(
            bundle.scene.stats().lights,
            2,
            "the light quad's two triangles"
        );
    }
    // Mitsuba's Cornell box: one OBJ per part, without materials.
    for part in [
        "cbox_back",
        "cbox_ceiling",
        "cbox_floor",
        "cbox_greenwall",
        "cbox_largebox",
        "cbox_luminaire",
        "cbox_redwall",
        "cbox_smallbox",
    ] {
        let Some(path) = asset(&format!("cornell/mitsuba-cbox/meshes/{part}.obj")) else {
            continue;
        };
        let desc = load_scene(&path).unwrap_or_else(|e| panic!("{e}"));
        assert!(!desc.meshes.is_empty(), "{part}");
        desc.build(&BuildOptions::default()).unwrap();
    }
}

/// Truncated and bit-flipped copies of real files: every loader returns, never panics.
#[test]
fn corrupted_files_never_panic() {
    let files = [
        "gltf/Box.glb",
        "gltf/EmissiveStrengthTest.glb",
        "gltf/MetalRoughSpheresNoTextures.glb",
        "cornell/tinyobjloader/cornell_box.obj",
        "meshes/bunny-lowres-npm.obj",
        "meshes/dragon_vrip_res3.ply",
    ];
    let dir = std::env::temp_dir().join(format!("pt-corrupt-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    let (mut ok, mut err) = (0, 0);
    for name in files {
        let Some(path) = asset(name) else { continue };
        let bytes = std::fs::read(&path).unwrap();
        let ext = path.extension().unwrap().to_str().unwrap().to_string();
        let target = dir.join(format!("corrupt.{ext}"));
        let mut variants: Vec<Vec<u8>> = [0usize, 1, 12, 20, 100]
            .iter()
            .chain(&[bytes.len() / 3, bytes.len() / 2, bytes.len() - 1])
            .filter(|&&n| n < bytes.len())
            .map(|&n| bytes[..n].to_vec())
            .collect();
        for _ in 0..40 {
            let mut v = bytes.clone();
            for _ in 0..1 + next() % 8 {
                let i = (next() % v.len() as u64) as usize;
                v[i] ^= 1 << (next() % 8);
            }
            variants.push(v);
        }
        for v in variants {
            std::fs::write(&target, &v).unwrap();
            match load_scene(&target) {
                Ok(desc) => {
                    ok += 1;
                    let _ = desc.build(&BuildOptions::default());
                }
                Err(e) => {
                    err += 1;
                    assert!(
                        e.to_string().contains("corrupt."),
                        "error names the file: {e}"
                    );
                }
            }
        }
    }
    println!("{ok} corrupted files loaded, {err} rejected");
    std::fs::remove_dir_all(&dir).ok();
}

/// A hand-written glTF with an embedded buffer, a floor triangle, a camera and one light of each
/// `KHR_lights_punctual` kind.
const PUNCTUAL: &str = r#"{"asset": {"version": "2.0"}, "extensionsUsed": ["KHR_lights_punctual"], "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "color": [1, 0.5, 0.25], "intensity": 4}, {"type": "spot", "intensity": 10, "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.5}}, {"type": "directional", "intensity": 2}]}}, "buffers": [{"byteLength": 36, "uri": "data:application/octet-stream;base64,AAAAwAAAAAAAAADAAAAAAAAAAAAAAABAAAAAQAAAAAAAAADA"}], "bufferViews": [{"buffer": 0, "byteLength": 36}], "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [-2, 0, -2], "max": [2, 0, 2]}], "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}], "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1}}], "nodes": [{"mesh": 0}, {"translation": [0, 1, 0], "extensions": {"KHR_lights_punctual": {"light": 0}}}, {"translation": [0, 2, 0], "rotation": [-0.7071068, 0, 0, 0.7071068], "extensions": {"KHR_lights_punctual": {"light": 1}}}, {"rotation": [-0.7071068, 0, 0, 0.7071068], "extensions": {"KHR_lights_punctual": {"light": 2}}}, {"translation": [0, 3, 5], "rotation": [-0.3007058, 0, 0, 0.9537170], "camera": 0}], "scenes": [{"nodes": [0, 1, 2, 3, 4]}], "scene": 0}"#;

#[test]
fn gltf_punctual_lights_and_cameras() {
    use pt_scene::desc::LightDesc;
    let dir = std::env::temp_dir().join(format!("pt-punctual-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("lights.gltf");
    std::fs::write(&path, PUNCTUAL).unwrap();
    let desc = load_scene(&path).unwrap();
    assert_eq!(desc.lights.len(), 3);
    let close = |a: pt_core::glam::Vec3, b: pt_core::glam::Vec3| (a - b).length() < 1e-5;
    let down = pt_core::glam::Vec3::NEG_Y;
    for l in &desc.lights {
        match *l {
            LightDesc::Point {
                position,
                intensity,
            } => {
                assert!(close(position, pt_core::glam::Vec3::Y));
                assert_eq!(intensity, pt_core::Rgb::new(4.0, 2.0, 1.0));
            }
            LightDesc::Spot {
                position,
                direction,
                inner_angle,
                outer_angle,
                ..
            } => {
                assert!(close(position, pt_core::glam::Vec3::new(0.0, 2.0, 0.0)));
                assert!(close(direction, down), "{direction}");
                assert_eq!((inner_angle, outer_angle), (0.2, 0.5));
            }
            LightDesc::Directional { direction, .. } => assert!(close(direction, down)),
            other => panic!("unexpected light {other:?}"),
        }
    }
    assert_eq!(desc.cameras.len(), 1);
    assert!((desc.cameras[0].yfov_deg - 0.8f32.to_degrees()).abs() < 1e-4);
    let bundle = desc.build(&BuildOptions::default()).unwrap();
    assert_eq!(bundle.camera.eye(), pt_core::glam::Vec3::new(0.0, 3.0, 5.0));
    let out = render(
        &bundle.scene,
        &bundle.camera,
        &RenderOptions::new(16, 16).spp(4),
        None,
    )
    .unwrap();
    assert!(out.image.mean().luminance() > 0.0, "the floor is lit");

    // A required extension pt does not know is an error that names it.
    let unknown = PUNCTUAL.replace(
        r#""extensionsUsed": ["KHR_lights_punctual"]"#,
        r#""extensionsUsed": ["KHR_lights_punctual", "EXT_unknown"], "extensionsRequired": ["EXT_unknown"]"#,
    );
    std::fs::write(&path, unknown).unwrap();
    let e = load_scene(&path).unwrap_err().to_string();
    assert!(
        e.contains("EXT_unknown") && e.contains("lights.gltf"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn gltf_textures_are_decoded_and_used() {
    for (name, textures) in [
        ("gltf/BoxTextured.glb", 1),
        ("gltf/Suzanne/Suzanne.gltf", 2),
    ] {
        let Some(path) = asset(name) else { continue };
        let desc = load_scene(&path).unwrap();
        assert_eq!(desc.textures.len(), textures, "{name}");
        let m = desc.materials[0].to_material_with(&desc.textures).unwrap();
        assert!(
            matches!(&m, pt_core::BuiltinMaterial::Pbr(p) if p.layered),
            "{name}: a textured glTF material is evaluated per hit with glTF's BSDF"
        );
    }
    // BoxTextured's texture is the glTF logo: mostly blue and green on white, not grey.
    if let Some(path) = asset("gltf/BoxTextured.glb") {
        let desc = load_scene(&path).unwrap();
        let t = &desc.textures[0];
        let mean = t.image().mean();
        assert!(mean.b > mean.r && mean.g > mean.r, "{mean:?}");
    }
}

#[test]
fn obj_diffuse_textures_and_missing_texture_files() {
    let dir = std::env::temp_dir().join(format!("pt-objtex-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // A 2x1 texture: red on the left, blue on the right.
    let png = image::RgbImage::from_fn(2, 1, |x, _| {
        if x == 0 {
            image::Rgb([255, 0, 0])
        } else {
            image::Rgb([0, 0, 255])
        }
    });
    png.save(dir.join("tex.png")).unwrap();
    std::fs::write(
        dir.join("m.mtl"),
        "newmtl t\nKd 0.5 0.5 0.5\nmap_Kd tex.png\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("s.obj"),
        "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0.1 0.5\nvt 0.9 0.5\nvt 0.9 0.5\nusemtl t\nf 1/1 2/2 3/3\n",
    )
    .unwrap();
    let desc = load_scene(dir.join("s.obj")).unwrap();
    assert_eq!(desc.textures.len(), 1);
    let t = &desc.textures[0];
    let left = t.eval(pt_core::glam::Vec2::new(0.25, 0.5));
    let right = t.eval(pt_core::glam::Vec2::new(0.75, 0.5));
    assert!(
        left.r > 0.9 && left.b < 0.1 && right.b > 0.9,
        "{left:?} {right:?}"
    );
    // Evaluated per hit, as the dominant lobe's model: OBJ describes no layering.
    assert!(matches!(
        desc.materials[0].to_material_with(&desc.textures).unwrap(),
        pt_core::BuiltinMaterial::Pbr(p) if !p.layered
    ));
    // A missing texture file is an error naming it.
    std::fs::write(dir.join("m.mtl"), "newmtl t\nmap_Kd nowhere.png\n").unwrap();
    let e = load_scene(dir.join("s.obj")).unwrap_err().to_string();
    assert!(e.contains("nowhere.png"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

/// Regression inputs found by fuzzing (`fuzz/`, docs/testing.md): each once panicked inside a
/// loader and must now give an error naming the file.
#[test]
fn fuzz_regressions_give_errors() {
    // An image with neither a `uri` nor a `bufferView` (the fuzzer had garbled the key), used
    // by a material: `gltf::Image::source` unwrapped the missing URI.
    let no_source = r#"{"asset": {"version": "2.0"},
        "images": [{"mimeType": "image/png", "buffeiwVre": 3}],
        "textures": [{"source": 0}],
        "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
        "scenes": [{"nodes": []}], "scene": 0}"#;
    // A buffer view without a MIME type: the same function unwrapped the missing type.
    let no_mime = r#"{"asset": {"version": "2.0"},
        "buffers": [{"byteLength": 4, "uri": "data:application/octet-stream;base64,AAAAAA=="}],
        "bufferViews": [{"buffer": 0, "byteLength": 4}],
        "images": [{"bufferView": 0}],
        "textures": [{"source": 0}],
        "materials": [{"emissiveTexture": {"index": 0}}],
        "scenes": [{"nodes": []}], "scene": 0}"#;
    for (name, json) in [("no-source.gltf", no_source), ("no-mime.gltf", no_mime)] {
        let err = pt_scene::gltf::load_gltf_slice(json.as_bytes(), name)
            .expect_err("an image without a source must be refused");
        let msg = err.to_string();
        assert!(msg.contains(name) && msg.contains("image 0"), "{msg}");
    }

    // Accessors the gltf crate's readers would panic on: a TEXCOORD_0 whose buffer view has a
    // stride (4) smaller than its element (8 bytes) (found by fuzzing), and, checked with it,
    // a POSITION of bytes, an accessor running past its view, a view running past its buffer.
    let triangle = |accessors: &str, views: &str, attributes: &str| {
        format!(
            r#"{{"asset": {{"version": "2.0"}},
            "buffers": [{{"byteLength": 36, "uri": "data:application/octet-stream;base64,AAAAwAAAAAAAAADAAAAAAAAAAAAAAABAAAAAQAAAAAAAAADA"}}],
            "bufferViews": [{views}], "accessors": [{accessors}],
            "meshes": [{{"primitives": [{{"attributes": {attributes}}}]}}],
            "nodes": [{{"mesh": 0}}], "scenes": [{{"nodes": [0]}}], "scene": 0}}"#
        )
    };
    let position = r#"{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [-2, 0, -2], "max": [2, 0, 2]}"#;
    let whole = r#"{"buffer": 0, "byteLength": 36}"#;
    let cases = [
        (
            "stride.gltf",
            triangle(
                &format!(
                    r#"{position}, {{"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"}}"#
                ),
                &format!(r#"{whole}, {{"buffer": 0, "byteLength": 24, "byteStride": 4}}"#),
                r#"{"POSITION": 0, "TEXCOORD_0": 1}"#,
            ),
            "stride 4",
        ),
        (
            "bytes.gltf",
            triangle(
                r#"{"bufferView": 0, "componentType": 5121, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 1]}"#,
                whole,
                r#"{"POSITION": 0}"#,
            ),
            "expected Vec3",
        ),
        (
            "past-view.gltf",
            triangle(
                r#"{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-2, 0, -2], "max": [2, 0, 2]}"#,
                whole,
                r#"{"POSITION": 0}"#,
            ),
            "past",
        ),
        (
            "past-buffer.gltf",
            triangle(
                position,
                r#"{"buffer": 0, "byteLength": 36, "byteOffset": 12}"#,
                r#"{"POSITION": 0}"#,
            ),
            "",
        ),
    ];
    // A POSITION accessor that does not exist: the gltf crate's own validation indexed it
    // (third fuzzing find).
    let missing = r#"{"asset": {"version": "2.0"},
        "meshes": [{"primitives": [{"attributes": {"POSITION": 2}}]}],
        "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}], "scene": 0}"#;
    let cases =
        cases
            .into_iter()
            .chain([("missing-accessor.gltf", missing.to_string(), "accessor 2")]);
    for (name, json, what) in cases {
        let msg = match pt_scene::gltf::load_gltf_slice(json.as_bytes(), name) {
            Ok(_) => panic!("{name}: loaded"),
            Err(e) => e.to_string(),
        };
        assert!(msg.contains(name) && msg.contains(what), "{name}: {msg}");
    }
}
