//! Auxiliary outputs (albedo and normal of the first non-specular hit) and the Open Image
//! Denoise pass they guide.
//!
//! The AOVs are checked where their values are known exactly (a Lambertian wall seen directly
//! and through an ideal mirror, rays that escape), for leaving the colour untouched, and for
//! being as deterministic and mergeable as the colour. The denoiser is checked against a
//! converged reference: it must cut the relMSE of a 16-spp Cornell box at least fourfold. It
//! needs the library at run time: the test skips without it unless `PT_REQUIRE_OIDN=1` (CI sets
//! it, with `OIDN_DIR` pointing at the `pyoidn` wheel's copy).

use pt::prelude::*;

/// A camera at the origin looking down -z at a `reflectance` Lambertian quad at `z = -1`
/// (covering the view but for its right fifth), or, with `mirror`, at an ideal mirror there and
/// the Lambertian quad behind the camera at `z = 1`, facing it.
fn quads(reflectance: Rgb, mirror: bool) -> SceneBundle {
    let mut b = SceneBuilder::new();
    let quad = |z: f32, x1: f32| {
        let v = vec![
            Vec3::new(-2.0, -2.0, z),
            Vec3::new(x1, -2.0, z),
            Vec3::new(x1, 2.0, z),
            Vec3::new(-2.0, 2.0, z),
        ];
        // Front faces toward the origin.
        let tris = if z < 0.0 {
            vec![[0, 1, 2], [0, 2, 3]]
        } else {
            vec![[0, 2, 1], [0, 3, 2]]
        };
        Mesh::new(TriangleMesh::new(v, tris).unwrap())
    };
    // The view spans x in [-0.27, 0.27] at distance 1 (30 degrees); x1 = 0.16 leaves a strip.
    let wall = b.add_material(BuiltinMaterial::diffuse(reflectance));
    if mirror {
        let m = b.add_material(BuiltinMaterial::mirror(Rgb::splat(0.9)));
        let front = b.add_mesh(quad(-1.0, 0.16));
        b.add_object(Object::new(front, m));
        let back = b.add_mesh(quad(1.0, 2.0));
        b.add_object(Object::new(back, wall));
    } else {
        let front = b.add_mesh(quad(-1.0, 0.16));
        b.add_object(Object::new(front, wall));
    }
    let camera =
        PinholeCamera::look_at(Vec3::ZERO, Vec3::new(0.0, 0.0, -1.0), Vec3::Y, 30.0).unwrap();
    SceneBundle {
        scene: b.build().unwrap(),
        camera,
    }
}

#[test]
fn albedo_and_normal_of_known_surfaces() {
    let rho = Rgb::new(0.2, 0.45, 0.7);
    let options = RenderOptions::new(32, 32).spp(4).aovs(Aovs::ALL);
    for mirror in [false, true] {
        let bundle = quads(rho, mirror);
        let out = render(&bundle.scene, &bundle.camera, &options, None).unwrap();
        let (albedo, normal) = (out.albedo.unwrap(), out.normal.unwrap());
        // The wall's normal: toward the camera, or (seen in the mirror) away from it.
        let n = if mirror { -1.0 } else { 1.0 };
        for y in 0..32 {
            // Well inside the quad, and well inside the strip where rays escape.
            let (a, nrm) = (albedo.get(4, y), normal.get(4, y));
            assert!(
                (a.r - rho.r).abs() < 1e-6
                    && (a.g - rho.g).abs() < 1e-6
                    && (a.b - rho.b).abs() < 1e-6,
                "mirror {mirror}: albedo {a:?} at (4, {y}), expected {rho:?}"
            );
            assert_eq!(
                (nrm.r, nrm.g, nrm.b),
                (0.0, 0.0, n),
                "mirror {mirror}, (4, {y})"
            );
            assert_eq!(
                albedo.get(31, y),
                Rgb::BLACK,
                "escaping rays have no albedo"
            );
            assert_eq!(
                normal.get(31, y),
                Rgb::BLACK,
                "escaping rays have no normal"
            );
        }
    }
}

#[test]
fn aovs_leave_the_colour_alone_and_merge_exactly() {
    let bundle = presets::cornell_box().unwrap();
    let plain = RenderOptions::new(40, 32).spp(8).seed(3).max_depth(6);
    let with = plain.clone().aovs(Aovs::ALL);
    let a = render(&bundle.scene, &bundle.camera, &plain, None).unwrap();
    let b = render(&bundle.scene, &bundle.camera, &with, None).unwrap();
    assert_eq!(a.image, b.image, "asking for AOVs changed the colour");
    assert!(a.albedo.is_none() && b.albedo.is_some() && b.normal.is_some());
    let albedo = b.albedo.as_ref().unwrap();
    assert!(albedo.as_slice().iter().all(|v| (0.0..=1.0).contains(v)));
    assert!(
        albedo.mean().luminance() > 0.2,
        "the box's walls have albedo"
    );

    // One thread or two, and sample ranges merged through files: the same sums.
    let one = render(
        &bundle.scene,
        &bundle.camera,
        &with.clone().threads(Some(1)),
        None,
    )
    .unwrap();
    assert_eq!(one.film, b.film, "the thread count changed the AOVs");
    let dir = std::env::temp_dir().join(format!("pt-aov-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut merged = PartialRender::empty(&with, "cornell");
    for range in [3..8, 0..3] {
        let part = render(
            &bundle.scene,
            &bundle.camera,
            &with.clone().spp_range(range),
            None,
        )
        .unwrap();
        let path = dir.join("part.exr");
        PartialRender::new(&part, "cornell")
            .write_exr(&path)
            .unwrap();
        merged
            .merge(&PartialRender::read_exr(&path).unwrap())
            .unwrap();
    }
    assert_eq!(
        merged.film, b.film,
        "merged parts differ from the whole render"
    );
    assert_eq!(merged.film.albedo_image().as_ref(), b.albedo.as_ref());

    // A part without AOVs does not merge into parts with them.
    let bare = render(
        &bundle.scene,
        &bundle.camera,
        &plain.clone().spp_range(0..3),
        None,
    )
    .unwrap();
    let mut m = PartialRender::empty(&with, "cornell");
    let err = m.merge(&PartialRender::new(&bare, "cornell")).unwrap_err();
    assert!(err.to_string().contains("auxiliary"), "{err}");

    // The layered EXR holds the colour and both AOVs.
    let path = dir.join("layers.exr");
    b.write_exr(&path).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    for name in ["albedo.R", "normal.Z", "B"] {
        assert!(
            bytes.windows(name.len()).any(|w| w == name.as_bytes()),
            "{name}"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// Whether the denoiser must be there (CI), rather than skipped when it is not.
fn oidn_required() -> bool {
    std::env::var("PT_REQUIRE_OIDN").is_ok_and(|v| v == "1")
}

#[test]
fn a_missing_library_is_named() {
    let empty = std::env::temp_dir().join(format!("pt-no-oidn-{}", std::process::id()));
    std::fs::create_dir_all(&empty).unwrap();
    let err = Denoiser::from_dir(&empty).unwrap_err().to_string();
    std::fs::remove_dir_all(&empty).ok();
    if err.contains("--features denoise") {
        assert!(
            !oidn_required(),
            "PT_REQUIRE_OIDN=1 but pt was built without `denoise`"
        );
        return;
    }
    assert!(
        err.contains("OIDN_DIR") && err.contains(&*empty.to_string_lossy()),
        "{err}"
    );
}

#[test]
fn denoising_cuts_the_error_of_a_noisy_render() {
    let denoiser = match Denoiser::new() {
        Ok(d) => d,
        Err(e) if !oidn_required() => {
            eprintln!("skipped: {e}");
            return;
        }
        Err(e) => panic!("PT_REQUIRE_OIDN=1: {e}"),
    };
    let bundle = presets::cornell_box().unwrap();
    let options = RenderOptions::new(64, 64).max_depth(8).aovs(Aovs::ALL);
    let reference = render(
        &bundle.scene,
        &bundle.camera,
        &options.clone().spp(1024).seed(1),
        None,
    )
    .unwrap()
    .image;
    let noisy = render(
        &bundle.scene,
        &bundle.camera,
        &options.clone().spp(16),
        None,
    )
    .unwrap();
    let error = |image: &Image| image.difference(&reference).unwrap().rel_mse;
    let guided = denoiser
        .denoise(&noisy.image, noisy.albedo.as_ref(), noisy.normal.as_ref())
        .unwrap();
    let bare = denoiser.denoise(&noisy.image, None, None).unwrap();
    let (e_noisy, e_guided, e_bare) = (error(&noisy.image), error(&guided), error(&bare));
    eprintln!("relMSE noisy {e_noisy:.3e}, denoised {e_guided:.3e} (colour only {e_bare:.3e})");
    assert!(e_guided < 0.25 * e_noisy, "{e_guided} against {e_noisy}");
    assert!(e_bare < e_noisy, "{e_bare} against {e_noisy}");
    // The mean level is kept (a denoiser that darkened or brightened would be caught here).
    let (m, r) = (guided.mean().luminance(), reference.mean().luminance());
    assert!((m - r).abs() < 0.03 * r, "mean {m} against {r}");
    // RenderOutput::denoise is the same pass, and leaves the noisy image as it was.
    let before = noisy.image.clone();
    assert_eq!(noisy.denoise().unwrap(), guided);
    assert_eq!(noisy.image, before);
    // Guides of another size are refused, naming the guide.
    let small = Image::new(8, 8);
    let err = denoiser
        .denoise(&noisy.image, Some(&small), None)
        .unwrap_err();
    assert!(err.to_string().contains("albedo"), "{err}");
}
