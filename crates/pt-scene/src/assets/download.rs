//! Downloading known assets (feature `download`, or `download-http` without TLS): over HTTP(S)
//! with [ureq](https://docs.rs/ureq),
//! gzip sources decompressed with [flate2](https://docs.rs/flate2), every file checked against
//! the manifest's size and sha256 ([sha2](https://docs.rs/sha2)) before it is moved into place.
//!
//! Files land in the user cache folder ([`cache_dir`](super::cache_dir)) unless another folder is
//! given. A download is written to a temporary file next to its destination and renamed only
//! after the check, so a failed or corrupted transfer never leaves a file that a later lookup
//! would trust.

use std::io::Read;
use std::path::{Path, PathBuf};

use sha2::{Digest, Sha256};

use super::{AssetError, AssetInfo, Source};

/// The largest file pt downloads (the biggest known asset is a few MiB).
const MAX_BYTES: u64 = 256 << 20;

/// Lowercase hex SHA-256 of `bytes`.
#[must_use]
pub fn sha256_hex(bytes: &[u8]) -> String {
    let digest = Sha256::digest(bytes);
    let mut s = String::with_capacity(64);
    for b in digest {
        s.push_str(&format!("{b:02x}"));
    }
    s
}

fn fail(info: &AssetInfo, url: &str, message: impl Into<String>) -> AssetError {
    AssetError::Download {
        name: info.name.to_string(),
        url: url.to_string(),
        message: message.into(),
    }
}

/// The URL to fetch `info` from: `mirror/<name>` when a mirror base URL is given (the file as
/// stored, already decompressed), else the manifest's source. Converted assets have no URL.
#[must_use]
pub fn source_url(info: &AssetInfo, mirror: Option<&str>) -> Option<(String, bool)> {
    if let Some(base) = mirror {
        return Some((
            format!("{}/{}", base.trim_end_matches('/'), info.name),
            false,
        ));
    }
    match info.source {
        Source::Raw(url) => Some((url.to_string(), false)),
        Source::Gzip(url) => Some((url.to_string(), true)),
        Source::Converted(_) => None,
    }
}

/// Fetch `info` from `url` (gunzipping when `gzip`), check its size and sha256, and store it as
/// `dest_dir/<name>`. Returns the stored path.
pub fn download_to(
    info: &AssetInfo,
    url: &str,
    gzip: bool,
    dest_dir: &Path,
) -> Result<PathBuf, AssetError> {
    let response = ureq::get(url)
        .call()
        .map_err(|e| fail(info, url, e.to_string()))?;
    let mut body = Vec::new();
    response
        .into_body()
        .into_reader()
        .take(MAX_BYTES + 1)
        .read_to_end(&mut body)
        .map_err(|e| fail(info, url, format!("reading the response: {e}")))?;
    if body.len() as u64 > MAX_BYTES {
        return Err(fail(info, url, "the response is larger than 256 MiB"));
    }
    let bytes = if gzip {
        let mut out = Vec::new();
        flate2::read::GzDecoder::new(body.as_slice())
            .take(MAX_BYTES + 1)
            .read_to_end(&mut out)
            .map_err(|e| fail(info, url, format!("not valid gzip: {e}")))?;
        out
    } else {
        body
    };
    if bytes.len() as u64 != info.size {
        return Err(fail(
            info,
            url,
            format!(
                "got {} bytes, expected {}; the file was not stored",
                bytes.len(),
                info.size
            ),
        ));
    }
    let hash = sha256_hex(&bytes);
    if hash != info.sha256 {
        return Err(fail(
            info,
            url,
            format!(
                "sha256 {hash} does not match the expected {}; the file was not stored",
                info.sha256
            ),
        ));
    }
    let dest = dest_dir.join(info.name);
    let parent = dest.parent().unwrap_or(dest_dir);
    std::fs::create_dir_all(parent)
        .map_err(|e| fail(info, url, format!("creating {}: {e}", parent.display())))?;
    let tmp = dest.with_extension(format!("part{}", std::process::id()));
    std::fs::write(&tmp, &bytes)
        .map_err(|e| fail(info, url, format!("writing {}: {e}", tmp.display())))?;
    std::fs::rename(&tmp, &dest).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        fail(info, url, format!("moving into {}: {e}", dest.display()))
    })?;
    Ok(dest)
}

/// Make the known asset `name` available in `dest_dir`: return it if it is already there with
/// the expected size, else download it (from `mirror/<name>` when a mirror is given, else from
/// the manifest's URL) and verify it.
pub fn download_asset(
    name: &str,
    mirror: Option<&str>,
    dest_dir: &Path,
) -> Result<PathBuf, AssetError> {
    let info = super::info(name).ok_or_else(|| AssetError::Download {
        name: name.to_string(),
        url: String::new(),
        message: "not a known asset, so there is nothing to download".into(),
    })?;
    let dest = dest_dir.join(info.name);
    if std::fs::metadata(&dest).is_ok_and(|m| m.len() == info.size) {
        return Ok(dest);
    }
    let Some((url, gzip)) = source_url(info, mirror) else {
        let how = match info.source {
            Source::Converted(how) => how,
            _ => "not downloadable",
        };
        return Err(AssetError::Download {
            name: name.to_string(),
            url: String::new(),
            message: format!("it has no download URL: it is {how}"),
        });
    };
    download_to(info, &url, gzip, dest_dir)
}
