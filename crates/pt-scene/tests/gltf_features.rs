//! glTF features against the Khronos feature-test models in `gltf-conformance/`: each test
//! reads what a correct renderer shows (the model's README) as a comparison between two parts
//! of the model, a "test" part that only a correct implementation makes look like its "sample
//! pass" part. Surfaces are compared by their reflectance, the BSDF at normal incidence times
//! pi, sampled on a grid of rays cast straight at each part, so no noise enters.

use std::path::PathBuf;

use pt_core::glam::{Affine2, Vec2, Vec3};
use pt_core::pt_accel::Ray;
use pt_core::{Bsdf, Material, MaterialContext, Rgb, TransportMode};
use pt_scene::assets::find_asset_or_skip;
use pt_scene::{BuildOptions, SceneBundle, SceneDesc, load_scene};

use crate::support::Scratch;

fn conformance(model: &str, file: &str) -> Option<(SceneDesc, SceneBundle)> {
    let path: PathBuf = find_asset_or_skip(&format!("gltf-conformance/{model}/{file}")).unwrap()?;
    let desc = load_scene(&path).unwrap_or_else(|e| panic!("{e}"));
    let bundle = desc
        .build(&BuildOptions::default())
        .unwrap_or_else(|e| panic!("{e}"));
    Some((desc, bundle))
}

/// A rectangle in the object space of the mesh named `mesh` (the loader names glTF meshes
/// "mesh M primitive P"): corner, two edges, and the side
/// the rays come from.
struct Patch<'a> {
    mesh: &'a str,
    corner: Vec3,
    u: Vec3,
    v: Vec3,
    up: Vec3,
    /// How far above the patch (along `up`, object space) the rays start.
    lift: f32,
}

/// Reflectance at normal incidence on an `n` by `n` grid over `patch`, `None` where a ray
/// hits nothing.
fn reflectance_grid(
    desc: &SceneDesc,
    bundle: &SceneBundle,
    patch: &Patch<'_>,
    n: usize,
) -> Vec<Option<Rgb>> {
    let mesh = desc
        .meshes
        .iter()
        .position(|m| m.name == patch.mesh)
        .unwrap_or_else(|| panic!("no mesh {}", patch.mesh));
    let instance = desc
        .instances
        .iter()
        .find(|i| i.mesh == mesh)
        .unwrap_or_else(|| panic!("mesh {} is not placed", patch.mesh));
    let t = instance.transform;
    let scene = &bundle.scene;
    let mut out = Vec::with_capacity(n * n);
    for j in 0..n {
        for i in 0..n {
            let (s, r) = ((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
            let local = patch.corner + patch.u * s + patch.v * r + patch.up * patch.lift;
            let origin = t.transform_point3(local);
            let dir = t.transform_vector3(-patch.up).normalize();
            let hit = scene.intersect(&Ray::new(origin, dir)).map(|si| {
                let m = &scene.materials()[si.material as usize];
                let ctx = MaterialContext::new(si.point.p, si.n(), si.ns(), si.wo, si.uv)
                    .with_attributes(si.attributes);
                m.bsdf(&ctx).eval(Vec3::Z, Vec3::Z, TransportMode::Radiance) * std::f32::consts::PI
            });
            out.push(hit);
        }
    }
    out
}

/// The fraction of grid points where `a` and `b` differ by more than `tol` in some channel
/// (or one hits and the other does not).
fn disagreement(a: &[Option<Rgb>], b: &[Option<Rgb>], tol: f32) -> f32 {
    let bad = a
        .iter()
        .zip(b)
        .filter(|(x, y)| match (x, y) {
            (Some(x), Some(y)) => {
                (x.r - y.r).abs() > tol || (x.g - y.g).abs() > tol || (x.b - y.b).abs() > tol
            }
            (None, None) => false,
            _ => true,
        })
        .count();
    bad as f32 / a.len() as f32
}

/// The fraction of grid points that are red: the failure marks of the Khronos tests.
fn red_fraction(a: &[Option<Rgb>]) -> f32 {
    let red = a
        .iter()
        .flatten()
        .filter(|c| c.r > 0.2 && c.r > 3.0 * c.g && c.r > 3.0 * c.b)
        .count();
    red as f32 / a.len() as f32
}

/// VertexColorTest: the top row's checks are multiplied by red, green and blue vertex colours
/// (`COLOR_0`) that cancel a cross in the other two channels; with them applied the row looks
/// like the white-coloured bottom row.
#[test]
fn vertex_colours_multiply_the_base_colour() {
    let Some((desc, bundle)) = conformance("VertexColorTest", "VertexColorTest.glb") else {
        return;
    };
    let mesh = "mesh 1 primitive 0"; // VertexColorTestMesh
    assert!(
        !desc
            .meshes
            .iter()
            .find(|m| m.name == mesh)
            .unwrap()
            .colors
            .is_empty(),
        "COLOR_0 was not read"
    );
    // The three test checks span x in [-0.78, 0.82], y in [0.11, 0.57] at z = 0.487 (read
    // from the vertex colours); the sample row is the same shapes moved down by 0.868.
    let (lo, hi) = (Vec3::new(-0.78, 0.11, 0.487), Vec3::new(0.82, 0.57, 0.487));
    let test = Patch {
        mesh,
        corner: lo,
        u: Vec3::X * (hi.x - lo.x),
        v: Vec3::Y * (hi.y - lo.y),
        up: Vec3::Z,
        lift: 0.01,
    };
    let sample = Patch {
        corner: lo - Vec3::Y * 0.868,
        ..test
    };
    let a = reflectance_grid(&desc, &bundle, &test, 48);
    let b = reflectance_grid(&desc, &bundle, &sample, 48);
    let d = disagreement(&a, &b, 0.1);
    println!("vertex colours: {:.3} of the points disagree", d);
    // Edges of the checks differ a little (the rows' coordinates are not identical): 0.08 of
    // the points; without the vertex colours, 0.31.
    assert!(d < 0.15, "{d} of the test row differs from the sample row");
}

/// TextureSettingsTest: in each row the test quad (left) shows, through its sampler's wrap
/// modes or its `doubleSided` flag, the same picture as the sample quad (right, 2.146 further
/// along x); wrong modes show red crosses or solid red. Rows: mirror, repeat and clamp along
/// s and t, then double-sided (a polygon facing away from the camera in front of the test
/// quad, visible) and single-sided (the same, invisible from behind).
#[test]
fn sampler_wrap_modes_and_sidedness_match_the_sample_column() {
    let Some((desc, bundle)) = conformance("TextureSettingsTest", "TextureSettingsTest.glb") else {
        return;
    };
    // (row, glTF mesh index); the camera looks from -y (the quads' normals).
    let rows = [
        ("mirror s", 0),
        ("mirror t", 1),
        ("repeat s", 2),
        ("repeat t", 5),
        ("clamp s", 3),
        ("clamp t", 6),
        ("double-sided", 7),
        ("single-sided", 8),
    ];
    for (row, mesh) in rows {
        let name = format!("mesh {mesh} primitive 0");
        let m = desc.meshes.iter().find(|m| m.name == name).unwrap();
        let lo = m.positions.iter().fold(Vec3::MAX, |a, &p| a.min(p));
        let hi = m.positions.iter().fold(Vec3::MIN, |a, &p| a.max(p));
        // The test quad spans x in [0.005, 0.905]; 2% margins.
        let (x0, x1) = (0.005 + 0.018, 0.905 - 0.018);
        let dz = (hi.z - lo.z) * 0.02;
        let test = Patch {
            mesh: &name,
            corner: Vec3::new(x0, 0.0, lo.z + dz),
            u: Vec3::X * (x1 - x0),
            v: Vec3::Z * (hi.z - lo.z - 2.0 * dz),
            up: -Vec3::Y,
            lift: 0.5,
        };
        let sample = Patch {
            corner: test.corner + Vec3::X * 2.146,
            ..test
        };
        let a = reflectance_grid(&desc, &bundle, &test, 48);
        let b = reflectance_grid(&desc, &bundle, &sample, 48);
        assert!(
            a.iter().chain(&b).all(Option::is_some),
            "{row}: a ray missed"
        );
        let (d, red) = (disagreement(&a, &b, 0.1), red_fraction(&a));
        println!("{row}: {d:.3} of the points disagree, {red:.3} red");
        // Edges differ a little (measured 0 to 0.10).
        assert!(
            d < 0.15,
            "{row}: {d} of the test quad differs from the sample"
        );
        assert!(red < 0.01, "{row}: {red} of the test quad is red");
    }
}

/// TextureTransformTest: `KHR_texture_transform` offsets, rotations and scales become the
/// coordinate transform T(offset) R(-rotation) S(scale) of the specification, in that order.
#[test]
fn texture_transforms_follow_the_specification() {
    let Some((desc, _)) = conformance("TextureTransformTest", "TextureTransformTest.gltf") else {
        return;
    };
    // The specification's matrices, applied to a point (row-major as written there).
    let spec = |offset: Vec2, rotation: f32, scale: Vec2, p: Vec2| {
        let (s, c) = rotation.sin_cos();
        let q = p * scale;
        Vec2::new(c * q.x + s * q.y, -s * q.x + c * q.y) + offset
    };
    let expected = [
        ("Offset U", Vec2::new(0.5, 0.0), 0.0, Vec2::ONE),
        ("Offset V", Vec2::new(0.0, 0.5), 0.0, Vec2::ONE),
        ("Offset UV", Vec2::new(0.5, 0.5), 0.0, Vec2::ONE),
        (
            "Rotation",
            Vec2::ZERO,
            std::f32::consts::FRAC_PI_8,
            Vec2::ONE,
        ),
        ("Scale", Vec2::ZERO, 0.0, Vec2::splat(1.5)),
        ("All", Vec2::new(-0.2, -0.1), 0.3, Vec2::splat(1.5)),
    ];
    for (name, offset, rotation, scale) in expected {
        let m = desc
            .materials
            .iter()
            .find(|m| m.name == name)
            .unwrap_or_else(|| panic!("no material {name}"));
        let t: Affine2 = m.base_color_texture.unwrap().transform;
        for p in [Vec2::ZERO, Vec2::X, Vec2::Y, Vec2::new(0.3, 0.7)] {
            let got = t.transform_point2(p);
            let want = spec(offset, rotation, scale, p);
            assert!(
                (got - want).length() < 1e-4,
                "{name} at {p}: {got} != {want}"
            );
        }
    }
}

/// The fraction of rays cast at the panel of glTF mesh `mesh` (object space x in [-0.55,
/// 0.55], y in [0.1, 1.97], z = 0, seen from +z) that stop on it rather than passing through
/// to what is behind.
fn panel_coverage(desc: &SceneDesc, bundle: &SceneBundle, mesh: usize, n: usize) -> f32 {
    let name = format!("mesh {mesh} primitive 0");
    let m = desc.meshes.iter().position(|m| m.name == name).unwrap();
    let (index, inst) = desc
        .instances
        .iter()
        .enumerate()
        .find(|(_, i)| i.mesh == m)
        .unwrap();
    let mut stopped = 0;
    for j in 0..n {
        for i in 0..n {
            let local = Vec3::new(
                -0.5 + (i as f32 + 0.5) / n as f32,
                0.15 + 1.77 * (j as f32 + 0.5) / n as f32,
                0.3,
            );
            let ray = Ray::new(inst.transform.transform_point3(local), -Vec3::Z);
            if bundle
                .scene
                .intersect(&ray)
                .is_some_and(|si| si.instance as usize == index)
            {
                stopped += 1;
            }
        }
    }
    stopped as f32 / (n * n) as f32
}

/// AlphaBlendModeTest: five panels with the same alpha gradient (1 near the bottom to 0 near
/// the top): opaque, blended, and masked at cutoffs 0.25, 0.5 (the default) and 0.75. Masked
/// panels keep the part at or above the cutoff, the blended one stops rays with probability
/// alpha (on average its mean alpha), the opaque one stops all. The expected fractions were
/// computed apart from pt, by a Python script reading the PNG's alpha channel (PIL) and
/// filtering it bilinearly at the same 64x64 grid's texture coordinates.
#[test]
fn alpha_modes_cut_out_and_blend() {
    let Some((desc, bundle)) = conformance("AlphaBlendModeTest", "AlphaBlendModeTest.glb") else {
        return;
    };
    // (panel, glTF mesh index, expected fraction of rays stopped, tolerance).
    // Masks: within 0.005 (a few boundary points). Blend: 4096 Bernoulli trials of mean
    // 0.468, standard deviation 0.0078; 0.03 is 3.8 of them.
    let panels = [
        ("opaque", 6, 1.0, 0.0),
        ("blend", 3, 0.4679, 0.03),
        ("cutoff 0.25", 0, 0.6284, 0.005),
        ("cutoff default", 8, 0.4644, 0.005),
        ("cutoff 0.75", 1, 0.3003, 0.005),
    ];
    for (panel, mesh, expected, tol) in panels {
        let f = panel_coverage(&desc, &bundle, mesh, 64);
        println!("{panel}: {f:.3} of the rays stop");
        assert!(
            (f - expected).abs() <= tol,
            "{panel}: {f} of the rays stop, expected {expected}"
        );
    }
}

/// NegativeScaleTest: checks drawn on quads placed by transforms with negative determinant
/// (their front face is the clockwise one, as glTF says) must look like the positively scaled
/// ones: no red cross of a culled or wrongly faced quad shows through.
#[test]
fn mirroring_transforms_keep_the_front_face() {
    let Some((_, bundle)) = conformance("NegativeScaleTest", "NegativeScaleTest.glb") else {
        return;
    };
    // The two rows of check cells: x in [-0.44, 4.28], y in [1.07, 3.13] (world), seen from +z.
    let n = 64;
    let mut grid = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let p = Vec3::new(
                -0.44 + 4.72 * (i as f32 + 0.5) / n as f32,
                1.07 + 2.06 * (j as f32 + 0.5) / n as f32,
                1.0,
            );
            let si = bundle.scene.intersect(&Ray::new(p, -Vec3::Z));
            grid.push(si.map(|si| {
                let m = &bundle.scene.materials()[si.material as usize];
                let ctx = MaterialContext::new(si.point.p, si.n(), si.ns(), si.wo, si.uv)
                    .with_attributes(si.attributes);
                m.bsdf(&ctx).eval(Vec3::Z, Vec3::Z, TransportMode::Radiance) * std::f32::consts::PI
            }));
        }
    }
    let red = red_fraction(&grid);
    println!("{red:.4} of the check cells are red");
    assert!(red < 0.002, "{red} of the check cells are red");
}

/// Reflectance at normal incidence (BSDF times pi) of the file's material named `name`, at
/// texture coordinates (0.5, 0.5).
fn material_reflectance(desc: &SceneDesc, name: &str) -> Rgb {
    let m = desc
        .materials
        .iter()
        .find(|m| m.name == name)
        .unwrap_or_else(|| panic!("no material {name}"));
    reflectance_of(desc, m)
}

/// [`material_reflectance`] of a material given by itself.
fn reflectance_of(desc: &SceneDesc, m: &pt_scene::desc::MaterialDesc) -> Rgb {
    let material = m.to_material_with(&desc.textures).unwrap();
    let ctx = MaterialContext::new(Vec3::ZERO, Vec3::Z, Vec3::Z, Vec3::Z, Vec2::splat(0.5));
    material
        .bsdf(&ctx)
        .eval(Vec3::Z, Vec3::Z, TransportMode::Radiance)
        * std::f32::consts::PI
}

/// SpecularTest, ClearCoatTest, AnisotropyStrengthTest, IridescenceSuzanne and UnlitTest: the
/// extensions are read (factors and textures)
/// and change what the surface reflects as their READMEs describe: black spheres whose
/// reflection grows with `specularFactor` and takes `specularColorFactor`'s colour; a coat
/// that adds a sharp reflection; unlit surfaces that emit their base colour and reflect
/// nothing.
#[test]
fn material_extensions_change_the_reflection() {
    if let Some((desc, _)) = conformance("SpecularTest", "SpecularTest.glb") {
        let by_name = |n: &str| desc.materials.iter().find(|m| m.name == n).unwrap();
        assert_eq!(by_name("M1.3_specFac").specular, 0.212_231);
        assert_eq!(
            by_name("M5.5_yellowFac").specular_color,
            Rgb::new(1.0, 1.0, 0.0)
        );
        assert!(by_name("M2_SpecTex").specular_texture.is_some());
        assert!(by_name("M4_whiteTex").specular_color_texture.is_some());
        // Rising with the factor, from nothing (the base colour is black).
        let row: Vec<f32> = (1..=5)
            .map(|i| {
                let name = desc.materials[i].name.clone();
                material_reflectance(&desc, &name).g
            })
            .collect();
        println!("specular factor row: {row:?}");
        assert!(row[0] < 1e-6, "{row:?}");
        assert!(row.windows(2).all(|w| w[1] > w[0]), "{row:?}");
        let yellow = material_reflectance(&desc, "M5.5_yellowFac");
        assert!(yellow.r > 0.0 && yellow.b < 1e-6 * yellow.r, "{yellow:?}");
        // Colour factors above 1 raise F0 (clamped at 1): more than the white factor 1.
        let hdr = material_reflectance(&desc, "M7.3_HDR");
        assert!(hdr.g > 2.0 * material_reflectance(&desc, "M3.5_whiteFac").g);
    }
    if let Some((desc, _)) = conformance("ClearCoatTest", "ClearCoatTest.glb") {
        let by_name = |n: &str| desc.materials.iter().find(|m| m.name == n).unwrap();
        let coated = by_name("Simple_Coated");
        assert_eq!((coated.clearcoat, coated.clearcoat_roughness), (1.0, 0.03));
        assert!(by_name("Partial_Coated").clearcoat_texture.is_some());
        assert!(
            by_name("RoughVariations_Coated")
                .clearcoat_roughness_texture
                .is_some()
        );
        // The coat's own normal map is read; the base's map is not the coat's.
        assert!(
            by_name("CoatNorm_Coated")
                .clearcoat_normal_texture
                .is_some()
        );
        let base_mapped = by_name("BaseNorm_Coated");
        assert!(
            base_mapped.normal_texture.is_some() && base_mapped.clearcoat_normal_texture.is_none()
        );
        // The smooth coat's peak at normal incidence dwarfs the rough base's reflection.
        let (base, coat) = (
            material_reflectance(&desc, "Simple_Base"),
            material_reflectance(&desc, "Simple_Coated"),
        );
        println!("base {base:?}, coated {coat:?}");
        assert!(coat.b > 10.0 * base.b, "{base:?} {coat:?}");
    }
    if let Some((desc, _)) = conformance("AnisotropyStrengthTest", "AnisotropyStrengthTest.glb") {
        // Strengths 0, 1/6, ... per row, read from the extension.
        assert_eq!(desc.materials[1].anisotropy_strength, 1.0 / 6.0);
        assert!(desc.materials.iter().any(|m| m.anisotropy_strength == 1.0));
        // The spheres' tangents (from the file) reach the mesh.
        let sphere = desc.instances.iter().find(|i| i.material == 1).unwrap();
        assert!(!desc.meshes[sphere.mesh].tangents.is_empty());
    }
    if let Some((desc, _)) = conformance("IridescenceSuzanne", "IridescenceSuzanne.glb") {
        // The file requires the extension: it loads, and the film colours the grey metal's
        // reflection (a bare grey metal reflects the same in every channel).
        let metal = &desc.materials[1];
        assert_eq!(
            (
                metal.iridescence,
                metal.iridescence_ior,
                metal.iridescence_thickness.1
            ),
            (1.0, 1.33, 400.0)
        );
        assert!(desc.materials[2].iridescence_thickness_texture.is_some());
        // The grey metal, and the glass (transmissive: its interface carries the film).
        for (i, what) in [(1, "grey metal"), (2, "glass")] {
            let f = reflectance_of(&desc, &desc.materials[i]);
            let spread = f.max_component() - f.r.min(f.g).min(f.b);
            println!("iridescent {what} at normal incidence: {f:?}");
            assert!(spread > 0.1 * f.max_component(), "{what}: {f:?}");
        }
    }
    if let Some((desc, bundle)) = conformance("UnlitTest", "UnlitTest.glb") {
        for name in ["Orange", "Blue"] {
            let m = desc.materials.iter().find(|m| m.name == name).unwrap();
            assert!(m.unlit, "{name}");
            assert!(material_reflectance(&desc, name).is_black(), "{name}");
        }
        let orange = desc.materials.iter().find(|m| m.name == "Orange").unwrap();
        assert_eq!(orange.emission, Rgb::new(1.0, 0.217_637_64, 0.0));
        assert!(!bundle.scene.lights().is_empty());
    }
}

/// SimpleInstancing: `EXT_mesh_gpu_instancing` places its one mesh 125 times, each under its
/// own translation, rotation and scale (one geometry, so the two-level BVH shares it).
#[test]
fn gpu_instancing_places_every_instance() {
    let Some((desc, bundle)) = conformance("SimpleInstancing", "SimpleInstancing.glb") else {
        return;
    };
    assert_eq!(desc.meshes.len(), 1);
    assert_eq!(desc.instances.len(), 125);
    let mut origins: Vec<[i64; 3]> = desc
        .instances
        .iter()
        .map(|i| (i.transform.translation * 1000.0).as_i64vec3().to_array())
        .collect();
    origins.sort_unstable();
    origins.dedup();
    assert_eq!(origins.len(), 125, "instances share a position");
    assert_eq!(bundle.scene.stats().objects, 125);
}

/// A minimal file, loaded: one triangle, its node instanced by `instancing` (the extension's
/// JSON).
fn load_instanced_triangle(instancing: &str) -> Result<SceneDesc, pt_scene::LoadError> {
    let mut bytes = Vec::new();
    for v in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    let b64 = crate::conventions::base64(&bytes);
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"extensionsUsed":["EXT_mesh_gpu_instancing"],
        "scene":0,"scenes":[{{"nodes":[0]}}],
        "nodes":[{{"mesh":0,"extensions":{{"EXT_mesh_gpu_instancing":{instancing}}}}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3",
                      "min":[0,0,0],"max":[1,1,0]}}],
        "bufferViews":[{{"buffer":0,"byteLength":36}}],
        "buffers":[{{"byteLength":36,"uri":"data:application/octet-stream;base64,{b64}"}}]}}"#
    );
    let dir = Scratch::new(&format!("gltf-instancing-{}", instancing.len()));
    let file = dir.join("t.gltf");
    std::fs::write(&file, json).unwrap();
    load_scene(&file)
}

#[test]
fn gpu_instancing_reads_its_accessors_and_refuses_wrong_ones() {
    // The vertex positions as translations: three instances there.
    let desc = load_instanced_triangle(r#"{"attributes":{"TRANSLATION":0}}"#).unwrap();
    let at: Vec<Vec3> = desc
        .instances
        .iter()
        .map(|i| i.transform.translation.into())
        .collect();
    assert_eq!(at, [Vec3::ZERO, Vec3::X, Vec3::Y]);
    // A rotation must be four components: the error names the node and the extension.
    let e = load_instanced_triangle(r#"{"attributes":{"ROTATION":0}}"#)
        .unwrap_err()
        .to_string();
    assert!(e.contains("node 0, EXT_mesh_gpu_instancing"), "{e}");
    // An accessor that does not exist.
    let e = load_instanced_triangle(r#"{"attributes":{"SCALE":7}}"#)
        .unwrap_err()
        .to_string();
    assert!(e.contains("SCALE names no accessor"), "{e}");
}
