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

mod common;

use std::path::PathBuf;
use std::process::exit;

use pt::pt_core::PartialRender;

const NAME: &str = "merge";

fn usage() -> ! {
    eprintln!(
        "usage: cargo run --example merge -- PART.exr [PART.exr ...] --out OUT.(exr|png)\n\n\
         Merges partial renders written by `--spp-range A..B`. OUT.exr keeps the exact sums\n\
         (it can be merged again); OUT.png is the tone-mapped image."
    );
    exit(2)
}

fn main() {
    common::init(NAME);
    let mut parts = Vec::new();
    let mut out = None;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--out" => out = Some(PathBuf::from(args.next().unwrap_or_else(|| usage()))),
            "--help" | "-h" => usage(),
            s if s.starts_with("--") => {
                eprintln!("{NAME}: unknown option {s}");
                usage()
            }
            _ => parts.push(PathBuf::from(a)),
        }
    }
    let Some(out) = out else { usage() };
    if parts.is_empty() {
        usage()
    }
    let die = |e: &dyn std::fmt::Display| -> ! {
        eprintln!("{NAME}: {e}");
        exit(1)
    };
    // The parts are input files named on the command line: a bad one is exit code 2.
    let bad = |e: &dyn std::fmt::Display| -> ! {
        eprintln!("{NAME}: {e}");
        exit(2)
    };
    let ext = out
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    if !matches!(ext.as_deref(), Some("exr" | "png")) {
        bad(&format!(
            "--out must end in .exr or .png, got {}",
            out.display()
        ));
    }

    let mut merged: Option<PartialRender> = None;
    for path in &parts {
        let part = PartialRender::read_exr(path).unwrap_or_else(|e| bad(&e));
        // pt's radiance is never negative, so neither is a sum of it: such a part was edited.
        let (w, h) = (part.film.width(), part.film.height());
        if let Some((x, y)) = (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .find(|&(x, y)| part.film.pixel(x, y).mean().min_component() < 0.0)
        {
            bad(&format!(
                "{}: pixel ({x}, {y}) has a negative sum: not a pt render, or edited",
                path.display()
            ));
        }
        println!(
            "{NAME}: {}: samples {} of {}, {}x{}",
            path.display(),
            part.ranges_text(),
            part.spp,
            part.film.width(),
            part.film.height()
        );
        match &mut merged {
            None => merged = Some(part),
            Some(m) => m
                .merge(&part)
                .unwrap_or_else(|e| bad(&format!("{}: {e}", path.display()))),
        }
    }
    let merged = merged.expect("at least one part");
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).unwrap_or_else(|e| die(&format!("{}: {e}", dir.display())));
    }
    let result = match ext.as_deref() {
        Some("exr") => merged.write_exr(&out),
        _ => merged.film.to_image().write(&out),
    };
    result.unwrap_or_else(|e| die(&e));
    let status = if merged.is_complete() {
        "complete".to_string()
    } else {
        format!(
            "incomplete: {} of {} spp",
            merged.samples_held(),
            merged.spp
        )
    };
    println!(
        "{NAME}: {} parts -> {} (samples {}, {status}; {} non-finite samples dropped, {} clamped): {}",
        parts.len(),
        out.display(),
        merged.ranges_text(),
        merged.film.non_finite_samples(),
        merged.film.clamped_samples(),
        merged.label
    );
}
