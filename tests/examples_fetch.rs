//! The examples as a newcomer runs them, on a machine with no assets: a local HTTP server on
//! 127.0.0.1 stands in for the network (`PT_ASSETS_MIRROR`), serving the real files. An example
//! run with an empty cache fetches the asset, verifies it and renders; a second run uses the
//! cache and asks the server for nothing; a corrupted download is refused, exit code 1, and
//! nothing is left in the cache; offline, the message names the asset, its URL, the cache and
//! the variables that provide it. `render` lights a file that has no lights with the default
//! environment and says so; `--env none` keeps it dark.
//!
//! The examples are separate programs: `.ci/run` builds the ones tested here (`cargo build --example ...`) before
//! the tests. Run alone, these tests skip, saying so, when the example binaries are not built.

use std::io::{BufRead, BufReader, Write};
use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

use crate::support::{Scratch, example};
use pt::pt_scene::assets::find_asset_or_skip;

/// Serve `routes` (path, body) on 127.0.0.1, counting the requests.
fn serve(routes: Vec<(String, Vec<u8>)>) -> (String, Arc<AtomicUsize>) {
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = listener.local_addr().unwrap();
    let count = Arc::new(AtomicUsize::new(0));
    let seen = count.clone();
    std::thread::spawn(move || {
        for stream in listener.incoming() {
            let Ok(mut stream) = stream else { continue };
            seen.fetch_add(1, Ordering::SeqCst);
            let mut reader = BufReader::new(stream.try_clone().unwrap());
            let mut request = String::new();
            let _ = reader.read_line(&mut request);
            let mut line = String::new();
            while reader.read_line(&mut line).is_ok_and(|n| n > 2) {
                line.clear();
            }
            let path = request.split_whitespace().nth(1).unwrap_or("/");
            let body = routes.iter().find(|(p, _)| p == path).map(|(_, b)| b);
            let head = match body {
                Some(b) => format!("HTTP/1.1 200 OK\r\nContent-Length: {}\r\n", b.len()),
                None => "HTTP/1.1 404 Not Found\r\nContent-Length: 0\r\n".to_string(),
            };
            let _ = stream.write_all(format!("{head}Connection: close\r\n\r\n").as_bytes());
            let _ = stream.write_all(body.map_or(&[][..], Vec::as_slice));
        }
    });
    (format!("http://{addr}"), count)
}

/// A fresh folder standing for a new user's home (cache inside) and working folder, removed
/// after the test.
fn home(name: &str) -> Scratch {
    Scratch::new(&format!("newcomer-{name}"))
}

/// Run `exe` as a new user would: no assets folder, an empty cache in `home`, `vars` added.
fn run_fresh(exe: &Path, home: &Path, args: &[&str], vars: &[(&str, &str)]) -> Output {
    let mut cmd = Command::new(exe);
    cmd.args(args)
        .current_dir(home)
        .env_remove("PT_ASSETS_DIR")
        .env_remove("PT_ASSETS_MIRROR")
        .env_remove("PT_OFFLINE")
        .env_remove("RUST_LOG")
        .env("HOME", home)
        .env("XDG_CACHE_HOME", home.join("cache"));
    for (k, v) in vars {
        cmd.env(k, v);
    }
    cmd.output().unwrap()
}

fn text(out: &Output) -> String {
    format!(
        "exit {:?}\nstdout: {}\nstderr: {}",
        out.status.code(),
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    )
}

/// Everything below the folder, as paths relative to it.
fn files_under(dir: &Path) -> Vec<PathBuf> {
    let mut found = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).into_iter().flatten().flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else {
                found.push(p.strip_prefix(dir).unwrap().to_path_buf());
            }
        }
    }
    found
}

const BUNNY: &str = "meshes/stanford-bunny.obj";
const SMALL: [&str; 6] = ["--size", "16x16", "--spp", "1", "--out", "out.png"];

#[test]
fn an_example_fetches_its_asset_on_first_use_then_uses_the_cache() {
    let Some(exe) = example("specular_bunny") else {
        return;
    };
    let Some(bunny) = find_asset_or_skip(BUNNY).unwrap() else {
        return;
    };
    let bytes = std::fs::read(bunny).unwrap();
    let (base, requests) = serve(vec![(format!("/{BUNNY}"), bytes.clone())]);
    let home = home("fetch");
    let mirror = [("PT_ASSETS_MIRROR", base.as_str())];

    let first = run_fresh(&exe, &home, &SMALL, &mirror);
    assert!(first.status.success(), "{}", text(&first));
    let err = String::from_utf8_lossy(&first.stderr);
    assert!(
        err.contains(&format!("fetching asset {BUNNY}")) && err.contains(&base),
        "one line says what is fetched from where: {}",
        text(&first)
    );
    let cached = home.join("cache/pt/assets").join(BUNNY);
    assert_eq!(
        std::fs::read(&cached).unwrap(),
        bytes,
        "verified and cached"
    );
    assert!(home.join("out.png").is_file(), "and rendered");
    assert_eq!(requests.load(Ordering::SeqCst), 1);
    assert_eq!(
        files_under(&home.join("cache")),
        vec![Path::new("pt/assets").join(BUNNY)],
        "nothing else is left in the cache"
    );

    let second = run_fresh(&exe, &home, &SMALL, &mirror);
    assert!(second.status.success(), "{}", text(&second));
    assert!(!String::from_utf8_lossy(&second.stderr).contains("fetching"));
    assert_eq!(
        requests.load(Ordering::SeqCst),
        1,
        "the second run uses the cache"
    );
}

#[test]
fn a_corrupted_download_is_refused_and_nothing_is_cached() {
    let Some(exe) = example("specular_bunny") else {
        return;
    };
    let Some(bunny) = find_asset_or_skip(BUNNY).unwrap() else {
        return;
    };
    let mut bytes = std::fs::read(bunny).unwrap();
    bytes[1000] ^= 0x20;
    let (base, _) = serve(vec![(format!("/{BUNNY}"), bytes)]);
    let home = home("corrupt");
    let out = run_fresh(&exe, &home, &SMALL, &[("PT_ASSETS_MIRROR", &base)]);
    assert_eq!(out.status.code(), Some(1), "{}", text(&out));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("sha256") && err.contains(BUNNY),
        "{}",
        text(&out)
    );
    assert_eq!(files_under(&home.join("cache")), Vec::<PathBuf>::new());
    assert!(!home.join("out.png").exists());
}

#[test]
fn offline_the_message_says_what_is_missing_and_how_to_provide_it() {
    let Some(exe) = example("specular_bunny") else {
        return;
    };
    let home = home("offline");
    let out = run_fresh(&exe, &home, &SMALL, &[("PT_OFFLINE", "1")]);
    assert_eq!(out.status.code(), Some(1), "{}", text(&out));
    let err = String::from_utf8_lossy(&out.stderr);
    let cache = home.join("cache/pt/assets");
    for needle in [
        BUNNY,
        "https://raw.githubusercontent.com/",
        cache.to_str().unwrap(),
        "PT_ASSETS_DIR",
        "PT_ASSETS_MIRROR",
        "PT_OFFLINE",
    ] {
        assert!(err.contains(needle), "names {needle}: {}", text(&out));
    }
}

#[test]
fn fetch_assets_lists_every_known_asset() {
    let Some(exe) = example("fetch_assets") else {
        return;
    };
    let home = home("list");
    let out = run_fresh(&exe, &home, &["--list"], &[]);
    assert!(out.status.success(), "{}", text(&out));
    let listing = String::from_utf8_lossy(&out.stdout);
    for a in pt::pt_scene::assets::MANIFEST {
        assert!(listing.contains(a.name), "lists {}: {listing}", a.name);
    }
    assert!(listing.contains("missing"), "{listing}");
}

#[test]
fn render_lights_a_file_without_lights_and_says_so() {
    let Some(exe) = example("render") else {
        return;
    };
    let Some(file) = find_asset_or_skip("gltf/Box.glb").unwrap() else {
        return;
    };
    let Some(studio) = find_asset_or_skip("env/studio_small_03_1k.hdr").unwrap() else {
        return;
    };
    let assets = studio.parent().and_then(Path::parent).unwrap();
    let home = home("unlit");
    let file = file.to_str().unwrap();
    let dir = [("PT_ASSETS_DIR", assets.to_str().unwrap())];
    let mean = |args: &[&str]| {
        let out = run_fresh(&exe, &home, args, &dir);
        assert!(out.status.success(), "{}", text(&out));
        let img = pt::pt_scene::load_image_linear(home.join("out.exr")).unwrap();
        let px = img.as_slice();
        let mean = px.iter().map(|&v| f64::from(v)).sum::<f64>() / px.len() as f64;
        (String::from_utf8_lossy(&out.stdout).into_owned(), mean)
    };
    let small = ["--size", "24x24", "--spp", "2", "--out", "out.exr"];
    let (summary, lit) = mean(&[&[file][..], &small].concat());
    assert!(
        summary.contains("lit by the studio environment"),
        "{summary}"
    );
    assert!(lit > 0.05, "a lit image, mean {lit}");
    let (summary, dark) = mean(&[&[file][..], &small, &["--env", "none"]].concat());
    assert!(!summary.contains("lit by"), "{summary}");
    assert_eq!(dark, 0.0, "--env none keeps a file without lights dark");
}

/// The test command README.md gives is the one `.ci/run` runs, and it builds every example a
/// test runs (through `support::example`): an example added to a test but not to the command
/// would fail in CI only, and one dropped from README.md would skip for its readers.
#[test]
fn the_test_command_builds_every_example_the_tests_run() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let readme = std::fs::read_to_string(root.join("README.md")).unwrap();
    let command = readme
        .lines()
        .find(|l| l.ends_with("# the test suite, as CI runs it"))
        .expect("README.md gives the test command");
    let ci = std::fs::read_to_string(root.join(".ci/run")).unwrap();
    let ci_lines: Vec<&str> = ci.lines().map(str::trim).collect();
    for step in command.split(" # ").next().unwrap().split(" && ") {
        assert!(
            ci_lines.contains(&step.trim()),
            ".ci/run does not run README.md's step `{}`",
            step.trim()
        );
    }
    let mut names = Vec::new();
    for entry in std::fs::read_dir(root.join("tests")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "rs") {
            let text = std::fs::read_to_string(&path).unwrap();
            for piece in text.split("example(\"").skip(1) {
                names.push(piece.split('"').next().unwrap().to_owned());
            }
        }
    }
    assert!(names.len() >= 4, "found the tests' examples: {names:?}");
    for name in names {
        assert!(
            command.contains(&format!("--example {name} ")),
            "README.md's test command does not build the example `{name}` a test runs"
        );
    }
}
