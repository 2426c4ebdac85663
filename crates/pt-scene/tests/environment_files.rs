//! Environment map files: an OpenEXR map survives a write/read round trip, 8-bit faces are
//! decoded from sRGB, and bad files give errors that name the file and the problem.

use pt_core::glam::Vec3;
use pt_core::{Image, Light, LightSampleContext, Rgb};
use pt_scene::LoadError;
use pt_scene::assets::find_asset_or_skip;

use crate::support::Scratch;

fn scratch(name: &str) -> Scratch {
    Scratch::new(&format!("env-{name}"))
}

#[test]
fn exr_map_round_trips() {
    let mut img = Image::new(8, 4);
    for y in 0..4 {
        for x in 0..8 {
            img.set(x, y, Rgb::new(x as f32 * 0.5, y as f32 * 2.0, 100.0));
        }
    }
    let dir = scratch("exr");
    let path = dir.join("map.exr");
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

/// 8-bit colour maps (decoded by table) hold exactly what decoding each channel through
/// `image`'s float conversion and `srgb_to_linear` gives, for every byte value, in RGB and RGBA
/// PNGs; grey ones too (they take the float path).
#[test]
fn eight_bit_maps_decode_every_value_exactly() {
    let dir = scratch("eight-bit");
    let rgb = image::RgbImage::from_fn(256, 2, |x, y| {
        let v = x as u8;
        image::Rgb([v, 255 - v, if y == 0 { v / 2 } else { v.rotate_left(3) }])
    });
    let rgba = image::RgbaImage::from_fn(256, 1, |x, _| {
        let v = x as u8;
        image::Rgba([255 - v, v, v ^ 0x5a, 17])
    });
    let grey = image::GrayImage::from_fn(256, 1, |x, _| image::Luma([x as u8]));
    for (name, img) in [
        ("rgb.png", image::DynamicImage::ImageRgb8(rgb)),
        ("rgba.png", image::DynamicImage::ImageRgba8(rgba)),
        ("grey.png", image::DynamicImage::ImageLuma8(grey)),
    ] {
        let path = dir.join(name);
        img.save(&path).unwrap();
        let loaded = pt_scene::load_image_linear(&path).unwrap();
        let expected: Vec<f32> = img
            .into_rgb32f()
            .into_raw()
            .into_iter()
            .map(pt_core::color::srgb_to_linear)
            .collect();
        let got: Vec<f32> = (0..loaded.height())
            .flat_map(|y| (0..loaded.width()).map(move |x| (x, y)))
            .flat_map(|(x, y)| {
                let c = loaded.get(x, y);
                [c.r, c.g, c.b]
            })
            .collect();
        assert_eq!(
            got.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            expected.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            "{name}"
        );
    }
}

#[test]
fn truncated_hdr_is_a_clear_error() {
    let Some(src) = find_asset_or_skip("env/venice_sunset_1k.hdr").unwrap() else {
        return;
    };
    let bytes = std::fs::read(src).unwrap();
    let dir = scratch("trunc");
    let path = dir.join("half.hdr");
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
    let msg = pt_scene::load_cubemap(&*dir).unwrap_err().to_string();
    assert!(msg.contains("cube face px"), "{msg}");
}

#[test]
fn negative_texels_are_rejected_with_their_position() {
    let mut img = Image::new(4, 2);
    img.set(2, 1, Rgb::new(-1.0, 0.0, 0.0));
    let dir = scratch("neg");
    let path = dir.join("neg.exr");
    img.write_exr(&path).unwrap();
    let msg = pt_scene::load_equirect(&path).unwrap_err().to_string();
    assert!(
        msg.contains("neg.exr") && msg.contains("texel (2, 1)"),
        "{msg}"
    );
}
