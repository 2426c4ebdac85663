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
                    None => write!(f, " (not a known asset)")?,
                }
                write!(
                    f,
                    " and put it under one of these folders, or set PT_ASSETS_DIR to the folder holding it"
                )?;
                if !cfg!(feature = "download-http") {
                    write!(f, " (or build with the `download` feature to fetch it)")?;
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
    {
        let mirror = std::env::var("PT_ASSETS_MIRROR")
            .ok()
            .filter(|m| !m.is_empty());
        return download::download_asset(name, mirror.as_deref(), &cache).map_err(|e| {
            log::warn!("{e}");
            match e {
                AssetError::Download { name, url, message } => AssetError::Download {
                    name,
                    url,
                    message: format!("{message}; and {missing}"),
                },
                other => other,
            }
        });
    }
    Err(missing)
}

/// For tests and benchmarks: the asset's path, or `Ok(None)` when it is missing and the
/// `PT_REQUIRE_ASSETS` environment variable is not `1` (the caller then skips). When assets are
/// required (CI sets `PT_REQUIRE_ASSETS=1`), a missing asset is an error, so the test fails instead
/// of silently skipping.
pub fn find_asset_or_skip(name: &str) -> Result<Option<PathBuf>, AssetError> {
    match find_asset(name) {
        Ok(p) => Ok(Some(p)),
        Err(e) if std::env::var("PT_REQUIRE_ASSETS").is_ok_and(|v| v == "1") => Err(e),
        Err(e) => {
            // Logged, not printed: library code never writes to the terminal.
            log::warn!("skipping (set PT_REQUIRE_ASSETS=1 to fail instead): {e}");
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
