//! Finding real meshes and maps by name.
//!
//! Assets are never part of the repository. A name such as `meshes/stanford-bunny.obj` is looked
//! up, in order, in:
//!
//! 1. the folder named by the `PT_ASSETS_DIR` environment variable;
//! 2. `assets/` in the current directory, then `assets/` at the root of this workspace;
//! 3. the user cache folder (`$XDG_CACHE_HOME/pt/assets`, else `~/.cache/pt/assets`, or
//!    `%LOCALAPPDATA%\pt\assets` on Windows).
//!
//! When the asset is found nowhere and the `download` feature is on, a known asset is downloaded
//! into the cache folder from its public URL (or from `$PT_ASSETS_MIRROR/<name>` when that
//! variable holds a base URL) and checked against its size and sha256 before use (the `download`
//! module, present with the feature). Otherwise, or when that fails, the error lists every
//! folder searched, says where the file comes from (the [`MANIFEST`] records each known asset's public URL, size and
//! sha256) and why the download failed.
//!
//! Downloading is opt-in for library users: a program that depends on `pt-scene` without the
//! feature never reaches the network. The examples of the `pt` repository turn it on. With
//! `PT_OFFLINE=1` nothing is fetched even when the feature is on. A program shows downloads to
//! its user by registering an observer with `set_download_observer` (feature `download`); the
//! library itself never prints.

#[cfg(feature = "download-http")]
mod convert;
#[cfg(feature = "download-http")]
pub mod download;
mod manifest;

use std::fmt;
use std::path::{Path, PathBuf};

pub use manifest::MANIFEST;

/// Where a known asset can be obtained.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum Source {
    /// These exact bytes are served at this URL.
    Raw(&'static str),
    /// These exact bytes are the gzip-decompressed content of this URL.
    Gzip(&'static str),
    /// The file was converted from a public original; the text says from what.
    Converted(&'static str),
    /// The file is made from the gzip-compressed public original at `url` (whose own sha256 is
    /// `sha256`) by an exact [`Conversion`], so it can be downloaded although no public copy has
    /// its bytes.
    GzipConverted {
        /// The compressed original.
        url: &'static str,
        /// SHA-256 of the compressed original, lowercase hex.
        sha256: &'static str,
        /// How the stored bytes are made from the decompressed original.
        conversion: Conversion,
    },
}

/// An exact conversion from a public original to an asset's stored bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum Conversion {
    /// An ASCII PLY of xyz float vertices and triangles, written as binary little-endian PLY
    /// with these header comments (the f32 nearest each decimal, the same element order).
    AsciiPlyToBinary {
        /// The `comment` lines of the output header, in order.
        comments: &'static [&'static str],
    },
}

/// A known asset.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AssetInfo {
    /// Name, which is also its path below an assets folder.
    pub name: &'static str,
    /// Size in bytes.
    pub size: u64,
    /// SHA-256 of the file, lowercase hex.
    pub sha256: &'static str,
    /// Where it comes from.
    pub source: Source,
}

/// The manifest entry of a known asset.
#[must_use]
pub fn info(name: &str) -> Option<&'static AssetInfo> {
    MANIFEST.iter().find(|a| a.name == name)
}

/// Why an asset could not be found.
#[derive(Clone, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum AssetError {
    /// The asset is in none of the searched folders.
    Missing {
        /// The name asked for.
        name: String,
        /// The folders searched, in order.
        searched: Vec<PathBuf>,
    },
    /// Downloading the asset failed (feature `download`): nothing was stored.
    Download {
        /// The asset.
        name: String,
        /// The URL tried (empty when there is none).
        url: String,
        /// What went wrong.
        message: String,
    },
}

impl fmt::Display for AssetError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Missing { name, searched } => {
                write!(f, "asset `{name}` not found; looked in:")?;
                for dir in searched {
                    write!(f, " {},", dir.display())?;
                }
                match info(name).map(|i| i.source) {
                    Some(Source::Raw(url)) => write!(f, " get it from {url}")?,
                    Some(Source::Gzip(url)) => write!(f, " get it by decompressing {url}")?,
                    Some(Source::Converted(how)) => write!(f, " it is {how}")?,
                    Some(Source::GzipConverted { url, .. }) => write!(
                        f,
                        " it is converted from {url} (with the `download` feature pt does it)"
                    )?,
                    None => write!(f, " (not a known asset)")?,
                }
                write!(
                    f,
                    " and put it under one of these folders, or set PT_ASSETS_DIR to the folder holding it"
                )?;
                if let Some(cache) = cache_dir() {
                    write!(f, " (downloads are cached in {})", cache.display())?;
                }
                write!(
                    f,
                    ", or set PT_ASSETS_MIRROR to a base URL that serves `<name>`"
                )?;
                if !cfg!(feature = "download-http") {
                    write!(f, " (and build with the `download` feature to fetch it)")?;
                } else if offline() {
                    write!(f, " (and unset PT_OFFLINE, which turns fetching off)")?;
                }
                Ok(())
            }
            Self::Download { name, url, message } => {
                if url.is_empty() {
                    write!(f, "asset `{name}` cannot be downloaded: {message}")
                } else {
                    write!(f, "downloading asset `{name}` from {url} failed: {message}")
                }
            }
        }
    }
}

impl std::error::Error for AssetError {}

/// True when `PT_OFFLINE` is set to anything but `0` or the empty string: nothing is downloaded.
#[must_use]
pub fn offline() -> bool {
    std::env::var_os("PT_OFFLINE").is_some_and(|v| !v.is_empty() && v != "0")
}

/// What a download reports while it runs, to the observer set with [`set_download_observer`].
#[cfg(feature = "download-http")]
#[derive(Debug)]
#[non_exhaustive]
pub enum DownloadEvent<'a> {
    /// A download begins.
    Started {
        /// The asset.
        name: &'a str,
        /// Where it is fetched from.
        url: &'a str,
        /// Its size once stored (the manifest's).
        size: u64,
        /// Where it will be stored.
        dest: &'a Path,
    },
    /// Bytes arrived.
    Progress {
        /// The asset.
        name: &'a str,
        /// Bytes received so far (compressed, for gzip sources).
        bytes: u64,
        /// Bytes expected in all, or 0 when unknown.
        total: u64,
    },
    /// The file was verified and stored.
    Finished {
        /// The asset.
        name: &'a str,
        /// Where it is now.
        path: &'a Path,
    },
    /// The download failed; nothing was stored.
    Failed {
        /// The asset.
        name: &'a str,
        /// Why.
        error: &'a AssetError,
    },
}

/// A function that is shown every [`DownloadEvent`].
#[cfg(feature = "download-http")]
pub type DownloadObserver = Box<dyn Fn(&DownloadEvent<'_>) + Send + Sync>;

#[cfg(feature = "download-http")]
static OBSERVER: std::sync::RwLock<Option<DownloadObserver>> = std::sync::RwLock::new(None);

/// Show every download of this process to `observer` (a program's progress bar, say), replacing
/// any observer set before. Without one, a download is logged at `info` level when it starts.
#[cfg(feature = "download-http")]
pub fn set_download_observer(observer: impl Fn(&DownloadEvent<'_>) + Send + Sync + 'static) {
    let mut slot = OBSERVER
        .write()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    *slot = Some(Box::new(observer));
}

#[cfg(feature = "download-http")]
fn notify(event: &DownloadEvent<'_>) {
    let slot = OBSERVER
        .read()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    match (&*slot, event) {
        (Some(observer), _) => observer(event),
        (None, DownloadEvent::Started { name, url, .. }) => {
            log::info!("downloading asset `{name}` from {url}");
        }
        (None, _) => {}
    }
}

/// The user cache folder for assets, if the environment names a home or cache folder.
#[must_use]
pub fn cache_dir() -> Option<PathBuf> {
    let var = |k: &str| {
        std::env::var_os(k)
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
    };
    if cfg!(windows) {
        return var("LOCALAPPDATA").map(|d| d.join("pt").join("assets"));
    }
    var("XDG_CACHE_HOME")
        .or_else(|| var("HOME").map(|h| h.join(".cache")))
        .map(|d| d.join("pt").join("assets"))
}

/// The folders searched for assets, in order.
#[must_use]
pub fn search_dirs() -> Vec<PathBuf> {
    let mut dirs = Vec::new();
    if let Some(d) = std::env::var_os("PT_ASSETS_DIR").filter(|v| !v.is_empty()) {
        dirs.push(PathBuf::from(d));
    }
    if let Ok(cwd) = std::env::current_dir() {
        dirs.push(cwd.join("assets"));
    }
    let workspace = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join("..")
        .join("assets");
    if !dirs.contains(&workspace) {
        dirs.push(workspace);
    }
    dirs.extend(cache_dir());
    dirs
}

/// The path of an asset, searching the folders of [`search_dirs`] in order.
pub fn find_asset(name: &str) -> Result<PathBuf, AssetError> {
    let searched = search_dirs();
    for dir in &searched {
        let candidate = dir.join(name);
        if candidate.is_file() {
            return Ok(candidate);
        }
    }
    let missing = AssetError::Missing {
        name: name.to_string(),
        searched,
    };
    #[cfg(feature = "download-http")]
    if let Some(cache) = cache_dir()
        && info(name).is_some()
        && !offline()
    {
        let mirror = std::env::var("PT_ASSETS_MIRROR")
            .ok()
            .filter(|m| !m.is_empty());
        return download::download_asset(name, mirror.as_deref(), &cache).map_err(|e| match e {
            AssetError::Download { name, url, message } => AssetError::Download {
                name,
                url,
                message: format!("{message}; and {missing}"),
            },
            other => other,
        });
    }
    Err(missing)
}

/// For tests and benchmarks: the asset's path, or `Ok(None)` when it is missing and the
/// `PT_REQUIRE_ASSETS` environment variable is not `1` (the caller then skips, and this function
/// has written a `SKIPPED` line naming the asset to stderr). When assets are
/// required (CI sets `PT_REQUIRE_ASSETS=1`), a missing asset is an error, so the test fails instead
/// of silently skipping.
pub fn find_asset_or_skip(name: &str) -> Result<Option<PathBuf>, AssetError> {
    match find_asset(name) {
        Ok(p) => Ok(Some(p)),
        Err(e) if std::env::var("PT_REQUIRE_ASSETS").is_ok_and(|v| v == "1") => Err(e),
        Err(e) => {
            // A test helper, the one place pt-scene writes to the terminal: straight to stderr,
            // past the test harness's capture, so that `cargo test` shows every skip even when
            // the test passes (a skip that says nothing looks like a pass).
            use std::io::Write;
            let line = format!(
                "SKIPPED (asset `{name}` missing; set PT_ASSETS_DIR, or PT_REQUIRE_ASSETS=1 to fail instead)\n"
            );
            let _ = std::io::stderr().write_all(line.as_bytes());
            log::warn!("skipping: {e}");
            Ok(None)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn manifest_names_are_unique_and_hashes_well_formed() {
        let mut names: Vec<&str> = MANIFEST.iter().map(|a| a.name).collect();
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), MANIFEST.len());
        for a in MANIFEST {
            assert_eq!(a.sha256.len(), 64);
            assert!(
                a.sha256
                    .bytes()
                    .all(|b| b.is_ascii_hexdigit() && !b.is_ascii_uppercase())
            );
        }
        assert!(info("meshes/stanford-bunny.obj").is_some());
    }

    #[test]
    fn missing_asset_error_says_where_it_looked_and_where_to_get_it() {
        let e = find_asset("meshes/no-such-mesh.obj")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("no-such-mesh.obj")
                && e.contains("looked in")
                && e.contains("PT_ASSETS_DIR"),
            "{e}"
        );
        let e = AssetError::Missing {
            name: "meshes/stanford-bunny.obj".into(),
            searched: vec![PathBuf::from("/nowhere")],
        }
        .to_string();
        assert!(
            e.contains("/nowhere") && e.contains("https://raw.githubusercontent.com"),
            "{e}"
        );
    }
}
