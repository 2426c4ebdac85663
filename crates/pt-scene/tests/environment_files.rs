//! Environment map files: an OpenEXR map survives a write/read round trip, 8-bit faces are
//! decoded from sRGB, and bad files give errors that name the file and the problem.

use std::path::PathBuf;

use pt_core::glam::Vec3;
use pt_core::{Image, Light, LightSampleContext, Rgb};
use pt_scene::LoadError;
use pt_scene::assets::find_asset_or_skip;

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("pt-env-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn exr_map_round_trips() {
    let mut img = Image::new(8, 4);
    for y in 0..4 {
        for x in 0..8 {
            img.set(x, y, Rgb::new(x as f32 * 0.5, y as f32 * 2.0, 100.0));
        }
    }
    let path = scratch("exr").join("map.exr");
    img.write_exr(&path).unwrap();
    let env = pt_scene::load_equirect(&path).unwrap();
    assert_eq!(env.image(), &img, "linear values kept exactly");
    // Straight up is row 0; the map's centre column looks toward -z.
    let up = env.radiance(Vec3::Y);
    assert_eq!(up.g, 0.0);
    assert!(env.pdf_li(&LightSampleContext::default(), Vec3::NEG_Z) > 0.0);
}

#[test]
fn eight_bit_faces_are_decoded_from_srgb() {
    let Some(face) = find_asset_or_skip("env/cubemap-Park3Med/px.jpg").unwrap() else {
        return;
    };
    let img = pt_scene::load_image_linear(&face).unwrap();
    let raw = image::open(&face).unwrap().to_rgb8();
    let p = raw.get_pixel(100, 200);
    let expected = pt_core::color::srgb_to_linear(f32::from(p[0]) / 255.0);
    assert!((img.get(100, 200).r - expected).abs() < 1e-6);
}

#[test]
fn truncated_hdr_is_a_clear_error() {
    let Some(src) = find_asset_or_skip("env/venice_sunset_1k.hdr").unwrap() else {
        return;
    };
    let bytes = std::fs::read(src).unwrap();
    let path = scratch("trunc").join("half.hdr");
    std::fs::write(&path, &bytes[..bytes.len() / 2]).unwrap();
    let e = pt_scene::load_equirect(&path).unwrap_err();
    let msg = e.to_string();
    assert!(msg.contains("half.hdr"), "{msg}");
    assert!(
        matches!(e, LoadError::Parse { .. } | LoadError::Io { .. }),
        "{e:?}"
    );
}

#[test]
fn not_an_image_and_missing_files_are_errors() {
    let dir = scratch("bad");
    let path = dir.join("notes.hdr");
    std::fs::write(&path, b"this is not a Radiance file").unwrap();
    let msg = pt_scene::load_equirect(&path).unwrap_err().to_string();
    assert!(msg.contains("notes.hdr"), "{msg}");
    let msg = pt_scene::load_equirect(dir.join("absent.exr"))
        .unwrap_err()
        .to_string();
    assert!(msg.contains("absent.exr"), "{msg}");
    // A cube map directory without its faces names the first missing face.
    let msg = pt_scene::load_cubemap(&dir).unwrap_err().to_string();
    assert!(msg.contains("cube face px"), "{msg}");
}

#[test]
fn negative_texels_are_rejected_with_their_position() {
    let mut img = Image::new(4, 2);
    img.set(2, 1, Rgb::new(-1.0, 0.0, 0.0));
    let path = scratch("neg").join("neg.exr");
    img.write_exr(&path).unwrap();
    let msg = pt_scene::load_equirect(&path).unwrap_err().to_string();
    assert!(
        msg.contains("neg.exr") && msg.contains("texel (2, 1)"),
        "{msg}"
    );
}
