//! The fuzz targets of `fuzz/` (which need nightly and cargo-fuzz) driven from stable Rust: a
//! seeded mutation loop over the real sample files, bounded in time. Each mutated input goes
//! through the same code as the targets (load, then build the scene); a panic fails the test
//! and leaves the input in `target/fuzz-failures/` with the seed that made it. An input that
//! made pt allocate without bound would abort the whole test binary, which fails CI as well.
//!
//! CI runs it for `PT_FUZZ_SECONDS` (default 4 s) per format; a longer campaign:
//! `PT_FUZZ_SECONDS=600 cargo test --release -p pt-scene --test integration fuzz_stable -- --nocapture`.
//! Mutations: bit flips, interesting bytes (0, 0xff, 0x7f, 0x80, digits, minus), inserted,
//! deleted and duplicated ranges, truncation, splices of two seeds, and, for the text formats,
//! numbers replaced by extreme ones (1e30, -1, 4294967295, nan, 1e-45).

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use pt_scene::assets::find_asset_or_skip;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

fn build(desc: pt_scene::SceneDesc) {
    let _ = desc.build(&pt_scene::BuildOptions::default());
}

/// The fuzz targets, as in `fuzz/fuzz_targets/*.rs`.
fn target(format: &str, data: &[u8]) {
    match format {
        "gltf" => {
            if let Ok(desc) = pt_scene::gltf::load_gltf_slice(data, "fuzz.glb") {
                build(desc);
            }
        }
        "obj" => {
            if let Ok(desc) = pt_scene::obj::load_obj_scene_from_bytes(data, "fuzz.obj") {
                build(desc);
            }
        }
        _ => {
            let _ = pt_scene::ply::parse_ply(data, Path::new("fuzz.ply"));
        }
    }
}

fn mutate(rng: &mut Pcg64, seeds: &[Vec<u8>], text: bool) -> Vec<u8> {
    let mut d = seeds[rng.random_range(0..seeds.len())].clone();
    for _ in 0..rng.random_range(1..=4) {
        if d.is_empty() {
            d.push(b'0');
        }
        let len = d.len();
        let at = rng.random_range(0..len);
        match rng.random_range(0..9) {
            0 => d[at] ^= 1 << rng.random_range(0..8),
            1 => d[at] = [0, 0xff, 0x7f, 0x80, b'9', b'-', b'.', b'\n'][rng.random_range(0..8)],
            2 => {
                let n = rng.random_range(1..16);
                let bytes: Vec<u8> = (0..n).map(|_| rng.random()).collect();
                d.splice(at..at, bytes);
            }
            3 => {
                let end = (at + rng.random_range(1..64)).min(len);
                d.drain(at..end);
            }
            4 => {
                let end = (at + rng.random_range(1..256)).min(len);
                let chunk = d[at..end].to_vec();
                d.splice(at..at, chunk);
            }
            5 => d.truncate(at),
            6 => {
                let other = &seeds[rng.random_range(0..seeds.len())];
                let from = rng.random_range(0..other.len().max(1));
                d.truncate(at);
                d.extend_from_slice(&other[from.min(other.len())..]);
            }
            _ if text => {
                // Replace the number that starts at or after `at` by an extreme one.
                let Some(start) = (at..len).find(|&i| d[i].is_ascii_digit()) else {
                    continue;
                };
                let end = (start..len)
                    .find(|&i| !(d[i].is_ascii_digit() || d[i] == b'.'))
                    .unwrap_or(len);
                let extreme = ["1e30", "-1", "4294967295", "nan", "1e-45", "0", "-0"];
                d.splice(
                    start..end,
                    extreme[rng.random_range(0..extreme.len())].bytes(),
                );
            }
            _ => d[at] = rng.random(),
        }
    }
    d
}

fn campaign(format: &str, files: &[&str], text: bool) {
    let mut seeds = Vec::new();
    for name in files {
        let Some(path) = find_asset_or_skip(name).unwrap() else {
            return;
        };
        seeds.push(std::fs::read(path).unwrap());
    }
    let seconds: u64 = std::env::var("PT_FUZZ_SECONDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(4);
    let budget = Duration::from_secs(seconds);
    let start = Instant::now();
    let mut runs = 0u64;
    while start.elapsed() < budget {
        let seed = runs;
        let mut rng = Pcg64::seed_from_u64(seed ^ 0x5eed);
        let input = mutate(&mut rng, &seeds, text);
        let result = std::panic::catch_unwind(|| target(format, &input));
        if result.is_err() {
            let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../target/fuzz-failures");
            let _ = std::fs::create_dir_all(&dir);
            let file = dir.join(format!("{format}-{seed}.bin"));
            let _ = std::fs::write(&file, &input);
            panic!(
                "{format}: seed {seed} panicked; input saved as {}",
                file.display()
            );
        }
        runs += 1;
    }
    use std::io::Write;
    let _ = writeln!(
        std::io::stderr(),
        "fuzz_stable {format}: {runs} inputs in {:.1} s, no panic",
        start.elapsed().as_secs_f64()
    );
}

#[test]
fn gltf_mutations_never_panic() {
    campaign(
        "gltf",
        &[
            "gltf/Box.glb",
            "gltf/BoxTextured.glb",
            "gltf/EmissiveStrengthTest.glb",
        ],
        false,
    );
}

#[test]
fn obj_mutations_never_panic() {
    campaign(
        "obj",
        &[
            "cornell/tinyobjloader/cornell_box.obj",
            "cornell/mitsuba-cbox/meshes/cbox_largebox.obj",
        ],
        true,
    );
}

#[test]
fn ply_mutations_never_panic() {
    campaign("ply", &["meshes/dragon_vrip_res3.ply"], true);
}

/// What the stable fuzzer found, kept as exact cases: a GLB header declaring a length below its
/// own 12 bytes (the `gltf` crate subtracted unchecked and panicked with overflow checks on).
#[test]
fn fuzz_findings_give_errors() {
    let mut glb = b"glTF".to_vec();
    glb.extend_from_slice(&2u32.to_le_bytes());
    for declared in [0u32, 11, 4096] {
        let mut data = glb.clone();
        data.extend_from_slice(&declared.to_le_bytes());
        data.extend_from_slice(&[0; 20]);
        let e = pt_scene::gltf::load_gltf_slice(&data, "short.glb")
            .unwrap_err()
            .to_string();
        assert!(e.contains("short.glb") && e.contains("GLB header"), "{e}");
    }
}
