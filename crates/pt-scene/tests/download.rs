//! The download path (feature `download`) against a local HTTP server on 127.0.0.1 serving files
//! from the real assets folder: a good file is fetched, verified and stored; a corrupted one
//! (one flipped byte) and a truncated one are rejected and nothing is stored; a gzip source is
//! decompressed before the check; a missing URL gives an error naming the asset and the URL.

use std::io::{BufRead, BufReader, Write};
use std::net::TcpListener;

use pt_scene::assets::download::{download_to, sha256_hex};
use pt_scene::assets::{AssetError, find_asset_or_skip, info};

use crate::support::Scratch;

/// Serve `GET /<anything>` from `routes` (path, body) on 127.0.0.1 until the test ends.
fn serve(routes: Vec<(String, Vec<u8>)>) -> String {
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = listener.local_addr().unwrap();
    std::thread::spawn(move || {
        for stream in listener.incoming() {
            let Ok(mut stream) = stream else { continue };
            let mut reader = BufReader::new(stream.try_clone().unwrap());
            let mut request = String::new();
            if reader.read_line(&mut request).is_err() {
                continue;
            }
            // Drain the headers.
            loop {
                let mut line = String::new();
                if reader.read_line(&mut line).map_or(true, |n| n == 0) || line == "\r\n" {
                    break;
                }
            }
            let path = request.split_whitespace().nth(1).unwrap_or("/").to_string();
            let response = match routes.iter().find(|(p, _)| *p == path) {
                Some((_, body)) => {
                    let mut r = format!(
                        "HTTP/1.1 200 OK\r\nContent-Length: {}\r\nConnection: close\r\n\r\n",
                        body.len()
                    )
                    .into_bytes();
                    r.extend_from_slice(body);
                    r
                }
                None => b"HTTP/1.1 404 Not Found\r\nContent-Length: 0\r\nConnection: close\r\n\r\n"
                    .to_vec(),
            };
            let _ = stream.write_all(&response);
        }
    });
    format!("http://{addr}")
}

fn scratch(name: &str) -> Scratch {
    Scratch::new(&format!("dl-{name}"))
}

#[test]
fn downloads_are_verified_before_they_are_stored() {
    let name = "gltf/Box.glb";
    let Some(path) = find_asset_or_skip(name).unwrap() else {
        return;
    };
    let good = std::fs::read(path).unwrap();
    let mut corrupt = good.clone();
    corrupt[100] ^= 0x40;
    let truncated = good[..good.len() - 10].to_vec();
    let base = serve(vec![
        ("/good".into(), good.clone()),
        ("/corrupt".into(), corrupt),
        ("/short".into(), truncated),
    ]);
    let meta = info(name).unwrap();
    assert_eq!(
        sha256_hex(&good),
        meta.sha256,
        "the manifest matches the shared file"
    );

    let dir = scratch("verify");
    let stored = download_to(meta, &format!("{base}/good"), false, &dir).unwrap();
    assert_eq!(stored, dir.join(name));
    assert_eq!(std::fs::read(&stored).unwrap(), good);

    let dir = scratch("corrupt");
    let e = download_to(meta, &format!("{base}/corrupt"), false, &dir).unwrap_err();
    let msg = e.to_string();
    assert!(msg.contains("sha256") && msg.contains(name), "{msg}");
    assert!(
        !dir.join(name).exists(),
        "a corrupted download is not stored"
    );

    let e = download_to(meta, &format!("{base}/short"), false, &dir).unwrap_err();
    assert!(e.to_string().contains("bytes"), "{e}");
    assert!(!dir.join(name).exists());

    let e = download_to(meta, &format!("{base}/absent"), false, &dir).unwrap_err();
    assert!(matches!(e, AssetError::Download { .. }));
    assert!(e.to_string().contains("/absent"), "{e}");
}

#[test]
fn gzip_sources_are_decompressed_then_verified() {
    let name = "meshes/bunny-lowres-npm.obj";
    let Some(path) = find_asset_or_skip(name).unwrap() else {
        return;
    };
    let plain = std::fs::read(path).unwrap();
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    gz.write_all(&plain).unwrap();
    let base = serve(vec![("/bunny.gz".into(), gz.finish().unwrap())]);
    let dir = scratch("gzip");
    let meta = info(name).unwrap();
    let stored = download_to(meta, &format!("{base}/bunny.gz"), true, &dir).unwrap();
    assert_eq!(std::fs::read(stored).unwrap(), plain);
}

#[test]
fn assets_download_through_a_mirror_into_a_cache() {
    let name = "gltf/Box.glb";
    let Some(path) = find_asset_or_skip(name).unwrap() else {
        return;
    };
    let base = serve(vec![(format!("/{name}"), std::fs::read(path).unwrap())]);
    let cache = scratch("cache");
    let found = pt_scene::assets::download::download_asset(name, Some(&base), &cache).unwrap();
    assert_eq!(found, cache.join(name));
}

/// The converted res2 dragon is made again from an ASCII original, bit for bit: the stored
/// binary PLY is written out as ASCII (each f32 in its shortest decimal, which parses back to
/// the same f32, as the original's six-digit decimals do), gzipped and served; the conversion's
/// output must then match the manifest's size and sha256, as a download from the public
/// original must.
#[test]
fn converted_assets_are_rebuilt_exactly_from_their_original() {
    use pt_scene::assets::{Source, download::download_original};
    let name = "meshes/dragon_vrip_res2.binary.ply";
    let Some(path) = find_asset_or_skip(name).unwrap() else {
        return;
    };
    let binary = std::fs::read(path).unwrap();
    let start = binary
        .windows(11)
        .position(|w| w == b"end_header\n")
        .unwrap()
        + 11;
    let (nv, nf) = (100_250, 202_520);
    let mut ascii = format!(
        "ply\nformat ascii 1.0\ncomment generated by ply_writer\nelement vertex {nv}\n\
         property float x\nproperty float y\nproperty float z\nelement face {nf}\n\
         property list uchar int vertex_indices\nend_header\n"
    );
    let f = |i: usize| f32::from_le_bytes(binary[i..i + 4].try_into().unwrap());
    for v in 0..nv {
        let o = start + 12 * v;
        ascii.push_str(&format!("{} {} {} \n", f(o), f(o + 4), f(o + 8)));
    }
    let faces = start + 12 * nv;
    for t in 0..nf {
        let o = faces + 13 * t + 1;
        let i = |k: usize| i32::from_le_bytes(binary[o + 4 * k..o + 4 * k + 4].try_into().unwrap());
        ascii.push_str(&format!("3 {} {} {} \n", i(0), i(1), i(2)));
    }
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    gz.write_all(ascii.as_bytes()).unwrap();
    let gz = gz.finish().unwrap();
    let base = serve(vec![("/dragon.ply.gz".into(), gz.clone())]);

    let mut meta = *info(name).unwrap();
    let Source::GzipConverted {
        url, conversion, ..
    } = meta.source
    else {
        panic!("the res2 dragon is made from the public gzip original");
    };
    assert!(url.ends_with("dragon_vrip_res2.ply.gz"));
    // This original is a stand-in, so its own hash is the one to check against.
    let hash: &'static str = Box::leak(sha256_hex(&gz).into_boxed_str());
    meta.source = Source::GzipConverted {
        url,
        sha256: hash,
        conversion,
    };
    let dir = scratch("convert");
    let stored = download_original(&meta, &format!("{base}/dragon.ply.gz"), &dir).unwrap();
    assert_eq!(std::fs::read(stored).unwrap(), binary);

    // An original whose own hash is wrong is refused before it is converted.
    let mut wrong = meta;
    wrong.source = Source::GzipConverted {
        url,
        sha256: info(name).map(|i| i.sha256).unwrap(),
        conversion,
    };
    let dir = scratch("convert-wrong");
    let e = download_original(&wrong, &format!("{base}/dragon.ply.gz"), &dir).unwrap_err();
    assert!(e.to_string().contains("original's sha256"), "{e}");
    assert!(!dir.join(name).exists());
}
