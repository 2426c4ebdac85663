//! Partial renders: films that hold a range of each pixel's sample indices, merged exactly.
//!
//! A render can be split by sample index: render `0..64` on one machine and `64..128` on another
//! (see [`RenderOptions::spp_range`](crate::RenderOptions#structfield.spp_range)), save each as a
//! partial EXR, and merge the files. Because the sampler's values depend only on (seed, pixel,
//! sample index, dimension) and the film's sums are fixed-point integers, the merged film equals
//! the film of one `0..128` render **bit for bit**, whatever the order of merging.
//!
//! ```
//! use pt_core::{render, PartialRender, RenderOptions};
//! # use pt_core::{BuiltinMaterial, Emission, Mesh, Object, PinholeCamera, Rgb, SceneBuilder};
//! # use pt_core::pt_accel::TriangleMesh;
//! # use pt_core::glam::Vec3;
//! # let mut b = SceneBuilder::new();
//! # let tri = b.add_mesh(Mesh::new(TriangleMesh::new(
//! #     vec![Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, -1.0, 0.0), Vec3::new(0.0, 1.0, 0.0)],
//! #     vec![[0, 1, 2]],
//! # )?));
//! # let m = b.add_material(BuiltinMaterial::diffuse(Rgb::splat(0.5)));
//! # b.add_object(Object::new(tri, m).with_emission(Emission::new(Rgb::splat(2.0))));
//! # let scene = b.build()?;
//! # let camera = PinholeCamera::look_at(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y, 30.0)?;
//! let options = RenderOptions::new(16, 16).spp(8).seed(3);
//! let whole = render(&scene, &camera, &options, None)?;
//! let mut merged = PartialRender::empty(&options, "triangle");
//! for range in [4..8, 0..4] {
//!     let part = render(&scene, &camera, &options.clone().spp_range(range), None)?;
//!     merged.merge(&PartialRender::new(&part, "triangle"))?;
//! }
//! assert!(merged.is_complete());
//! assert_eq!(merged.film, whole.film);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! # File format
//! A partial render is an ordinary OpenEXR file (feature `exr`) that any viewer shows: channels
//! `R`, `G`, `B` hold the pixel means as f32. Alongside them, 32-bit unsigned channels hold the
//! exact state: `pt.count` (samples in the pixel) and `pt.sum.{R,G,B}.{0..3}` (the 128-bit
//! fixed-point sums, least significant word first). The text attribute `pt.partial` holds the
//! fields, one `key=value` per line (backslash and line breaks escaped): `pt.format`
//! (`pt-partial-1`), `pt.spp`, `pt.seed`, `pt.ranges` (for example `0..64,128..192`),
//! `pt.label`, `pt.non_finite`, `pt.clamped` and `pt.saturated` say which samples the file
//! holds and of what. A render with auxiliary outputs ([`crate::aov`]) adds their means as
//! `albedo.{R,G,B}` and `normal.{X,Y,Z}` (f32) and their exact sums as `pt.aux.{albedo.R,
//! albedo.G, albedo.B, normal.X, normal.Y, normal.Z}.{0,1}` (64-bit fixed point with 32
//! fractional bits, two u32 words, least significant first). (Files written before 2026-12-02 hold each field as its own attribute;
//! they are read as well.)

// A list of sample ranges that holds one range is the common case here, not a mistake.
#![allow(clippy::single_range_in_vec_init)]

use std::fmt;
use std::ops::Range;

use crate::film::Film;
use crate::render::{RenderOptions, RenderOutput};

/// The film of a render of some sample ranges, with what is needed to merge it with others.
#[derive(Clone, Debug, PartialEq)]
pub struct PartialRender {
    /// The pixel sums and counts.
    pub film: Film,
    /// Samples per pixel of the complete render.
    pub spp: u32,
    /// The seed of the render.
    pub seed: u64,
    /// The sample-index ranges held, sorted, disjoint and not adjacent (adjacent ranges are
    /// joined).
    pub ranges: Vec<Range<u32>>,
    /// What was rendered (scene and settings, in the caller's words); only partials with equal
    /// labels merge, so that parts of different renders are not mixed by mistake.
    pub label: String,
}

/// Why two partial renders cannot be merged.
#[derive(Clone, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum MergeError {
    /// The images have different sizes.
    Size {
        /// Size of the render merged into.
        expected: (u32, u32),
        /// Size of the other.
        found: (u32, u32),
    },
    /// Different seeds: the parts are not pieces of one render.
    Seed {
        /// Seed of the render merged into.
        expected: u64,
        /// Seed of the other.
        found: u64,
    },
    /// Different total samples per pixel.
    Spp {
        /// Total spp of the render merged into.
        expected: u32,
        /// Total spp of the other.
        found: u32,
    },
    /// Different labels.
    Label {
        /// Label of the render merged into.
        expected: String,
        /// Label of the other.
        found: String,
    },
    /// Both hold some of the same samples (for example the same part merged twice).
    Overlap {
        /// A range held by both.
        range: Range<u32>,
    },
    /// One holds auxiliary outputs (albedo and normal) and the other not.
    Aovs {
        /// Whether the render merged into has them.
        expected: bool,
    },
}

impl fmt::Display for MergeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Size { expected, found } => write!(
                f,
                "image sizes differ: {}x{} and {}x{}",
                expected.0, expected.1, found.0, found.1
            ),
            Self::Seed { expected, found } => {
                write!(f, "seeds differ: {expected} and {found}")
            }
            Self::Spp { expected, found } => {
                write!(f, "total samples per pixel differ: {expected} and {found}")
            }
            Self::Label { expected, found } => {
                write!(f, "labels differ: {expected:?} and {found:?}")
            }
            Self::Aovs { expected } => write!(
                f,
                "{} has auxiliary outputs (albedo, normal) and the other not (render every part \
                 with the same --aov)",
                if *expected { "the first" } else { "the second" }
            ),
            Self::Overlap { range } => write!(
                f,
                "both hold samples {}..{} (was a part merged twice?)",
                range.start, range.end
            ),
        }
    }
}

impl std::error::Error for MergeError {}

impl PartialRender {
    /// The partial render of `output` (its sample range, total spp and seed are in its stats).
    #[must_use]
    pub fn new(output: &RenderOutput, label: impl Into<String>) -> Self {
        Self {
            film: output.film.clone(),
            spp: output.stats.total_spp,
            seed: output.stats.seed,
            ranges: vec![output.stats.sample_range.clone()],
            label: label.into(),
        }
    }

    /// A partial render that holds no samples yet, to merge parts into.
    #[must_use]
    pub fn empty<K>(options: &RenderOptions<K>, label: impl Into<String>) -> Self {
        Self {
            film: Film::new_with(options.width, options.height, options.aovs.any()),
            spp: options.spp,
            seed: options.seed,
            ranges: Vec::new(),
            label: label.into(),
        }
    }

    /// True when the ranges cover `0..spp`.
    #[must_use]
    pub fn is_complete(&self) -> bool {
        self.ranges == vec![0..self.spp]
    }

    /// Samples per pixel held.
    #[must_use]
    pub fn samples_held(&self) -> u32 {
        self.ranges.iter().map(|r| r.end - r.start).sum()
    }

    /// The sample ranges as text, for example `0..64,128..192` (empty when none).
    #[must_use]
    pub fn ranges_text(&self) -> String {
        self.ranges
            .iter()
            .map(|r| format!("{}..{}", r.start, r.end))
            .collect::<Vec<_>>()
            .join(",")
    }

    /// Add the samples of `other` (exact and order-independent). Fails, leaving `self`
    /// unchanged, when the two are not disjoint parts of the same render.
    pub fn merge(&mut self, other: &PartialRender) -> Result<(), MergeError> {
        let size = |f: &Film| (f.width(), f.height());
        if size(&self.film) != size(&other.film) {
            return Err(MergeError::Size {
                expected: size(&self.film),
                found: size(&other.film),
            });
        }
        if self.seed != other.seed {
            return Err(MergeError::Seed {
                expected: self.seed,
                found: other.seed,
            });
        }
        if self.spp != other.spp {
            return Err(MergeError::Spp {
                expected: self.spp,
                found: other.spp,
            });
        }
        if self.label != other.label {
            return Err(MergeError::Label {
                expected: self.label.clone(),
                found: other.label.clone(),
            });
        }
        if self.film.has_aux() != other.film.has_aux() {
            return Err(MergeError::Aovs {
                expected: self.film.has_aux(),
            });
        }
        for a in &self.ranges {
            for b in &other.ranges {
                let (lo, hi) = (a.start.max(b.start), a.end.min(b.end));
                if lo < hi {
                    return Err(MergeError::Overlap { range: lo..hi });
                }
            }
        }
        self.film.merge(&other.film);
        self.ranges = normalise(self.ranges.iter().chain(&other.ranges).cloned().collect());
        Ok(())
    }
}

/// Sort ranges and join the adjacent ones (they are already known to be disjoint).
pub(crate) fn normalise(mut ranges: Vec<Range<u32>>) -> Vec<Range<u32>> {
    ranges.retain(|r| r.start < r.end);
    ranges.sort_by_key(|r| r.start);
    let mut out: Vec<Range<u32>> = Vec::with_capacity(ranges.len());
    for r in ranges {
        match out.last_mut() {
            Some(last) if last.end >= r.start => last.end = last.end.max(r.end),
            _ => out.push(r),
        }
    }
    out
}

/// Parse `a..b,c..d` into ranges; `None` when malformed.
#[cfg_attr(not(feature = "exr"), allow(dead_code))]
pub(crate) fn parse_ranges(text: &str) -> Option<Vec<Range<u32>>> {
    if text.is_empty() {
        return Some(Vec::new());
    }
    text.split(',')
        .map(|part| {
            let (a, b) = part.trim().split_once("..")?;
            let (a, b) = (a.parse().ok()?, b.parse().ok()?);
            (a < b).then_some(a..b)
        })
        .collect()
}

/// The most pixels a partial render file may declare (as many as a render may have).
#[cfg_attr(not(feature = "exr"), allow(dead_code))]
pub(crate) const MAX_PARTIAL_PIXELS: u64 = 1 << 28;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::color::Rgb;

    fn part(range: Range<u32>, label: &str) -> PartialRender {
        let mut film = Film::new(2, 1);
        for i in range.clone() {
            film.add_sample(0, 0, Rgb::splat(i as f32 * 0.37));
            film.add_sample(1, 0, Rgb::new(1.0 / (i + 1) as f32, 2.0, 1e4));
        }
        PartialRender {
            film,
            spp: 8,
            seed: 1,
            ranges: vec![range],
            label: label.into(),
        }
    }

    #[test]
    fn merging_in_any_order_equals_the_whole() {
        let whole = part(0..8, "a");
        let mut m = part(6..8, "a");
        m.merge(&part(0..3, "a")).unwrap();
        assert_eq!(m.ranges, vec![0..3, 6..8]);
        assert!(!m.is_complete());
        m.merge(&part(3..6, "a")).unwrap();
        assert!(m.is_complete());
        assert_eq!(m.film, whole.film);
    }

    #[test]
    fn mismatches_are_refused() {
        let mut a = part(0..4, "a");
        let before = a.clone();
        assert!(matches!(
            a.merge(&part(2..6, "a")),
            Err(MergeError::Overlap { range }) if range == (2..4)
        ));
        assert!(matches!(
            a.merge(&part(4..8, "b")),
            Err(MergeError::Label { .. })
        ));
        let mut other = part(4..8, "a");
        other.seed = 2;
        assert!(matches!(a.merge(&other), Err(MergeError::Seed { .. })));
        other.seed = 1;
        other.spp = 16;
        assert!(matches!(a.merge(&other), Err(MergeError::Spp { .. })));
        other.spp = 8;
        other.film = Film::new(3, 1);
        assert!(matches!(a.merge(&other), Err(MergeError::Size { .. })));
        other.film = Film::with_aux(2, 1);
        assert!(matches!(
            a.merge(&other),
            Err(MergeError::Aovs { expected: false })
        ));
        assert_eq!(a, before, "a refused merge changes nothing");
    }

    #[test]
    fn ranges_parse_and_normalise() {
        assert_eq!(parse_ranges("0..4,8..12"), Some(vec![0..4, 8..12]));
        assert_eq!(parse_ranges(""), Some(vec![]));
        assert_eq!(parse_ranges("4..4"), None);
        assert_eq!(parse_ranges("x..4"), None);
        assert_eq!(normalise(vec![4..8, 0..4, 10..12]), vec![0..8, 10..12]);
    }
}
