//! Merging the parts of a render (`pt merge`): the step a render farm runs after its shards.
//!
//! The parts may come from different machines or processes in any order: the merged film is
//! bit for bit the film of one render over all the samples (`pt_core::partial`). Parts of
//! different renders (other scene, settings, seed or size) are refused; a part given twice
//! (a retried or duplicated shard, bit-identical to the first) is used once; two different
//! parts holding the same samples are refused. `--expect N` refuses a set that is not the N
//! shards of `--shard I/N` complete, and names the missing ones.

use std::path::{Path, PathBuf};

use pt_core::PartialRender;

use crate::Failure;
use crate::args::shard_range;

/// What a merge produced.
#[derive(Debug)]
pub struct Merged {
    /// The merged render.
    pub render: PartialRender,
    /// One line per part read (and per duplicate skipped).
    pub lines: Vec<String>,
}

/// Merge the partial EXRs at `parts`.
///
/// # Errors
///
/// Exit code 2: a part cannot be read, has a negative sum (edited), belongs to another render
/// or overlaps another part; with `expect`, shards are missing.
pub fn merge(parts: &[PathBuf], expect: Option<u32>) -> Result<Merged, Failure> {
    let mut merged: Option<PartialRender> = None;
    // Each part merged so far by its ranges and a hash of its sums: one film is held at a time
    // besides the merge, whatever the number of parts.
    let mut seen: Vec<(PathBuf, String, u64)> = Vec::new();
    let mut lines = Vec::new();
    for path in parts {
        let part = read_part(path)?;
        let (ranges, hash) = (part.ranges_text(), fingerprint(&part));
        if let Some((first, _, _)) = seen.iter().find(|(_, r, h)| *r == ranges && *h == hash) {
            lines.push(format!(
                "{}: samples {}: the same part as {}, used once",
                path.display(),
                part.ranges_text(),
                first.display()
            ));
            continue;
        }
        lines.push(format!(
            "{}: samples {} of {}, {}x{}",
            path.display(),
            part.ranges_text(),
            part.spp,
            part.film.width(),
            part.film.height()
        ));
        match &mut merged {
            None => merged = Some(part),
            Some(m) => m
                .merge(&part)
                .map_err(|e| Failure::usage(format!("{}: {e}", path.display())))?,
        }
        seen.push((path.clone(), ranges, hash));
    }
    let render = merged.ok_or_else(|| Failure::usage("no parts to merge"))?;
    if let Some(n) = expect {
        let missing = missing_shards(&render, n);
        if !missing.is_empty() {
            return Err(Failure::usage(format!(
                "incomplete: {} of the {n} shards are missing ({}); samples held: {} of {}",
                missing.len(),
                missing
                    .iter()
                    .map(|(i, r)| format!("shard {i}/{n} = samples {}..{}", r.start, r.end))
                    .collect::<Vec<_>>()
                    .join(", "),
                render.ranges_text(),
                render.spp
            )));
        }
    }
    Ok(Merged { render, lines })
}

/// A hash of a part's exact sums, counts and counters (two parts with the same ranges and hash
/// are the same part: a retried shard).
fn fingerprint(part: &PartialRender) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = std::hash::DefaultHasher::new();
    let film = &part.film;
    (film.width(), film.height()).hash(&mut h);
    for y in 0..film.height() {
        for x in 0..film.width() {
            film.pixel(x, y).hash(&mut h);
            film.aux_pixel(x, y).hash(&mut h);
        }
    }
    (
        film.non_finite_samples(),
        film.clamped_samples(),
        film.saturated_samples(),
        part.spp,
        part.seed,
        &part.label,
    )
        .hash(&mut h);
    h.finish()
}

/// The shards of `--shard I/N` whose samples `render` does not hold, with their ranges.
#[must_use]
pub fn missing_shards(render: &PartialRender, n: u32) -> Vec<(u32, std::ops::Range<u32>)> {
    let held: Vec<std::ops::Range<u32>> = render
        .ranges_text()
        .split(',')
        .filter_map(|r| {
            let (a, b) = r.split_once("..")?;
            Some(a.parse().ok()?..b.parse().ok()?)
        })
        .collect();
    (0..n)
        .map(|i| (i, shard_range(i, n, render.spp)))
        .filter(|(_, r)| !held.iter().any(|h| h.start <= r.start && r.end <= h.end))
        .collect()
}

/// Read one part and refuse one with a negative sum (pt's radiance never is: it was edited).
fn read_part(path: &Path) -> Result<PartialRender, Failure> {
    let part = PartialRender::read_exr(path).map_err(Failure::usage)?;
    let (w, h) = (part.film.width(), part.film.height());
    if let Some((x, y)) = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .find(|&(x, y)| part.film.pixel(x, y).mean().min_component() < 0.0)
    {
        return Err(Failure::usage(format!(
            "{}: pixel ({x}, {y}) has a negative sum: not a pt render, or edited",
            path.display()
        )));
    }
    Ok(part)
}

/// Write a merge: `.exr` keeps the exact sums (it can be merged again), `.png` is the
/// tone-mapped image.
///
/// # Errors
///
/// Exit code 2 for another extension; 1 when the file cannot be written.
pub fn write(render: &PartialRender, out: &Path) -> Result<(), Failure> {
    let ext = out
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let result = match ext.as_deref() {
        Some("exr") => {
            create_parent(out)?;
            render.write_exr(out)
        }
        Some("png") => {
            create_parent(out)?;
            render.film.to_image().write(out)
        }
        _ => {
            return Err(Failure::usage(format!(
                "--out must end in .exr or .png, got {}",
                out.display()
            )));
        }
    };
    result.map_err(Failure::run)
}

fn create_parent(out: &Path) -> Result<(), Failure> {
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .map_err(|e| Failure::run(format!("{}: {e}", dir.display())))?;
    }
    Ok(())
}

/// The summary line of a merge.
#[must_use]
pub fn summary(name: &str, parts: usize, out: &Path, render: &PartialRender) -> String {
    let status = if render.is_complete() {
        "complete".to_string()
    } else {
        format!(
            "incomplete: {} of {} spp",
            render.samples_held(),
            render.spp
        )
    };
    format!(
        "{name}: {parts} parts -> {} (samples {}, {status}; {} non-finite samples dropped, {} clamped): {}",
        out.display(),
        render.ranges_text(),
        render.film.non_finite_samples(),
        render.film.clamped_samples(),
        render.label
    )
}
