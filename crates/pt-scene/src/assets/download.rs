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
use std::time::Duration;

use sha2::{Digest, Sha256};

use super::{AssetError, AssetInfo, DownloadEvent, Source};

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
        Source::Gzip(url) | Source::GzipConverted { url, .. } => Some((url.to_string(), true)),
        Source::Converted(_) => None,
    }
}

/// How long a connection (and a name lookup) may take before the download is given up.
const CONNECT_TIMEOUT: Duration = Duration::from_secs(15);
/// How long the server may stay silent mid-transfer before the download is given up.
const READ_TIMEOUT: Duration = Duration::from_secs(30);
/// Bytes read between two progress reports.
const CHUNK: usize = 64 << 10;

/// Fetch `info` from `url` (gunzipping when `gzip`), check its size and sha256, and store it as
/// `dest_dir/<name>`. Returns the stored path.
///
/// A connection that cannot be made within 15 s, or a transfer that stalls for 30 s, fails with
/// [`AssetError::Download`]. Progress goes to the observer set with
/// [`set_download_observer`](super::set_download_observer), if any.
pub fn download_to(
    info: &AssetInfo,
    url: &str,
    gzip: bool,
    dest_dir: &Path,
) -> Result<PathBuf, AssetError> {
    let decode = if gzip { Decode::Gzip } else { Decode::Plain };
    download_decoded(info, url, decode, dest_dir)
}

/// What is done to the bytes of a response before they are checked against the manifest.
#[derive(Clone, Copy)]
enum Decode {
    /// Stored as received.
    Plain,
    /// Gunzipped.
    Gzip,
    /// Checked against the original's sha256, gunzipped and converted.
    GzipConvert {
        sha256: &'static str,
        conversion: super::Conversion,
    },
}

fn download_decoded(
    info: &AssetInfo,
    url: &str,
    decode: Decode,
    dest_dir: &Path,
) -> Result<PathBuf, AssetError> {
    let dest = dest_dir.join(info.name);
    super::notify(&DownloadEvent::Started {
        name: info.name,
        url,
        size: info.size,
        dest: &dest,
    });
    let result =
        fetch_verified(info, url, decode).and_then(|bytes| store(info, url, &bytes, &dest));
    super::notify(&match &result {
        Ok(path) => DownloadEvent::Finished {
            name: info.name,
            path,
        },
        Err(error) => DownloadEvent::Failed {
            name: info.name,
            error,
        },
    });
    result
}

/// The body of `url`, decompressed when `gzip`, once its size and sha256 match `info`.
fn fetch_verified(info: &AssetInfo, url: &str, decode: Decode) -> Result<Vec<u8>, AssetError> {
    let gzip = !matches!(decode, Decode::Plain);
    let agent: ureq::Agent = ureq::Agent::config_builder()
        .timeout_resolve(Some(CONNECT_TIMEOUT))
        .timeout_connect(Some(CONNECT_TIMEOUT))
        .timeout_recv_response(Some(READ_TIMEOUT))
        .timeout_per_read(Some(READ_TIMEOUT))
        .build()
        .into();
    let response = agent
        .get(url)
        .call()
        .map_err(|e| fail(info, url, e.to_string()))?;
    // Progress is reported against the bytes on the wire: the manifest's size for plain files,
    // the server's length (when it sends one) for compressed ones.
    let total = if gzip {
        response.body().content_length().unwrap_or(0)
    } else {
        info.size
    };
    let mut reader = response.into_body().into_reader();
    let mut body = Vec::new();
    let mut chunk = vec![0u8; CHUNK];
    loop {
        let n = reader
            .read(&mut chunk)
            .map_err(|e| fail(info, url, format!("reading the response: {e}")))?;
        if n == 0 {
            break;
        }
        body.extend_from_slice(&chunk[..n]);
        if body.len() as u64 > MAX_BYTES {
            return Err(fail(info, url, "the response is larger than 256 MiB"));
        }
        super::notify(&DownloadEvent::Progress {
            name: info.name,
            bytes: body.len() as u64,
            total,
        });
    }
    if let Decode::GzipConvert { sha256, .. } = decode {
        let hash = sha256_hex(&body);
        if hash != sha256 {
            return Err(fail(
                info,
                url,
                format!("the original's sha256 {hash} does not match the expected {sha256}"),
            ));
        }
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
    let bytes = match decode {
        Decode::GzipConvert { conversion, .. } => super::convert::convert(conversion, &bytes)
            .map_err(|e| fail(info, url, format!("converting the original: {e}")))?,
        _ => bytes,
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
    Ok(bytes)
}

/// Write verified bytes to a temporary file beside `dest`, then rename it into place, so an
/// interrupted run never leaves a partial file under the asset's name.
fn store(info: &AssetInfo, url: &str, bytes: &[u8], dest: &Path) -> Result<PathBuf, AssetError> {
    let parent = dest.parent().unwrap_or(dest);
    std::fs::create_dir_all(parent)
        .map_err(|e| fail(info, url, format!("creating {}: {e}", parent.display())))?;
    let tmp = dest.with_extension(format!("part{}", std::process::id()));
    std::fs::write(&tmp, bytes)
        .map_err(|e| fail(info, url, format!("writing {}: {e}", tmp.display())))?;
    std::fs::rename(&tmp, dest).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        fail(info, url, format!("moving into {}: {e}", dest.display()))
    })?;
    Ok(dest.to_path_buf())
}

/// Fetch the public original of `info` from `url` (the manifest's URL or a copy of that file
/// elsewhere), decode it as its [`Source`] says (as is, gunzipped, or checked, gunzipped and
/// converted), check the result and store it as `dest_dir/<name>`.
pub fn download_original(
    info: &AssetInfo,
    url: &str,
    dest_dir: &Path,
) -> Result<PathBuf, AssetError> {
    let decode = match info.source {
        Source::Gzip(_) => Decode::Gzip,
        Source::GzipConverted {
            sha256, conversion, ..
        } => Decode::GzipConvert { sha256, conversion },
        _ => Decode::Plain,
    };
    download_decoded(info, url, decode, dest_dir)
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
    if mirror.is_none()
        && let Source::GzipConverted { url, .. } = info.source
    {
        return download_original(info, url, dest_dir);
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
