//! The command-line contract of the examples (DESIGN.md section 8, docs/conventions.md): bad
//! arguments and bad input files named on the command line exit with code 2 and a message
//! naming the problem, before any rendering; absurd sizes and thread counts are refused from
//! the options alone; an unwritable `--out` is found before the render; `.PNG` is `.png`.

use std::process::Command;

use std::path::Path;

use crate::support::{Scratch, example};

/// Run `render` in `dir` on a tiny generated OBJ with `args`; the exit code and stderr.
fn render(dir: &Path, args: &[&str]) -> Option<(Option<i32>, String)> {
    let exe = example("render")?;
    let obj = dir.join("tri.obj");
    std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let env: &[&str] = if args.contains(&"--env") {
        &[]
    } else {
        &["--env", "none"]
    };
    let out = Command::new(exe)
        .arg(&obj)
        .args(["--size", "8x8", "--spp", "1"])
        .args(env)
        .args(args)
        .current_dir(dir)
        .env("PT_OFFLINE", "1")
        .output()
        .unwrap();
    Some((
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    ))
}

#[test]
fn bad_arguments_exit_2_naming_the_problem() {
    let dir = Scratch::new("cli-bad-arguments");
    for (args, says) in [
        (
            &["--look-from", "1,x,3"][..],
            "'--look-from <X,Y,Z>': expects three numbers",
        ),
        (
            &["--look-from", "1,2,3,4"],
            "'--look-from <X,Y,Z>': expects three numbers",
        ),
        (&["--fov", "0"], "field of view"),
        (&["--look-from", "0,0,1", "--look-at", "0,0,1"], "coincide"),
        (&["--env", "/nonexistent/sky.hdr"], "/nonexistent/sky.hdr"),
        (&["--threads", "100000"], "1024"),
        (&["--size", "1x100000000"], "max_film_bytes"),
        (&["--size", "16384x16384"], "max_film_bytes"),
        (&["--spp", "x"], "invalid value 'x' for '--spp <N>'"),
        (&["--spp", "0"], "'--spp <N>'"),
        (&["--size", "64"], "expects WxH"),
        (&["--shard", "4/4"], "below the count"),
        (
            &["--shard", "0/4", "--spp-range", "0..1"],
            "cannot be used with",
        ),
        (
            &["--sampler", "halton"],
            "expected independent, stratified or sobol",
        ),
        (&["--out", "/proc/pt-cannot-write-here/x.png"], "--out"),
        (&["--out", "x.tiff"], ".png or .exr"),
        (&["--frobnicate"], "unexpected argument '--frobnicate'"),
        (&["--aov", "albedo,depth"], "unknown AOV \"depth\""),
        (&["--denoise", "--shard", "0/2"], "cannot be used with"),
    ] {
        let Some((code, err)) = render(&dir, args) else {
            return;
        };
        assert_eq!(code, Some(2), "{args:?}: {err}");
        assert!(err.contains(says), "{args:?} should say {says:?}: {err}");
        // Argument errors come with the usage; bad input names the file or flag.
        if says.contains("'--") || says.contains("unexpected") || says.contains("cannot be used") {
            assert!(err.contains("Usage:"), "{args:?}: no usage in {err}");
        }
    }
}

#[test]
fn an_upper_case_png_extension_is_a_png() {
    let dir = Scratch::new("cli-upper-case");
    let Some((code, err)) = render(&dir, &["--out", "UPPER.PNG"]) else {
        return;
    };
    assert_eq!(code, Some(0), "{err}");
}

/// `--aov` writes the AOVs beside a PNG (as layers of an EXR); `--denoise` writes the denoised
/// image beside the unbiased one, or, where pt was built without the feature or the library is
/// missing, exits 2 before rendering, saying which (`PT_REQUIRE_OIDN=1`: it must work).
#[test]
fn aovs_and_the_denoised_image_go_beside_the_image() {
    let dir = Scratch::new("cli-aov");
    let Some((code, err)) = render(&dir, &["--aov", "albedo,normal", "--out", "aov.png"]) else {
        return;
    };
    assert_eq!(code, Some(0), "{err}");
    for name in ["aov.png", "aov.albedo.png", "aov.normal.png"] {
        assert!(dir.join(name).is_file(), "{name} not written");
    }
    let (code, err) = render(&dir, &["--denoise", "--out", "dn.exr"]).unwrap();
    let required = std::env::var("PT_REQUIRE_OIDN").is_ok_and(|v| v == "1");
    if code == Some(0) {
        assert!(dir.join("dn.exr").is_file() && dir.join("dn.denoised.exr").is_file());
    } else {
        assert!(!required, "PT_REQUIRE_OIDN=1 but --denoise failed: {err}");
        assert_eq!(code, Some(2), "{err}");
        assert!(
            err.contains("OIDN_DIR") || err.contains("--features denoise"),
            "{err}"
        );
        assert!(
            !dir.join("dn.exr").exists(),
            "rendered before failing: {err}"
        );
    }
}

#[test]
fn a_missing_scene_file_exits_2() {
    let Some(exe) = example("render") else {
        return;
    };
    let out = Command::new(exe)
        .arg("/nonexistent/scene.gltf")
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("/nonexistent/scene.gltf"));
}

#[test]
fn merge_refuses_parts_with_negative_sums() {
    let Some(exe) = example("merge") else {
        return;
    };
    let dir = Scratch::new("cli-merge");
    let mut film = pt::pt_core::Film::new(2, 1);
    film.add_sample(0, 0, pt::pt_core::Rgb::splat(0.5));
    film.add_sample(1, 0, pt::pt_core::Rgb::new(-3.0, 0.0, 0.0));
    // The part holds sample 0 of 2 (one range).
    let held = 0..1;
    let part = pt::pt_core::PartialRender {
        film,
        spp: 2,
        seed: 0,
        ranges: vec![held],
        label: "edited".into(),
    };
    let file = dir.join("edited.0-1.exr");
    part.write_exr(&file).unwrap();
    let out = Command::new(exe)
        .arg(&file)
        .args(["--out", dir.join("m.exr").to_str().unwrap()])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("edited.0-1.exr") && err.contains("negative"),
        "{err}"
    );
}
