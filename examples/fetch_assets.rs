//! Fetch every known asset into the user cache at once, and list what is where.
//!
//! ```text
//! cargo run --example fetch_assets            # fetch what is missing, then list
//! cargo run --example fetch_assets -- --list  # only list, fetch nothing
//! ```
//!
//! Each asset is looked up as the examples look it up (`PT_ASSETS_DIR`, `assets/`, the cache);
//! one found nowhere is downloaded from its public URL (or `$PT_ASSETS_MIRROR/<name>`) and
//! checked against the manifest's sha256 before it is stored. `PT_OFFLINE=1` fetches nothing.
//! Exit code 0 when every asset is available, 1 when some could not be fetched, 2 on bad
//! arguments.

use pt::pt_scene::assets::{self, MANIFEST};

const NAME: &str = "fetch_assets";

/// Fetch every known asset that is not yet available, and list where each one is.
#[derive(clap::Parser)]
struct Cli {
    /// Only list the assets and where they are found; fetch nothing
    #[arg(long)]
    list: bool,
}

fn main() {
    pt_cli::init(NAME);
    let matches = pt_cli::get_matches(
        <Cli as clap::CommandFactory>::command().name(NAME),
        std::env::args_os(),
    );
    let list_only = <Cli as clap::FromArgMatches>::from_arg_matches(&matches)
        .unwrap_or_else(|e| e.exit())
        .list;
    let total: u64 = MANIFEST.iter().map(|a| a.size).sum();
    println!(
        "{} known assets, {:.1} MiB in all; cache: {}",
        MANIFEST.len(),
        total as f64 / (1u64 << 20) as f64,
        assets::cache_dir().map_or("(none: no HOME)".into(), |d| d.display().to_string())
    );
    let mut failed = 0;
    for a in MANIFEST {
        let found = if list_only {
            assets::search_dirs()
                .into_iter()
                .map(|d| d.join(a.name))
                .find(|p| p.is_file())
                .ok_or_else(|| "missing".to_string())
        } else {
            assets::find_asset(a.name).map_err(|e| e.to_string())
        };
        match found {
            Ok(path) => println!("  ok       {:<48} {}", a.name, path.display()),
            Err(e) => {
                failed += 1;
                if list_only {
                    println!("  missing  {}", a.name);
                } else {
                    println!("  FAILED   {:<48} {e}", a.name);
                }
            }
        }
    }
    if failed > 0 && !list_only {
        eprintln!(
            "{NAME}: {failed} of {} assets could not be fetched",
            MANIFEST.len()
        );
        std::process::exit(1);
    }
}
