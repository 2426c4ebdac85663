//! The `pt` command as a user runs it: the command-line contract of DESIGN.md section 8 (bad
//! arguments exit 2 with the usage, the summary line's format, every flag reaching the render),
//! shards that merge bit for bit into the single render, `merge --expect`, duplicated shards,
//! `info`, `completions` and `--version`.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn pt(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pt"))
        .args(args)
        .current_dir(dir)
        .env("PT_OFFLINE", "1")
        .env_remove("PT_SHARD_INDEX")
        .env_remove("SLURM_ARRAY_TASK_ID")
        .env_remove("JOB_COMPLETION_INDEX")
        .output()
        .expect("pt runs")
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

/// A scratch folder with a small lit OBJ scene (a floor and a one-sided lamp facing it).
fn scene(tag: &str) -> (PathBuf, PathBuf) {
    let dir = std::env::temp_dir().join(format!("pt-cli-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("room.mtl"),
        "newmtl grey\nKd 0.6 0.6 0.6\nnewmtl lamp\nKd 0 0 0\nKe 8 8 8\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("room.obj"),
        "mtllib room.mtl\n\
         v -2 0 -2\nv 2 0 -2\nv 2 0 2\nv -2 0 2\n\
         v -0.5 2 -0.5\nv 0.5 2 -0.5\nv 0.5 2 0.5\nv -0.5 2 0.5\n\
         usemtl grey\nf 1 3 2\nf 1 4 3\n\
         usemtl lamp\nf 5 6 7\nf 5 7 8\n",
    )
    .unwrap();
    let file = dir.join("room.obj");
    (dir, file)
}

const VIEW: [&str; 6] = [
    "--look-from",
    "0,1,5",
    "--look-at",
    "0,0.5,0",
    "--env",
    "none",
];

#[test]
fn bad_arguments_exit_2_with_the_usage() {
    let (dir, file) = scene("usage");
    let f = file.to_str().unwrap();
    for args in [
        &["render"][..],
        &["render", f, "--spp", "0"],
        &["render", f, "--spp", "many"],
        &["render", f, "--shard", "1/0"],
        &["render", f, "--shard", "1"],
        &["render", f, "--frobnicate"],
        &["merge", "--out", "x.png"],
        &["merge", "a.exr", "--out", "x.png", "--expect", "0"],
        &["frobnicate"],
        &["completions", "tcsh"],
        &["render", f, "--camera-from-file", "--up", "0,0,1"],
    ] {
        let out = pt(&dir, args);
        let err = text(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains("Usage:"), "{args:?}: no usage in {err}");
    }
    // Bad input named on the command line: exit 2, naming it.
    let out = pt(&dir, &["render", "/nonexistent/scene.glb"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("/nonexistent/scene.glb"));
    let out = pt(&dir, &["render", f, "--up", "0,0,0"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("--up 0,0,0 is not a direction"));
    let out = pt(&dir, &["render", f, "--fov", "0"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("field of view 0 degrees"));
    let out = pt(&dir, &["render", f, "--shard", "env/4"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("SLURM_ARRAY_TASK_ID"));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_summary_line_and_every_flag() {
    let (dir, file) = scene("flags");
    let f = file.to_str().unwrap();
    let mut args = vec![
        "render", f, "--size", "12x8", "--spp", "3", "--out", "a.png",
    ];
    args.extend(VIEW);
    let out = pt(&dir, &args);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let line = text(&out.stdout);
    // `<name>: <W>x<H>, <N> spp, <T> s, <X> Msamples/s, <Y> Mrays/s, <K> non-finite samples dropped`
    let rest = line.strip_prefix("pt: 12x8, 3 spp, ").expect(&line);
    let parts: Vec<&str> = rest.splitn(5, ", ").collect();
    assert!(parts[0].ends_with(" s") && parts[0][..parts[0].len() - 2].parse::<f64>().is_ok());
    assert!(parts[1].ends_with(" Msamples/s"), "{line}");
    assert!(parts[2].ends_with(" Mrays/s"), "{line}");
    assert!(parts[3].ends_with(" non-finite samples dropped"), "{line}");
    assert!(dir.join("a.png").is_file());

    // Every render flag reaches the render (the JSON summary reports what was rendered).
    let mut args = vec![
        "render",
        f,
        "--size",
        "10x6",
        "--spp",
        "8",
        "--max-depth",
        "2",
        "--seed",
        "7",
        "--threads",
        "1",
        "--clamp",
        "0.5",
        "--sampler",
        "independent",
        "--strategy",
        "light",
        "--adaptive",
        "0.5",
        "--adaptive-min",
        "4",
        "--out",
        "b.exr",
        "--json",
    ];
    args.extend(VIEW);
    let out = pt(&dir, &args);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["width"], 10);
    assert_eq!(json["height"], 6);
    assert_eq!(json["spp"], 8);
    assert_eq!(json["seed"], 7);
    assert!(json["clamped_samples"].as_u64().unwrap() > 0, "{json}");
    assert!(json["adaptive_saved"].as_f64().unwrap() > 0.0, "{json}");
    assert!(json["samples"].as_u64().unwrap() < 10 * 6 * 8);
    assert!(dir.join("b.exr").is_file());
    // --up and --fov alone change the camera that frames the scene, and nothing else: at
    // their defaults it is the default framing, bit for bit (a Z-up view of this Y-up room
    // looks at the floor from below, where no light falls).
    let framed = |name: &str, flags: &[&str]| {
        let mut args = vec!["render", f, "--size", "8x6", "--spp", "1", "--env", "none"];
        args.extend(flags);
        args.extend(["--out", name]);
        let out = pt(&dir, &args);
        assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
        std::fs::read(dir.join(name)).unwrap()
    };
    let default = framed("d.png", &[]);
    assert_eq!(framed("y.png", &["--up", "0,1,0", "--fov", "40"]), default);
    assert_ne!(framed("z.png", &["--up", "0,0,1"]), default);
    assert_ne!(framed("f.png", &["--fov", "20"]), default);
    // --quiet prints nothing on success.
    let mut args = vec!["render", f, "--size", "4x4", "--spp", "1", "--quiet"];
    args.extend(VIEW);
    let out = pt(&dir, &args);
    assert_eq!(out.status.code(), Some(0));
    assert!(out.stdout.is_empty(), "{}", text(&out.stdout));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn shards_merge_into_the_single_render_bit_for_bit() {
    let (dir, file) = scene("shards");
    let f = file.to_str().unwrap();
    let base = |extra: &[&str]| {
        let mut a = vec!["render", f, "--size", "24x16", "--spp", "10", "--quiet"];
        a.extend(VIEW);
        a.extend(extra);
        a.into_iter().map(String::from).collect::<Vec<_>>()
    };
    let run = |args: &[String], env: Option<(&str, &str)>| {
        let mut c = Command::new(env!("CARGO_BIN_EXE_pt"));
        c.args(args).current_dir(&dir).env("PT_OFFLINE", "1");
        for v in [
            "PT_SHARD_INDEX",
            "SLURM_ARRAY_TASK_ID",
            "JOB_COMPLETION_INDEX",
        ] {
            c.env_remove(v);
        }
        if let Some((k, v)) = env {
            c.env(k, v);
        }
        let out = c.output().unwrap();
        assert_eq!(
            out.status.code(),
            Some(0),
            "{args:?}: {}",
            text(&out.stderr)
        );
    };
    // Shard 0 given, shards 1-3 from the three schedulers' variables; 10 spp over 3 and 4
    // shards of unequal length.
    run(&base(&["--shard", "0/4"]), None);
    run(&base(&["--shard", "env/4"]), Some(("PT_SHARD_INDEX", "1")));
    run(
        &base(&["--shard", "env/4"]),
        Some(("SLURM_ARRAY_TASK_ID", "2")),
    );
    run(
        &base(&["--shard", "env/4"]),
        Some(("JOB_COMPLETION_INDEX", "3")),
    );
    let parts: Vec<String> = ["0-2", "2-5", "5-7", "7-10"]
        .iter()
        .map(|r| format!("out/render.{r}.exr"))
        .collect();
    for p in &parts {
        assert!(dir.join(p).is_file(), "{p}");
    }
    // The whole render, as one part holding every sample.
    run(&base(&["--spp-range", "0..10", "--out", "whole.exr"]), None);
    let mut merge: Vec<&str> = vec!["merge"];
    merge.extend(parts.iter().map(String::as_str));
    merge.extend(["--expect", "4", "--out", "merged.exr"]);
    let out = pt(&dir, &merge);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert!(text(&out.stdout).contains("complete"));
    let (a, b) = (
        std::fs::read(dir.join("whole.exr")).unwrap(),
        std::fs::read(dir.join("merged.exr")).unwrap(),
    );
    assert!(a == b, "the merged shards differ from the single render");

    // A retried shard (the same part twice) is used once; an incomplete set is refused with
    // what is missing.
    let mut again = merge.clone();
    again.insert(2, parts[1].as_str());
    let out = pt(&dir, &again);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert!(text(&out.stdout).contains("used once"));
    assert_eq!(std::fs::read(dir.join("merged.exr")).unwrap(), a);
    let out = pt(
        &dir,
        &[
            "merge", &parts[0], &parts[2], "--expect", "4", "--out", "x.exr",
        ],
    );
    assert_eq!(out.status.code(), Some(2));
    let err = text(&out.stderr);
    assert!(
        err.contains("shard 1/4 = samples 2..5") && err.contains("shard 3/4 = samples 7..10"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn info_completions_and_version() {
    let (dir, file) = scene("info");
    let out = pt(&dir, &["info", file.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let s = text(&out.stdout);
    assert!(
        s.contains("4 unique triangles") && s.contains("1 emissive"),
        "{s}"
    );
    let out = pt(&dir, &["info", file.to_str().unwrap(), "--json"]);
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["unique_triangles"], 4);
    assert_eq!(json["scene_lights"], 2);
    assert_eq!(json["materials"]["Diffuse"], 2);
    let out = pt(&dir, &["completions", "bash"]);
    assert_eq!(out.status.code(), Some(0));
    assert!(text(&out.stdout).contains("_pt"));
    let out = pt(&dir, &["--version"]);
    assert_eq!(out.status.code(), Some(0));
    assert_eq!(
        text(&out.stdout).trim(),
        format!("pt {}", env!("CARGO_PKG_VERSION"))
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Shards rendered with `--aov` merge with their AOVs (a shard without them is refused), and
/// `merge --denoise` writes the denoised image beside the merge, or, without the feature or the
/// library (and not `PT_REQUIRE_OIDN=1`), exits 2 naming what is missing before merging.
#[test]
fn shards_with_aovs_merge_and_denoise() {
    let (dir, file) = scene("aov-shards");
    let f = file.to_str().unwrap();
    for (shard, aov) in [("0/2", true), ("1/2", true), ("1/2", false)] {
        let mut args = vec!["render", f, "--size", "16x12", "--spp", "4", "--quiet"];
        args.extend(VIEW);
        args.extend(["--shard", shard]);
        let out_dir = if aov { "parts/" } else { "bare/" };
        args.extend(["--out", out_dir]);
        if aov {
            args.extend(["--aov", "albedo,normal"]);
        }
        let out = pt(&dir, &args);
        assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    }
    let mixed = pt(
        &dir,
        &[
            "merge",
            "parts/render.0-2.exr",
            "bare/render.2-4.exr",
            "--out",
            "x.exr",
        ],
    );
    assert_eq!(mixed.status.code(), Some(2));
    assert!(
        text(&mixed.stderr).contains("auxiliary"),
        "{}",
        text(&mixed.stderr)
    );

    let out = pt(
        &dir,
        &[
            "merge",
            "parts/render.0-2.exr",
            "parts/render.2-4.exr",
            "--out",
            "m.png",
            "--denoise",
        ],
    );
    let err = text(&out.stderr);
    if out.status.code() == Some(0) {
        assert!(dir.join("m.png").is_file() && dir.join("m.denoised.png").is_file());
        assert!(
            text(&out.stdout).contains("denoised in"),
            "{}",
            text(&out.stdout)
        );
    } else {
        let required = std::env::var("PT_REQUIRE_OIDN").is_ok_and(|v| v == "1");
        assert!(
            !required,
            "PT_REQUIRE_OIDN=1 but merge --denoise failed: {err}"
        );
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert!(
            err.contains("OIDN_DIR") || err.contains("--features denoise"),
            "{err}"
        );
        assert!(!dir.join("m.png").exists(), "merged before failing: {err}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn fov_changes_a_file_cameras_lens_and_up_leaves_it_alone() {
    let dir = std::env::temp_dir().join(format!("pt-cli-camera-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    // An emissive triangle, and a camera at (0, 0, 3) looking down -z.
    let corners: Vec<u8> = [-1.0f32, -1.0, 0.0, 1.0, -1.0, 0.0, 0.0, 1.0, 0.0]
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    std::fs::write(dir.join("tri.bin"), corners).unwrap();
    std::fs::write(
        dir.join("cam.gltf"),
        r#"{"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0,1]}],
        "nodes":[{"mesh":0},{"camera":0,"translation":[0,0,3]}],
        "cameras":[{"type":"perspective","perspective":{"yfov":0.6,"znear":0.1}}],
        "meshes":[{"primitives":[{"attributes":{"POSITION":0},"material":0}]}],
        "materials":[{"emissiveFactor":[1,1,1]}],
        "accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3",
                      "min":[-1,-1,0],"max":[1,1,0]}],
        "bufferViews":[{"buffer":0,"byteLength":36}],
        "buffers":[{"byteLength":36,"uri":"tri.bin"}]}"#,
    )
    .unwrap();
    let render = |name: &str, flags: &[&str]| {
        let mut args = vec!["render", "cam.gltf", "--size", "8x6", "--spp", "1"];
        args.extend(["--env", "none", "--out", name]);
        args.extend(flags);
        let out = pt(&dir, &args);
        assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
        (std::fs::read(dir.join(name)).unwrap(), text(&out.stderr))
    };
    let (file, _) = render("file.png", &[]);
    let (wide, _) = render("wide.png", &["--fov", "60"]);
    let (placed, _) = render(
        "placed.png",
        &["--look-from", "0,0,3", "--look-at", "0,0,2", "--fov", "60"],
    );
    // The file's view through a 60-degree lens: the same camera placed by hand.
    assert_ne!(wide, file);
    assert_eq!(wide, placed);
    let (rolled, err) = render("rolled.png", &["--up", "1,0,0"]);
    assert_eq!(rolled, file);
    assert!(
        err.contains("--up has no effect on the camera of cam.gltf"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
