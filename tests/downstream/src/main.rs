//! Builds a scene, renders 16x16 pixels and reads them back, using only what `pt` exports. With
//! `--features full` it also writes PNG and EXR files and stores the options as JSON and reads
//! them back.

use std::sync::atomic::AtomicBool;

use pt::prelude::*;
use pt::pt_accel::TriangleMesh;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // A scene built in code: a diffuse floor under an emitting quad.
    let mut b = SceneBuilder::new();
    let quad = |y: f32, s: f32| {
        TriangleMesh::new(
            vec![
                Vec3::new(-s, y, -s),
                Vec3::new(s, y, -s),
                Vec3::new(s, y, s),
                Vec3::new(-s, y, s),
            ],
            vec![[0, 2, 1], [0, 3, 2]],
        )
    };
    let floor = b.add_mesh(Mesh::new(quad(0.0, 2.0)?));
    let lamp = b.add_mesh(Mesh::new(quad(1.5, 0.5)?));
    let grey = b.add_material(BuiltinMaterial::diffuse(Rgb::splat(0.5)));
    let glass = b.add_material(Glass::new(1.5)?);
    b.add_object(Object::new(floor, grey));
    b.add_object(
        Object::new(lamp, glass).with_emission(Emission::new(Rgb::splat(4.0)).two_sided()),
    );
    let scene = b.build()?;
    let camera = PinholeCamera::look_at(Vec3::new(0.0, 1.0, 3.0), Vec3::ZERO, Vec3::Y, 50.0)?;

    let options = RenderOptions::new(16, 16).spp(8).seed(1);
    let cancel = AtomicBool::new(false);
    let out = render(
        &scene,
        &camera,
        &options,
        Some(&RenderControl::new().cancel(&cancel)),
    )?;
    let pixels: &[f32] = out.image.as_slice();
    assert_eq!(pixels.len(), 16 * 16 * 3);
    assert!(pixels.iter().all(|v| v.is_finite() && *v >= 0.0));
    assert!(out.image.mean().g > 0.0, "the floor is lit");
    assert_eq!(out.stats.non_finite_samples, 0);

    // A preset scene and a partial render, merged.
    let bundle = presets::cornell_box()?;
    let whole = RenderOptions::new(16, 16).spp(4);
    let mut merged = PartialRender::empty(&whole, "cornell");
    for range in [0..2, 2..4] {
        let part = render(
            &bundle.scene,
            &bundle.camera,
            &whole.clone().spp_range(range),
            None,
        )?;
        merged.merge(&PartialRender::new(&part, "cornell"))?;
    }
    assert_eq!(
        merged.film,
        render(&bundle.scene, &bundle.camera, &whole, None)?.film
    );

    #[cfg(feature = "full")]
    {
        let stored = serde_json::to_string(&options)?;
        let restored: RenderOptions = serde_json::from_str(&stored)?;
        assert_eq!(restored, options);
        let dir = std::env::temp_dir().join("pt-downstream-check");
        std::fs::create_dir_all(&dir)?;
        out.image.write(dir.join("out.png"))?;
        out.image.write(dir.join("out.exr"))?;

        // AOVs as EXR layers, and the denoiser where the library is there.
        let guided = render(&scene, &camera, &options.clone().aovs(Aovs::ALL), None)?;
        assert_eq!(guided.image, out.image, "AOVs do not change the colour");
        guided.write_exr(dir.join("layers.exr"))?;
        match guided.denoise() {
            Ok(clean) => assert_eq!(clean.width(), 16),
            Err(e) if std::env::var_os("PT_REQUIRE_OIDN").is_none() => {
                assert!(e.to_string().contains("OIDN_DIR"), "{e}");
            }
            Err(e) => return Err(e.into()),
        }
        std::fs::remove_dir_all(&dir)?;
    }
    println!("pt-downstream-check: {}", out.stats);
    Ok(())
}
