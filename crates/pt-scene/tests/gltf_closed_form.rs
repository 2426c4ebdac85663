//! glTF features end to end through files the tests write: a one-quad `.gltf` (buffers and
//! images embedded as data URIs) loaded, built and rendered, against results known in closed
//! form. The quad spans `[-1, 1]^2` at `z = 0`, facing `+z`, with texture coordinates `(0, 0)`
//! at its top-left corner; the camera at `(0, 0, 1)` looks down `-z` with a 90-degree field of
//! view, so the quad fills the image exactly and pixel `(x, y)` sees texture coordinates
//! `((x + 0.5) / w, (y + 0.5) / h)` at its centre.

use std::io::Cursor;

use pt_core::glam::Vec3;
use pt_core::light::UniformEnvironment;
use pt_core::{
    Bsdf, Frame, Image, MetallicRoughness, PinholeCamera, RenderOptions, Rgb, TransportMode, render,
};
use pt_scene::{BuildOptions, load_scene};

use crate::support::Scratch;

/// Standard base64 (RFC 4648, padded), for data URIs.
fn base64(bytes: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for c in bytes.chunks(3) {
        let n = (u32::from(c[0]) << 16)
            | (u32::from(*c.get(1).unwrap_or(&0)) << 8)
            | u32::from(*c.get(2).unwrap_or(&0));
        for k in 0..4 {
            if k <= c.len() {
                out.push(A[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// A PNG of `w x h` RGBA texels (rows top to bottom).
fn png(w: u32, h: u32, rgba: &[[u8; 4]]) -> Vec<u8> {
    let img = image::RgbaImage::from_fn(w, h, |x, y| image::Rgba(rgba[(y * w + x) as usize]));
    let mut out = Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png).unwrap();
    out.into_inner()
}

/// The one-quad file: `material` (a glTF material object), `images` (PNG files, each its own
/// texture sampled with `sampler`), `extensions` used, and `extra_nodes` (JSON objects
/// appended to the nodes, e.g. a light) with the top-level `extra` members.
/// With `depth`, a second quad at `z = -depth` facing `-z`: the front and back of a slab
/// (camera rays through the middle cross both).
fn quad_gltf(
    depth: Option<f32>,
    material: &str,
    images: &[Vec<u8>],
    sampler: &str,
    extensions: &[&str],
    extra_nodes: &str,
    extra: &str,
) -> String {
    // Vertices: top-left, top-right, bottom-right, bottom-left.
    let mut p: Vec<[f32; 3]> = vec![[-1., 1., 0.], [1., 1., 0.], [1., -1., 0.], [-1., -1., 0.]];
    let mut n = vec![[0f32, 0., 1.]; 4];
    let mut uv: Vec<[f32; 2]> = vec![[0., 0.], [1., 0.], [1., 1.], [0., 1.]];
    // Counter-clockwise seen from +z.
    let mut idx = vec![0u16, 3, 2, 0, 2, 1];
    if let Some(d) = depth {
        p.extend([[-1., 1., -d], [1., 1., -d], [1., -1., -d], [-1., -1., -d]]);
        n.extend([[0f32, 0., -1.]; 4]);
        uv.extend([[0., 0.], [1., 0.], [1., 1.], [0., 1.]]);
        // Counter-clockwise seen from -z.
        idx.extend([4u16, 6, 7, 4, 5, 6]);
    }
    let v = p.len();
    let mut buf = Vec::new();
    for x in &p {
        buf.extend(x.iter().flat_map(|c| c.to_le_bytes()));
    }
    for x in &n {
        buf.extend(x.iter().flat_map(|c| c.to_le_bytes()));
    }
    for t in &uv {
        buf.extend(t.iter().flat_map(|c| c.to_le_bytes()));
    }
    for _ in 0..v {
        buf.extend([1f32, 0., 0., 1.].iter().flat_map(|c| c.to_le_bytes()));
    }
    for i in &idx {
        buf.extend(i.to_le_bytes());
    }
    let uri = format!("data:application/octet-stream;base64,{}", base64(&buf));
    let images_json: Vec<String> = images
        .iter()
        .map(|png| format!(r#"{{"uri": "data:image/png;base64,{}"}}"#, base64(png)))
        .collect();
    let textures_json: Vec<String> = (0..images.len())
        .map(|i| format!(r#"{{"source": {i}, "sampler": 0}}"#))
        .collect();
    let used: Vec<String> = extensions.iter().map(|e| format!("\"{e}\"")).collect();
    format!(
        r#"{{
  "asset": {{"version": "2.0"}},
  "extensionsUsed": [{used}],
  "scene": 0,
  "scenes": [{{"nodes": [0{more}]}}],
  "nodes": [{{"mesh": 0}}{extra_nodes}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2, "TANGENT": 3}}, "indices": 4, "material": 0}}]}}],
  "materials": [{material}],
  "images": [{images}],
  "samplers": [{sampler}],
  "textures": [{textures}],
  "buffers": [{{"byteLength": {len}, "uri": "{uri}"}}],
  "bufferViews": [
    {{"buffer": 0, "byteOffset": 0, "byteLength": {b12}}},
    {{"buffer": 0, "byteOffset": {b12}, "byteLength": {b12}}},
    {{"buffer": 0, "byteOffset": {b24}, "byteLength": {b8}}},
    {{"buffer": 0, "byteOffset": {b32}, "byteLength": {b16}}},
    {{"buffer": 0, "byteOffset": {b48}, "byteLength": {bi}}}
  ],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": {v}, "type": "VEC3", "min": [-1, -1, {zmin}], "max": [1, 1, 0]}},
    {{"bufferView": 1, "componentType": 5126, "count": {v}, "type": "VEC3"}},
    {{"bufferView": 2, "componentType": 5126, "count": {v}, "type": "VEC2"}},
    {{"bufferView": 3, "componentType": 5126, "count": {v}, "type": "VEC4"}},
    {{"bufferView": 4, "componentType": 5123, "count": {ni}, "type": "SCALAR"}}
  ]{extra}
}}"#,
        b12 = 12 * v,
        b24 = 24 * v,
        b8 = 8 * v,
        b32 = 32 * v,
        b16 = 16 * v,
        b48 = 48 * v,
        bi = 2 * idx.len(),
        ni = idx.len(),
        zmin = -depth.unwrap_or(0.0),
        used = used.join(", "),
        more = if extra_nodes.is_empty() { "" } else { ", 1" },
        images = images_json.join(", "),
        textures = textures_json.join(", "),
        len = buf.len(),
    )
}

/// The file rendered at `size x size`, `spp` samples, lit by a uniform environment of
/// radiance 1 when `furnace`.
fn render_quad(gltf: &str, size: u32, spp: u32, furnace: bool) -> Image {
    let mut h = std::hash::DefaultHasher::new();
    std::hash::Hash::hash(gltf, &mut h);
    let dir = Scratch::new(&format!(
        "gltf-closed-form-{:x}",
        std::hash::Hasher::finish(&h)
    ));
    let path = dir.join("quad.gltf");
    std::fs::write(&path, gltf).unwrap();
    let desc = load_scene(&path).unwrap_or_else(|e| panic!("{e}"));
    let camera = PinholeCamera::look_at(Vec3::Z, Vec3::ZERO, Vec3::Y, 90.0).unwrap();
    let mut options = BuildOptions::default().camera(camera);
    if furnace {
        options = options.environment(UniformEnvironment::new(Rgb::WHITE).unwrap().into());
    }
    let bundle = desc.build(&options).unwrap_or_else(|e| panic!("{e}"));
    render(
        &bundle.scene,
        &bundle.camera,
        &RenderOptions::new(size, size).spp(spp),
        None,
    )
    .unwrap()
    .image
}

const NEAREST: &str = r#"{"magFilter": 9728, "minFilter": 9728}"#;

/// `alphaMode: BLEND` with alpha 0.5 over a black unlit quad in a furnace: half the rays pass,
/// so the quad shows half the background, 0.5 (mean of 64 x 64 pixels at 16 samples: a
/// standard error of 0.002, tolerance 0.01). Opaque, the same quad is black.
#[test]
fn blended_alpha_half_shows_half_the_furnace() {
    let material = |mode: &str| {
        format!(
            r#"{{"alphaMode": "{mode}", "pbrMetallicRoughness": {{"baseColorFactor": [0, 0, 0, 0.5]}}, "extensions": {{"KHR_materials_unlit": {{}}}}}}"#
        )
    };
    let blend = quad_gltf(
        None,
        &material("BLEND"),
        &[],
        NEAREST,
        &["KHR_materials_unlit"],
        "",
        "",
    );
    let img = render_quad(&blend, 64, 16, true);
    let mean = img.pixels().map(|c| c.g).sum::<f32>() / (64.0 * 64.0);
    assert!((mean - 0.5).abs() < 0.01, "mean {mean}");
    let opaque = quad_gltf(
        None,
        &material("OPAQUE"),
        &[],
        NEAREST,
        &["KHR_materials_unlit"],
        "",
        "",
    );
    let img = render_quad(&opaque, 16, 4, true);
    assert!(img.pixels().all(|c| c.is_black()));
}

/// `KHR_materials_volume` through a slab 0.5 deep whose faces are transmissive with IOR 1 (no
/// refraction, no reflection), attenuation colour `c` at distance 0.5, in a furnace: rays
/// straight through the middle keep `exp(-sigma d) = c` exactly in expectation (Beer-Lambert,
/// `sigma = -ln(c) / 0.5`); the centre pixels' rays are nearly straight (under 3 degrees), so
/// their chords exceed 0.5 by under 0.2%. Tolerance 1%; without absorption they keep 1.
#[test]
fn a_volume_transmits_its_attenuation_colour_through_a_slab() {
    let c = Rgb::new(0.5, 0.25, 0.8);
    let material = |volume: &str| {
        format!(
            r#"{{"doubleSided": true, "pbrMetallicRoughness": {{"baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0, "roughnessFactor": 0}}, "extensions": {{"KHR_materials_transmission": {{"transmissionFactor": 1}}, "KHR_materials_ior": {{"ior": 1}}{volume}}}}}"#
        )
    };
    let used = [
        "KHR_materials_transmission",
        "KHR_materials_ior",
        "KHR_materials_volume",
    ];
    let slab = quad_gltf(
        Some(0.5),
        &material(&format!(
            r#", "KHR_materials_volume": {{"thicknessFactor": 0.5, "attenuationDistance": 0.5, "attenuationColor": [{}, {}, {}]}}"#,
            c.r, c.g, c.b
        )),
        &[],
        NEAREST,
        &used,
        "",
        "",
    );
    let img = render_quad(&slab, 33, 16, true);
    let mut centre = Rgb::BLACK;
    for y in 15..18 {
        for x in 15..18 {
            centre += img.get(x, y) / 9.0;
        }
    }
    for (got, want) in [(centre.r, c.r), (centre.g, c.g), (centre.b, c.b)] {
        assert!((got - want).abs() < 0.01 * want, "{centre:?} against {c:?}");
    }
    let clear = quad_gltf(Some(0.5), &material(""), &[], NEAREST, &used, "", "");
    let img = render_quad(&clear, 33, 4, true);
    assert!((img.get(16, 16) - Rgb::WHITE).max_component().abs() < 1e-4);
}

/// `alphaMode: MASK` with cutoff 0.5 on a texture whose left texel has alpha 0.2 and right
/// one 0.8 (nearest filtering): the left half of the quad is cut out (the furnace's 1 shows,
/// exactly), the right half is there (black, exactly).
#[test]
fn masked_alpha_cuts_out_exactly_where_the_texture_says() {
    let texture = png(2, 1, &[[255, 255, 255, 51], [255, 255, 255, 204]]);
    let gltf = quad_gltf(
        None,
        r#"{"alphaMode": "MASK", "alphaCutoff": 0.5, "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1], "baseColorTexture": {"index": 0}}, "extensions": {"KHR_materials_unlit": {}}}"#,
        &[texture],
        NEAREST,
        &["KHR_materials_unlit"],
        "",
        "",
    );
    let img = render_quad(&gltf, 32, 4, true);
    for y in 0..32 {
        for x in (0..15).chain(17..32) {
            let want = if x < 16 { Rgb::WHITE } else { Rgb::BLACK };
            assert_eq!(img.get(x, y), want, "pixel ({x}, {y})");
        }
    }
}

/// `KHR_texture_transform` offset `(0.5, 0)` on a 2 x 2 texture (red, green / blue, white),
/// nearest and repeating, unlit: the halves trade places, so the top-left quadrant shows
/// green and the top-right red, exactly (sRGB 0 and 255 decode to 0 and 1).
#[test]
fn a_texture_transform_moves_texels_to_known_pixels() {
    let texture = png(
        2,
        2,
        &[
            [255, 0, 0, 255],
            [0, 255, 0, 255],
            [0, 0, 255, 255],
            [255, 255, 255, 255],
        ],
    );
    let material = |transform: &str| {
        format!(
            r#"{{"pbrMetallicRoughness": {{"baseColorTexture": {{"index": 0{transform}}}}}, "extensions": {{"KHR_materials_unlit": {{}}}}}}"#
        )
    };
    let at = |img: &Image| {
        [
            img.get(8, 8),
            img.get(24, 8),
            img.get(8, 24),
            img.get(24, 24),
        ]
    };
    let (r, g, b, w) = (
        Rgb::new(1.0, 0.0, 0.0),
        Rgb::new(0.0, 1.0, 0.0),
        Rgb::new(0.0, 0.0, 1.0),
        Rgb::WHITE,
    );
    let plain = quad_gltf(
        None,
        &material(""),
        std::slice::from_ref(&texture),
        NEAREST,
        &["KHR_materials_unlit"],
        "",
        "",
    );
    assert_eq!(at(&render_quad(&plain, 32, 4, false)), [r, g, b, w]);
    let moved = quad_gltf(
        None,
        &material(r#", "extensions": {"KHR_texture_transform": {"offset": [0.5, 0]}}"#),
        &[texture],
        NEAREST,
        &["KHR_materials_unlit", "KHR_texture_transform"],
        "",
        "",
    );
    assert_eq!(at(&render_quad(&moved, 32, 4, false)), [g, r, w, b]);
}

/// A constant normal map tilting the normal 30 degrees toward `+y` (the file's tangent `+x`,
/// bitangent `+y`) on a flat white quad lit by a directional light along `-z` (irradiance 1)
/// and seen from straight above: the centre pixels equal the metallic-roughness BSDF in the
/// tilted frame times the cosine there, as a quad tilted by the geometry would show
/// (tolerance 1%; ignoring the map gives 13% less, cos 30).
#[test]
fn a_constant_normal_map_shades_like_tilted_geometry() {
    let tilt = 30f32.to_radians();
    let n = Vec3::new(0.0, tilt.sin(), tilt.cos());
    let c = |v: f32| ((v + 1.0) * 0.5 * 255.0).round() as u8;
    let texel = [c(n.x), c(n.y), c(n.z), 255];
    // The normal the texel encodes, after 8-bit rounding.
    let decoded =
        Vec3::new(texel[0] as f32, texel[1] as f32, texel[2] as f32) * (2.0 / 255.0) - Vec3::ONE;
    let decoded = decoded.normalize();
    let gltf = quad_gltf(
        None,
        r#"{"pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0, "roughnessFactor": 1}, "normalTexture": {"index": 0}}"#,
        &[png(1, 1, &[texel])],
        NEAREST,
        &["KHR_lights_punctual"],
        r#", {"extensions": {"KHR_lights_punctual": {"light": 0}}}"#,
        r#", "extensions": {"KHR_lights_punctual": {"lights": [{"type": "directional", "intensity": 1}]}}"#,
    );
    let img = render_quad(&gltf, 33, 64, false);
    let centre = img.get(16, 16);
    let frame = Frame::from_z(decoded);
    let (wo, wi) = (frame.to_local(Vec3::Z), frame.to_local(Vec3::Z));
    let want =
        MetallicRoughness::new(Rgb::WHITE, 0.0, 1.0, 1.5).eval(wo, wi, TransportMode::Radiance)
            * wi.z;
    for (got, want) in [(centre.r, want.r), (centre.g, want.g)] {
        assert!((got - want).abs() < 0.01 * want, "{got} against {want}");
    }
    // The test tells: the flat quad's value is far outside the tolerance.
    let flat = MetallicRoughness::new(Rgb::WHITE, 0.0, 1.0, 1.5)
        .eval(Vec3::Z, Vec3::Z, TransportMode::Radiance)
        .r;
    assert!((flat - want.r).abs() > 0.1 * want.r, "{flat} {}", want.r);
}
