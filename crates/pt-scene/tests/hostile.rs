//! Hostile files, generated here, against the loaders' limits (`pt_scene::Limits`): each gives a
//! clear error naming the file and the problem, in bounded time and memory. Memory is bounded
//! for real: each case runs in a child process (this test binary again, one case selected by
//! `PT_HOSTILE_CASE`) under a 1 GiB address-space limit (`ulimit -v`), so a loader that
//! allocated gigabytes would abort the child instead of passing.
//!
//! The reproducers: a 3 KB glTF whose node lists itself as a child 1,000 times (was 6.2 GB and
//! an abort); a chain of nodes each listing the next twice, which places 2^40 instances; a
//! buffer of declared `byteLength` 48 whose file is 10 GB (sparse) or `/dev/zero`; `mtllib
//! /dev/zero`; a PNG header claiming 20000x20000 pixels as a glTF image, an OBJ `map_Kd` and
//! an environment map (was 5-7.8 GB).

use std::io::Write;
use std::path::Path;
use std::process::Command;
use std::time::Instant;

use crate::support::Scratch;

fn scratch(name: &str) -> Scratch {
    Scratch::new(&format!("hostile-{name}"))
}

/// The error of loading `file` as a scene (it must fail).
fn load_error(file: &Path) -> String {
    match pt_scene::load_scene(file) {
        Ok(_) => panic!("{} loaded", file.display()),
        Err(e) => e.to_string(),
    }
}

/// A PNG that claims `w x h` greyscale pixels: a valid signature and header chunk, and one
/// empty data chunk (decoding would fail; only the header is meant to be read).
fn png_claiming(w: u32, h: u32) -> Vec<u8> {
    let chunk = |kind: &[u8], data: &[u8]| {
        let mut c = (data.len() as u32).to_be_bytes().to_vec();
        let mut crc = flate2::Crc::new();
        crc.update(kind);
        crc.update(data);
        c.extend_from_slice(kind);
        c.extend_from_slice(data);
        c.extend_from_slice(&crc.sum().to_be_bytes());
        c
    };
    let mut ihdr = w.to_be_bytes().to_vec();
    ihdr.extend_from_slice(&h.to_be_bytes());
    ihdr.extend_from_slice(&[8, 0, 0, 0, 0]); // 8-bit greyscale
    let mut png = Vec::new();
    png.extend_from_slice(&[0x89, b'P', b'N', b'G', 0x0d, 0x0a, 0x1a, 0x0a]);
    png.extend(chunk(b"IHDR", &ihdr));
    png.extend(chunk(b"IDAT", &[]));
    png.extend(chunk(b"IEND", &[]));
    png
}

fn gltf_with(extra: &str) -> String {
    format!(r#"{{"asset":{{"version":"2.0"}},{extra}}}"#)
}

/// One hostile case: writes its files in `dir`, loads them, and checks the error.
fn case(name: &str, dir: &Path) {
    match name {
        "self_child" => {
            let children = vec!["0"; 1000].join(",");
            let f = dir.join("cycle.gltf");
            std::fs::write(
                &f,
                gltf_with(&format!(
                    r#""scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"children":[{children}]}}]"#
                )),
            )
            .unwrap();
            let e = load_error(&f);
            assert!(
                e.contains("cycle.gltf") && e.contains("node 0") && e.contains("cyclic"),
                "{e}"
            );
        }
        "exponential_dag" => {
            // Node i lists node i+1 twice: 2^40 placements of the last node.
            let nodes: Vec<String> = (0..40)
                .map(|i| format!(r#"{{"children":[{},{}]}}"#, i + 1, i + 1))
                .chain(std::iter::once("{}".to_string()))
                .collect();
            let f = dir.join("dag.gltf");
            std::fs::write(
                &f,
                gltf_with(&format!(
                    r#""scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{}]"#,
                    nodes.join(",")
                )),
            )
            .unwrap();
            let e = load_error(&f);
            assert!(e.contains("dag.gltf") && e.contains("max_instances"), "{e}");
        }
        "buffer_larger_than_declared" => {
            let big = dir.join("big.bin");
            std::fs::File::create(&big)
                .unwrap()
                .set_len(10 << 30)
                .unwrap();
            let f = dir.join("buf.gltf");
            std::fs::write(
                &f,
                gltf_with(r#""buffers":[{"uri":"big.bin","byteLength":48}]"#),
            )
            .unwrap();
            let e = load_error(&f);
            assert!(
                e.contains("buffer 0") && e.contains("declares 48 bytes"),
                "{e}"
            );
        }
        "buffer_is_a_device" => {
            let f = dir.join("dev.gltf");
            std::fs::write(
                &f,
                gltf_with(r#""buffers":[{"uri":"/dev/zero","byteLength":48}]"#),
            )
            .unwrap();
            let e = load_error(&f);
            assert!(
                e.contains("buffer 0") && e.contains("not a regular file"),
                "{e}"
            );
        }
        "mtllib_is_a_device" => {
            let f = dir.join("dev.obj");
            std::fs::write(&f, "mtllib /dev/zero\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
            // A missing or unreadable MTL is a warning, as in every viewer: the mesh loads.
            let desc = pt_scene::load_scene(&f).unwrap();
            assert_eq!(desc.meshes.len(), 1);
        }
        "image_bomb_gltf" => {
            std::fs::write(dir.join("bomb.png"), png_claiming(20_000, 20_000)).unwrap();
            let f = dir.join("tex.gltf");
            std::fs::write(
                &f,
                gltf_with(
                    r#""scene":0,"scenes":[{"nodes":[]}],"images":[{"uri":"bomb.png"}],
                    "textures":[{"source":0}],
                    "materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0}}}]"#,
                ),
            )
            .unwrap();
            let e = load_error(&f);
            assert!(
                e.contains("image 0") && e.contains("max_image_pixels"),
                "{e}"
            );
        }
        "image_bomb_obj" => {
            std::fs::write(dir.join("bomb.png"), png_claiming(20_000, 20_000)).unwrap();
            std::fs::write(dir.join("m.mtl"), "newmtl t\nmap_Kd bomb.png\n").unwrap();
            let f = dir.join("tex.obj");
            std::fs::write(
                &f,
                "mtllib m.mtl\nusemtl t\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
            )
            .unwrap();
            let e = load_error(&f);
            assert!(
                e.contains("bomb.png") && e.contains("max_image_pixels"),
                "{e}"
            );
        }
        "image_bomb_env" => {
            let f = dir.join("bomb.png");
            std::fs::write(&f, png_claiming(20_000, 20_000)).unwrap();
            let e = pt_scene::load_equirect(&f).unwrap_err().to_string();
            assert!(
                e.contains("bomb.png") && e.contains("20000x20000") && e.contains("Limits::"),
                "{e}"
            );
        }
        other => panic!("no hostile case {other}"),
    }
}

const CASES: [&str; 8] = [
    "self_child",
    "exponential_dag",
    "buffer_larger_than_declared",
    "buffer_is_a_device",
    "mtllib_is_a_device",
    "image_bomb_gltf",
    "image_bomb_obj",
    "image_bomb_env",
];

/// The child's side: run the case named by `PT_HOSTILE_CASE`, if any.
#[test]
fn hostile_case_in_child() {
    if let Ok(name) = std::env::var("PT_HOSTILE_CASE") {
        case(&name, &scratch(&name));
    }
}

#[test]
fn hostile_files_fail_cleanly_in_bounded_memory_and_time() {
    let exe = std::env::current_exe().unwrap();
    for name in CASES {
        let start = Instant::now();
        let out = if cfg!(unix) && Path::new("/bin/sh").exists() {
            // 1 GiB of address space: the test binary itself needs a few hundred MB (threads'
            // stacks), the loaders' old behaviour needed 4 to 12 GB.
            Command::new("/bin/sh")
                .arg("-c")
                .arg(r#"ulimit -v 1048576 && exec "$0" --exact hostile::hostile_case_in_child --test-threads 1"#)
                .arg(&exe)
                .env("PT_HOSTILE_CASE", name)
                .output()
                .unwrap()
        } else {
            Command::new(&exe)
                .args(["--exact", "hostile::hostile_case_in_child"])
                .env("PT_HOSTILE_CASE", name)
                .output()
                .unwrap()
        };
        let secs = start.elapsed().as_secs_f64();
        assert!(
            out.status.success(),
            "{name}: {}\n{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(
            String::from_utf8_lossy(&out.stdout).contains("1 passed"),
            "{name}: the child ran no test: {}",
            String::from_utf8_lossy(&out.stdout)
        );
        assert!(secs < 10.0, "{name} took {secs:.1} s");
        let _ = std::io::stderr().flush();
    }
}

/// A glTF file with one triangle of corners `scale * (0,0,0), (1,0,0), (0,1,0)`, placed by a node
/// with this translation.
fn triangle_gltf(scale: f32, translation: f32) -> Vec<u8> {
    let mut bytes = Vec::new();
    for v in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
        bytes.extend_from_slice(&(v * scale).to_le_bytes());
    }
    let b64 = crate::conventions::base64(&bytes);
    gltf_with(&format!(
        r#""scene":0,"scenes":[{{"nodes":[0]}}],
        "nodes":[{{"mesh":0,"translation":[{translation:e},0,0]}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],
        "materials":[],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3",
                      "min":[0,0,0],"max":[{scale:e},{scale:e},0]}}],
        "bufferViews":[{{"buffer":0,"byteLength":36}}],
        "buffers":[{{"byteLength":36,"uri":"data:application/octet-stream;base64,{b64}"}}]"#
    ))
    .into_bytes()
}

#[test]
fn a_node_transform_cannot_carry_vertices_beyond_the_traceable_range() {
    let desc = pt_scene::gltf::load_gltf_slice(&triangle_gltf(1.0, 1e20), "far.gltf").unwrap();
    let e = desc
        .build(&pt_scene::BuildOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("far.gltf") && e.contains("instance 0") && e.contains("beyond"),
        "{e}"
    );
}

#[test]
fn a_scene_a_micrometre_across_is_framed_and_seen() {
    use pt_core::{RenderOptions, render};
    for scale in [1e-6f32, 1e-9] {
        let desc =
            pt_scene::gltf::load_gltf_slice(&triangle_gltf(scale, 0.0), "tiny.gltf").unwrap();
        let env = pt_core::UniformEnvironment::new(pt_core::Rgb::WHITE).unwrap();
        let bundle = desc
            .build(&pt_scene::BuildOptions::default().environment(env.into()))
            .unwrap();
        // The framing camera sees the triangle: some pixels are darker than the white sky.
        let out = render(
            &bundle.scene,
            &bundle.camera,
            &RenderOptions::new(16, 16).spp(4),
            None,
        )
        .unwrap();
        let shaded = out.image.pixels().filter(|p| p.r < 0.99).count();
        assert!(
            shaded > 10,
            "scale {scale}: {shaded} pixels show the triangle"
        );
    }
}

/// Messages that name the line and the problem, for the malformed files a user meets.
#[test]
fn malformed_text_files_name_the_line_and_the_problem() {
    let dir = scratch("messages");
    let tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    // Loads: a byte-order mark, old Mac and Windows line ends, `v` with w.
    for (name, bytes) in [
        ("bom.obj", [&b"\xef\xbb\xbf"[..], tri.as_bytes()].concat()),
        ("cr.obj", tri.replace('\n', "\r").into_bytes()),
        ("crlf.obj", tri.replace('\n', "\r\n").into_bytes()),
        ("w.obj", tri.replace("v 0 0 0", "v 0 0 0 1").into_bytes()),
    ] {
        let f = dir.join(name);
        std::fs::write(&f, bytes).unwrap();
        let desc = pt_scene::load_scene(&f).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(desc.meshes.len(), 1, "{name}");
    }
    // Refused, naming line and problem.
    for (name, bytes, says) in [
        ("latin1.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 \xff\nf 1 2 3\n".to_vec(), "line 3: byte 0xff is not UTF-8"),
        ("v7.obj", tri.replace("v 0 0 0", "v 0 0 0 1 1 1 1").into_bytes(), "line 1"),
        ("f2.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n".to_vec(), "line 4: a face needs at least three vertices"),
        (
            "nan.ply",
            b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar float vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 nan 2\n".to_vec(),
            "face 0: vertex index NaN",
        ),
    ] {
        let f = dir.join(name);
        std::fs::write(&f, bytes).unwrap();
        let e = load_error(&f);
        assert!(e.contains(name) && e.contains(says), "{name}: {e}");
    }
    // A truncated Radiance HDR says so.
    let Some(hdr) = pt_scene::assets::find_asset_or_skip("env/venice_sunset_1k.hdr").unwrap()
    else {
        return;
    };
    let cut = dir.join("cut.hdr");
    std::fs::write(&cut, &std::fs::read(hdr).unwrap()[..4000]).unwrap();
    let e = pt_scene::load_equirect(&cut).unwrap_err().to_string();
    assert!(e.contains("cut.hdr") && e.contains("truncated"), "{e}");
}
