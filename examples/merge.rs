//! Merge partial renders (`--spp-range A..B` of any example) into one image.
//!
//! ```text
//! cargo run --release --example glass_bunny -- --spp 128 --spp-range 0..64
//! cargo run --release --example glass_bunny -- --spp 128 --spp-range 64..128
//! cargo run --release --example merge -- out/glass_bunny.0-64.exr out/glass_bunny.64-128.exr \
//!     --out out/glass_bunny.png
//! ```
//!
//! The parts may come from different machines or processes in any order: the merged film is
//! bit for bit the film of one render over all the samples (see `pt_core::partial`). Parts of
//! different renders (other scene, settings, seed or size) and parts holding the same samples
//! are refused. An `.exr` output is itself a partial EXR, so merges can be merged; a `.png`
//! output is the tone-mapped image. Merging an incomplete set works and says what is missing.

use std::path::PathBuf;

use clap::Parser;

const NAME: &str = "merge";

/// Merge partial renders (`--spp-range A..B` or `--shard I/N` of any example) into one image
/// (the `pt merge` command as an example).
#[derive(Parser)]
struct Cli {
    /// The partial EXRs, in any order
    #[arg(required = true)]
    parts: Vec<PathBuf>,
    /// Output: .exr keeps the exact sums (it can be merged again), .png is tone-mapped
    #[arg(long, value_name = "PATH")]
    out: PathBuf,
    /// Refuse the merge unless the parts are the N shards of `--shard I/N`, complete
    #[arg(long, value_name = "N")]
    expect: Option<u32>,
}

fn main() {
    pt_cli::init(NAME);
    let matches = pt_cli::get_matches(
        <Cli as clap::CommandFactory>::command().name(NAME),
        std::env::args_os(),
    );
    let cli =
        <Cli as clap::FromArgMatches>::from_arg_matches(&matches).unwrap_or_else(|e| e.exit());
    let merged = pt_cli::farm::merge(&cli.parts, cli.expect).unwrap_or_else(|f| f.exit());
    pt_cli::farm::write(&merged.render, &cli.out).unwrap_or_else(|f| f.exit());
    for line in &merged.lines {
        println!("{NAME}: {line}");
    }
    println!(
        "{}",
        pt_cli::farm::summary(NAME, cli.parts.len(), &cli.out, &merged.render)
    );
}
