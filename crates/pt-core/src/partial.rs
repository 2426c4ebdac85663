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
//! fixed-point sums, least significant word first). Header attributes `pt.format`
//! (`pt-partial-1`), `pt.spp`, `pt.seed`, `pt.ranges` (for example `0..64,128..192`),
//! `pt.label`, `pt.non_finite` and `pt.clamped` say which samples the file holds and of what.

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
            film: Film::new(options.width, options.height),
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
fn normalise(mut ranges: Vec<Range<u32>>) -> Vec<Range<u32>> {
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
fn parse_ranges(text: &str) -> Option<Vec<Range<u32>>> {
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
const MAX_PARTIAL_PIXELS: u64 = 1 << 28;

#[cfg(feature = "exr")]
mod file {
    use std::collections::HashMap;
    use std::path::Path;

    use exr::prelude::{
        AnyChannel, AnyChannels, AttributeValue, Encoding, FlatSamples, Image as ExrImage, Layer,
        LayerAttributes, ReadChannels, ReadLayers, SmallVec, Text, WritableImage, read,
    };

    use super::{MAX_PARTIAL_PIXELS, PartialRender, normalise, parse_ranges};
    use crate::film::{Film, PixelSum};
    use crate::image::ImageError;

    const FORMAT: &str = "pt-partial-1";
    const COLOURS: [&str; 3] = ["R", "G", "B"];

    fn decode(path: &Path, message: impl Into<String>) -> ImageError {
        ImageError::Decode {
            path: path.to_path_buf(),
            message: message.into(),
        }
    }

    fn exr_error(path: &Path, e: exr::error::Error) -> ImageError {
        match e {
            exr::error::Error::Io(source) => ImageError::Io {
                path: path.to_path_buf(),
                source,
            },
            other => decode(path, other.to_string()),
        }
    }

    impl PartialRender {
        /// Write as a partial EXR (see the [module documentation](crate::partial) for the
        /// layout): viewable as an image, and exact for [`PartialRender::read_exr`].
        pub fn write_exr(&self, path: impl AsRef<Path>) -> Result<(), ImageError> {
            let path = path.as_ref();
            let (w, h) = (self.film.width() as usize, self.film.height() as usize);
            let pixels = self.film.pixels();
            let mut channels: Vec<AnyChannel<FlatSamples>> = Vec::with_capacity(16);
            for (k, name) in COLOURS.iter().enumerate() {
                let mean = pixels.iter().map(|p| p.mean().to_array()[k]).collect();
                channels.push(AnyChannel::new(*name, FlatSamples::F32(mean)));
                for word in 0..4 {
                    let data = pixels
                        .iter()
                        .map(|p| (p.raw().0[k] as u128 >> (32 * word)) as u32)
                        .collect();
                    channels.push(AnyChannel::new(
                        format!("pt.sum.{name}.{word}").as_str(),
                        FlatSamples::U32(data),
                    ));
                }
            }
            let counts = pixels.iter().map(|p| p.raw().1).collect();
            channels.push(AnyChannel::new("pt.count", FlatSamples::U32(counts)));

            let mut attributes = LayerAttributes::named("pt partial render");
            let mut text = |key: &str, value: String| {
                attributes.other.insert(
                    Text::from(key),
                    AttributeValue::Text(Text::new_or_panic(value.as_str())),
                );
            };
            text("pt.format", FORMAT.to_string());
            text("pt.spp", self.spp.to_string());
            text("pt.seed", self.seed.to_string());
            text("pt.ranges", self.ranges_text());
            text("pt.label", self.label.clone());
            text("pt.non_finite", self.film.non_finite_samples().to_string());
            text("pt.clamped", self.film.clamped_samples().to_string());
            text("pt.saturated", self.film.saturated_samples().to_string());

            let layer = Layer::new(
                (w, h),
                attributes,
                Encoding::SMALL_LOSSLESS,
                AnyChannels::sort(SmallVec::from_vec(channels)),
            );
            ExrImage::from_layer(layer)
                .write()
                .to_file(path)
                .map_err(|e| exr_error(path, e))
        }

        /// Read a partial EXR written by [`PartialRender::write_exr`]. Errors name the file
        /// and what is wrong (not a partial render, missing channel, bad attribute, counts
        /// that disagree with the ranges).
        pub fn read_exr(path: impl AsRef<Path>) -> Result<Self, ImageError> {
            let path = path.as_ref();
            if !path.is_file() {
                return Err(ImageError::Io {
                    path: path.to_path_buf(),
                    source: std::io::Error::new(std::io::ErrorKind::NotFound, "no such file"),
                });
            }
            // The header first: a small file may claim a data window of 100000x100000 (40 GB
            // of channels); nothing is decoded for a window larger than a film can be.
            let meta =
                exr::meta::MetaData::read_from_file(path, false).map_err(|e| exr_error(path, e))?;
            for header in meta.headers.iter() {
                let (w, h) = (header.layer_size.0 as u64, header.layer_size.1 as u64);
                if w * h > MAX_PARTIAL_PIXELS {
                    return Err(decode(
                        path,
                        format!(
                            "its data window claims {w}x{h} pixels, more than a render can have \
                             ({MAX_PARTIAL_PIXELS})"
                        ),
                    ));
                }
            }
            let image = read()
                .no_deep_data()
                .largest_resolution_level()
                .all_channels()
                .first_valid_layer()
                .all_attributes()
                .from_file(path)
                .map_err(|e| exr_error(path, e))?;
            let layer = image.layer_data;
            let attrs: HashMap<String, String> = layer
                .attributes
                .other
                .iter()
                .filter_map(|(k, v)| match v {
                    AttributeValue::Text(t) => Some((k.to_string(), t.to_string())),
                    _ => None,
                })
                .collect();
            let get = |key: &str| {
                attrs
                    .get(key)
                    .ok_or_else(|| decode(path, format!("not a pt partial render (no {key})")))
            };
            if get("pt.format")? != FORMAT {
                return Err(decode(
                    path,
                    format!("unknown partial format {:?}", get("pt.format")?),
                ));
            }
            fn number<T: std::str::FromStr>(
                path: &Path,
                key: &str,
                v: &str,
            ) -> Result<T, ImageError> {
                v.parse()
                    .map_err(|_| decode(path, format!("attribute {key} is not a number: {v:?}")))
            }
            let spp: u32 = number(path, "pt.spp", get("pt.spp")?)?;
            let seed: u64 = number(path, "pt.seed", get("pt.seed")?)?;
            let non_finite: u64 = number(path, "pt.non_finite", get("pt.non_finite")?)?;
            let clamped: u64 = number(path, "pt.clamped", get("pt.clamped")?)?;
            // Absent in files written before it existed.
            let saturated: u64 = match attrs.get("pt.saturated") {
                Some(v) => number(path, "pt.saturated", v)?,
                None => 0,
            };
            let ranges_text = get("pt.ranges")?;
            // Ranges inside one file are disjoint: overlapping ones would count samples twice.
            if let Some(mut parsed) = parse_ranges(ranges_text) {
                parsed.sort_by_key(|r| r.start);
                if parsed.windows(2).any(|w| w[1].start < w[0].end) {
                    return Err(decode(
                        path,
                        format!("overlapping sample ranges {ranges_text:?}"),
                    ));
                }
            }
            let ranges = parse_ranges(ranges_text)
                .map(normalise)
                .filter(|r| r.iter().all(|r| r.end <= spp))
                .ok_or_else(|| {
                    decode(
                        path,
                        format!("bad sample ranges {ranges_text:?} for {spp} spp"),
                    )
                })?;
            let label = get("pt.label")?.clone();
            // The examples' labels name the spp; one that disagrees with the attribute was
            // edited.
            let words: Vec<&str> = label.split_whitespace().collect();
            if let Some(w) = words.windows(2).find(|w| w[0] == "spp")
                && w[1] != spp.to_string()
            {
                return Err(decode(
                    path,
                    format!("pt.spp is {spp} but the label says spp {}", w[1]),
                ));
            }

            let size = layer.size;
            let (w, h) = (
                u32::try_from(size.0).map_err(|_| decode(path, "image too wide"))?,
                u32::try_from(size.1).map_err(|_| decode(path, "image too tall"))?,
            );
            let n = size.0 * size.1;
            let channel = |name: &str| -> Result<&[u32], ImageError> {
                let c = layer
                    .channel_data
                    .list
                    .iter()
                    .find(|c| c.name.to_string() == name)
                    .ok_or_else(|| decode(path, format!("missing channel {name}")))?;
                match &c.sample_data {
                    FlatSamples::U32(v) if v.len() == n => Ok(v),
                    _ => Err(decode(
                        path,
                        format!("channel {name} is not {n} u32 samples"),
                    )),
                }
            };
            let counts = channel("pt.count")?;
            let mut words = Vec::with_capacity(12);
            for name in COLOURS {
                for word in 0..4 {
                    words.push(channel(&format!("pt.sum.{name}.{word}"))?);
                }
            }
            let held: u32 = ranges.iter().map(|r| r.end - r.start).sum();
            let mut pixels = Vec::with_capacity(n);
            for i in 0..n {
                if counts[i] != held {
                    return Err(decode(
                        path,
                        format!(
                            "pixel {} holds {} samples but the ranges {ranges_text:?} give {held}",
                            i, counts[i]
                        ),
                    ));
                }
                let mut sum = [0i128; 3];
                for (k, s) in sum.iter_mut().enumerate() {
                    let mut v = 0u128;
                    for word in 0..4 {
                        v |= u128::from(words[4 * k + word][i]) << (32 * word);
                    }
                    *s = v as i128;
                }

                pixels.push(PixelSum::from_raw(sum, counts[i]));
            }
            let mut film = Film::from_parts(w, h, pixels, non_finite, clamped);
            film.set_saturated(saturated);
            Ok(Self {
                film,
                spp,
                seed,
                ranges,
                label,
            })
        }
    }
}

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

    #[cfg(feature = "exr")]
    #[test]
    fn files_round_trip_exactly_and_bad_files_are_named() {
        let dir = std::env::temp_dir().join(format!("pt-partial-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        // Five samples per pixel, with values that stress the fixed-point sums.
        let mut film = Film::new(3, 2);
        for (i, l) in [
            Rgb::new(f32::NAN, 0.0, 0.0),
            Rgb::new(-2.5, 1e-19, 3e7),
            Rgb::splat(100.0),
            Rgb::new(0.1, 0.2, 0.3),
            Rgb::new(f32::MIN_POSITIVE, 1e-30, 65504.0),
        ]
        .into_iter()
        .enumerate()
        {
            for y in 0..2 {
                for x in 0..3 {
                    film.add_sample_clamped(x, y, l * (1.0 + (x + 3 * y + i as u32) as f32), 1e6);
                }
            }
        }
        let p = PartialRender {
            film,
            spp: 8,
            seed: u64::MAX - 3,
            ranges: vec![0..2, 5..8],
            label: "cornell, label with spaces".into(),
        };
        let path = dir.join("p.exr");
        p.write_exr(&path).unwrap();
        let back = PartialRender::read_exr(&path).unwrap();
        assert_eq!(back, p, "the file holds the film exactly");
        assert_eq!(back.film.non_finite_samples(), 6);
        assert!(back.film.clamped_samples() > 0);

        // Counts that disagree with the ranges: the file is refused, and named.
        let bad = dir.join("bad.exr");
        let mut r = p.clone();
        r.ranges = vec![0..6];
        r.write_exr(&bad).unwrap();
        let err = PartialRender::read_exr(&bad).unwrap_err().to_string();
        assert!(err.contains("bad.exr") && err.contains("samples"), "{err}");

        // Overlapping ranges inside one file would count samples twice.
        let overlap = dir.join("overlap.exr");
        let mut r = p.clone();
        r.ranges = vec![0..2, 1..4];
        r.write_exr(&overlap).unwrap();
        let err = PartialRender::read_exr(&overlap).unwrap_err().to_string();
        assert!(
            err.contains("overlap.exr") && err.contains("overlapping"),
            "{err}"
        );

        // A label that names another spp than the attribute was edited.
        let edited = dir.join("edited.exr");
        let mut r = p.clone();
        r.label = "cornell_box 3x2 spp 16 max-depth 8".into();
        r.write_exr(&edited).unwrap();
        let err = PartialRender::read_exr(&edited).unwrap_err().to_string();
        assert!(
            err.contains("edited.exr") && err.contains("spp 16"),
            "{err}"
        );

        // Saturated samples survive the file.
        let mut film = Film::new(1, 1);
        film.add_sample(0, 0, Rgb::splat(1e30));
        let s = PartialRender {
            film,
            spp: 1,
            seed: 0,
            ranges: vec![0..1],
            label: "saturated".into(),
        };
        let sat = dir.join("sat.exr");
        s.write_exr(&sat).unwrap();
        assert_eq!(
            PartialRender::read_exr(&sat)
                .unwrap()
                .film
                .saturated_samples(),
            1
        );

        // A data window claiming 100000x100000 pixels (40 GB of channels) in a small file is
        // refused from the header, before anything is allocated.
        let bomb = dir.join("bomb.exr");
        let mut bytes = std::fs::read(&path).unwrap();
        let key = b"dataWindow\0box2i\0";
        let at = bytes.windows(key.len()).position(|w| w == key).unwrap() + key.len() + 4;
        bytes[at + 8..at + 12].copy_from_slice(&99_999i32.to_le_bytes());
        bytes[at + 12..at + 16].copy_from_slice(&99_999i32.to_le_bytes());
        std::fs::write(&bomb, bytes).unwrap();
        let err = PartialRender::read_exr(&bomb).unwrap_err().to_string();
        assert!(
            err.contains("bomb.exr") && err.contains("100000x100000"),
            "{err}"
        );

        // A plain image is not a partial render.
        let plain = dir.join("plain.exr");
        crate::image::Image::new(2, 2).write_exr(&plain).unwrap();
        let err = PartialRender::read_exr(&plain).unwrap_err().to_string();
        assert!(
            err.contains("plain.exr") && err.contains("not a pt partial"),
            "{err}"
        );
        let err = PartialRender::read_exr(dir.join("missing.exr"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("missing.exr"), "{err}");
        std::fs::write(dir.join("junk.exr"), b"not an exr").unwrap();
        let err = PartialRender::read_exr(dir.join("junk.exr"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("junk.exr"), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
